// avar(): allanvar 1.1's non-overlapping Allan variance at octave cluster sizes.
#include "exact_sums.h"
#include "parallel.h"
#include <vector>

// [[Rcpp::export(rng = false)]]
Rcpp::DataFrame avar_octave_exact(const Rcpp::NumericVector& values,
                                  double freq, int threads) {
  const R_xlen_t N = values.size();
  const double tau = 1.0 / freq;
  const int p = allanvar::octave_count(N);
  Rcpp::NumericVector time(p + 1), av(p + 1), error(p + 1);
  std::vector<R_xlen_t> sizes(p + 1);
  for (int i = 0; i <= p; ++i) sizes[i] = static_cast<R_xlen_t>(1) << i;
  // Every level re-sums all N samples; levels are shared between threads.
  if (threads > p + 1) threads = p + 1;
  std::vector<std::vector<double> > sums(threads, std::vector<double>(N));
  const double* x = values.begin();
  double* avp = av.begin();
  allanvar::parallel_for(p + 1, threads, [&](R_xlen_t i, int worker) {
    allanvar::cluster_avars(x, N, &sizes[i], 1, avp + i, sums[worker].data(),
                            [] {});
  });
  for (int i = 0; i <= p; ++i) {
    const double c = std::ldexp(1.0, i);
    time[i] = c * tau;
    error[i] = allanvar::cluster_error(N, c);
  }
  return Rcpp::DataFrame::create(Rcpp::Named("time") = time,
                                 Rcpp::Named("av") = av,
                                 Rcpp::Named("error") = error);
}
