// The log-likelihood warmup_ml() (R/warmup-judge.R) maximises, in one call
// per evaluation: the block means y and regressors X (the columns of Y)
// whitened by the warm-up's Kalman filter (warmup_kalman.h) under the
// noise model white 1, random walk q, AR(1)s phis of variances s; the
// regressors taken out by least squares; the scale concentrated out. The
// optimiser calls it hundreds of times per fit, and the R expression it
// replaces spent most of its time building and factorising. The
// arithmetic is that expression's: R's qr() (LINPACK dqrdc2, tol 1e-7),
// qr.coef() and qr.resid() (dqrsl, as dqrcf and dqrrsd call it), sums in
// long double as R's sum() makes them, so the likelihood and the fits are
// identical.
#include <Rcpp.h>
#include <R_ext/Applic.h>
#include <R_ext/Linpack.h>
#include <climits>
#include <cmath>
#include <limits>
#include <vector>
#include "warmup_kalman.h"

// [[Rcpp::export(rng = false)]]
Rcpp::List warmup_gls_ll(const Rcpp::NumericMatrix& Y, double q,
                         const Rcpp::NumericVector& phis, const Rcpp::NumericVector& s) {
  const R_xlen_t nb = Y.nrow(), nc = Y.ncol();
  if (nb < 2 || nc < 1 || s.size() != phis.size() || nb > INT_MAX / nc) {
    Rcpp::stop("warmup_gls_ll: Y needs two rows and a column, s one value per phi");
  }
  const R_xlen_t n = nb - 1;
  int k = static_cast<int>(nc - 1);
  // (written whole by the filter: a buffer kept between calls)
  static thread_local std::vector<double> E;
  if (E.size() < static_cast<size_t>(n * nc)) E.resize(n * nc);
  const double logdet = warmup_filter(Y.begin(), nb, nc, 1.0, q, phis.begin(), s.begin(),
                                      phis.size(), E.data());
  std::vector<double> e(E.begin(), E.begin() + n);
  Rcpp::NumericVector beta(k, NA_REAL);
  if (k > 0) {
    int ni = static_cast<int>(n), rank = 0, ny = 1, info = 0;
    double tol = 1e-7;
    std::vector<double> X(E.begin() + n, E.begin() + n * nc), qraux(k), work(2 * k);
    std::vector<int> pivot(k);
    for (int j = 0; j < k; ++j) pivot[j] = j + 1;
    F77_CALL(dqrdc2)(X.data(), &ni, &ni, &k, &tol, &rank, qraux.data(), pivot.data(),
                     work.data());
    if (rank > 0) {
      // qr.coef()'s dqrcf and qr.resid()'s dqrrsd are each one dqrsl call
      // (jobs 100 and 10) that overwrites its y with Q'y: a copy each, as
      // .Fortran() gives them
      std::vector<double> coef(rank), y1(e), y2(e), rsd(e);
      double dummy = 0;
      int job_coef = 100, job_resid = 10;
      F77_CALL(dqrsl)(X.data(), &ni, &ni, &rank, qraux.data(), y1.data(), &dummy, y1.data(),
                      coef.data(), &dummy, &dummy, &job_coef, &info);
      if (info) Rcpp::stop("exact singularity in 'qr.coef'");
      for (int j = 0; j < rank; ++j) beta[pivot[j] - 1] = coef[j];
      F77_CALL(dqrsl)(X.data(), &ni, &ni, &rank, qraux.data(), y2.data(), &dummy, y2.data(),
                      &dummy, rsd.data(), &dummy, &job_resid, &info);
      e = rsd;
    }
  }
  long double ss = 0;
  for (R_xlen_t j = 0; j < n; ++j) ss += e[j] * e[j];
  const double rss = std::max(static_cast<double>(ss), std::numeric_limits<double>::min());
  const double nn = static_cast<double>(n);
  const double ll = -logdet - nn / 2 * std::log(rss / nn) - nn / 2;
  return Rcpp::List::create(Rcpp::Named("ll") = ll, Rcpp::Named("rss") = rss,
                            Rcpp::Named("n") = nn, Rcpp::Named("beta") = beta);
}
