// Periodogram lines (R/spectrum.R, remove_lines()): the least-squares fit
// of a sinusoid a sin(2 pi f t) + b cos(2 pi f t) to a series, t = j /
// freq, and its removal, without evaluating sin and cos at every sample:
// within blocks the phase advances by a rotation (angle addition), and each
// block starts from sin/cos evaluated directly, so rounding cannot
// accumulate over the record.
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

// y - a sin(2 pi f t) - b cos(2 pi f t), t = j / freq, j = 0..n-1: one
// fitted line taken out (remove_lines()), the phases advanced in blocks of
// 256 (equal to the direct sin and cos to about 1e-13).
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

// ---- a line's sums near a frequency from block moments -------------------------
// fit_lines() maximises a line's least-squares power over f within a few
// Fourier bins of f0, about 17 evaluations. Demodulated at f0 once, the
// record's sum at any f near it follows from a few moments per block:
//   sum_j y_j e^{-i w j} = sum_b e^{-i d c_b} sum_k (-i d h)^k / k! M_bk,
//   M_bk = sum_{j in b} y_j e^{-i w0 j} v_j^k,  v_j = (j - c_b) / h,
// with d = w - w0, c_b the block's centre and h its half-width; the series
// stops at kMoments terms, whose remainder (|d h| <= kMaxArg) is below
// 1e-17 relative. Blocks are as long as that allows (796 samples at 1e6,
// f within 2 bins), so an evaluation costs O(n / 800).
namespace {
const int kMoments = 6;
const double kMaxArg = 0.005;  // kMaxArg^6 / 6! = 2e-17
}  // namespace

// Moments of `y` demodulated at `f0` for evaluations at |f - f0| <= span.
// [[Rcpp::export(rng = false)]]
Rcpp::List line_moments(const Rcpp::NumericVector& y, double f0, double freq, double span) {
  const R_xlen_t n = y.size();
  const double dmax = 2.0 * kPi * span / freq;
  // half-width h with dmax h <= kMaxArg, block length 2h + 1 at most
  const double hmax = dmax > 0 ? kMaxArg / dmax : static_cast<double>(n);
  R_xlen_t L = static_cast<R_xlen_t>(std::floor(2.0 * hmax)) + 1;
  L = std::max<R_xlen_t>(1, std::min<R_xlen_t>(L, n));
  const R_xlen_t nb = (n + L - 1) / L;
  Rcpp::NumericVector centre(nb), half(nb);
  Rcpp::NumericMatrix re(nb, kMoments), im(nb, kMoments);
  const double* v = y.begin();
  Phases4 ph(f0, freq);
  for (R_xlen_t b = 0; b < nb; ++b) {
    const R_xlen_t j0 = b * L, j1 = std::min(n, j0 + L);
    const double c = 0.5 * static_cast<double>(j0 + j1 - 1);
    const double h = std::max(0.5 * static_cast<double>(j1 - 1 - j0), 1.0);
    const double ih = 1.0 / h;
    centre[b] = c;
    half[b] = h;
    // e^{-i w0 j} = cos - i sin, four interleaved lanes as in line_subtract()
    ph.start(f0, freq, j0);
    double mr[4][kMoments] = {{0}}, mi[4][kMoments] = {{0}};
    auto add = [&](int q, R_xlen_t j) {
      const double zr = v[j] * ph.c[q], zi = -v[j] * ph.s[q];
      const double u = (static_cast<double>(j) - c) * ih;
      double p = 1.0;
      for (int k = 0; k < kMoments; ++k) {
        mr[q][k] += zr * p;
        mi[q][k] += zi * p;
        p *= u;
      }
    };
    R_xlen_t j = j0;
    for (; j + 4 <= j1; j += 4) {
      for (int q = 0; q < 4; ++q) add(q, j + q);
      ph.advance();
    }
    for (int q = 0; j + q < j1; ++q) add(q, j + q);
    for (int k = 0; k < kMoments; ++k) {
      re(b, k) = (mr[0][k] + mr[1][k]) + (mr[2][k] + mr[3][k]);
      im(b, k) = (mi[0][k] + mi[1][k]) + (mi[2][k] + mi[3][k]);
    }
    if ((b & 0x3FF) == 0) Rcpp::checkUserInterrupt();
  }
  return Rcpp::List::create(Rcpp::_["f0"] = f0, Rcpp::_["freq"] = freq,
                            Rcpp::_["span"] = span, Rcpp::_["n"] = static_cast<double>(n),
                            Rcpp::_["centre"] = centre, Rcpp::_["half"] = half,
                            Rcpp::_["re"] = re, Rcpp::_["im"] = im);
}

// c(sum s^2, sum c^2, sum s c, sum s y, sum c y), s = sin(2 pi f j / freq),
// c = cos(...), j = 0..n-1, of the series line_moments() read, at f
// (|f - f0| <= span): the sums with y from the moments, those of sin and cos alone in closed
// form (sum_j e^{2 i w j} = e^{i (n - 1) w} sin(n w) / sin(w)).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector line_sums_near(const Rcpp::List& mom, double f) {
  const double f0 = Rcpp::as<double>(mom["f0"]), freq = Rcpp::as<double>(mom["freq"]);
  const double span = Rcpp::as<double>(mom["span"]), n = Rcpp::as<double>(mom["n"]);
  if (!(std::fabs(f - f0) <= span * (1 + 1e-9))) {
    Rcpp::stop("line_sums_near(): f is farther from f0 than the moments allow");
  }
  const Rcpp::NumericVector centre = mom["centre"], half = mom["half"];
  const Rcpp::NumericMatrix re = mom["re"], im = mom["im"];
  const R_xlen_t nb = centre.size();
  const double d = 2.0 * kPi * (f - f0) / freq;
  double sr = 0, si = 0;
  for (R_xlen_t b = 0; b < nb; ++b) {
    // sum_k (-i d h)^k / k! M_k, by Horner in (-i d h)
    const double a = d * half[b];
    double pr = re(b, kMoments - 1), pi = im(b, kMoments - 1);
    for (int k = kMoments - 2; k >= 0; --k) {
      // (pr + i pi) * (-i a) / (k + 1) + M_k
      const double qr = pi * a / (k + 1), qi = -pr * a / (k + 1);
      pr = qr + re(b, k);
      pi = qi + im(b, k);
    }
    // times e^{-i d c_b}
    const double ph = d * centre[b];
    const double cb = std::cos(ph), sb = std::sin(ph);
    sr += pr * cb + pi * sb;
    si += pi * cb - pr * sb;
  }
  const double w = 2.0 * kPi * f / freq;
  const double sw = std::sin(w);
  // sin(n w) / sin(w): n at w = 0 or pi (then the sine column is 0)
  const double dir = std::fabs(sw) > 1e-300 ? std::sin(n * w) / sw : n;
  const double dr = dir * std::cos((n - 1) * w), di = dir * std::sin((n - 1) * w);
  return Rcpp::NumericVector::create(0.5 * (n - dr), 0.5 * (n + dr), 0.5 * di, -si, sr);
}
