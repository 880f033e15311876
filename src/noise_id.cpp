// Power-law noise identification (see noise_id.h for the method and its
// sources).
#include "noise_id.h"
#include <algorithm>
#include <cmath>
#include <vector>

namespace allanvar {

namespace {

// r1 and the step of Riley & Greenhall: delta = r1 / (1 + r1).
double lag1_delta(const double* e, R_xlen_t n) {
  long double mu = 0;
  for (R_xlen_t i = 0; i < n; ++i) mu += e[i];
  mu /= n;
  long double a = 0, b = 0;
  for (R_xlen_t i = 0; i < n; ++i) {
    const long double d = e[i] - mu;
    b += d * d;
    if (i + 1 < n) a += d * (e[i + 1] - mu);
  }
  const double r1 = b > 0 ? static_cast<double>(a / b) : 0.0;
  return r1 / (1.0 + r1);
}

}  // namespace

// Least-squares polynomial (degree 1 for frequency, 2 for phase) removed
// with the orthogonal polynomials of the equally spaced points
// p1 = i - c, p2 = p1^2 - (n^2 - 1)/12; then the lag-1 ACF, differencing
// while delta >= 0.25 and d < dmax (Riley & Greenhall 2004, eq. 2-4).
NoiseId acf_noise_id(const double* z, R_xlen_t n, bool phase, int dmax) {
  NoiseId out;
  out.points = n;
  if (n < 4) return out;
  const int deg = phase ? 2 : 1;
  const long double nn = static_cast<long double>(n);
  const long double c = (nn - 1) / 2;
  const long double q = (nn * nn - 1) / 12;
  const double z0 = z[0];
  long double s0 = 0, s1 = 0, s2 = 0;
  for (R_xlen_t i = 0; i < n; ++i) {
    const long double v = z[i] - z0;
    const long double p1 = i - c;
    s0 += v;
    s1 += v * p1;
    if (deg == 2) s2 += v * (p1 * p1 - q);
  }
  const long double a0 = s0 / nn;
  const long double a1 = s1 / (nn * (nn * nn - 1) / 12);
  const long double a2 =
      deg == 2 ? s2 / (nn * (nn * nn - 1) * (nn * nn - 4) / 180) : 0;
  std::vector<double> e(n);
  for (R_xlen_t i = 0; i < n; ++i) {
    const long double p1 = i - c;
    e[i] = static_cast<double>((z[i] - z0) - a0 - a1 * p1 -
                               a2 * (p1 * p1 - q));
  }
  int d = 0;
  R_xlen_t len = n;
  for (;;) {
    const double rho = lag1_delta(e.data(), len);
    if (rho < 0.25 || d >= dmax || len < 4) {
      const double add = phase ? 2.0 : 0.0;
      out.alpha = -2.0 * (rho + d) + add;
      out.alpha_int = static_cast<int>(-std::nearbyint(2 * rho) - 2.0 * d + add);
      out.method = NOISE_ID_ACF;
      return out;
    }
    for (R_xlen_t i = 0; i + 1 < len; ++i) e[i] = e[i + 1] - e[i];
    --len;
    ++d;
  }
}

// Standard (N-sample) variance over the two-sample (Allan) variance of the
// same averaged frequencies.
double b1_ratio(const double* y, R_xlen_t n) {
  long double mu = 0;
  for (R_xlen_t i = 0; i < n; ++i) mu += y[i];
  mu /= n;
  long double s2 = 0, a2 = 0;
  for (R_xlen_t i = 0; i < n; ++i) {
    s2 += (y[i] - mu) * (y[i] - mu);
    if (i + 1 < n) a2 += (static_cast<long double>(y[i + 1]) - y[i]) *
                         (static_cast<long double>(y[i + 1]) - y[i]);
  }
  s2 /= (n - 1);
  a2 /= 2 * (n - 1);
  if (!(a2 > 0)) return NAN;
  return static_cast<double>(s2 / a2);
}

// Expected B1 for N averaged frequencies whose Allan variance goes as
// tau^mu: N (1 - N^mu) / (2 (N - 1) (1 - 2^mu)), with its limit at mu = 0
// (Barnes 1969; Howe, Beard, Greenhall, Riley 2000, Table 3).
double b1_theory(double N, int mu) {
  if (mu == 0) return N * std::log(N) / (2 * (N - 1) * std::log(2.0));
  return N * (1 - std::pow(N, mu)) / (2 * (N - 1) * (1 - std::pow(2.0, mu)));
}

// mu whose expected B1 lies nearest the measured one on a log scale
// (boundaries at the geometric means of neighbours); mu -2 (white or
// flicker PM) up to 1 (random-walk FM), or 3 for the Hadamard family.
int b1_mu(double b1, R_xlen_t n, int dmax) {
  const int mu_max = dmax >= 3 ? 3 : 1;
  const double N = static_cast<double>(n);
  int mu = -2;
  while (mu < mu_max) {
    const double bound = std::sqrt(b1_theory(N, mu) * b1_theory(N, mu + 1));
    if (b1 < bound) break;
    ++mu;
  }
  return mu;
}

// Expected MVAR/AVAR at m (SP 1065 section 5.2.5 and Table 3): white PM
// 1/m; flicker PM with the measurement bandwidth f_h = 1/(2 tau0),
// 3 ln(256/27) / (2 (1.038 + 3 ln(2 pi f_h tau))); white, flicker and
// random-walk FM 0.50, 0.67 and 0.82.
double rn_theory(double m, int alpha) {
  const double pi = 3.14159265358979323846;
  switch (alpha) {
    case 2: return 1.0 / m;
    case 1: return 3 * std::log(256.0 / 27.0) / (2 * (1.038 + 3 * std::log(pi * m)));
    case 0: return 0.50;
    case -1: return 0.67;
    default: return 0.82;
  }
}

// The type whose expected R(n) is nearest on a log scale (boundaries at the
// geometric means of neighbours). B1 cannot tell PM from FM with a handful
// of averaged frequencies; R(n), read from every overlapping term, can, so
// a PM reading of B1 is checked against all five types: a white-FM record
// is not given the EDF of white PM (near N) at long tau.
int rn_alpha(double rn, double m) {
  // at very small m flicker PM's ratio is not below white FM's: PM only
  const int last = rn_theory(m, 1) < rn_theory(m, 0) ? -2 : 1;
  int alpha = 2;
  while (alpha > last) {
    const double bound = std::sqrt(rn_theory(m, alpha) * rn_theory(m, alpha - 1));
    if (rn < bound) break;
    --alpha;
  }
  return alpha;
}

double RnCache::ratio(R_xlen_t m) const {
  if (L_ - 1 < 4 * m) return NAN;
  const R_xlen_t ms = std::max<R_xlen_t>(1, (m + s_ / 2) / s_);
  const R_xlen_t nx = static_cast<R_xlen_t>(X_.size());
  const R_xlen_t np = static_cast<R_xlen_t>(P_.size());
  long double sd = 0, st = 0;
  R_xlen_t cnt = 0;
  for (R_xlen_t j = 0; j + 2 * ms < nx && j + 3 * ms < np; ++j) {
    const long double d = X_[j + 2 * ms] - 2 * X_[j + ms] + X_[j];
    const long double t = (P_[j + 3 * ms] - 3 * P_[j + 2 * ms] +
                           3 * P_[j + ms] - P_[j]) / (ms * s_);
    sd += d * d;
    st += t * t;
    ++cnt;
  }
  if (cnt == 0 || !(sd > 0)) return NAN;
  return static_cast<double>(st / sd);
}

}  // namespace allanvar
