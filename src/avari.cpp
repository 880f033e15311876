// avari(): allanvar 1.1's overlapping Allan variance of integrated input
// (angle, velocity) at octave cluster sizes.
#include "exact_sums.h"
#include <algorithm>

namespace {

inline double second_difference(const double* x, R_xlen_t k, R_xlen_t c) {
  // allanvar 1.1 forms (x[k+2c] - 2 x[k+c]) + x[k], in that order.
  return (x[k + 2 * c] - 2.0 * x[k + c]) + x[k];
}

// Sums of squared second differences for up to four cluster sizes in one
// pass: each level keeps its own left-to-right double accumulator (so its
// bits match the original), and the independent chains overlap.
void second_difference_sums(const double* x, R_xlen_t N, const R_xlen_t* c,
                            int levels, double* S) {
  R_xlen_t common = N;
  for (int j = 0; j < levels; ++j) common = std::min(common, N - 2 * c[j]);
  double acc[4] = {0.0, 0.0, 0.0, 0.0};
  if (levels == 4) {
    for (R_xlen_t k = 0; k < common; ++k) {
      const double d0 = second_difference(x, k, c[0]);
      const double d1 = second_difference(x, k, c[1]);
      const double d2 = second_difference(x, k, c[2]);
      const double d3 = second_difference(x, k, c[3]);
      const double q0 = d0 * d0, q1 = d1 * d1, q2 = d2 * d2, q3 = d3 * d3;
      acc[0] = acc[0] + q0;
      acc[1] = acc[1] + q1;
      acc[2] = acc[2] + q2;
      acc[3] = acc[3] + q3;
    }
  } else {
    common = 0;
  }
  for (int j = 0; j < levels; ++j) {
    double s = acc[j];
    for (R_xlen_t k = common; k < N - 2 * c[j]; ++k) {
      const double d = second_difference(x, k, c[j]);
      const double q = d * d;
      s = s + q;
    }
    S[j] = s;
  }
}

}  // namespace

// [[Rcpp::export(rng = false)]]
Rcpp::DataFrame avari_octave_exact(const Rcpp::NumericVector& values,
                                   double freq) {
  const R_xlen_t N = values.size();
  const double tau = 1.0 / freq;
  const int p = allanvar::octave_count(N);
  Rcpp::NumericVector time(p), av(p), error(p);
  const double* x = values.begin();
  for (int i0 = 0; i0 < p; i0 += 4) {
    const int levels = std::min(4, p - i0);
    R_xlen_t c[4];
    double S[4];
    for (int j = 0; j < levels; ++j) c[j] = static_cast<R_xlen_t>(1) << (i0 + j);
    second_difference_sums(x, N, c, levels, S);
    for (int j = 0; j < levels; ++j) {
      const double cj = static_cast<double>(c[j]);
      const double T = cj * tau;
      av[i0 + j] = S[j] / ((2.0 * (T * T)) * (static_cast<double>(N) - 2.0 * cj));
      time[i0 + j] = T;
      error[i0 + j] = allanvar::cluster_error(N, cj);
    }
    Rcpp::checkUserInterrupt();
  }
  return Rcpp::DataFrame::create(Rcpp::Named("time") = time,
                                 Rcpp::Named("av") = av,
                                 Rcpp::Named("error") = error);
}
