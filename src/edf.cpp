// Equivalent degrees of freedom of the allan() estimators.
//  * Greenhall & Riley (2004), "Uncertainty of stability variances based on
//    finite differences" (PTTI), the general algorithm, eqs. (7)-(13) and
//    Tables 1-3;
//  * exact Gaussian moments (Isserlis) for discrete white or random-walk
//    rate noise, where the continuous-time model of Greenhall overstates the
//    EDF at small m;
//  * for PDEV, the same moments under every discrete power-law noise, from
//    its terms' autocovariance (src/term_acov.h): terms_edf_cpp().
#include <Rcpp.h>
#include "term_acov.h"
#include "types.h"
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>
#include <vector>

namespace {

const double kInf = std::numeric_limits<double>::infinity();

double sw(double t, int alpha) {
  const double a = std::fabs(t);
  const double lg = t == 0 ? 0.0 : std::log(a);
  switch (alpha) {
    case 2: return -a;
    case 1: return t * t * lg;
    case 0: return a * a * a;
    case -1: return -t * t * t * t * lg;
    case -2: return -a * a * a * a * a;
    case -3: return std::pow(t, 6) * lg;
    case -4: return std::pow(a, 7);
  }
  return NA_REAL;
}

double sx(double t, double F, int alpha) {
  if (std::isinf(F)) return sw(t, alpha + 2);
  return F * F * (2 * sw(t, alpha) - sw(t - 1 / F, alpha) - sw(t + 1 / F, alpha));
}

double sz(double t, double F, int alpha, int d) {
  auto x = [&](double u) { return sx(u, F, alpha); };
  switch (d) {
    case 1: return 2 * x(t) - x(t - 1) - x(t + 1);
    case 2: return 6 * x(t) - 4 * (x(t - 1) + x(t + 1)) + x(t - 2) + x(t + 2);
    default:
      return 20 * x(t) - 15 * (x(t - 1) + x(t + 1)) + 6 * (x(t - 2) + x(t + 2)) -
             x(t - 3) - x(t + 3);
  }
}

double basic_sum(double J, double M, double S, double F, int alpha, int d) {
  const double z0 = sz(0, F, alpha, d), zJ = sz(J / S, F, alpha, d);
  double s = z0 * z0 + (1 - J / M) * zJ * zJ;
  if (alpha == 2 && std::isfinite(F)) {
    // White PM: sx(t) vanishes for |t| >= 1/F, so sz(j/S) is zero unless j
    // lies within S/F of a multiple of S: O(d) terms instead of O(J) (J
    // reaches N at long tau).
    const double rad = S / F;
    const double Jm = std::floor(J);
    double next = 1;  // the first j not summed yet
    for (double k = 0; k * S - rad < Jm; k += 1) {
      const double lo = std::max(next, std::floor(k * S - rad));
      const double hi = std::min(Jm - 1, std::ceil(k * S + rad));
      for (double j = lo; j <= hi; j += 1) {
        const double z = sz(j / S, F, alpha, d);
        s += 2 * (1 - j / M) * z * z;
      }
      next = std::max(next, hi + 1);
    }
    return s;
  }
  for (int j = 1; j < static_cast<int>(J); ++j) {
    const double z = sz(j / S, F, alpha, d);
    s += 2 * (1 - j / M) * z * z;
  }
  return s;
}

// Tables 1 and 2 of Greenhall & Riley: (a0, a1) by alpha (2..-4) and d.
const double kTable1[7][6] = {
    {2. / 3, 1. / 3, 7. / 9, 1. / 2, 22. / 25, 2. / 3},
    {0.840, 0.345, 0.997, 0.616, 1.141, 0.843},
    {1.079, 0.368, 1.033, 0.607, 1.184, 0.848},
    {NAN, NAN, 1.048, 0.534, 1.180, 0.816},
    {NAN, NAN, 1.302, 0.535, 1.175, 0.777},
    {NAN, NAN, NAN, NAN, 1.194, 0.703},
    {NAN, NAN, NAN, NAN, 1.489, 0.702}};
const double kTable2[7][6] = {
    {3. / 2, 1. / 2, 35. / 18, 1, 231. / 100, 3. / 2},
    {78.6, 25.2, 790, 410, 9950, 6520},
    {2. / 3, 1. / 6, 2. / 3, 1. / 3, 7. / 9, 1. / 2},
    {NAN, NAN, 0.852, 0.375, 0.997, 0.617},
    {NAN, NAN, 1.079, 0.368, 1.033, 0.607},
    {NAN, NAN, NAN, NAN, 1.053, 0.553},
    {NAN, NAN, NAN, NAN, 1.302, 0.535}};
const double kTable3[3][2] = {{6, 4}, {15.23, 12}, {47.8, 40}};

double greenhall(int alpha, int d, double m, double N, bool overlapping,
                 bool modified) {
  const double F = modified ? 1 : m;
  const double S = overlapping ? m : 1;
  const double L = m / F + m * d;
  const double M = 1 + std::floor(S * (N - L) / m);
  if (M < 1) return NA_REAL;
  const double J = std::min(M, (d + 1) * S);
  const double Jmax = 100;
  const double r = M / S;
  const int row = 2 - alpha, col = 2 * (d - 1);
  auto eq13 = [&](double Fp) {
    const double z = sz(0, Fp, alpha, d);
    return M * z * z / basic_sum(J, M, S, Fp, alpha, d);
  };
  if (modified) {
    if (J <= Jmax) return eq13(1);
    if (r > d + 1) {
      const double a0 = kTable1[row][col], a1 = kTable1[row][col + 1];
      return r / (a0 - a1 / r);
    }
    const double z = sz(0, 1, alpha, d);
    return Jmax * z * z / basic_sum(Jmax, Jmax, Jmax / r, 1, alpha, d);
  }
  if (alpha <= 0) {
    if (J <= Jmax) return eq13(m * (d + 1) <= Jmax ? m : kInf);
    if (r > d + 1) {
      const double a0 = kTable2[row][col], a1 = kTable2[row][col + 1];
      return r / (a0 - a1 / r);
    }
    const double z = sz(0, kInf, alpha, d);
    return Jmax * z * z / basic_sum(Jmax, Jmax, Jmax / r, kInf, alpha, d);
  }
  if (alpha == 1) {
    if (J <= Jmax) return eq13(m);
    const double b = kTable3[d - 1][0] + kTable3[d - 1][1] * std::log(m);
    if (r > d + 1) {
      const double a0 = kTable2[row][col], a1 = kTable2[row][col + 1];
      return b * b * r / (a0 - a1 / r);
    }
    return Jmax * b * b / basic_sum(Jmax, Jmax, Jmax / r, Jmax / r, 1, d);
  }
  // alpha = 2
  if (std::ceil(r) > d) {
    const double a0 = (d == 1 ? 6.0 / 4 : d == 2 ? 70.0 / 36 : 924.0 / 400);
    return M / (a0 - d / 2.0 / r);
  }
  return eq13(m);
}

// Weights of one term on the innovations of discrete white (rw = false) or
// random-walk (rw = true) rate noise: second differences of cluster sums
// (d = 2), third differences (d = 3), or for the modified type the sum of m
// shifted second differences.
std::vector<double> weights(int type, long m, bool rw) {
  const allanvar::EstimatorInfo& info = allanvar::estimator_info(type);
  std::vector<double> g;
  if (info.d == 3) {
    g.assign(3 * m, 1.0);
    for (long i = m; i < 2 * m; ++i) g[i] = -2.0;
  } else {
    std::vector<double> p(2 * m, 1.0);
    for (long i = 0; i < m; ++i) p[i] = -1.0;
    if (info.modified) {
      g.assign(3 * m - 1, 0.0);
      for (long i = 0; i < 2 * m; ++i)
        for (long j = 0; j < m; ++j) g[i + j] += p[i];
    } else {
      g = p;
    }
  }
  if (rw) {  // y = cumsum(w): tail sums of the weights (they sum to zero)
    std::vector<double> t(g.size() - 1);
    double s = 0;
    for (long i = static_cast<long>(g.size()) - 1; i >= 1; --i) {
      s += g[i];
      t[i - 1] = s;
    }
    g.swap(t);
  }
  return g;
}

// edf = 2 E[AV]^2 / Var[AV] = n^2 c(0)^2 / sum_{|h|<n} (n - |h|) c(h s)^2,
// with c the autocovariance of the term weights and s the term spacing.
double discrete(int type, long m, double n, bool rw) {
  const std::vector<double> g = weights(type, m, rw);
  const long G = static_cast<long>(g.size());
  const long s = allanvar::estimator_info(type).overlapping ? 1 : m;
  double c0 = 0;
  for (long t = 0; t < G; ++t) c0 += g[t] * g[t];
  double den = n * c0 * c0;
  for (long h = 1; h < n && h * s < G; ++h) {
    double c = 0;
    for (long t = 0; t + h * s < G; ++t) c += g[t] * g[t + h * s];
    den += 2 * (n - h) * c * c;
  }
  return n * n * c0 * c0 / den;
}

// NIST SP 1065 Table 5 (after Howe, Allan & Barnes; Stein 1985): the simple
// EDF of the overlapping Allan variance, N phase points. Flicker FM at
// m = 1 keeps the square of (N - 2) (allantools drops it).
double edf_simple_oavar(double N, double m, int alpha) {
  switch (alpha) {
    case 2: return (N + 1) * (N - 2 * m) / (2 * (N - m));
    case 1:
      return std::exp(std::sqrt(std::log((N - 1) / (2 * m)) *
                                std::log((2 * m + 1) * (N - 1) / 4)));
    case 0:
      return (3 * (N - 1) / (2 * m) - 2 * (N - 2) / N) * 4 * m * m /
             (4 * m * m + 5);
    case -1:
      if (m == 1) return 2 * (N - 2) * (N - 2) / (2.3 * N - 4.9);
      return 5 * N * N / (4 * m * (N + 3 * m));
    default:
      return (N - 2) / m * ((N - 1) * (N - 1) - 3 * m * (N - 1) + 4 * m * m) /
             ((N - 3) * (N - 3));
  }
}

// Exact two-moment EDF of the total variance under discrete white PM
// (unit variance): V = |W x|^2 over its L - 2 terms (centres 1 .. L-2 of
// the reflected record), E[V] = tr(A), Var[V] = 2 |A|_F^2 with
// A = W'W = A_I + A_B (inner terms, centres m .. L-1-m, and the <= 2(m-1)
// reflected ones). |A_I|_F^2 = |W_I W_I'|_F^2 from the inner terms'
// autocovariance 6, -4, 1 at lags 0, m, 2m; A_B is kept sparse (<= 25
// entries per term) and <A_I, A_B> read entry by entry: O(m log m), where
// the reflected terms' shared end points (weight 2 in m - 1 terms) make
// the EDF fall far below Table 5's (N = 1024, m = 64: 137 for 440).
double edf_total_wpm(long m, long L) {
  if (m < 1 || L < 2 * m + 1) return NA_REAL;
  const double M = static_cast<double>(L - 2 * m);  // inner terms
  double tr = 6 * M;
  double fro = 36 * M + 2 * 16 * std::max(0.0, M - m) +
               2 * std::max(0.0, M - 2 * m);
  std::map<std::pair<long, long>, double> ab;
  auto reflect = [&](long t, double w, std::vector<std::pair<long, double>>& v) {
    if (t < 0) {
      v.emplace_back(0, 2 * w);
      v.emplace_back(-t, -w);
    } else if (t > L - 1) {
      v.emplace_back(L - 1, 2 * w);
      v.emplace_back(2 * (L - 1) - t, -w);
    } else {
      v.emplace_back(t, w);
    }
  };
  std::vector<std::pair<long, double>> v;
  for (long c = 1; c <= L - 2; ++c) {
    if (c >= m && c <= L - 1 - m) continue;
    v.clear();
    reflect(c - m, 1, v);
    reflect(c, -2, v);
    reflect(c + m, 1, v);
    std::map<long, double> w;  // merge repeated points
    for (const auto& pw : v) w[pw.first] += pw.second;
    for (const auto& a : w) {
      tr += a.second * a.second;
      for (const auto& b : w) ab[{a.first, b.first}] += a.second * b.second;
    }
  }
  // A_I(p, q): the inner centres c whose points c - m, c, c + m hold both
  auto inner = [&](long p, long q) {
    auto in = [&](long c) { return c >= m && c <= L - 1 - m; };
    const long d = std::labs(p - q), lo = std::min(p, q);
    if (d == 0) {
      return (in(p + m) ? 1.0 : 0.0) + (in(p) ? 4.0 : 0.0) +
             (in(p - m) ? 1.0 : 0.0);
    }
    if (d == m) return (in(lo + m) ? -2.0 : 0.0) + (in(lo) ? -2.0 : 0.0);
    if (d == 2 * m) return in(lo + m) ? 1.0 : 0.0;
    return 0.0;
  };
  for (const auto& e : ab) {
    fro += e.second * e.second + 2 * e.second * inner(e.first.first,
                                                       e.first.second);
  }
  return tr * tr / fro;
}

// The total variance (NIST SP 1065 section 5.2.11): Table 7,
// b (N - 1)/m - c, for white, flicker and random-walk FM; for white PM the
// exact two-moment EDF above (Stable32 takes Table 5's simple overlapping
// EDF, 1.3-2.3x too high at N/m = 16-32); for flicker PM the
// overlapping EDF (Greenhall's), not Table 5's simple formula, which
// overstates it at long records: at N = 556989, m = 20 and 100, the Monte
// Carlo EDF of the total variance of flicker PM is 1.28e5 and 4.5e4,
// Greenhall's 9.6e4 and 3.5e4, Table 5's 1.96e5 and 1.16e5. Greenhall's
// is the conservative side (at N = 1024 it is 10-25% below the Monte
// Carlo EDF, Table 5's 0-20% above). Below
// m = 8 the Total terms are (almost) the overlapping ones, and so is their
// EDF: Table 7's 1.5 (N - 1)/m would claim 1500 at m = 1, N = 1001 where
// the exact value for sampled white FM is 666 (the same terms as the
// overlapping AV, whose Table 5 value is 666 too).
double edf_total(double m, double L, int alpha, double oav_edf) {
  // the sparse part grows as 50 m map entries: exact up to m = 4096
  // (~2e5 entries); beyond it the exact EDF at m = 4096 and the same N/m,
  // which it has nearly reached (at N/m = 3-32 it grows by 0.2-1.8% from
  // m = 2048 to 4096; Table 5's simple EDF, used there before, was 100x too
  // high at m = 8192, N = 55700: 68% coverage 0.03)
  if (alpha == 2 && L < 1e15) {
    double ms = m, Ls = L;
    if (m > 4096) {
      ms = 4096;
      Ls = std::floor((L - 1) * ms / m) + 1;
    }
    const double e = edf_total_wpm(static_cast<long>(ms), static_cast<long>(Ls));
    if (std::isfinite(e) && e > 0) return e;
  }
  if (alpha == 1 && std::isfinite(oav_edf) && oav_edf > 0) return oav_edf;
  if (alpha >= 1) return edf_simple_oavar(L, m, alpha);
  const double b = alpha == 0 ? 1.50 : alpha == -1 ? 1.17 : 0.93;
  const double c = alpha == 0 ? 0.0 : alpha == -1 ? 0.22 : 0.36;
  const double tab = b * (L - 1) / m - c;
  if (m < 8 && std::isfinite(oav_edf) && oav_edf > 0) return oav_edf;
  return std::isfinite(oav_edf) && oav_edf > tab ? oav_edf : tab;
}

}  // namespace

