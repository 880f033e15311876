// Power-law noise identification at one averaging factor m, as NIST SP 1065
// (section 5.6) and Stable32 do it (W.J. Riley, "Handbook of Frequency
// Stability Analysis", NIST SP 1065, 5.6; the Stable32 manual, "Noise
// identification"):
//  * the lag-1 autocorrelation method of Riley & Greenhall (2004, EFTF,
//    "Power law noise identification using the lag 1 autocorrelation") on
//    the WHOLE decimated series (phase data: every m-th phase point;
//    frequency data: averages of m samples) while it has at least
//    acf_min points (64; Stable32 and allantools: 30; R/taus.R
//    noise_id_rules()). As Stable32: no detrending of phase (removing drift
//    is the user's preprocessing);
//  * below that, Barnes' B1 ratio (standard / Allan variance of the averaged
//    frequencies; Barnes 1969, Howe et al. 2000 Tables 3-4) with N the
//    number of terms of the statistic, as Stable32 (for the total type
//    random walk is told from flicker FM with the count of averaged
//    frequencies: see b1_mu()), and the R(n) ratio MVAR/AVAR where B1 says
//    PM (SP 1065 5.6.1; rn_alpha()).
// Every m is identified from the data alone, never copied from another m.
// The choices were checked against 9,582 noise types printed by Stable32 in
// the allantools and allantoolkit test suites (tools/check-stable32*.R).
//
// Use: identify_noise(x, L, m, dmax, phase_data, rn, nterms, modified,
// rules) with x(k) the phase at k = 0 .. L-1 (any constant offset; for
// frequency data the running sum of the samples, L = N + 1), nterms the
// statistic's number of terms at m (Stable32's N of B1), modified for the
// modified family, rules a NoiseIdRules (R/taus.R noise_id_rules()), and rn
// whose ratio(m) gives R(n) (a LazyRn over the same phase, shared by the
// threads).
#ifndef ALLANVAR_NOISE_ID_H
#define ALLANVAR_NOISE_ID_H

#include <Rcpp.h>
#include <cmath>
#include <mutex>
#include <vector>

