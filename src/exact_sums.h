// Arithmetic that reproduces allanvar 1.1 (R code) bit for bit.
#ifndef ALLANVAR_EXACT_SUMS_H
#define ALLANVAR_EXACT_SUMS_H

#include <Rcpp.h>
#include <cfloat>

namespace allanvar {

// R's sum() of doubles: long double, left to right from 0, rounded once, with
// R's own overflow rule (a sum beyond DBL_MAX is Inf even if it would round
// down to DBL_MAX).
inline double r_sum_result(long double s) {
  if (s > DBL_MAX) return R_PosInf;
  if (s < -DBL_MAX) return R_NegInf;
  return static_cast<double>(s);
}

// out[k] = sum(x[k*c + 0 .. k*c + c-1]) / c for k in [0, M), each cluster sum
// formed as R's sum() forms it. Four clusters are summed at once: their
// long-double chains are independent, so the adds overlap in the pipeline
// while each chain keeps its own left-to-right order.
inline void cluster_means(const double* x, R_xlen_t c, R_xlen_t M,
                          double* out) {
  const double dc = static_cast<double>(c);
  R_xlen_t k = 0;
  for (; k + 4 <= M; k += 4) {
    const double* p0 = x + k * c;
    const double* p1 = p0 + c;
    const double* p2 = p1 + c;
    const double* p3 = p2 + c;
    long double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    for (R_xlen_t j = 0; j < c; ++j) {
      s0 += p0[j];
      s1 += p1[j];
      s2 += p2[j];
      s3 += p3[j];
    }
    out[k] = r_sum_result(s0) / dc;
    out[k + 1] = r_sum_result(s1) / dc;
    out[k + 2] = r_sum_result(s2) / dc;
    out[k + 3] = r_sum_result(s3) / dc;
  }
  for (; k < M; ++k) {
    const double* p = x + k * c;
    long double s = 0;
    for (R_xlen_t j = 0; j < c; ++j) s += p[j];
    out[k] = r_sum_result(s) / dc;
  }
}

// allanvar 1.1's non-overlapping Allan variance from M cluster means:
// S = S + (w[k+1] - w[k])^2 in double, left to right, then S / (2 (M - 1)).
inline double cluster_mean_avar(const double* w, R_xlen_t M) {
  double S = 0.0;
  for (R_xlen_t k = 0; k + 1 < M; ++k) {
    const double d = w[k + 1] - w[k];
    const double d2 = d * d;
    S = S + d2;
  }
  return S / (2.0 * (static_cast<double>(M) - 1.0));
}

// The `error` column of allanvar 1.1: 1/sqrt(2 (N/c - 1)).
inline double cluster_error(R_xlen_t N, double c) {
  return 1.0 / std::sqrt(2.0 * ((static_cast<double>(N) / c) - 1.0));
}

// The largest octave exponent p = floor(log10(n)/log10(2)), n = ceiling((N-1)/2),
// computed with the same double expressions as allanvar 1.1.
inline int octave_count(R_xlen_t N) {
  const double n = std::ceil((static_cast<double>(N) - 1.0) / 2.0);
  return static_cast<int>(std::floor(std::log10(n) / std::log10(2.0)));
}

}  // namespace allanvar

#endif
