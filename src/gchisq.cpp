// The exact distribution of an Allan-family estimator under discrete
// power-law noise: the estimate over its expectation is a
// generalized chi-square, sum_i lambda_i chi2_1 with sum lambda = 1, the
// lambda the eigenvalues of the terms' covariance matrix over its trace.
//  * noise: phase x = (1 - B)^(-delta) e, e white, delta = (2 - alpha)/2
//    (alpha the rate PSD exponent: 2 white PM ... -2 random-walk FM, -4 for
//    the Hadamard types), Kasdin's discrete power-law model; a term is
//    v(B) (1 - B)^d x = v(B) u with u = (1 - B)^(d - delta) e stationary
//    (fractionally differenced white noise, autocovariance in closed form);
//  * CDF by Imhof (1961), his integral by QUADPACK's dqagi (R's Rdqagi);
//    quantiles from the saddlepoint's by secant steps on it in log q.
#include <Rcpp.h>
#include <RcppEigen.h>
#include <R_ext/Applic.h>
#include "term_acov.h"
#include "types.h"
#include <algorithm>
#include <cmath>
#include <vector>

namespace {

// The weights of Q, the largest kKeep as they are and the rest as one term
// c chi2_k with c and k matching their mean and variance (Imhof's formula
// takes a real multiplicity k): the smallest weights shape the distribution
// little, and each integrand evaluation then costs kKeep + 1 terms, not
// hundreds.
const std::size_t kKeep = 40;

struct Weights {
  std::vector<double> lam, mult;
};

Weights compress(const std::vector<double>& lambda) {
  Weights w;
  std::vector<double> l(lambda);
  std::sort(l.begin(), l.end(), std::greater<double>());
  double s1 = 0, s2 = 0;
  for (std::size_t i = 0; i < l.size(); ++i) {
    if (i < kKeep) {
      w.lam.push_back(l[i]);
      w.mult.push_back(1);
    } else {
      s1 += l[i];
      s2 += l[i] * l[i];
    }
  }
  if (s2 > 0) {
    w.lam.push_back(s2 / s1);
    w.mult.push_back(s1 * s1 / s2);
  }
  return w;
}

struct ImhofData {
  const Weights* w;
  double q;
};

// Imhof's integrand sin(theta(u)) / (u rho(u)), evaluated in place.
void imhof_integrand(double* x, int n, void* ex) {
  const ImhofData* d = static_cast<const ImhofData*>(ex);
  const std::vector<double>& lam = d->w->lam;
  const std::vector<double>& mult = d->w->mult;
  const std::size_t K = lam.size();
  for (int k = 0; k < n; ++k) {
    const double u = x[k];
    if (u == 0) {
      double s = 0;
      for (std::size_t i = 0; i < K; ++i) s += mult[i] * lam[i];
      x[k] = 0.5 * (s - d->q);
      continue;
    }
    double th = 0, lr = 0;
    for (std::size_t i = 0; i < K; ++i) {
      th += mult[i] * std::atan(lam[i] * u);
      lr += mult[i] * std::log1p(lam[i] * lam[i] * u * u);
    }
    th = 0.5 * th - 0.5 * d->q * u;
    x[k] = std::sin(th) / (u * std::exp(0.25 * lr));
  }
}

// Ruben's (1962) series for a few positive weights: P(Q <= q) =
// sum_j a_j P(chi2_{K + 2j} <= q / b), b = min lambda, all terms positive;
// it converges geometrically (ratio 1 - b / max lambda) where Imhof's
// integrand decays slowly (as u^(-1 - K/2)), so it is both faster and more
// accurate there. Returns NA where it would need too many terms.
double ruben_cdf(const std::vector<double>& lam, double q) {
  const std::size_t K = lam.size();
  const double b = *std::min_element(lam.begin(), lam.end());
  std::vector<double> r(K);
  double a0 = 1;
  for (std::size_t i = 0; i < K; ++i) {
    r[i] = 1 - b / lam[i];
    a0 *= std::sqrt(b / lam[i]);
  }
  std::vector<double> a{a0}, g{0};
  std::vector<double> rp(K, 1.0);
  double mass = a0, p = a0 * R::pchisq(q / b, static_cast<double>(K), 1, 0);
  for (int j = 1; j < 20000 && 1 - mass > 1e-11; ++j) {
    double gj = 0;
    for (std::size_t i = 0; i < K; ++i) {
      rp[i] *= r[i];
      gj += rp[i];
    }
    g.push_back(gj);
    double aj = 0;
    for (int k = 0; k < j; ++k) aj += g[j - k] * a[k];
    aj /= 2.0 * j;
    a.push_back(aj);
    mass += aj;
    p += aj * R::pchisq(q / b, static_cast<double>(K + 2 * j), 1, 0);
  }
  return 1 - mass > 1e-9 ? NA_REAL : p;
}

// P(Q <= q), Q = sum mult_i lambda_i chi2_1 (lambda > 0).
double gchisq_cdf(const Weights& w, double q) {
  if (q <= 0) return 0;
  if (w.lam.size() <= 6 && w.lam.size() < kKeep) {  // uncompressed: mult 1
    const double lo = *std::min_element(w.lam.begin(), w.lam.end());
    const double hi = *std::max_element(w.lam.begin(), w.lam.end());
    if (hi <= 50 * lo) {  // at most ~1300 terms (O(J^2) recurrence)
      const double p = ruben_cdf(w.lam, q);
      if (!ISNAN(p)) return std::min(1.0, std::max(0.0, p));
    }
  }
  ImhofData data{&w, q};
  double bound = 0, result = 0, abserr = 0;
  int inf = 1, neval = 0, ier = 0, limit = 1000, lenw = 4 * limit, last = 0;
  double epsabs = 1e-8, epsrel = 1e-6;
  std::vector<int> iwork(limit);
  std::vector<double> work(lenw);
  Rdqagi(imhof_integrand, &data, &bound, &inf, &epsabs, &epsrel, &result,
         &abserr, &neval, &ier, &limit, &lenw, &last, iwork.data(), work.data());
  const double p = 0.5 - result / M_PI;  // Imhof: P(Q > q) = 1/2 + I/pi
  return std::min(1.0, std::max(0.0, p));
}

// Lugannani-Rice's saddlepoint approximation of P(Q <= q) (Kuonen 1999):
// about three digits, no integral. It only starts the Imhof root (most of
// the quantile's cost was the CDF evaluations that narrowed a wide
// bracket: up to 20 ms each for random-walk FM's few dominant weights).
// NaN near the mean, where the formula is singular.
double saddle_cdf(const Weights& w, double q) {
  const std::size_t K = w.lam.size();
  double mean = 0, lmax = 0;
  for (std::size_t i = 0; i < K; ++i) {
    mean += w.mult[i] * w.lam[i];
    lmax = std::max(lmax, w.lam[i]);
  }
  if (!(q > 0) || std::fabs(q - mean) < 1e-6 * mean) return NAN;
  auto k1 = [&](double t) {
    double s = 0;
    for (std::size_t i = 0; i < K; ++i) s += w.mult[i] * w.lam[i] / (1 - 2 * w.lam[i] * t);
    return s;
  };
  // K'(t) = q on (-inf, 1 / (2 lmax)), K' increasing
  double tlo, thi;
  if (q > mean) {
    tlo = 0;
    thi = 0.5 / lmax;
  } else {
    thi = 0;
    tlo = -1 / lmax;
    for (int k = 0; k < 200 && k1(tlo) > q; ++k) tlo *= 2;
  }
  double t = 0.5 * (tlo + thi);
  for (int it = 0; it < 200 && thi - tlo > 1e-14 * (std::fabs(tlo) + std::fabs(thi)); ++it) {
    double f = -q, d = 0;
    for (std::size_t i = 0; i < K; ++i) {
      const double r = 1 / (1 - 2 * w.lam[i] * t);
      f += w.mult[i] * w.lam[i] * r;
      d += 2 * w.mult[i] * w.lam[i] * w.lam[i] * r * r;
    }
    if (f > 0) thi = t; else tlo = t;
    double tn = t - f / d;
    if (!(tn > tlo && tn < thi)) tn = 0.5 * (tlo + thi);
    if (std::fabs(tn - t) < 1e-15 * (1 + std::fabs(t))) break;
    t = tn;
  }
  double kt = 0, k2 = 0;
  for (std::size_t i = 0; i < K; ++i) {
    const double a = 1 - 2 * w.lam[i] * t;
    kt -= 0.5 * w.mult[i] * std::log(a);
    k2 += 2 * w.mult[i] * w.lam[i] * w.lam[i] / (a * a);
  }
  const double r = t * q - kt;
  if (!(r > 0) || !(k2 > 0)) return NAN;
  const double wv = (t > 0 ? 1 : -1) * std::sqrt(2 * r);
  const double u = t * std::sqrt(k2);
  const double p = R::pnorm(wv, 0, 1, 1, 0) + R::dnorm(wv, 0, 1, 0) * (1 / wv - 1 / u);
  return std::isfinite(p) ? std::min(1.0, std::max(0.0, p)) : NAN;
}

// The root in log q of f(lq) - p by Illinois false position from the
// bracket (lo, hi), widened geometrically by `step`, to a bracket narrower
// than `tol` or |f| below `ftol`; NaN without a bracket.
template <class F>
double log_root(F f, double lo, double hi, double step, double tol, double ftol) {
  double flo = f(lo), fhi = f(hi);
  if (ISNAN(flo) || ISNAN(fhi)) return NAN;
  for (double s = step; flo > 0 && s < 1e3; s *= 2) {
    hi = lo;
    fhi = flo;
    lo -= s;
    flo = f(lo);
  }
  for (double s = step; fhi < 0 && s < 1e3; s *= 2) {
    lo = hi;
    flo = fhi;
    hi += s;
    fhi = f(hi);
  }
  if (ISNAN(flo) || ISNAN(fhi) || flo > 0 || fhi < 0) return NAN;
  for (int it = 0; it < 200 && hi - lo > tol; ++it) {
    double x = lo - flo * (hi - lo) / (fhi - flo);
    if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
    const double fx = f(x);
    if (ISNAN(fx)) return NAN;
    if (std::fabs(fx) <= ftol) return x;
    if ((fx < 0) == (flo < 0)) {
      lo = x;
      flo = fx;
      fhi *= 0.5;
    } else {
      hi = x;
      fhi = fx;
      flo *= 0.5;
    }
  }
  return 0.5 * (lo + hi);
}

// The secant iteration from x0, x1 (close to the root: a few steps where
// the start is good); NaN when it strays more than 0.5 from x0 or has not
// converged in 12 steps, for the bracketed root to take over.
template <class F>
double secant_root(F f, double x0, double x1, double tol, double ftol) {
  double f0 = f(x0);
  if (ISNAN(f0)) return NAN;
  if (std::fabs(f0) <= ftol) return x0;
  const double start = x0;
  for (int it = 0; it < 12; ++it) {
    const double f1 = f(x1);
    if (ISNAN(f1)) return NAN;
    if (std::fabs(f1) <= ftol) return x1;
    if (f1 == f0) return NAN;
    const double x2 = x1 - f1 * (x1 - x0) / (f1 - f0);
    if (!std::isfinite(x2) || std::fabs(x2 - start) > 0.5) return NAN;
    if (std::fabs(x2 - x1) <= tol) return x2;
    x0 = x1;
    f0 = f1;
    x1 = x2;
  }
  return NAN;
}

}  // namespace

