// The exact discrete Allan variance per squared amplitude of catalogue
// terms: the Gauss-Markov process (R/effect-gauss-markov.R) and white noise
// through the sensor's filter (R/filter-noise.R, filter_av(): a moving
// average, the IIR low-passes): the R expressions' operations in their
// order, R's x^2 as x * x, sums in long double as R's sum(), complex
// values in R's arithmetic (src/r_complex.h), so the values are R's
// (identical(); checked in the tests). The loop's searches evaluate them
// at every value they visit.
#include <Rcpp.h>
#include "r_complex.h"
#include <cmath>
#include <complex>
#include <vector>

// gm_basis_continuous(tau, tc) at the taus below a sample and
// gm_basis_discrete(tau / tau0, tau0 / tc) at the others (the entry's
// basis with tau0 given): `fact` is factorial(3:14), the small-x series'
// denominators as R computes them.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector gm_basis_cpp(const Rcpp::NumericVector& tau, double tau0, double tc,
                                 const Rcpp::NumericVector& fact) {
  if (fact.size() != 12) Rcpp::stop("gm_basis_cpp: fact must hold factorial(3:14)");
  const R_xlen_t n = tau.size();
  Rcpp::NumericVector out(n);
  const double lim = tau0 * (1 - 1e-9);  // discrete_tau()
  const double eps = tau0 / tc;
  const double e1 = -std::expm1(-eps);
  const double e2 = -std::expm1(-2.0 * eps);
  for (R_xlen_t i = 0; i < n; i++) {
    const double t = tau[i];
    if (t >= lim) {
      const double m = t / tau0;
      if (m * eps < 1e-5) {
        out[i] = eps * (2 * (m * m) + 1) / (3 * m);
      } else {
        const double em = -std::expm1(-(m + 1) * eps);
        const double e2m = -std::expm1(-(2 * m + 1) * eps);
        const double num = 3 * e1 + m * e2 - 4 * em + e2m;
        out[i] = num / ((m * m) * (e1 * e1));
      }
    } else {
      const double x = t / tc;
      double br;
      if (x < 0.05) {
        // the bracket's series (the R loop over k = 3..14)
        br = 0;
        for (int k = 3; k <= 14; k++) {
          const double sg = (k % 2) ? -1.0 : 1.0;
          br = br + sg * std::pow(x, k) * (4 - std::pow(2.0, k)) / fact[k - 3];
        }
      } else {
        br = 2 * x - 3 + 4 * std::exp(-x) - std::exp(-2 * x);
      }
      out[i] = br / (x * x);
    }
  }
  return out;
}

namespace {

// R's sum() of doubles: accumulated in long double.
double r_sum(const double* v, size_t n) {
  long double s = 0.0;
  for (size_t i = 0; i < n; i++) s += v[i];
  return static_cast<double>(s);
}

// R's sum() of complex values: each part in long double.
std::complex<double> r_csum(const std::vector<std::complex<double>>& v) {
  long double sr = 0.0, si = 0.0;
  for (const std::complex<double>& z : v) {
    sr += z.real();
    si += z.imag();
  }
  return std::complex<double>(static_cast<double>(sr), static_cast<double>(si));
}

}  // namespace

