// Raw-data evidence (R/evidence.R): the autocovariance of a series at the
// first few lags, by direct sums. For a few dozen lags this is cheaper than
// an FFT of the whole record (O(n L) with L ~ 50 against two transforms of
// n points) and exact to rounding.
#include <Rcpp.h>
#include <algorithm>
#include <vector>

// sum_j x[j] x[j + k] for k = 0..max_lag, x already centred by the caller.
// Blocked over j so that each block is read from cache for every lag.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector acf_sums(const Rcpp::NumericVector& x, int max_lag) {
  const R_xlen_t n = x.size();
  const R_xlen_t L = std::max(0, max_lag);
  std::vector<double> acc(L + 1, 0.0);
  const double* v = x.begin();
  const R_xlen_t block = 4096;
  R_xlen_t done = 0;
  for (R_xlen_t j0 = 0; j0 < n; j0 += block) {
    const R_xlen_t j1 = std::min(n, j0 + block);
    for (R_xlen_t k = 0; k <= L; ++k) {
      const R_xlen_t end = std::min(j1, n - k);
      // four partial sums: independent chains the CPU can overlap
      double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
      R_xlen_t j = j0;
      for (; j + 3 < end; j += 4) {
        s0 += v[j] * v[j + k];
        s1 += v[j + 1] * v[j + 1 + k];
        s2 += v[j + 2] * v[j + 2 + k];
        s3 += v[j + 3] * v[j + 3 + k];
      }
      for (; j < end; ++j) s0 += v[j] * v[j + k];
      acc[k] += (s0 + s1) + (s2 + s3);
    }
    // poll Ctrl-C every ~2^22 products
    done += (j1 - j0) * (L + 1);
    if (done >= (R_xlen_t(1) << 22)) {
      done = 0;
      Rcpp::checkUserInterrupt();
    }
  }
  return Rcpp::NumericVector(acc.begin(), acc.end());
}

// x minus its least-squares line on t = 1..n: with t centred, the slope is
// sum(t x) / sum(t^2) and the intercept the mean (long double sums, as R's
// sum() and mean()).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector detrend_line(const Rcpp::NumericVector& x) {
  const R_xlen_t n = x.size();
  Rcpp::NumericVector out(n);
  if (n == 0) return out;
  const double* v = x.begin();
  long double s = 0;
  for (R_xlen_t j = 0; j < n; ++j) s += v[j];
  const double mean = static_cast<double>(s / n);
  const double c = (static_cast<double>(n) + 1.0) / 2.0;
  long double stx = 0, stt = 0;
  for (R_xlen_t j = 0; j < n; ++j) {
    const double t = static_cast<double>(j + 1) - c;
    stx += static_cast<long double>(t) * v[j];
    stt += static_cast<long double>(t) * t;
    if ((j & 0x3FFFFF) == 0) Rcpp::checkUserInterrupt();
  }
  const double slope = stt > 0 ? static_cast<double>(stx / stt) : 0.0;
  for (R_xlen_t j = 0; j < n; ++j) {
    const double t = static_cast<double>(j + 1) - c;
    out[j] = v[j] - mean - t * slope;
  }
  return out;
}