// Eigenvalues, over their sum, of the covariance of the terms of estimator
// `type` (src/types.h; Allan and Hadamard families, PDEV) with cluster size
// m and n terms, under power-law noise of rate PSD exponent alpha; decreasing,
// those below 1e-13 of the largest dropped. Clean input: alpha + 2 d > 1,
// n >= 1, m >= 1.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector gchisq_weights_cpp(int type, double m, double n, int alpha) {
  const allanvar::EstimatorInfo& info = allanvar::estimator_info(type);
  const long mm = static_cast<long>(m), nn = static_cast<long>(n);
  const std::vector<double> c = allanvar::term_acov(
      allanvar::phase_weights(type, mm), info.d, alpha,
      info.overlapping ? 1 : mm, nn);
  Eigen::MatrixXd C(nn, nn);
  for (long i = 0; i < nn; ++i)
    for (long j = 0; j < nn; ++j) C(i, j) = c[std::labs(i - j)];
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(C, Eigen::EigenvaluesOnly);
  std::vector<double> ev(es.eigenvalues().data(),
                         es.eigenvalues().data() + nn);
  std::sort(ev.begin(), ev.end(), std::greater<double>());
  const double top = ev[0];
  double sum = 0;
  std::vector<double> keep;
  for (double e : ev) {
    if (e > 1e-13 * top) {
      keep.push_back(e);
      sum += e;
    }
  }
  Rcpp::NumericVector out(keep.size());
  for (std::size_t i = 0; i < keep.size(); ++i) out[i] = keep[i] / sum;
  return out;
}