namespace allanvar {

enum NoiseIdMethod {
  NOISE_ID_NONE = 0,   // too few points (< 3 averaged frequencies)
  NOISE_ID_ACF = 1,    // lag-1 autocorrelation
  NOISE_ID_B1 = 2,     // B1 ratio
  NOISE_ID_B1_RN = 3,  // B1 ratio, white/flicker PM told apart by R(n)
  NOISE_ID_ACF_RN = 4  // lag-1 ACF, white/flicker PM told apart by R(n)
};

// Which of Stable32's rules apply (options(allanvar.noise_id), R/taus.R).
struct NoiseIdRules {
  R_xlen_t acf_min = 64;     // fewest points the lag-1 ACF is read from
  bool b1_rw_own = false;    // random walk vs flicker FM: B1 with its own count
  bool rn_stable32 = false;  // R(n): PM only for the modified family, and
                             // flicker PM where it cannot be read
  bool rn_check_wfm = false; // R(n) may turn B1's white-FM verdict into PM
                             // (from 8 averaged frequencies; b1_noise_id())
};

struct NoiseId {
  double alpha = NA_REAL;       // continuous estimate (ACF), else = alpha_int
  int alpha_int = NA_INTEGER;   // exponent of the frequency PSD, S_y ~ f^alpha
  int method = NOISE_ID_NONE;
  R_xlen_t points = 0;          // length of the series it was read from
  double rho = NA_REAL;         // the ACF's last delta (its alpha's slope)
};

// acf_min: Stable32 and allantools use the lag-1 ACF from 30 points on.
// Between 30 and 63 points it misreads (r1 has standard error 1/sqrt(n))
// flicker PM as white PM often enough that TOTDEV's 68% intervals cover
// 0.55 (overlapping: 0.58) at N/m = 32, N = 1024, and white FM's 0.645
// (tools/mc-coverage.R, tests/testthat/test-edf.R); B1 with R(n) over the
// whole record reads those rows, by default from 64 points; it changes none
// of the limits compared with Stable32's (tools/check-stable32*.R).
// options(allanvar.noise_id = "stable32") uses 30.

// Lag-1 ACF method on z[0..n): decimated phase (phase = true) or averaged
// frequency. dmax: most differences taken (2 for Allan, 3 for Hadamard).
NoiseId acf_noise_id(const double* z, R_xlen_t n, bool phase, int dmax);

namespace noise_id_detail {

// delta = r1 / (1 + r1) of Riley & Greenhall from r1 = num / den (NIST SP
// 1065 eq. 72). Stable32 is said to scale r1 by (n - 1)/n (allantoolkit);
// that matches 21 more of 9,582 Stable32 noise types but none of the 711
// limits, and SP 1065's definition is kept.
inline double delta_of(double num, double den, R_xlen_t) {
  const double r1 = den > 0 ? num / den : 0.0;
  return r1 / (1.0 + r1);
}

// delta of e[0..n) (two passes: mean, then lag-0 and lag-1 sums).
inline double lag1_delta(const double* e, R_xlen_t n) {
  double mu = 0;
  for (R_xlen_t i = 0; i < n; ++i) mu += e[i];
  mu /= static_cast<double>(n);
  double a = 0, b = 0, prev = e[0] - mu;
  b = prev * prev;
  for (R_xlen_t i = 1; i < n; ++i) {
    const double d = e[i] - mu;
    b += d * d;
    a += prev * d;
    prev = d;
  }
  return delta_of(a, b, n);
}

}  // namespace noise_id_detail

// The mean and (frequency data) the slope about the centre (n - 1)/2 that
// the lag-1 ACF removes first.
struct AcfLine {
  double mu = 0, b = 0;
};

// The line from the sums s0 = sum (z - ref) and sp = sum (i - c)(z - ref),
// c = (n - 1)/2, about any reference `ref` near the data (sum (i - c) = 0,
// so sp needs no mean).
inline AcfLine acf_line_from(double s0, double sp, double ref, R_xlen_t n,
                             bool phase) {
  const double nn = static_cast<double>(n);
  AcfLine out;
  out.mu = s0 / nn + ref;
  if (!phase) out.b = sp / (nn * (nn * nn - 1) / 12);
  return out;
}

// The line of z(0..n) in one pass (about z(0), which keeps the sums small).
template <class Z>
AcfLine acf_line(const Z& z, R_xlen_t n, bool phase) {
  const double z0 = z(0);
  const double c = (static_cast<double>(n) - 1) / 2;
  double s0 = 0, s1 = 0, p0 = 0, p1 = 0;
  R_xlen_t i = 0;
  if (phase) {
    for (; i + 2 <= n; i += 2) {
      s0 += z(i) - z0;
      s1 += z(i + 1) - z0;
    }
    if (i < n) s0 += z(i) - z0;
  } else {
    for (; i + 2 <= n; i += 2) {
      const double a = z(i) - z0, b = z(i + 1) - z0;
      const double t = static_cast<double>(i) - c;
      s0 += a;
      s1 += b;
      p0 += t * a;
      p1 += (t + 1) * b;
    }
    if (i < n) {
      const double a = z(i) - z0;
      s0 += a;
      p0 += (static_cast<double>(i) - c) * a;
    }
  }
  return acf_line_from(s0 + s1, p0 + p1, z0, n, phase);
}

// The lag-1 ACF of z(0..n) about the line `ln` (acf_line()), differencing
// while delta >= 0.25 and d < dmax (Riley & Greenhall 2004, eq. 2-4). The
// first step reads z(i) once and stores nothing (most series stop there);
// differencing works on a copy.
template <class Z>
NoiseId acf_noise_id_line(const Z& z, R_xlen_t n, bool phase, int dmax,
                          const AcfLine& ln) {
  using namespace noise_id_detail;
  NoiseId out;
  out.points = n;
  if (n < 4) return out;
  const double c = (static_cast<double>(n) - 1) / 2;
  const double mu = ln.mu, b = ln.b;
  // averaged frequencies: a linear drift removed; phase is read as it is,
  // as Stable32 does
  auto res = [&](R_xlen_t k) {
    return z(k) - mu - b * (static_cast<double>(k) - c);
  };
  // two chains per sum: the add latency bounds one
  double S2 = 0, Sc = 0, S2b = 0, Scb = 0;
  double prev = res(0);
  S2 = prev * prev;
  R_xlen_t i = 1;
  for (; i + 2 <= n; i += 2) {
    const double e0 = res(i), e1 = res(i + 1);
    S2 += e0 * e0;
    S2b += e1 * e1;
    Sc += prev * e0;
    Scb += e0 * e1;
    prev = e1;
  }
  if (i < n) {
    const double e = res(i);
    S2 += e * e;
    Sc += prev * e;
  }
  double rho = delta_of(Sc + Scb, S2 + S2b, n);
  int d = 0;
  std::vector<double> e;
  R_xlen_t len = n;
  for (;;) {
    if (!std::isfinite(rho)) return out;  // sums beyond the double range
    if (rho < 0.25 || d >= dmax || len < 4) {
      const double add = phase ? 2.0 : 0.0;
      out.alpha = -2.0 * (rho + d) + add;
      out.rho = rho;
      out.alpha_int = static_cast<int>(-std::nearbyint(2 * rho) - 2.0 * d + add);
      out.method = NOISE_ID_ACF;
      return out;
    }
    if (e.empty()) {
      e.resize(n);
      for (R_xlen_t k = 0; k < n; ++k) e[k] = res(k);
    }
    for (R_xlen_t k = 0; k + 1 < len; ++k) e[k] = e[k + 1] - e[k];
    --len;
    ++d;
    rho = lag1_delta(e.data(), len);
  }
}

// The same method (averaged frequencies, the line removed) from moments of
// z(0..n) read in one pass elsewhere: s0 = sum z, sp = sum (i - c) z,
// q[k] the sum of squared k-th differences (k = 0 .. dmax + 1), first and
// last the first and last four values. Each sum of squares about a mean
// comes from a raw one minus the mean's share, and the lag-1 sum from the
// next order's squared differences: sum (u_i - u_{i-1})^2 = 2 sum u^2 -
// u_0^2 - u_{n-1}^2 - 2 sum u_{i-1} u_i. ok = false where the mean or line
// takes more than all but 1e-6 of a raw sum (six digits lost): the caller
// then reads z as acf_noise_id_line() does.
struct AcfMoments {
  double s0 = 0, sp = 0;
  double q[5] = {0, 0, 0, 0, 0};
  double first[4] = {0, 0, 0, 0}, last[4] = {0, 0, 0, 0};
};

inline NoiseId acf_noise_id_moments(const AcfMoments& mo, R_xlen_t n,
                                    int dmax, bool& ok) {
  using namespace noise_id_detail;
  NoiseId out;
  out.points = n;
  ok = true;
  if (n < 4) return out;
  if (dmax > 3) {
    ok = false;
    return out;
  }
  const double nn = static_cast<double>(n), c = (nn - 1) / 2;
  const double T = nn * (nn * nn - 1) / 12;
  const double mu = mo.s0 / nn, b = mo.sp / T;
  const double S = mo.q[0] - nn * mu * mu - b * b * T;
  const double e0 = mo.first[0] - mu + b * c;
  const double en = mo.last[3] - mu - b * (nn - 1 - c);
  const double De = mo.q[1] - 2 * b * (mo.last[3] - mo.first[0]) +
                    (nn - 1) * b * b;
  if (!(S > 1e-6 * mo.q[0]) || !(De > 1e-6 * mo.q[1])) {
    ok = false;
    return out;
  }
  double rho = delta_of((2 * S - e0 * e0 - en * en - De) / 2, S, n);
  // k-th difference at the start and at the end of the record
  auto head = [&mo](int k) {
    double t[4];
    for (int i = 0; i <= k; ++i) t[i] = mo.first[i];
    for (int o = 1; o <= k; ++o)
      for (int i = 0; i + o <= k; ++i) t[i] = t[i + 1] - t[i];
    return t[0];
  };
  auto tail = [&mo](int k) {
    double t[4];
    for (int i = 0; i <= k; ++i) t[i] = mo.last[3 - k + i];
    for (int o = 1; o <= k; ++o)
      for (int i = 0; i + o <= k; ++i) t[i] = t[i + 1] - t[i];
    return t[0];
  };
  int d = 0;
  R_xlen_t len = n;
  for (;;) {
    if (!std::isfinite(rho)) return out;  // sums beyond the double range
    if (rho < 0.25 || d >= dmax || len < 4) {
      out.alpha = -2.0 * (rho + d);
      out.rho = rho;
      out.alpha_int = static_cast<int>(-std::nearbyint(2 * rho) - 2.0 * d);
      out.method = NOISE_ID_ACF;
      return out;
    }
    ++d;
    --len;
    // w = the d-th differences: their sum telescopes
    const double ln = static_cast<double>(len);
    const double wbar = (tail(d - 1) - head(d - 1)) / ln;
    const double Sw = mo.q[d] - ln * wbar * wbar;
    if (!(Sw > 1e-6 * mo.q[d])) {
      ok = false;
      return out;
    }
    const double wf = head(d) - wbar, wl = tail(d) - wbar;
    rho = delta_of((2 * Sw - wf * wf - wl * wl - mo.q[d + 1]) / 2, Sw, len);
  }
}

// The lag-1 ACF method on z(0..n): two passes (line, then the sums about it).
template <class Z>
NoiseId acf_noise_id_at(const Z& z, R_xlen_t n, bool phase, int dmax) {
  if (n < 4) {
    NoiseId out;
    out.points = n;
    return out;
  }
  return acf_noise_id_line(z, n, phase, dmax, acf_line(z, n, phase));
}

// B1 ratio of the averaged frequencies ybar[0..n); rn() gives MVAR/AVAR at
// m, called only when B1 points to white or flicker PM (NaN: unavailable).
double b1_ratio(const double* ybar, R_xlen_t n);
int b1_mu(double b1, double n_stat, double n_own);  // tau exponent of AVAR
double b1_theory(double N, int mu);
double rn_theory(double m, int alpha);          // expected MVAR/AVAR
int rn_alpha(double rn, double m, bool pm_only);  // alpha from R(n)

// Phase values at a coarse grid (step s, at most ~4096 points) and their
// prefix sums, for R(n) at long averaging factors (m >= L/30, so the window
// lengths are rounded to the grid by at most 1/136 of m).
class RnCache {
 public:
  void init(R_xlen_t L) {
    L_ = L;
    s_ = L > 4096 ? L / 4096 : 1;
    k_ = 0;
    gap_ = 0;
    sum_ = comp_ = 0;
    X_.clear();
    P_.clear();
    X_.reserve(L / s_ + 2);
    P_.reserve(L / s_ + 2);
  }
  bool empty() const { return X_.empty(); }
  // The phase at k = 0, 1, ..., L-1, in order.
  void push(double xk) {
    if (--gap_ <= 0) {
      X_.push_back(xk);
      P_.push_back(sum_ + comp_);
      gap_ = s_;
    }
    // compensated running sum (Kahan-Babuska)
    const double t = sum_ + xk;
    comp_ += std::fabs(sum_) >= std::fabs(xk) ? (sum_ - t) + xk : (xk - t) + sum_;
    sum_ = t;
    if (++k_ == L_ && L_ % s_ == 0) P_.push_back(sum_ + comp_);
  }
  // The same from the phase x(k), k < L, in blocks of s points.
  template <class X>
  void build(const X& x, R_xlen_t L) {
    init(L);
    double P = 0;
    R_xlen_t k = 0;
    for (; k + s_ <= L; k += s_) {
      X_.push_back(x(k));
      P_.push_back(P);
      double a = 0, b = 0;
      R_xlen_t t = 0;
      for (; t + 2 <= s_; t += 2) {
        a += x(k + t);
        b += x(k + t + 1);
      }
      if (t < s_) a += x(k + t);
      P += a + b;
    }
    if (k == L) P_.push_back(P);
    k_ = L_;
  }
  // The same from rate samples v[0..N) about c (phase L = N + 1 points).
  void build_from_rate(const double* v, R_xlen_t N, double c);
  // The same from sums over nb blocks of B samples of v - c, sum[i] and
  // ramp[i] = sum (B-1-u)(v_{iB+u} - c): no pass over the samples. The grid
  // step is then a multiple of B no coarser than build_from_rate()'s
  // (exact at m = 2^j >= B), which needs L/4096 >= B and no partial last
  // block; false (nothing built) otherwise.
  static bool blocks_usable(R_xlen_t B, R_xlen_t N) {
    const R_xlen_t L = N + 1;
    if (B < 1 || L / 4096 < B) return false;
    const R_xlen_t s = (L / 4096 / B) * B;
    return L % s != 0;
  }
  bool build_from_blocks(const double* sum, const double* ramp, R_xlen_t nb,
                         R_xlen_t B, R_xlen_t N);
  // MVAR/AVAR at (about) m; NaN when the record holds less than 4 m phase
  // points (the MVAR terms would all overlap: one effective sample).
  double ratio(R_xlen_t m) const;

