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
//    quantiles by R's zeroin (Brent).
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

struct RootData {
  const Weights* w;
  double p;
};

double cdf_minus_p(double lq, void* info) {
  const RootData* d = static_cast<const RootData*>(info);
  return gchisq_cdf(*d->w, std::exp(lq)) - d->p;
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
// the root of the Imhof CDF in log q (false position), bracketed from the two-moment
// chi-square's quantile.
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
    RootData data{&w, p[i]};
    const double q0 = s1 * R::qchisq(p[i], nu, 1, 0) / nu;
    double lo = std::log(q0) - 0.5, hi = std::log(q0) + 0.5;
    double flo = cdf_minus_p(lo, &data), fhi = cdf_minus_p(hi, &data);
    for (int k = 0; k < 60 && flo > 0; ++k) {
      hi = lo;
      fhi = flo;
      lo -= 2;
      flo = cdf_minus_p(lo, &data);
    }
    for (int k = 0; k < 60 && fhi < 0; ++k) {
      lo = hi;
      flo = fhi;
      hi += 1;
      fhi = cdf_minus_p(hi, &data);
    }
    if (flo > 0 || fhi < 0) {
      out[i] = NA_REAL;
      continue;
    }
    // Illinois false position, bisecting when it stalls
    for (int it = 0; it < 100 && hi - lo > 1e-10; ++it) {
      double x = lo - flo * (hi - lo) / (fhi - flo);
      if (!(x > lo && x < hi) || it % 4 == 3) x = 0.5 * (lo + hi);
      const double fx = cdf_minus_p(x, &data);
      if (fx == 0) {
        lo = hi = x;
        break;
      }
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
    out[i] = std::exp(0.5 * (lo + hi));
  }
  return out;
}