// EDF per row: estimator code (src/types.h), cluster size m, number of
// terms n, phase points L, noise exponent alpha; exact discrete moments when
// `exact` (white or random-walk rate noise at small m), Greenhall otherwise;
// the total type by edf_total() over the overlapping EDF.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector allan_edf_cpp(int type, const Rcpp::NumericVector& m,
                                  const Rcpp::NumericVector& n, double L,
                                  const Rcpp::IntegerVector& alpha,
                                  const Rcpp::LogicalVector& exact) {
  if (!allanvar::valid_estimator(type))
    Rcpp::stop("internal: no EDF kernel for estimator code %d", type);
  const bool total = type == allanvar::TOTAL;
  const int base = total ? static_cast<int>(allanvar::OVERLAPPING) : type;
  const allanvar::EstimatorInfo& info = allanvar::estimator_info(base);
  const R_xlen_t k = m.size();
  if ((!total && n.size() != k) || alpha.size() != k || exact.size() != k)
    Rcpp::stop("internal: allan_edf_cpp needs n, alpha and exact per m");
  Rcpp::NumericVector out(k);
  for (R_xlen_t i = 0; i < k; ++i) {
    // the total type: the overlapping EDF where it has terms
    const double ni = total ? L - 2 * m[i] : n[i];
    double e = NA_REAL;
    if (ni >= 1) {
      if (exact[i]) {
        e = discrete(base, static_cast<long>(m[i]), ni, alpha[i] == -2);
      } else {
        e = greenhall(alpha[i], info.d, m[i], L, info.overlapping,
                      info.modified);
      }
    }
    if (total) e = edf_total(m[i], L, alpha[i], e);
    out[i] = std::isfinite(e) && e > 0 ? e : NA_REAL;
  }
  return out;
}

