// The warm-up's Kalman filter (R/nonstationary.R, warmup_whiten()): the
// gains of a diffuse level, AR(1) states and white noise, and the columns
// of Y whitened by them. Shared by the R-facing kernels in series.cpp and
// the likelihood in warmup_ml.cpp, so that both run the same arithmetic.
#ifndef ALLANVAR_WARMUP_KALMAN_H
#define ALLANVAR_WARMUP_KALMAN_H

#include <Rcpp.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

// Gains K (m x nb, column j at K + j m) and innovation sds sF (nb) from
// the initial covariance P0 (m x m), PP = phi phi', the state noise Q and
// the white variance h: Pz = rowSums(P) and F = sum(Pz) + h in long double
// sums, K = phi Pz / F, stopped at the steady state (sF and K still to
// 1e-12: the remaining gains are the last one).
inline void warmup_gains_core(const double* P0, const double* pp, const double* Q,
                              const double* phi, double h, R_xlen_t m, R_xlen_t nb,
                              double* k, double* sF) {
  std::vector<double> P(P0, P0 + m * m), Pz(m);
  for (R_xlen_t j = 0; j < nb; ++j) {
    for (R_xlen_t i = 0; i < m; ++i) {
      long double r = 0;
      for (R_xlen_t c = 0; c < m; ++c) r += P[i + c * m];
      Pz[i] = static_cast<double>(r);
    }
    long double t = 0;
    for (R_xlen_t i = 0; i < m; ++i) t += Pz[i];
    const double F = static_cast<double>(t) + h;
    double* kj = k + j * m;
    for (R_xlen_t i = 0; i < m; ++i) kj[i] = phi[i] * Pz[i] / F;
    sF[j] = std::sqrt(F);
    if (j > 1 && std::fabs(sF[j] / sF[j - 1] - 1) < 1e-12) {
      double dmax = 0, kmax = 0;
      for (R_xlen_t i = 0; i < m; ++i) {
        dmax = std::max(dmax, std::fabs(kj[i] - kj[i - m]));
        kmax = std::max(kmax, std::fabs(kj[i]));
      }
      if (dmax < 1e-12 * kmax) {
        for (R_xlen_t q = j + 1; q < nb; ++q) {
          std::copy(kj, kj + m, k + q * m);
          sF[q] = sF[j];
        }
        break;
      }
    }
    for (R_xlen_t c = 0; c < m; ++c) {
      for (R_xlen_t i = 0; i < m; ++i) {
        P[i + c * m] = pp[i + c * m] * (P[i + c * m] - (Pz[i] * Pz[c]) / F);
      }
    }
    for (R_xlen_t i = 0; i < m; ++i) P[i + i * m] = P[i + i * m] + Q[i];
  }
}

// Every column of Y (nb x nc) through the filter: per row j, v = Y[j, ]
// minus the sum of the state a (summed in order from 0, as BLAS dgemv does
// one %*% a), E[j - 1, ] = v / sF[j] (the first row, the diffuse start,
// dropped), a = phi * a + (0 + K[, j] v). E is (nb - 1) x nc.
inline void warmup_whiten_core(const double* y, R_xlen_t nb, R_xlen_t nc, const double* k,
                               const double* f, const double* p, R_xlen_t m, double* e) {
  std::vector<double> a(m * nc, 0.0);      // the states, column c at a[c m]
  for (R_xlen_t j = 0; j < nb; ++j) {
    const double* kj = k + j * m;
    for (R_xlen_t c = 0; c < nc; ++c) {
      double* ac = a.data() + c * m;
      double s = 0.0;
      for (R_xlen_t l = 0; l < m; ++l) s = s + ac[l] * 1.0;
      const double v = y[j + c * nb] - s;
      if (j > 0) e[(j - 1) + c * (nb - 1)] = v / f[j];
      for (R_xlen_t l = 0; l < m; ++l) ac[l] = p[l] * ac[l] + (0.0 + v * kj[l]);
    }
    if ((j & 255) == 255) Rcpp::checkUserInterrupt();
  }
}

// The whole filter of a noise model: white h, a diffuse level of random
// walk q, AR(1) states phis of variances s (np of them), as
// warmup_whiten() states it: phi = c(1, phis), Q = c(q, s (1 - phis^2)),
// P0 = diag(c(big, s)), big = 1e6 (h + sum(s) + q nb) (the sum in long
// double, as R's sum()). Y (nb x nc) whitened into E ((nb - 1) x nc);
// returns the log-determinant sum(log(sF[-1])), in long double likewise.
inline double warmup_filter(const double* Y, R_xlen_t nb, R_xlen_t nc, double h, double q,
                            const double* phis, const double* s, R_xlen_t np, double* E) {
  const R_xlen_t m = np + 1;
  std::vector<double> phi(m), Q(m), P0(m * m, 0.0), PP(m * m);
  long double ssum = 0;
  for (R_xlen_t i = 0; i < np; ++i) ssum += s[i];
  const double big = 1e6 * (h + static_cast<double>(ssum) + q * static_cast<double>(nb));
  phi[0] = 1;
  Q[0] = q;
  P0[0] = big;
  for (R_xlen_t i = 1; i < m; ++i) {
    phi[i] = phis[i - 1];
    Q[i] = s[i - 1] * (1 - phis[i - 1] * phis[i - 1]);
    P0[i + i * m] = s[i - 1];
  }
  for (R_xlen_t c = 0; c < m; ++c)
    for (R_xlen_t i = 0; i < m; ++i) PP[i + c * m] = phi[i] * phi[c];
  // The gains and sds are written whole by every call: buffers kept
  // between calls (the optimiser's hundreds of evaluations spent a tenth
  // of the filter allocating and zeroing them).
  static thread_local std::vector<double> K, sF;
  if (K.size() < static_cast<size_t>(m * nb)) K.resize(m * nb);
  if (sF.size() < static_cast<size_t>(nb)) sF.resize(nb);
  warmup_gains_core(P0.data(), PP.data(), Q.data(), phi.data(), h, m, nb, K.data(), sF.data());
  warmup_whiten_core(Y, nb, nc, K.data(), sF.data(), phi.data(), m, E);
  // sF holds one value from the steady state on: its log taken once per
  // value (the same double added in the same order)
  long double ld = 0;
  double last = std::numeric_limits<double>::quiet_NaN(), lg = 0;
  for (R_xlen_t j = 1; j < nb; ++j) {
    if (!(sF[j] == last)) {
      last = sF[j];
      lg = std::log(last);
    }
    ld += lg;
  }
  return static_cast<double>(ld);
}

#endif