 private:
  R_xlen_t L_ = 0, s_ = 1, k_ = 0, gap_ = 0;
  double sum_ = 0, comp_ = 0;
  std::vector<double> X_, P_;
};

// An RnCache built on first use by whichever thread asks first (the others
// wait): the build is a pass over the whole record, needed only where B1
// reads PM or white FM, and it overlaps the other threads' ACF passes.
template <class Build>
class LazyRn {
 public:
  explicit LazyRn(Build build) : build_(build) {}
  double ratio(R_xlen_t m) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!built_) {
        build_(rn_);
        built_ = true;
      }
    }
    return rn_.ratio(m);
  }

 private:
  Build build_;
  RnCache rn_;
  std::mutex mutex_;
  bool built_ = false;
};

// The decimated series for the ACF has this many points at m.
inline R_xlen_t acf_points(R_xlen_t L, R_xlen_t m, bool phase) {
  return phase ? (L - 1) / m + 1 : (L - 1) / m;
}

// Fewest averaged frequencies at which R(n) may turn B1's white FM into
// white PM (ratio ~1/m, far below every FM type's), and into flicker PM
// (NoiseIdRules::rn_check_wfm). From 4 to 7 averaged frequencies flicker
// PM's ratio is too close to the FM ones' (random-walk and flicker FM
// would be read as PM in enough replicates to cover 0.57-0.59 at N/m = 4).
constexpr R_xlen_t kRnCheckWpm = 4, kRnCheckFpm = 8;

