// avarn(): allanvar 1.1's non-overlapping Allan variance at every cluster size.
// Exactness forces O(N^2) work (each size re-sums every sample in long
// double), so blocks of consecutive cluster sizes are shared between threads.
#include "exact_sums.h"
#include "parallel.h"
#include <algorithm>
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
  // Blocks of 16 sizes: the last clusters of neighbouring sizes overlap.
  const R_xlen_t block = 16;
  const R_xlen_t blocks = (n + block - 1) / block;
  std::vector<R_xlen_t> sizes(n);
  for (R_xlen_t i = 0; i < n; ++i) sizes[i] = i + 1;
  std::vector<std::vector<double> > sums(threads, std::vector<double>(N));
  allanvar::parallel_for(blocks, threads, [&](R_xlen_t b, int worker) {
    const R_xlen_t from = b * block;
    const R_xlen_t count = std::min(block, n - from);
    allanvar::cluster_avars(x, N, sizes.data() + from, count, avp + from,
                            sums[worker].data(), [] {});
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