// P(Q <= q) for Q = sum lambda_i chi2_1, each q (lambda > 0; beyond the
// 40 largest, two-moment compressed).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector gchisq_cdf_cpp(const Rcpp::NumericVector& lambda,
                                   const Rcpp::NumericVector& q) {
  const Weights w = compress(std::vector<double>(lambda.begin(), lambda.end()));
  Rcpp::NumericVector out(q.size());
  for (R_xlen_t i = 0; i < q.size(); ++i) out[i] = gchisq_cdf(w, q[i]);
  return out;
}

// Quantiles of Q = sum lambda_i chi2_1 at probabilities p (in (0, 1)):
// the root of the Imhof CDF in log q by secant steps from the
// saddlepoint's quantile (false position in a bracket where they stray).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector gchisq_quantile_cpp(const Rcpp::NumericVector& lambda,
                                        const Rcpp::NumericVector& p) {
  const Weights w = compress(std::vector<double>(lambda.begin(), lambda.end()));
  double s1 = 0, s2 = 0;
  for (double l : lambda) {
    s1 += l;
    s2 += l * l;
  }
  const double nu = s1 * s1 / s2;  // the two-moment EDF
  Rcpp::NumericVector out(p.size());
  for (R_xlen_t i = 0; i < p.size(); ++i) {
    const double pi = p[i];
    // the start: the saddlepoint's quantile (else the two-moment
    // chi-square's), which the Imhof root then refines in a narrow bracket
    const double q0 = s1 * R::qchisq(pi, nu, 1, 0) / nu;
    const double ls = log_root([&](double lq) { return saddle_cdf(w, std::exp(lq)) - pi; },
                               std::log(q0) - 0.1, std::log(q0) + 0.1, 0.25, 1e-6, 1e-7);
    const double l0 = ISNAN(ls) ? std::log(q0) : ls;
    const double half = ISNAN(ls) ? 0.1 : 0.01;
    // to 1e-9 in probability or 1e-8 in log q: the CDF itself is good to
    // about 1e-8 (the integral's tolerances), so a tighter root only chases
    // its noise
    auto f = [&](double lq) { return gchisq_cdf(w, std::exp(lq)) - pi; };
    double lr = secant_root(f, l0, l0 + 0.2 * half, 1e-8, 1e-9);
    if (ISNAN(lr)) lr = log_root(f, l0 - half, l0 + half, 2 * half, 1e-8, 1e-9);
    out[i] = ISNAN(lr) ? NA_REAL : std::exp(lr);
  }
  return out;
}