// B1 (and R(n)) from the decimated series z (phase or averaged frequency);
// nterms: the statistic's number of terms at m, Stable32's N of the
// expected B1 (SP 1065 5.6; with the count of averaged frequencies instead,
// 7,552 instead of 8,652 of 9,582 Stable32 noise types are matched).
template <class RN>
NoiseId b1_noise_id(const double* z, R_xlen_t n, bool phase, R_xlen_t m,
                    double nterms, bool modified, const NoiseIdRules& rules,
                    RN rn) {
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
  const double N = nterms >= 2 ? nterms : static_cast<double>(na);
  const int mu = b1_mu(b1, N, rules.b1_rw_own ? static_cast<double>(na) : N);
  if (mu == -2) {
    // white or flicker PM: R(n) tells the type where it can be read; where
    // it cannot, flicker PM under Stable32's rules, else no type (the
    // widest interval)
    const double r = m > 1 ? rn() : NAN;
    if (!std::isfinite(r) && !rules.rn_stable32) return out;
    out.alpha_int = std::isfinite(r)
                        ? rn_alpha(r, static_cast<double>(m),
                                   modified && rules.rn_stable32)
                        : 1;
    out.method = std::isfinite(r) ? NOISE_ID_B1_RN : NOISE_ID_B1;
  } else {
    out.alpha_int = -mu - 1;  // mu -1, 0, 1, 2 -> alpha 0, -1, -2, -3
    out.method = NOISE_ID_B1;
    // B1 from a handful of averaged frequencies reads white or flicker PM
    // as white FM in 21-60% of replicates at N/m <= 16 (N = 1024), and
    // white FM's EDF is far below PM's there: the 68% intervals of
    // overlapping PM covered 0.77-0.89. R(n) reads the whole record and
    // tells PM (ratio ~1/m or less) from white FM (0.5) with a wide margin.
    if (mu == -1 && rules.rn_check_wfm && na >= kRnCheckWpm && m > 1) {
      const double r = rn();
      if (std::isfinite(r)) {
        const int a = rn_alpha(r, static_cast<double>(m), false);
        if (a == 2 || (a == 1 && na >= kRnCheckFpm)) {
          out.alpha_int = a;
          out.method = NOISE_ID_B1_RN;
        }
      }
    }
  }
  out.alpha = out.alpha_int;
  return out;
}

