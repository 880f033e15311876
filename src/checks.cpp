// Input checks that would otherwise allocate a logical vector per call.
#include <Rcpp.h>
#include <cmath>

// 1-based position of the first NA, NaN or infinite value; 0 when all are
// finite.
// [[Rcpp::export(rng = false)]]
double first_nonfinite(const Rcpp::NumericVector& x) {
  const R_xlen_t n = x.size();
  const double* p = x.begin();
  for (R_xlen_t i = 0; i < n; ++i) {
    if (!std::isfinite(p[i])) return static_cast<double>(i + 1);
  }
  return 0.0;
}
