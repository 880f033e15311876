// Exact Gaussian log-likelihood pieces of a rate series
//   y_t = r_t + g_t + e_t,
// r a random walk (increment variance qr, diffuse start: the sensor's bias
// is unknown), g an AR(1) Gauss-Markov process (coefficient phi, innovation
// variance qg, stationary start), e white measurement noise (variance R).
// Kalman filter with state (r, g), T = diag(1, phi), Z = (1, 1) (Harvey
// 1989, Forecasting, Structural Time Series Models and the Kalman Filter,
// ch. 3). The diffuse start is exact and closed-form (Durbin & Koopman
// 2012, sec. 5.2): y_1 fixes r_1 = y_1 - g_1 - e_1, so after y_1 the state
// has mean (y_1, 0) and covariance [[s2 + R, -s2], [-s2, s2]], s2 the GM
// variance; the likelihood is that of y_2..y_n given y_1 (the likelihood of
// the first differences). Bench-only code for bench/gmwm-mle.R, not part of
// the package.
#include <Rcpp.h>
#include <cmath>

// Returns c(sum log F_t, sum v_t^2 / F_t, number of terms): the
// log-likelihood is -(count log(2 pi) + sum log F + sum v^2/F) / 2, and
// with every variance scaled by R the maximising R is sum(v^2/F) / count.
// [[Rcpp::export]]
Rcpp::NumericVector kf_sums(Rcpp::NumericVector y, double R, double qr,
                            double qg, double phi) {
  const R_xlen_t n = y.size();
  const double s2 = qg / (1.0 - phi * phi);
  double ar = y[0], ag = 0.0;
  double Prr = s2 + R, Prg = -s2, Pgg = s2;
  double slogF = 0.0, sv2F = 0.0;
  for (R_xlen_t t = 1; t < n; ++t) {
    if ((t & 0xFFFFF) == 0) Rcpp::checkUserInterrupt();
    const double pr = ar, pg = phi * ag;
    const double Mrr = Prr + qr, Mrg = phi * Prg, Mgg = phi * phi * Pgg + qg;
    const double v = y[t] - pr - pg;
    const double Kr = Mrr + Mrg, Kg = Mrg + Mgg;  // predicted covariance times Z'
    const double F = Kr + Kg + R;
    const double iF = 1.0 / F;
    slogF += std::log(F);
    sv2F += v * v * iF;
    ar = pr + Kr * iF * v;
    ag = pg + Kg * iF * v;
    Prr = Mrr - Kr * Kr * iF;
    Prg = Mrg - Kr * Kg * iF;
    Pgg = Mgg - Kg * Kg * iF;
  }
  return Rcpp::NumericVector::create(slogF, sv2F, static_cast<double>(n - 1));
}