// The lag-1 ACF of the decimated series tells white from flicker PM badly
// at small m: at N = 1024, m = 4-16, it read generated flicker PM as white
// PM in 25-47% of records, and white PM's narrower interval covered 0.49-0.61
// there. R(n) = MVAR/AVAR over the whole record tells them apart (SP 1065
// 5.6.1) where their expected ratios differ by kRnPmSplit or more (m >= 4;
// at m = 2 they are 0.50 and 0.51): at N = 1024 (own generators, 100
// records) its mean and sd were 0.250 +- 0.012 (white PM) and 0.384 +- 0.015
// (flicker PM) at m = 4, 0.062 +- 0.008 and 0.245 +- 0.023 at m = 16.
// The ACF's continuous reading alpha = -2 delta + const, delta = r1 / (1 +
// r1), has a standard error of about 2 (1 - delta)^2 / sqrt(n) (r1's
// 1/sqrt(n), n decimated points; the delta method); where the white/flicker PM boundary
// (alpha 1.5) lies within kAcfPmZ of them, R(n) chooses between the two PM
// types; elsewhere the ACF's reading stands, as in Stable32 (on its
// reference runs, long real records, R(n) at every PM row moved 289 noise
// types and 23 limits away from Stable32's). Not under Stable32's rules.
constexpr double kRnPmSplit = 1.5;
constexpr double kAcfPmZ = 2.0;

