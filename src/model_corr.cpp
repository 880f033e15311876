// Correlation of overlapping Allan variance estimates at different cluster
// sizes under a fitted noise model (Gaussian; Isserlis). With d^a_i the
// phase second difference at cluster size a starting at sample i and
// C_ab(h) = Cov(d^a_i, d^b_{i+h}),
//   Cov(AV-hat_a, AV-hat_b) ~ sum_h n_ab(h) C_ab(h)^2,
// n_ab(h) the number of pairs (i, i + h) with 0 <= i < M_a, 0 <= i + h < M_b
// (the constant factors cancel in the correlation), and
//   C_ab(h) = -1/2 sum_{p in {0,a,2a}} sum_{q in {0,b,2b}} u_p u_q V(h + q - p),
// u = (1, -2, 1), V the model's structure function (structure_fn.h). C_ab
// vanishes beyond the kernels' reach (plus the AR(1) tail), is smooth
// between the kinks h = p - q, and the count is linear between its own
// kinks: each piece is summed by the trapezoid rule with the end
// correction, the white-phase spikes at the kinks added exactly.
#include <Rcpp.h>
#include <algorithm>
#include <cmath>
#include <vector>
#include "parallel.h"
#include "structure_fn.h"

namespace {

using allanvar::StructureFn;

double cross_acov(const StructureFn& V, double h, double a, double b) {
  static const double u[3] = {1.0, -2.0, 1.0};
  double s = 0.0;
  for (int p = 0; p < 3; ++p)
    for (int q = 0; q < 3; ++q) s += u[p] * u[q] * V(h + q * b - p * a);
  return -0.5 * s;
}

// sum_h n_ab(h) C_ab(h)^2 (overlapping estimators).
double cross_sum(const StructureFn& V, double a, double Ma, double b, double Mb,
                 double tail) {
  // the windows [i, i + 2a] and [i + h, i + h + 2b] meet for -2b < h < 2a
  const double lo = std::max(-(2.0 * b + tail), -(Ma - 1.0));
  const double hi = std::min(2.0 * a + tail, Mb - 1.0);
  if (hi < lo) return 0.0;
  auto count = [&](double h) {
    const double c = std::min(Ma, Mb - h) - std::max(0.0, -h);
    return c > 0 ? c : 0.0;
  };
  StructureFn Vs = V;
  Vs.p = 0.0;
  auto f = [&](double h) {
    const double c = cross_acov(Vs, h, a, b);
    return count(h) * c * c;
  };
  std::vector<double> br = {lo, hi, 0.0, Mb - Ma};
  for (int p = 0; p < 3; ++p)
    for (int q = 0; q < 3; ++q) br.push_back(p * a - q * b);
  std::vector<double> cut;
  for (double x : br) if (x >= lo && x <= hi) cut.push_back(x);
  std::sort(cut.begin(), cut.end());
  cut.erase(std::unique(cut.begin(), cut.end()), cut.end());
  double s = 0.0;
  for (std::size_t i = 0; i + 1 < cut.size(); ++i)
    s += allanvar::segment_sum(cut[i], cut[i + 1], f, 64);
  s += f(cut.back());
  if (V.p > 0) {
    for (int p = 0; p < 3; ++p) {
      for (int q = 0; q < 3; ++q) {
        const double h = p * a - q * b;
        // each lag once, however many kink pairs meet there
        bool seen = false;
        for (int pp = 0; pp < 3 && !seen; ++pp)
          for (int qq = 0; qq < 3 && !seen; ++qq)
            if ((pp * 3 + qq) < (p * 3 + q) && pp * a - qq * b == h) seen = true;
        if (seen || h < lo || h > hi) continue;
        const double c = cross_acov(V, h, a, b), cs = cross_acov(Vs, h, a, b);
        s += count(h) * (c * c - cs * cs);
      }
    }
  }
  return s;
}

}  // namespace

// Correlation matrix of overlapping AV estimates at cluster sizes m (whole
// numbers; M second differences each) for the model given as parts of its
// structure function (see allanvar::structure_from_parts()); NA where a
// variance is not positive.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericMatrix avfit_model_corr(const Rcpp::NumericVector& m,
                                     const Rcpp::NumericVector& M,
                                     const Rcpp::IntegerVector& shape,
                                     const Rcpp::NumericVector& coef,
                                     const Rcpp::NumericVector& phi) {
  double tail = 0.0;
  const StructureFn V = allanvar::structure_from_parts(shape, coef, phi, tail);
  const R_xlen_t J = m.size();
  Rcpp::NumericMatrix out(J, J);
  std::vector<double> var(J);
  allanvar::InterruptScope scope;
  for (R_xlen_t i = 0; i < J; ++i) var[i] = cross_sum(V, m[i], M[i], m[i], M[i], tail);
  for (R_xlen_t i = 0; i < J; ++i) {
    if (allanvar::interrupted()) break;
    out(i, i) = var[i] > 0 ? 1.0 : NA_REAL;
    for (R_xlen_t j = i + 1; j < J; ++j) {
      const double c = cross_sum(V, m[i], M[i], m[j], M[j], tail);
      const double r = (var[i] > 0 && var[j] > 0) ? c / std::sqrt(var[i] * var[j])
                                                  : NA_REAL;
      out(i, j) = out(j, i) = r;
    }
  }
  scope.finish();
  return out;
}
