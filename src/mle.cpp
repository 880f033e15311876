// Exact Gaussian log-likelihood of a rate series under a linear state-space
// model with diagonal transition: y_t = sum_i s_i,t + e_t (Z = 1, ..., 1),
// s_i,t = T_i s_i,t-1 + w_i,t, Var(w_i) = Q_i, Var(e) = R. Kalman filter
// (Harvey 1989, Forecasting, Structural Time Series Models and the Kalman
// Filter, ch. 3). At most one state may start diffuse (a random walk whose
// level, the sensor's bias, is unknown); its exact diffuse start is closed
// form (Durbin & Koopman 2012, sec. 5.2): y_0 fixes it as y_0 minus the
// other states and e_0, and the likelihood is that of y_1.. given y_0.
// The model comes from the catalogue's `statespace` fields (R/fit-mle.R);
// this kernel reads only numbers.
#include <Rcpp.h>
#include <cmath>
#include <vector>

namespace {

struct KalmanModel {
  double R;                 // measurement-noise variance
  std::vector<double> T, Q, P0;
  int diffuse;              // index of the diffuse state, -1 for none
};

// sum log F_t, sum v_t^2 / F_t and the number of terms
struct KalmanSums { double logF, v2F, count; };

KalmanSums kalman_sums(const double* y, R_xlen_t n, const KalmanModel& m) {
  const std::size_t d = m.T.size();
  std::vector<double> a(d, 0.0), P(d * d, 0.0), k(d);
  KalmanSums out{0.0, 0.0, 0.0};
  R_xlen_t t0 = 0;
  for (std::size_t i = 0; i < d; ++i) P[i * d + i] = m.P0[i];
  if (m.diffuse >= 0) {
    // filtered state after y_0: s_j = y_0 - sum_{i != j} s_i - e_0
    const std::size_t j = static_cast<std::size_t>(m.diffuse);
    double pj = m.R;
    for (std::size_t i = 0; i < d; ++i) {
      if (i == j) continue;
      pj += m.P0[i];
      P[i * d + j] = P[j * d + i] = -m.P0[i];
    }
    P[j * d + j] = pj;
    a[j] = y[0];
    // predict to t = 1
    for (std::size_t i = 0; i < d; ++i) {
      a[i] *= m.T[i];
      for (std::size_t l = 0; l < d; ++l) P[i * d + l] *= m.T[i] * m.T[l];
      P[i * d + i] += m.Q[i];
    }
    t0 = 1;
  }
  // The Riccati recursion does not see the data: once an update leaves P
  // bit for bit unchanged, every later step has the same F and gain, so the
  // rest of the record runs with them fixed (no covariance update, one log)
  // and the sums are those of the full filter up to their order.
  // k = P Z' and the innovation variance F = Z P Z' + R
  auto gain = [&]() {
    double F = m.R;
    for (std::size_t i = 0; i < d; ++i) {
      double s = 0.0;
      for (std::size_t l = 0; l < d; ++l) s += P[i * d + l];
      k[i] = s;
      F += s;
    }
    return F;
  };
  std::vector<double> P_prev(d * d);
  R_xlen_t t = t0;
  bool steady = false;
  for (; t < n && !steady; ++t) {
    if ((t & 0xFFFF) == 0) Rcpp::checkUserInterrupt();
    P_prev = P;
    double pred = 0.0;
    for (std::size_t i = 0; i < d; ++i) pred += a[i];
    const double F = gain();
    const double v = y[t] - pred, iF = 1.0 / F;
    out.logF += std::log(F);
    out.v2F += v * v * iF;
    out.count += 1.0;
    // update, then predict (T diagonal)
    for (std::size_t i = 0; i < d; ++i) {
      a[i] = m.T[i] * (a[i] + k[i] * iF * v);
      for (std::size_t l = 0; l < d; ++l) {
        P[i * d + l] = m.T[i] * m.T[l] * (P[i * d + l] - k[i] * k[l] * iF);
      }
      P[i * d + i] += m.Q[i];
    }
    steady = P == P_prev;
  }
  if (t < n) {
    const double F = gain(), iF = 1.0 / F;
    std::vector<double> g(d);
    for (std::size_t i = 0; i < d; ++i) g[i] = k[i] * iF;
    out.logF += static_cast<double>(n - t) * std::log(F);
    out.count += static_cast<double>(n - t);
    for (; t < n; ++t) {
      if ((t & 0xFFFF) == 0) Rcpp::checkUserInterrupt();
      double pred = 0.0;
      for (std::size_t i = 0; i < d; ++i) pred += a[i];
      const double v = y[t] - pred;
      out.v2F += v * v * iF;
      for (std::size_t i = 0; i < d; ++i) a[i] = m.T[i] * (a[i] + g[i] * v);
    }
  }
  return out;
}

}  // namespace

// Internal entry point (R/fit-mle.R): c(sum log F, sum v^2 / F, count).
// [[Rcpp::export]]
Rcpp::NumericVector mle_kalman_sums(Rcpp::NumericVector y, double R,
                                    Rcpp::NumericVector T, Rcpp::NumericVector Q,
                                    Rcpp::NumericVector P0, int diffuse) {
  KalmanModel m{R, Rcpp::as<std::vector<double>>(T),
                Rcpp::as<std::vector<double>>(Q),
                Rcpp::as<std::vector<double>>(P0), diffuse};
  const KalmanSums s = kalman_sums(y.begin(), y.size(), m);
  return Rcpp::NumericVector::create(s.logF, s.v2F, s.count);
}
