// Periodogram lines (R/lines.R): the sums of the least-squares fit of a
// sinusoid a sin(2 pi f t) + b cos(2 pi f t) to a series, t = j / freq,
// without evaluating sin and cos at every sample: within blocks of 256
// samples the phase advances by a rotation (angle addition), and each block
// starts from sin/cos evaluated directly, so rounding cannot accumulate over
// the record. remove_lines() calls this about 20 times per line.
#include <Rcpp.h>
#include <algorithm>
#include <cmath>

namespace {
// R's pi (M_PI is POSIX, not standard C++)
constexpr double kPi = 3.141592653589793238462643383279502884;
}  // namespace

// c(sum s^2, sum c^2, sum s c, sum s y, sum c y) with s = sin(2 pi f j /
// freq), c = cos(...), j = 0..n-1.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector line_sums(const Rcpp::NumericVector& y, double f, double freq) {
  const R_xlen_t n = y.size();
  const double w = 2.0 * kPi * f / freq;
  const double cd = std::cos(w), sd = std::sin(w);
  const R_xlen_t block = 256;
  double ss = 0, cc = 0, sc = 0, sy = 0, cy = 0;
  const double* v = y.begin();
  for (R_xlen_t j0 = 0; j0 < n; j0 += block) {
    const R_xlen_t j1 = std::min(n, j0 + block);
    // the block's first phase as R computes it: 2 pi f (j0 / freq)
    const double th = 2.0 * kPi * f * (static_cast<double>(j0) / freq);
    double s = std::sin(th), c = std::cos(th);
    for (R_xlen_t j = j0; j < j1; ++j) {
      ss += s * s;
      cc += c * c;
      sc += s * c;
      sy += s * v[j];
      cy += c * v[j];
      const double s1 = s * cd + c * sd;
      c = c * cd - s * sd;
      s = s1;
    }
    if ((j0 & 0xFFFFF) == 0) Rcpp::checkUserInterrupt();
  }
  return Rcpp::NumericVector::create(ss, cc, sc, sy, cy);
}

// y - a sin(2 pi f t) - b cos(2 pi f t), t = j / freq, j = 0..n-1: one
// fitted line taken out (remove_lines()), sin and cos evaluated at every
// sample in the order of operations of the R expression it replaces, so
// the result is the same to the bit, without its six temporary vectors.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector line_subtract(const Rcpp::NumericVector& y, double f, double freq,
                                  double a, double b) {
  const R_xlen_t n = y.size();
  const double w = 2.0 * kPi * f;
  Rcpp::NumericVector out(n);
  const double* v = y.begin();
  double* o = out.begin();
  for (R_xlen_t j = 0; j < n; ++j) {
    const double th = w * (static_cast<double>(j) / freq);
    const double s = a * std::sin(th);
    const double c = b * std::cos(th);
    o[j] = (v[j] - s) - c;
    if ((j & 0xFFFFF) == 0) Rcpp::checkUserInterrupt();
  }
  return out;
}