// EDF and noise exponent for every row of a long curve from the rows `sub`
// (1-based, increasing, sub[0] = 1) where they were evaluated: log-log
// interpolation of the EDF between the neighbouring evaluated rows, the
// nearer row's exponent, and no interpolation across a change of exponent.
// One pass instead of a dozen R vectors of the curve's length.
// [[Rcpp::export(rng = false)]]
Rcpp::List edf_interpolate_cpp(const Rcpp::NumericVector& m,
                               const Rcpp::IntegerVector& sub,
                               const Rcpp::NumericVector& es,
                               const Rcpp::IntegerVector& alpha) {
  const R_xlen_t k = m.size(), ns = sub.size();
  std::vector<double> ls(ns), les(ns);
  for (R_xlen_t j = 0; j < ns; ++j) {
    ls[j] = std::log(m[sub[j] - 1]);
    les[j] = std::log(es[j]);
  }
  Rcpp::NumericVector edf(k);
  Rcpp::IntegerVector out_alpha(k);
  R_xlen_t lo = 0;  // largest j with ls[j] <= log(m[i])
  for (R_xlen_t i = 0; i < k; ++i) {
    const double lm = std::log(m[i]);
    while (lo + 1 < ns && ls[lo + 1] <= lm) ++lo;
    const R_xlen_t hi = lo + 1 < ns ? lo + 1 : lo;
    const double w = hi == lo ? 0.0 : (lm - ls[lo]) / (ls[hi] - ls[lo]);
    const R_xlen_t near = w > 0.5 ? hi : lo;
    out_alpha[i] = alpha[near];
    double e = alpha[lo] != alpha[hi] ? es[near]
                                      : std::exp(les[lo] + w * (les[hi] - les[lo]));
    edf[i] = e > 1e-3 ? e : 1e-3;
  }
  return Rcpp::List::create(Rcpp::Named("edf") = edf,
                            Rcpp::Named("alpha") = out_alpha);
}

