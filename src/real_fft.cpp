// Real-input transforms of a whole record for R/spectrum.R (the record's
// periodogram, the bands brought to their background): the series
// zero-padded to a power of two, two samples packed in each complex point
// and transformed by the package's FFT (src/fft.h) at half the length,
// then separated (Press et al., Numerical Recipes, sec. 12.3). R's fft()
// takes 0.12 s for 1e6 points and is quadratic in a large prime factor.
#include <Rcpp.h>
#include "fft.h"
#include <cmath>

namespace {

using allanvar::cplx;

// e^{-i pi k / m} for k = 0..m (m = n / 2 >= 2) from the plan's twiddles
// of size m, e^{-2 pi i j / m} for j < m / 2: the even k are those, an odd
// one the even one below it times e^{-i pi / m}; the second half by
// w[m - k] = -conj(w[k]).
void half_twiddles(std::vector<cplx>& w, const allanvar::FFTPlan& plan, size_t m) {
  const double pi = 3.14159265358979323846;
  const cplx* t = plan.twiddles();
  const cplx step(std::cos(pi / static_cast<double>(m)), -std::sin(pi / static_cast<double>(m)));
  w.resize(m + 1);
  for (size_t k = 0; 2 * k <= m; ++k) {
    w[k] = (k % 2 == 0) ? t[k / 2] : t[k / 2] * step;
    w[m - k] = -std::conj(w[k]);
  }
}

// The plan and half twiddles of the last size, kept between calls: the
// loop transforms records of one length several times per axis, and the
// twiddles' cosines cost a third of a transform. (R's main thread only.)
struct RecordPlan {
  size_t m = 0;
  allanvar::FFTPlan plan;
  std::vector<cplx> w;
};

const RecordPlan& record_plan(size_t m) {
  static RecordPlan rp;
  if (rp.m != m) {
    rp.m = 0;
    rp.plan.reset(m);
    half_twiddles(rp.w, rp.plan, m);
    rp.m = m;
  }
  return rp;
}

bool valid_size(double n, R_xlen_t len) {
  if (!(n >= 4) || n > 4503599627370496.0 || n < static_cast<double>(len)) return false;
  const size_t m = static_cast<size_t>(n);
  return static_cast<double>(m) == n && (m & (m - 1)) == 0;
}

}  // namespace

// The DFT at bins 0..n/2 of x zero-padded to n points (n a power of two,
// at least 4 and length(x)): X_k = sum_j x_j e^{-2 pi i j k / n}.
// [[Rcpp::export(rng = false)]]
Rcpp::ComplexVector real_fft_cpp(const Rcpp::NumericVector& x, double n) {
  const R_xlen_t len = x.size();
  if (!valid_size(n, len)) Rcpp::stop("real_fft_cpp: bad transform size");
  const size_t m = static_cast<size_t>(n) / 2;
  allanvar::cvec z(m);
  const double* v = x.begin();
  for (size_t j = 0; j < m; ++j) {
    const R_xlen_t a = static_cast<R_xlen_t>(2 * j);
    z[j] = cplx(a < len ? v[a] : 0.0, a + 1 < len ? v[a + 1] : 0.0);
  }
  const RecordPlan& rp = record_plan(m);
  rp.plan.run(z.data(), false);
  const std::vector<cplx>& w = rp.w;
  Rcpp::ComplexVector out(static_cast<R_xlen_t>(m + 1));
  cplx* o = reinterpret_cast<cplx*>(out.begin());
  const cplx half_i(0.0, -0.5);
  for (size_t k = 0; k <= m; ++k) {
    const cplx zk = z[k % m];
    const cplx zc = std::conj(z[(m - k) % m]);
    // the even samples' transform and the odd ones'
    const cplx e = 0.5 * (zk + zc);
    const cplx d = half_i * (zk - zc);
    o[k] = e + w[k] * d;
  }
  return out;
}

// The real series whose DFT at bins 0..n/2 is X (n a power of two, the
// other bins their mirrors' conjugates), without the 1/n factor (as R's
// fft(inverse = TRUE)); its first `keep` samples.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector real_ifft_cpp(const Rcpp::ComplexVector& X, double n, double keep) {
  if (!valid_size(n, 0) || X.size() != static_cast<R_xlen_t>(n / 2 + 1) ||
      !(keep >= 0 && keep <= n)) {
    Rcpp::stop("real_ifft_cpp: bad transform size");
  }
  const size_t m = static_cast<size_t>(n) / 2;
  const cplx* x = reinterpret_cast<const cplx*>(X.begin());
  const RecordPlan& rp = record_plan(m);
  const std::vector<cplx>& w = rp.w;
  allanvar::cvec z(m);
  for (size_t k = 0; k < m; ++k) {
    const cplx xk = x[k];
    const cplx xc = std::conj(x[m - k]);
    const cplx e = 0.5 * (xk + xc);
    const cplx d = 0.5 * (xk - xc) * std::conj(w[k]);
    z[k] = e + cplx(-d.imag(), d.real());  // e + i d
  }
  rp.plan.run(z.data(), true);
  const R_xlen_t nk = static_cast<R_xlen_t>(keep);
  Rcpp::NumericVector out(nk);
  double* o = out.begin();
  for (R_xlen_t j = 0; j < nk; ++j) {
    const cplx zj = z[static_cast<size_t>(j / 2)];
    o[j] = 2.0 * ((j % 2 == 0) ? zj.real() : zj.imag());
  }
  return out;
}
