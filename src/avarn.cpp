// avarn(): allanvar 1.1's non-overlapping Allan variance at every cluster size.
// Exactness forces O(N^2) work (each size re-sums every sample in long
// double), so cluster sizes are shared between threads.
#include "exact_sums.h"
#include "parallel.h"
#include <vector>

// [[Rcpp::export(rng = false)]]
Rcpp::DataFrame avarn_all_exact(const Rcpp::NumericVector& values, double freq,
                                int threads) {
  const R_xlen_t N = values.size();
  const double tau = 1.0 / freq;
  const R_xlen_t n =
      static_cast<R_xlen_t>(std::ceil((static_cast<double>(N) - 1.0) / 2.0));
  Rcpp::NumericVector time(n), av(n), error(n);
  const double* x = values.begin();
  double* avp = av.begin();
  std::vector<std::vector<double> > means(threads, std::vector<double>(N));
  allanvar::parallel_for(n, threads, [&](R_xlen_t i, int worker) {
    const R_xlen_t c = i + 1;
    const R_xlen_t M = N / c;
    double* w = means[worker].data();
    allanvar::cluster_means(x, c, M, w);
    avp[i] = allanvar::cluster_mean_avar(w, M);
  });
  for (R_xlen_t i = 0; i < n; ++i) {
    const double c = static_cast<double>(i + 1);
    time[i] = c * tau;
    error[i] = allanvar::cluster_error(N, c);
  }
  return Rcpp::DataFrame::create(Rcpp::Named("time") = time,
                                 Rcpp::Named("av") = av,
                                 Rcpp::Named("error") = error);
}
