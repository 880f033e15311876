// A resonance's two-sided PSD (R/resonance.R, resonance_psd()) at every
// frequency, in real arithmetic (band removal evaluates it on every bin
// of a record's FFT).
#include <Rcpp.h>
#include "r_complex.h"
#include <cmath>
#include <complex>
#include <vector>

// The real AR(2) with poles r exp(+-i w0), r = exp(-tau0 / tc),
// w0 = 2 pi fr tau0, variance sigma^2:
//   tau0 s_e^2 / (D(w0 - w) D(-w0 - w)),  w = 2 pi f tau0,
//   D(d) = |1 - r exp(i d)|^2 = (1 - r)^2 + 4 r sin(d / 2)^2,
//   s_e^2 = sigma^2 (1 - r^2) ((1 - r^2)^2 + 4 r^2 sin(w0)^2) / (1 + r^2)
// (|1 - p^2|^2 written without cancellation), with 1 - r from expm1: no
// digits lost where r is near 1 and d near 0 (a long tc at its peak).
namespace {

// The PSD above at n frequencies f into out.
void resonance_psd_into(const double* f, R_xlen_t n, double tau0, double sigma,
                        double fr, double tc, double* out) {
  const double pi = 3.141592653589793238462643383279502884;
  const double a = -std::expm1(-tau0 / tc);  // 1 - r
  const double r = 1.0 - a;
  const double a2 = a * a, r4 = 4.0 * r;
  // d / 2 = (+-w0 - w) / 2: both sines from one sine and cosine of w / 2
  const double h0 = pi * fr * tau0;
  const double sa = std::sin(h0), ca = std::cos(h0);
  const double s0 = 2.0 * sa * ca;           // sin(w0)
  const double q = a * (1.0 + r);            // 1 - r^2
  const double se2 = q * (q * q + 4.0 * r * r * s0 * s0) / (1.0 + r * r);
  const double scale = tau0 * (sigma * sigma) * se2;
  for (R_xlen_t k = 0; k < n; k++) {
    const double b = pi * f[k] * tau0;
    const double sb = std::sin(b), cb = std::cos(b);
    const double h1 = sa * cb - ca * sb;  // sin((w0 - w) / 2)
    const double h2 = sa * cb + ca * sb;  // -sin((-w0 - w) / 2)
    out[k] = scale / ((a2 + r4 * h1 * h1) * (a2 + r4 * h2 * h2));
    if ((k & 0xFFFFF) == 0) Rcpp::checkUserInterrupt();
  }
}

}  // namespace

// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector resonance_psd_cpp(const Rcpp::NumericVector& f, double tau0,
                                      double sigma, double fr, double tc) {
  Rcpp::NumericVector out(f.size());
  resonance_psd_into(f.begin(), f.size(), tau0, sigma, fr, tc, out.begin());
  return out;
}

// The objective of the band fits (R/spectrum.R, fit_resonance_psd() and
// band_pair_fit()): resonances from q = (log sigma, fr, log tc) each, their
// one-sided PSD 2 S(f) summed in order, and sum(((ex - M) / bg)^2) (R's
// sum() in long double); Nelder-Mead evaluates it hundreds of times a fit.
// [[Rcpp::export(rng = false)]]
double resonance_fit_obj_cpp(const Rcpp::NumericVector& q, const Rcpp::NumericVector& f,
                             const Rcpp::NumericVector& ex, const Rcpp::NumericVector& bg,
                             double tau0) {
  const R_xlen_t n = f.size();
  const R_xlen_t k = q.size() / 3;
  if (k < 1 || q.size() != 3 * k || ex.size() != n || bg.size() != n) {
    Rcpp::stop("resonance_fit_obj_cpp: bad arguments");
  }
  std::vector<double> M(n), m(n);
  for (R_xlen_t j = 0; j < k; j++) {
    resonance_psd_into(f.begin(), n, tau0, std::exp(q[3 * j]), q[3 * j + 1],
                       std::exp(q[3 * j + 2]), m.data());
    for (R_xlen_t i = 0; i < n; i++) M[i] = j == 0 ? 2 * m[i] : M[i] + 2 * m[i];
  }
  long double s = 0.0;
  for (R_xlen_t i = 0; i < n; i++) {
    const double d = (ex[i] - M[i]) / bg[i];
    s += d * d;
  }
  return static_cast<double>(s);
}

// A resonance's Allan variance at cluster sizes m (R/resonance.R,
// resonance_av()): Re(geometric_av(m, A, p)), p = exp(-tau0 / tc) *
// exp(1i * 2 * pi * fr * tau0), A = sigma^2 (1 - i c) with
// c = (1 - r^2) / (1 + r^2) / tan(2 * pi * fr * tau0), the R expressions' operations in their
// order and in R's complex arithmetic (each real promoted to complex before
// a product or sum), so the values are R's; the loop's searches evaluate it
// at every value they visit.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector resonance_av_cpp(const Rcpp::NumericVector& m, double tau0,
                                     double sigma, double fr, double tc) {
  typedef std::complex<double> cplx;
  const double pi = 3.141592653589793238462643383279502884;
  cplx w = cplx(0.0, 1.0) * cplx(2.0, 0.0);
  w = w * cplx(pi, 0.0);
  w = w * cplx(fr, 0.0);
  w = w * cplx(tau0, 0.0);
  const cplx p = cplx(std::exp(-tau0 / tc), 0.0) * std::exp(w);
  // resonance_c(): r^2 is r * r in R's arithmetic
  const double r = std::exp(-tau0 / tc);
  const double c = (1.0 - r * r) / (1.0 + r * r) / std::tan(2.0 * pi * fr * tau0);
  const double s2 = sigma * sigma;
  const cplx A(s2, -(s2 * c));
  const allanvar::GeometricAv geom(A, p);
  const R_xlen_t n = m.size();
  Rcpp::NumericVector out(n);
  for (R_xlen_t i = 0; i < n; i++) out[i] = geom(m[i]).real();
  return out;
}