// filter_av(m, list(family = "ma", L = L), tau0) for whole cluster sizes m
// (within 1e-9, as filter_av() tells them): the moving average's
// autocovariance at the lags the m need, then acov_av(). NULL when some m
// is fractional (filter_av() interpolates those in R).
// [[Rcpp::export(rng = false)]]
SEXP filter_ma_av_cpp(const Rcpp::NumericVector& m, double L, double tau0) {
  const R_xlen_t n = m.size();
  double mmax = R_NegInf;
  for (R_xlen_t i = 0; i < n; i++) {
    if (!(std::fabs(m[i] - std::nearbyint(m[i])) < 1e-9)) return R_NilValue;
    if (m[i] > mmax) mmax = m[i];
  }
  if (n == 0 || !(L >= 1) || !std::isfinite(L) || !(tau0 > 0)) return R_NilValue;
  // filter_support(), and the lags AV(m) below it reads
  const double K = std::ceil(L);
  const double need = std::min(K, 2 * std::ceil(mmax) + 2);
  // filter_acf(): max(L - k, 0) / (tot tau0)
  const double fl = std::floor(L);
  const double tot = L + 2 * (fl * L - fl * (fl + 1) / 2);
  const size_t Kg = static_cast<size_t>(need);
  std::vector<double> g(Kg);
  for (size_t k = 0; k < Kg; k++) {
    const double v = L - static_cast<double>(k);
    g[k] = (v < 0 ? 0.0 : v) / (tot * tau0);
  }
  // acov_av(): S and C from g, or ma_sums() when g is not the whole support
  double S, C;
  if (need < K) {
    S = 1 / tau0;
    C = (L * fl * (fl + 1) / 2 - fl * (fl + 1) * (2 * fl + 1) / 6) / (tot * tau0);
  } else {
    S = g[0] + 2 * r_sum(g.data() + 1, Kg - 1);
    std::vector<double> jg(Kg > 0 ? Kg - 1 : 0);
    for (size_t j = 1; j < Kg; j++) jg[j - 1] = static_cast<double>(j) * g[j];
    C = r_sum(jg.data(), jg.size());
  }
  auto gz = [&](double k) { return k < static_cast<double>(Kg) ? g[static_cast<size_t>(k)] : 0.0; };
  Rcpp::NumericVector out(n);
  std::vector<double> terms;
  for (R_xlen_t j = 0; j < n; j++) {
    const double mm = std::nearbyint(m[j]);
    if (mm < static_cast<double>(Kg)) {
      double s = mm * (g[0] - gz(mm));
      if (mm > 1) {
        const size_t nt = static_cast<size_t>(mm) - 1;
        terms.resize(nt);
        for (size_t i = 1; i <= nt; i++) {
          const double di = static_cast<double>(i);
          terms[i - 1] = di * (2 * gz(mm - di) - gz(di) - gz(2 * mm - di));
        }
        s = s + r_sum(terms.data(), nt);
      }
      out[j] = s / (mm * mm);
    } else {
      out[j] = S / mm - 3 * C / (mm * mm);
    }
    if ((j & 0xFF) == 0) Rcpp::checkUserInterrupt();
  }
  return out;
}

// filter_av(m, spec, tau0) of an IIR family from its rational form
// (filter_rational(): c0, residues r, poles p): rational_acov()'s
// geometric parts A and white part d0, then Re(d0 / m + sum_j
// geometric_av(m, A_j, p_j)) / tau0.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector rational_av_cpp(const Rcpp::NumericVector& m, double c0,
                                    const Rcpp::ComplexVector& r,
                                    const Rcpp::ComplexVector& p, double tau0) {
  typedef std::complex<double> cplx;
  const R_xlen_t k = p.size();
  if (r.size() != k) Rcpp::stop("rational_av_cpp: as many residues as poles");
  std::vector<cplx> rv(k), pv(k);
  for (R_xlen_t a = 0; a < k; a++) {
    rv[a] = cplx(r[a].r, r[a].i);
    pv[a] = cplx(p[a].r, p[a].i);
  }
  // element i = a + k b of rep(., k) and rep(., each = k): index a, then b
  const R_xlen_t kk = k * k;
  std::vector<cplx> pp(kk), G(kk);
  for (R_xlen_t i = 0; i < kk; i++) {
    const R_xlen_t a = i % k, b = i / k;
    pp[i] = cplx(1.0, 0.0) - pv[a] * pv[b];
    G[i] = rv[a] * rv[b] / pp[i];
  }
  // A <- r * (c0 + colSums(matrix(r / pp, k))), colSums() of a complex
  // matrix as R has it: colSums(Re) + 1i * colSums(Im)
  std::vector<cplx> A(k);
  for (R_xlen_t b = 0; b < k; b++) {
    long double sr = 0.0, si = 0.0;
    for (R_xlen_t a = 0; a < k; a++) {
      const cplx q = rv[a] / pp[a + k * b];
      sr += q.real();
      si += q.imag();
    }
    const cplx cs = cplx(static_cast<double>(sr), 0.0) +
      cplx(0.0, 1.0) * cplx(static_cast<double>(si), 0.0);
    A[b] = rv[b] * (cplx(c0, 0.0) + cs);
  }
  // g0 <- c0^2 + 2 * c0 * sum(r) + sum(G); d0 <- Re(g0 - sum(A))
  cplx g0 = cplx(c0 * c0, 0.0) + cplx(2 * c0, 0.0) * r_csum(rv);
  g0 = g0 + r_csum(G);
  const double d0 = (g0 - r_csum(A)).real();
  std::vector<allanvar::GeometricAv> geom;
  for (R_xlen_t j = 0; j < k; j++) geom.emplace_back(A[j], pv[j]);
  const R_xlen_t n = m.size();
  Rcpp::NumericVector out(n);
  for (R_xlen_t i = 0; i < n; i++) {
    double v = d0 / m[i];
    for (R_xlen_t j = 0; j < k; j++) v = v + geom[j](m[i]).real();
    out[i] = v / tau0;
  }
  return out;
}
