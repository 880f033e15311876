// avar(): allanvar 1.1's non-overlapping Allan variance at octave cluster sizes.
#include "exact_sums.h"
#include <vector>

// [[Rcpp::export(rng = false)]]
Rcpp::DataFrame avar_octave_exact(const Rcpp::NumericVector& values,
                                  double freq) {
  const R_xlen_t N = values.size();
  const double tau = 1.0 / freq;
  const int p = allanvar::octave_count(N);
  Rcpp::NumericVector time(p + 1), av(p + 1), error(p + 1);
  std::vector<double> means(N);
  const double* x = values.begin();
  for (int i = 0; i <= p; ++i) {
    const double c = std::ldexp(1.0, i);
    const R_xlen_t ci = static_cast<R_xlen_t>(c);
    const R_xlen_t M = N / ci;
    allanvar::cluster_means(x, ci, M, means.data());
    av[i] = allanvar::cluster_mean_avar(means.data(), M);
    time[i] = c * tau;
    error[i] = allanvar::cluster_error(N, c);
    Rcpp::checkUserInterrupt();
  }
  return Rcpp::DataFrame::create(Rcpp::Named("time") = time,
                                 Rcpp::Named("av") = av,
                                 Rcpp::Named("error") = error);
}
