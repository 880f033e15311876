// Power-law noise identification at one averaging factor m, as NIST SP 1065
// (section 5.6) and Stable32 do it:
//  * the lag-1 autocorrelation method of Riley & Greenhall (2004, EFTF,
//    "Power law noise identification using the lag 1 autocorrelation") on
//    the WHOLE decimated series (phase data: every m-th phase point,
//    quadratic detrend; frequency data: averages of m samples, linear
//    detrend) while it has at least kAcfMinPoints (64) points;
//  * below that, Barnes' B1 ratio (standard / Allan variance of the averaged
//    frequencies; Barnes 1969, Howe et al. 2000 Table 3), with the R(n)
//    ratio MVAR/AVAR to tell white from flicker PM (SP 1065 5.6.1).
// Every m is identified from the data alone, never copied from another m.
//
// Use: identify_noise(x, L, m, dmax, phase_data, rn) with x(k) the phase at
// k = 0 .. L-1 (any constant offset; for frequency data the running sum of
// the samples, L = N + 1) and an RnCache filled once from the same phase
// when some m has fewer than kAcfMinPoints points (needs_b1()).
#ifndef ALLANVAR_NOISE_ID_H
#define ALLANVAR_NOISE_ID_H

#include <Rcpp.h>
#include <cmath>
#include <vector>

namespace allanvar {

enum NoiseIdMethod {
  NOISE_ID_NONE = 0,   // too few points (< 3 averaged frequencies)
  NOISE_ID_ACF = 1,    // lag-1 autocorrelation
  NOISE_ID_B1 = 2,     // B1 ratio
  NOISE_ID_B1_RN = 3   // B1 ratio, white/flicker PM told apart by R(n)
};

struct NoiseId {
  double alpha = NA_REAL;       // continuous estimate (ACF), else = alpha_int
  int alpha_int = NA_INTEGER;   // exponent of the frequency PSD, S_y ~ f^alpha
  int method = NOISE_ID_NONE;
  R_xlen_t points = 0;          // length of the series it was read from
};

// Allantools and Stable32 use the lag-1 ACF from 30 points on. Between 30
// and 63 points it misreads white FM often enough (r1 has standard error
// 1/sqrt(n)) to push the 68% coverage of overlapping ADEV below 0.65 (Monte
// Carlo, N = 1024; tests/testthat/test-edf.R), and with 64 more Stable32
// limits agree (377 against 374 of 402 rows), so B1 and R(n) take over
// below 64 points.
const R_xlen_t kAcfMinPoints = 64;

// Lag-1 ACF method on z[0..n): decimated phase (phase = true) or averaged
// frequency. dmax: most differences taken (2 for Allan, 3 for Hadamard).
NoiseId acf_noise_id(const double* z, R_xlen_t n, bool phase, int dmax);

// B1 ratio of the averaged frequencies ybar[0..n); rn() gives MVAR/AVAR at
// m, called only when B1 points to white or flicker PM (NaN: unavailable).
double b1_ratio(const double* ybar, R_xlen_t n);
int b1_mu(double b1, R_xlen_t n, int dmax);   // tau exponent mu of AVAR
double b1_theory(double N, int mu);
double rn_theory(double m, int alpha);          // expected MVAR/AVAR
int rn_alpha(double rn, double m);              // alpha from R(n)

// Phase values at a coarse grid (step s, at most ~4096 points) and their
// prefix sums, for R(n) at long averaging factors (m >= L/30, so the window
// lengths are rounded to the grid by at most 1/136 of m).
class RnCache {
 public:
  void init(R_xlen_t L) {
    L_ = L;
    s_ = L > 4096 ? L / 4096 : 1;
    k_ = 0;
    sum_ = 0;
    X_.clear();
    P_.clear();
    X_.reserve(L / s_ + 2);
    P_.reserve(L / s_ + 2);
  }
  bool empty() const { return X_.empty(); }
  // The phase at k = 0, 1, ..., L-1, in order.
  void push(double xk) {
    if (k_ % s_ == 0) {
      X_.push_back(xk);
      P_.push_back(sum_);
    }
    sum_ += xk;
    if (++k_ == L_ && L_ % s_ == 0) P_.push_back(sum_);
  }
  // MVAR/AVAR at (about) m; NaN when the record holds less than 4 m phase
  // points (the MVAR terms would all overlap: one effective sample).
  double ratio(R_xlen_t m) const;

 private:
  R_xlen_t L_ = 0, s_ = 1, k_ = 0;
  long double sum_ = 0;
  std::vector<long double> X_, P_;
};

// The decimated series for the ACF has this many points at m.
inline R_xlen_t acf_points(R_xlen_t L, R_xlen_t m, bool phase) {
  return phase ? (L - 1) / m + 1 : (L - 1) / m;
}

inline bool needs_b1(R_xlen_t L, R_xlen_t m, bool phase) {
  return acf_points(L, m, phase) < kAcfMinPoints;
}

// B1 (and R(n)) from the decimated series z (phase or averaged frequency).
template <class RN>
NoiseId b1_noise_id(const double* z, R_xlen_t n, bool phase, R_xlen_t m,
                    int dmax, RN rn) {
  NoiseId out;
  out.points = n;
  std::vector<double> ybar;
  if (phase) {
    for (R_xlen_t i = 0; i + 1 < n; ++i) ybar.push_back(z[i + 1] - z[i]);
  } else {
    ybar.assign(z, z + n);
  }
  const R_xlen_t na = static_cast<R_xlen_t>(ybar.size());
  if (na < 3) return out;
  const double b1 = b1_ratio(ybar.data(), na);
  if (!std::isfinite(b1)) return out;
  const int mu = b1_mu(b1, na, dmax);
  if (mu == -2) {
    const double r = rn();
    if (std::isfinite(r) && m > 1) {
      out.alpha_int = rn_alpha(r, static_cast<double>(m));
      out.method = NOISE_ID_B1_RN;
    } else {
      return out;  // PM or not cannot be told: no type (widest interval)
    }
  } else {
    out.alpha_int = -mu - 1;  // mu -1, 0, 1, 2, 3 -> alpha 0, -1, ..., -4
    out.method = NOISE_ID_B1;
  }
  out.alpha = out.alpha_int;
  return out;
}

// Noise type at m from the phase x(k), k < L.
template <class X>
NoiseId identify_noise(const X& x, R_xlen_t L, R_xlen_t m, int dmax,
                       bool phase, RnCache& rn) {
  const R_xlen_t n = acf_points(L, m, phase);
  std::vector<double> z(n > 0 ? n : 0);
  for (R_xlen_t i = 0; i < n; ++i) {
    z[i] = phase ? x(i * m) : x((i + 1) * m) - x(i * m);
  }
  if (n >= kAcfMinPoints) return acf_noise_id(z.data(), n, phase, dmax);
  return b1_noise_id(z.data(), n, phase, m, dmax, [&]() {
    if (rn.empty()) {
      rn.init(L);
      for (R_xlen_t k = 0; k < L; ++k) rn.push(x(k));
    }
    return rn.ratio(m);
  });
}

}  // namespace allanvar

#endif
