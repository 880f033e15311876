// Input checks shared by the kernels.
#ifndef ALLANVAR_CHECKS_H
#define ALLANVAR_CHECKS_H

#include <Rcpp.h>
#include <cmath>

namespace allanvar {

// 1-based position of the first NA, NaN or infinite value; 0 when all are
// finite.
inline R_xlen_t first_nonfinite(const double* v, R_xlen_t n) {
  for (R_xlen_t i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return i + 1;
  }
  return 0;
}

}  // namespace allanvar

#endif
