// Input checks that would otherwise allocate a logical vector per call.
#include "checks.h"

// 1-based position of the first NA, NaN or infinite value of x; 0 when all
// are finite (a double, so that long vectors fit).
// [[Rcpp::export(rng = false)]]
double first_nonfinite(const Rcpp::NumericVector& x) {
  return static_cast<double>(allanvar::first_nonfinite(x.begin(), x.size()));
}
