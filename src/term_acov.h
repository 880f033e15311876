// The terms of a difference estimator as a filter on the phase, and their
// autocovariance under discrete power-law noise (Kasdin's model: phase
// x = (1 - B)^(-delta) e, e white, delta = (2 - alpha)/2, alpha the rate PSD
// exponent). Shared by the exact law of the estimate (gchisq.cpp: the
// eigenvalues of the terms' covariance) and its two-moment EDF (edf.cpp).
// A term is w(B) x with w(B) = (1 - B)^d v(B) (w annihilates polynomials of
// degree < d), so w(B) x = v(B) u with u = (1 - B)^(d - delta) e stationary
// (fractionally differenced white noise, autocovariance in closed form).
#ifndef ALLANVAR_TERM_ACOV_H
#define ALLANVAR_TERM_ACOV_H

#include "types.h"
#include <cmath>
#include <cstdlib>
#include <vector>

namespace allanvar {

// Weights of one term on the phase (first point at 0): second (d = 2) or
// third (d = 3) differences at spacing m; for the modified type the sum of
// m shifted second differences; for PDEV the parabolic weights
// (m - 1)/2 - k, k < m, then their negatives (src/pdev.cpp's S_i), and at
// m = 1, where those vanish, the second difference (PVAR(tau0) = AVAR).
inline std::vector<double> phase_weights(int type, long m) {
  const EstimatorInfo& info = estimator_info(type);
  std::vector<double> w;
  if (type == PDEV && m > 1) {
    w.assign(2 * m, 0.0);
    for (long k = 0; k < m; ++k) {
      w[k] = 0.5 * static_cast<double>(m - 1) - static_cast<double>(k);
      w[m + k] = -w[k];
    }
  } else if (info.d == 3) {
    w.assign(3 * m + 1, 0.0);
    w[0] = -1;
    w[m] = 3;
    w[2 * m] = -3;
    w[3 * m] = 1;
  } else if (info.modified) {
    w.assign(3 * m, 0.0);
    for (long j = 0; j < m; ++j) {
      w[j] += 1;
      w[j + m] -= 2;
      w[j + 2 * m] += 1;
    }
  } else {
    w.assign(2 * m + 1, 0.0);
    w[0] = 1;
    w[m] = -2;
    w[2 * m] = 1;
  }
  return w;
}

// v with w(B) = (1 - B)^d v(B): d running sums (exact in integers and
// half-integers; the last d entries vanish because w annihilates
// polynomials of degree < d).
inline std::vector<double> undifference(std::vector<double> w, int d) {
  for (int k = 0; k < d; ++k) {
    for (std::size_t i = 1; i < w.size(); ++i) w[i] += w[i - 1];
    w.pop_back();
  }
  return w;
}

// Autocovariance of (1 - B)^(-f) e, f <= 0, at lags 0..H (unit innovation
// variance): gamma(0) = Gamma(1 - 2f)/Gamma(1 - f)^2 and
// gamma(h + 1) = gamma(h) (h + f)/(h + 1 - f); at integer f the finite
// moving average's (the ratio reaches zero at h = -f).
inline std::vector<double> farima_acf(double f, long H) {
  std::vector<double> g(H + 1);
  g[0] = std::exp(std::lgamma(1 - 2 * f) - 2 * std::lgamma(1 - f));
  for (long h = 0; h < H; ++h) g[h + 1] = g[h] * (h + f) / (h + 1 - f);
  return g;
}

// Autocovariance c(k), k = 0..K-1, of terms w(B) x taken at stride s, under
// the power law alpha: c(k) = sum_l a(|l|) gamma(|k s + l|), a the
// autocorrelation of v. O(V^2 + K V) for V = length(v). Clean input:
// alpha + 2 d > 1, K >= 1.
inline std::vector<double> term_acov(const std::vector<double>& w, int d,
                                     int alpha, long s, long K) {
  const std::vector<double> v = undifference(w, d);
  const long V = static_cast<long>(v.size());
  std::vector<double> a(V);
  for (long l = 0; l < V; ++l) {
    double acc = 0;
    for (long i = 0; i + l < V; ++i) acc += v[i] * v[i + l];
    a[l] = acc;
  }
  const double f = (2.0 - alpha) / 2.0 - d;
  const std::vector<double> g = farima_acf(f, (K - 1) * s + V);
  std::vector<double> c(K);
  for (long k = 0; k < K; ++k) {
    double acc = a[0] * g[k * s];
    for (long l = 1; l < V; ++l) {
      acc += a[l] * (g[k * s + l] + g[std::labs(k * s - l)]);
    }
    c[k] = acc;
  }
  return c;
}

}  // namespace allanvar

#endif