template <class RN>
void rn_refine_pm(NoiseId& id, R_xlen_t m, const NoiseIdRules& rules, RN rn) {
  if (rules.rn_stable32 || id.alpha_int == NA_INTEGER || id.alpha_int < 1 ||
      m < 2)
    return;
  const double md = static_cast<double>(m);
  if (rn_theory(md, 1) < kRnPmSplit * rn_theory(md, 2)) return;
  if (!std::isfinite(id.rho) || id.points < 1) return;
  const double se = 2.0 * (1.0 - id.rho) * (1.0 - id.rho) /
                    std::sqrt(static_cast<double>(id.points));
  if (!(std::fabs(id.alpha - 1.5) < kAcfPmZ * se)) return;
  const double r = rn();
  if (!std::isfinite(r)) return;
  const int a = rn_alpha(r, md, true);
  if (a != id.alpha_int) {
    id.alpha_int = a;
    id.alpha = a;
  }
  id.method = NOISE_ID_ACF_RN;
}

// Noise type at m from the phase x(k), k < L.
template <class X, class RN>
NoiseId identify_noise(const X& x, R_xlen_t L, R_xlen_t m, int dmax,
                       bool phase, RN& rn, double nterms, bool modified,
                       const NoiseIdRules& rules) {
  const R_xlen_t n = acf_points(L, m, phase);
  if (n >= rules.acf_min) {
    NoiseId id =
        phase ? acf_noise_id_at([&](R_xlen_t i) { return x(i * m); }, n, true,
                                dmax)
              : acf_noise_id_at(
                    [&](R_xlen_t i) { return x((i + 1) * m) - x(i * m); }, n,
                    false, dmax);
    rn_refine_pm(id, m, rules, [&]() { return rn.ratio(m); });
    return id;
  }
  std::vector<double> z(n > 0 ? n : 0);
  for (R_xlen_t i = 0; i < n; ++i) {
    z[i] = phase ? x(i * m) : x((i + 1) * m) - x(i * m);
  }
  return b1_noise_id(z.data(), n, phase, m, nterms, modified, rules,
                     [&]() { return rn.ratio(m); });
}

}  // namespace allanvar

#endif