// Chi-square limits of the deviation for long curves (R/edf.R allan_ci()):
// adev * exp(f(log edf)), f the half log quantile factor given on a grid
// uniform in log edf (start lg0, step h; flo and fhi), read by four-point
// Lagrange interpolation (error ~h^4, below 1e-9 relative at 2000 points);
// below 0.05 degrees of freedom, where the factors are too steep for it,
// from qchisq() itself (p: the lower tail of the upper limit). One pass and
// three result vectors (adev too): the R version's temporaries of 500,000
// rows cost more in page faults than its arithmetic.
// [[Rcpp::export(rng = false)]]
Rcpp::List ci_long_cpp(const Rcpp::NumericVector& avar,
                       const Rcpp::NumericVector& edf, double lg0, double h,
                       const Rcpp::NumericVector& flo,
                       const Rcpp::NumericVector& fhi, double p) {
  const R_xlen_t n = avar.size(), g = flo.size();
  Rcpp::NumericVector lower(Rcpp::no_init(n)), upper(Rcpp::no_init(n)),
      adev(Rcpp::no_init(n));
  for (R_xlen_t i = 0; i < n; ++i) {
    const double a = std::sqrt(avar[i]);
    adev[i] = a;
    if (edf[i] < 0.05) {
      // qchisq(p, edf) underflows to 0 near 0.01: an unbounded limit
      lower[i] = a * std::sqrt(edf[i] / R::qchisq(1 - p, edf[i], 1, 0));
      upper[i] = a * std::sqrt(edf[i] / R::qchisq(p, edf[i], 1, 0));
      continue;
    }
    const double u = (std::log(edf[i]) - lg0) / h;
    // points j..j+3 around u (u clamped first: no cast of NaN or huge u)
    const double uc = u > 1 ? (u < static_cast<double>(g) ? u : g) : 1;
    R_xlen_t j = static_cast<R_xlen_t>(uc) - 1;
    if (j > g - 4) j = g - 4;
    const double t = u - static_cast<double>(j);  // in [0, 3] inside
    const double w0 = -(t - 1) * (t - 2) * (t - 3) / 6;
    const double w1 = t * (t - 2) * (t - 3) / 2;
    const double w2 = -t * (t - 1) * (t - 3) / 2;
    const double w3 = t * (t - 1) * (t - 2) / 6;
    lower[i] = a * std::exp(w0 * flo[j] + w1 * flo[j + 1] + w2 * flo[j + 2] +
                            w3 * flo[j + 3]);
    upper[i] = a * std::exp(w0 * fhi[j] + w1 * fhi[j + 1] + w2 * fhi[j + 2] +
                            w3 * fhi[j + 3]);
  }
  return Rcpp::List::create(Rcpp::Named("lower") = lower,
                            Rcpp::Named("upper") = upper,
                            Rcpp::Named("adev") = adev);
}

