// Periodogram lines (R/spectrum.R, remove_lines()): the sums of the least-squares fit of a
// sinusoid a sin(2 pi f t) + b cos(2 pi f t) to a series, t = j / freq,
// without evaluating sin and cos at every sample: within blocks of 256
// samples the phase advances by a rotation (angle addition), and each block
// starts from sin/cos evaluated directly, so rounding cannot accumulate over
// the record. remove_lines() calls line_sums() about 20 times per line.
#include <Rcpp.h>
#include <algorithm>
#include <cmath>

namespace {
// R's pi (M_PI is POSIX, not standard C++)
constexpr double kPi = 3.141592653589793238462643383279502884;

// The phases of four interleaved samples j + q (q = 0..3) within a block:
// each lane advances by the rotation of 4 w, so the four rotations are
// independent and run side by side (one lane's rotation waits on its own
// last step only). Each block starts from sin/cos evaluated directly at
// 2 pi f ((j0 + q) / freq).
struct Phases4 {
  double s[4], c[4];
  double c4, s4;
  Phases4(double f, double freq) {
    const double w4 = 2.0 * kPi * f * (4.0 / freq);
    c4 = std::cos(w4);
    s4 = std::sin(w4);
  }
  void start(double f, double freq, R_xlen_t j0) {
    for (int q = 0; q < 4; ++q) {
      const double th = 2.0 * kPi * f * (static_cast<double>(j0 + q) / freq);
      s[q] = std::sin(th);
      c[q] = std::cos(th);
    }
  }
  void advance() {
    for (int q = 0; q < 4; ++q) {
      const double s1 = s[q] * c4 + c[q] * s4;
      c[q] = c[q] * c4 - s[q] * s4;
      s[q] = s1;
    }
  }
};

const R_xlen_t kBlock = 256;  // a multiple of 4
}  // namespace

// c(sum s^2, sum c^2, sum s c, sum s y, sum c y) with s = sin(2 pi f j /
// freq), c = cos(...), j = 0..n-1; each sum kept per lane, added at the
// end.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector line_sums(const Rcpp::NumericVector& y, double f, double freq) {
  const R_xlen_t n = y.size();
  Phases4 ph(f, freq);
  double ss[4] = {0, 0, 0, 0}, cc[4] = {0, 0, 0, 0}, sc[4] = {0, 0, 0, 0},
         sy[4] = {0, 0, 0, 0}, cy[4] = {0, 0, 0, 0};
  const double* v = y.begin();
  // sample j + q in lane q
  auto add = [&](int q, R_xlen_t j) {
    const double s = ph.s[q], c = ph.c[q], x = v[j + q];
    ss[q] += s * s;
    cc[q] += c * c;
    sc[q] += s * c;
    sy[q] += s * x;
    cy[q] += c * x;
  };
  for (R_xlen_t j0 = 0; j0 < n; j0 += kBlock) {
    const R_xlen_t j1 = std::min(n, j0 + kBlock);
    ph.start(f, freq, j0);
    R_xlen_t j = j0;
    for (; j + 4 <= j1; j += 4) {
      for (int q = 0; q < 4; ++q) add(q, j);
      ph.advance();
    }
    for (int q = 0; j + q < j1; ++q) add(q, j);
    if ((j0 & 0xFFFFF) == 0) Rcpp::checkUserInterrupt();
  }
  auto total = [](const double* a) { return (a[0] + a[1]) + (a[2] + a[3]); };
  return Rcpp::NumericVector::create(total(ss), total(cc), total(sc), total(sy),
                                     total(cy));
}

// y - a sin(2 pi f t) - b cos(2 pi f t), t = j / freq, j = 0..n-1: one
// fitted line taken out (remove_lines()), the phases advanced as in
// line_sums() (equal to the direct sin and cos to about 1e-13).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector line_subtract(const Rcpp::NumericVector& y, double f, double freq,
                                  double a, double b) {
  const R_xlen_t n = y.size();
  Phases4 ph(f, freq);
  Rcpp::NumericVector out(n);
  const double* v = y.begin();
  double* o = out.begin();
  for (R_xlen_t j0 = 0; j0 < n; j0 += kBlock) {
    const R_xlen_t j1 = std::min(n, j0 + kBlock);
    ph.start(f, freq, j0);
    R_xlen_t j = j0;
    for (; j + 4 <= j1; j += 4) {
      for (int q = 0; q < 4; ++q) o[j + q] = (v[j + q] - a * ph.s[q]) - b * ph.c[q];
      ph.advance();
    }
    for (int q = 0; j + q < j1; ++q) o[j + q] = (v[j + q] - a * ph.s[q]) - b * ph.c[q];
    if ((j0 & 0xFFFFF) == 0) Rcpp::checkUserInterrupt();
  }
  return out;
}
