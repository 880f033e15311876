// The structure function of a noise model's rate samples, V(l) = Var(sum of
// l consecutive rate samples), from the parts the catalogue's entries
// declare (exact_edf), and the autocovariance of the phase second
// differences built from it; shared by the exact EDF (avfit.cpp) and the
// correlation of AV estimates across cluster sizes (model_corr.cpp).
#ifndef ALLANVAR_STRUCTURE_FN_H
#define ALLANVAR_STRUCTURE_FN_H

#include <Rcpp.h>
#include <algorithm>
#include <cmath>
#include <vector>

namespace allanvar {

// V(l) of white rate noise (w = N^2 / tau0), rate random walk (q = K^2 tau0;
// generalised structure function, defined up to terms the second difference
// removes), white phase (p = Q^2 / tau0^2) and AR(1) terms (variance s2,
// coefficient phi).
struct StructureFn {
  double w = 0, q = 0, p = 0;
  std::vector<double> s2, phi, lphi;
  double operator()(double l) const {
    l = std::fabs(l);
    double v = w * l - q * (l * l * l - l) / 6.0 + (l > 0 ? 2.0 * p : 0.0);
    for (std::size_t g = 0; g < s2.size(); ++g) {
      const double ph = phi[g], e = 1.0 - ph;
      // 1 - phi^l without cancellation
      const double el = -std::expm1(l * lphi[g]);
      v += s2[g] * (l * (1.0 + ph) / e - 2.0 * ph * el / (e * e));
    }
    return v;
  }
  double acov_d(double k, double m) const {
    const StructureFn& V = *this;
    return -0.5 * (6.0 * V(k) - 4.0 * V(k + m) - 4.0 * V(k - m) +
                   V(k + 2.0 * m) + V(k - 2.0 * m));
  }
};

// The model from its parts, one per entry of `shape` (0: coef * l,
// 1: -coef (l^3 - l) / 6, 2: 2 coef for l > 0, 3: an AR(1) part, coef =
// sigma^2 with its `phi`); `tail`: lags beyond which the AR(1) parts of
// the autocovariance have decayed to e^-12 of their size.
inline StructureFn structure_from_parts(const Rcpp::IntegerVector& shape,
                                        const Rcpp::NumericVector& coef,
                                        const Rcpp::NumericVector& phi,
                                        double& tail) {
  StructureFn V;
  tail = 0.0;
  for (R_xlen_t g = 0; g < shape.size(); ++g) {
    switch (shape[g]) {
    case 0: V.w += coef[g]; break;
    case 1: V.q += coef[g]; break;
    case 2: V.p += coef[g]; break;
    case 3:
      if (!(coef[g] > 0) || !(phi[g] > 0 && phi[g] < 1)) break;
      V.s2.push_back(coef[g]);
      V.phi.push_back(phi[g]);
      V.lphi.push_back(std::log(phi[g]));
      tail = std::max(tail, std::ceil(12.0 / -std::log(phi[g])));
      break;
    default: break;
    }
  }
  return V;
}

// sum_{k=a}^{b-1} f(k): exactly when short, else the trapezoid rule on
// `nodes` points plus the Euler-Maclaurin end correction (f is smooth
// between the kinks, which the callers make segment ends).
template <class F>
double segment_sum(double a, double b, F f, int nodes) {
  if (b <= a) return 0.0;
  if (b - a <= nodes) {
    double s = 0.0;
    for (double k = a; k < b; k += 1.0) s += f(k);
    return s;
  }
  double s = 0.0, prev_k = a, prev_f = f(a);
  const double fa = prev_f;
  for (int i = 1; i <= nodes; ++i) {
    double k = std::round(a + (b - a) * i / nodes);
    if (k <= prev_k) continue;
    double fk = f(k);
    s += (k - prev_k) * (fk + prev_f) / 2.0;
    prev_k = k;
    prev_f = fk;
  }
  return s + (fa - prev_f) / 2.0;
}

}  // namespace allanvar

#endif