// Two-moment EDF of an estimator whose terms are a stationary sequence of
// phase filters (PDEV; any type of src/term_acov.h): for the mean V of M terms with
// autocovariance c(k) under the power law, Isserlis gives
//   edf = 2 E[V]^2 / Var[V] = M^2 c(0)^2 / sum_{|k|<M} (M - |k|) c(k)^2,
// the (sum lambda)^2 / sum lambda^2 of the exact law's eigenvalues
// (src/gchisq.cpp) without the eigenproblem. Lags: c(k) vanishes beyond the
// filter's span under white PM, white FM and random-walk FM; flicker's tails
// (c(k) ~ k^-2 FM, k^-4 PM) are cut at 16 spans (EDF within 5e-6).
// Beyond m = kTermsMcap the terms' correlation is that of continuous time
// (at fixed M/m the EDF moves by under 2e-4 from m = 128 to 256, flicker PM
// the slowest), so the EDF is taken at a smaller m' with M' = M m'/m (real:
// the sum is linear in M between integers): m' = kTermsMcap, or more where
// that leaves fewer than kTermsMin terms (up to kTermsMmax; the EDF of a
// single term, or of a few nearly equal ones, is 1). Consecutive rows with
// the same (m', alpha) compute c once: O(V^2 + lags V), V ~ 2 m'.
namespace {
const long kTermsMcap = 128;
const long kTermsMmax = 2048;
const double kTermsMin = 64;
const long kFlickerSpans = 16;
}  // namespace

// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector terms_edf_cpp(int type, const Rcpp::NumericVector& m,
                                  const Rcpp::NumericVector& n,
                                  const Rcpp::IntegerVector& alpha) {
  if (type < 0 || type >= allanvar::N_TYPES)
    Rcpp::stop("internal: no estimator code %d", type);
  const allanvar::EstimatorInfo& info = allanvar::estimator_info(type);
  const R_xlen_t k = m.size();
  if (n.size() != k || alpha.size() != k)
    Rcpp::stop("internal: terms_edf_cpp needs n and alpha per m");
  Rcpp::NumericVector out(k);
  long cm = -1;
  int ca = 0;
  std::vector<double> c;  // c(k) of the last (m', alpha)
  for (R_xlen_t i = 0; i < k; ++i) {
    out[i] = NA_REAL;
    if (!(m[i] >= 1 && m[i] < 1e15) || !(n[i] >= 1) ||
        alpha[i] == NA_INTEGER || alpha[i] + 2 * info.d <= 1 || alpha[i] > 2)
      continue;
    long mp = static_cast<long>(m[i]);
    if (m[i] > kTermsMcap) {
      // terms at stride m keep their number; overlapping ones their N/m
      const double want = !info.overlapping ? 0 : std::min<double>(
          kTermsMmax, std::ceil(kTermsMin * m[i] / n[i]));
      mp = static_cast<long>(
          std::min(m[i], std::max<double>(kTermsMcap, want)));
    }
    const double M = info.overlapping ? n[i] * static_cast<double>(mp) / m[i]
                                      : n[i];
    if (M < 1) {
      out[i] = 1;
      continue;
    }
    const std::vector<double> w = allanvar::phase_weights(type, mp);
    const long s = info.overlapping ? 1 : mp;
    const long span = static_cast<long>(w.size()) + 2;
    const long reach = alpha[i] % 2 == 0 ? span : kFlickerSpans * span;
    // the lags the sum reads: those below M, at most the noise's reach
    const long lags = static_cast<long>(
        std::min<double>(reach / s + 1, std::ceil(M)));
    if (mp != cm || alpha[i] != ca || static_cast<long>(c.size()) < lags) {
      c = allanvar::term_acov(w, info.d, alpha[i], s, lags);
      cm = mp;
      ca = alpha[i];
    }
    const double c0 = c[0] * c[0];
    double den = M * c0;
    for (std::size_t j = 1; j < c.size() && static_cast<double>(j) < M; ++j)
      den += 2 * (M - static_cast<double>(j)) * c[j] * c[j];
    out[i] = M * M * c0 / den;
  }
  return out;
}
