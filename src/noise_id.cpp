// Power-law noise identification (see noise_id.h for the method and its
// sources).
#include "noise_id.h"
#include <algorithm>
#include <cmath>
#include <vector>

namespace allanvar {


// The lag-1 ACF method on a stored series.
NoiseId acf_noise_id(const double* z, R_xlen_t n, bool phase, int dmax) {
  return acf_noise_id_at([z](R_xlen_t i) { return z[i]; }, n, phase, dmax);
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

// mu whose expected B1 lies nearest the measured one: boundaries at the
// geometric means of neighbours, the arithmetic mean between mu 2 and 1
// (Howe et al. 2000, Table 4); mu -2 (white or flicker PM) up to 2 (flicker
// walk FM; the caller clamps to the statistic's range). Stable32 takes N,
// the count behind the expected B1, to be the statistic's number of terms
// (n_stat), far above the few averaged frequencies the ratio is read from
// at long tau: random walk's expected B1 (N/2) is then out of reach and
// random-walk FM is typed flicker or white FM. The 68% intervals still
// cover 0.60-0.65 for the Allan types, but TOTDEV's cover 0.57-0.59 at
// N/m = 4 (N = 1024 and 4096; tools/mc-coverage.R), so for the total type
// random walk is told from flicker FM with the count of averaged
// frequencies (n_own; NoiseIdRules::b1_rw_own).
int b1_mu(double b1, double n_stat, double n_own) {
  for (int mu = 2; mu > -2; --mu) {
    const double N = mu >= 1 ? n_own : n_stat;
    const double hi = b1_theory(N, mu), lo = b1_theory(N, mu - 1);
    const double bound = mu == 2 ? 0.5 * (hi + lo) : std::sqrt(hi * lo);
    if (b1 > bound) return mu;
  }
  return -2;
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
// geometric means of neighbours). Stable32 asks R(n) only for white against
// flicker PM once B1 has said PM (pm_only, the modified family, where the
// EDF of flicker PM is close to white FM's). For the unmodified types B1
// from a handful of averaged frequencies says PM for white FM often enough
// that a white-FM record would get the EDF of PM (near N) at long tau, so
// there all five types are weighed.
int rn_alpha(double rn, double m, bool pm_only) {
  if (pm_only) return rn > std::sqrt(rn_theory(m, 1) * rn_theory(m, 2)) ? 1 : 2;
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

// From rate samples: X(k) = sum_{i<k} (v_i - c), L = N + 1. Per block of s
// samples, X grows by sum w_t and P by s X + sum (s - 1 - t) w_t: two
// independent sums instead of a running chain.
void RnCache::build_from_rate(const double* v, R_xlen_t N, double c) {
  init(N + 1);
  double X = 0, P = 0;
  R_xlen_t k = 0;
  const double s = static_cast<double>(s_);
  for (; k + s_ <= N + 1; k += s_) {
    X_.push_back(X);
    P_.push_back(P);
    // block [k, k + s): x(k + t) = X + sum_{u < t} w_u, w_u = v[k + u] - c
    const R_xlen_t len = std::min<R_xlen_t>(s_, N - k);
    double sw0 = 0, sw1 = 0, sm0 = 0, sm1 = 0;
    R_xlen_t t = 0;
    for (; t + 2 <= len; t += 2) {
      const double w0 = v[k + t] - c, w1 = v[k + t + 1] - c;
      sw0 += w0;
      sw1 += w1;
      sm0 += (s - 1 - static_cast<double>(t)) * w0;
      sm1 += (s - 2 - static_cast<double>(t)) * w1;
    }
    for (; t < len; ++t) {
      const double w0 = v[k + t] - c;
      sw0 += w0;
      sm0 += (s - 1 - static_cast<double>(t)) * w0;
    }
    P += s * X + sm0 + sm1;
    X += sw0 + sw1;
  }
  if (k == N + 1) P_.push_back(P);
  k_ = L_;
}

bool RnCache::build_from_blocks(const double* sum, const double* ramp,
                                R_xlen_t nb, R_xlen_t B, R_xlen_t N) {
  if (!blocks_usable(B, N)) return false;
  const R_xlen_t L = N + 1, k = L / 4096 / B, s = k * B;
  if (nb < (L / s) * k) return false;
  L_ = L;
  s_ = s;
  X_.clear();
  P_.clear();
  X_.reserve(L / s + 1);
  P_.reserve(L / s + 1);
  // grid block g: phase points [g s, (g + 1) s), i.e. samples of the
  // blocks gk .. gk + k - 1 (the last sample's weight is 0)
  double X = 0, P = 0;
  const double Bd = static_cast<double>(B), sd = static_cast<double>(s);
  for (R_xlen_t g = 0; g < L / s; ++g) {
    X_.push_back(X);
    P_.push_back(P);
    double S = 0, R = 0;
    for (R_xlen_t i = 0; i < k; ++i) {
      const double si = sum[g * k + i];
      R += static_cast<double>(k - 1 - i) * Bd * si + ramp[g * k + i];
      S += si;
    }
    P += sd * X + R;
    X += S;
  }
  k_ = L_;
  return true;
}

double RnCache::ratio(R_xlen_t m) const {
  if (L_ - 1 < 4 * m) return NAN;
  const R_xlen_t ms = std::max<R_xlen_t>(1, (m + s_ / 2) / s_);
  const R_xlen_t nx = static_cast<R_xlen_t>(X_.size());
  const R_xlen_t np = static_cast<R_xlen_t>(P_.size());
  double sd = 0, st = 0;
  R_xlen_t cnt = 0;
  const double w = static_cast<double>(ms * s_);
  for (R_xlen_t j = 0; j + 2 * ms < nx && j + 3 * ms < np; ++j) {
    const double d = X_[j + 2 * ms] - 2 * X_[j + ms] + X_[j];
    const double t = (P_[j + 3 * ms] - 3 * P_[j + 2 * ms] +
                      3 * P_[j + ms] - P_[j]) / w;
    sd += d * d;
    st += t * t;
    ++cnt;
  }
  if (cnt == 0 || !(sd > 0)) return NAN;
  return st / sd;
}

}  // namespace allanvar
