// A resonance's two-sided PSD (R/resonance.R, resonance_psd()) at every
// frequency: the R expression's operations in their order, in the complex
// arithmetic R uses (C99: the compiler's complex product, libgcc's
// division, the C library's cexp), so the values are R's; without R's
// complex vectors (band removal evaluates it on half a million bins).
#include <Rcpp.h>
#include <complex>

// tau0 * sigma^2 * 0.5 * (one(w0 - w) + one(-w0 - w)), w = 2 pi f tau0,
// one(d) = Re((1 + q) / (1 - q)), q = r exp(1i * d), r = exp(-tau0 / tc)
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector resonance_psd_cpp(const Rcpp::NumericVector& f, double tau0,
                                      double sigma, double fr, double tc) {
  typedef std::complex<double> cplx;
  const double pi = 3.141592653589793238462643383279502884;
  const double r = std::exp(-tau0 / tc);
  const double w0 = 2 * pi * fr * tau0;
  const double scale = tau0 * (sigma * sigma) * 0.5;
  const cplx one_c(1.0, 0.0), i_c(0.0, 1.0), r_c(r, 0.0);
  auto one = [&](double d) {
    // R promotes the reals to complex before each product and sum
    const cplx q = r_c * std::exp(i_c * cplx(d, 0.0));
    return ((one_c + q) / (one_c - q)).real();
  };
  const R_xlen_t n = f.size();
  Rcpp::NumericVector out(n);
  for (R_xlen_t k = 0; k < n; k++) {
    const double w = 2 * pi * f[k] * tau0;
    out[k] = scale * (one(w0 - w) + one(-w0 - w));
  }
  return out;
}
