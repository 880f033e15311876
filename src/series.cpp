// The step search of the series pass (R/nonstationary.R) reads a series
// with its steps taken out, x - level, where the level is constant between
// the sorted step indices `at` (1-based; level[k] applies from at[k - 1] on,
// level[0] before the first). These kernels read x - level in place, so the
// search no longer builds an n-sample copy per step. Each value is the
// double x[i] - level[k] that remove_steps() makes, and sums run in long
// double in sample order like R's .colMeans() and cumsum(), so the results
// are identical to the R expressions they replace.
#include <Rcpp.h>
#include <algorithm>
#include <cmath>
#include <vector>

// Segment k of x - level runs from sample at[k - 1] - 1 (0-based) to
// at[k] - 2; walks the segments in order.
struct Segments {
  const int* at;
  const double* level;
  R_xlen_t na, k = 0, end;
  Segments(const Rcpp::IntegerVector& a, const Rcpp::NumericVector& l)
      : at(a.begin()), level(l.begin()), na(a.size()) {
    end = na ? R_xlen_t(at[0]) - 1 : R_XLEN_T_MAX;
  }
  // the level at sample i (i never decreasing between calls) and where it ends
  double at_sample(R_xlen_t i) {
    while (k < na && i >= end) {
      ++k;
      end = k < na ? R_xlen_t(at[k]) - 1 : R_XLEN_T_MAX;
    }
    return level[k];
  }
};

// Means of consecutive blocks of b samples of x - level (nb blocks), as
// .colMeans(xs[seq_len(nb * b)], b, nb): long double sum / b, then double.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector shifted_block_means(const Rcpp::NumericVector& x,
                                        const Rcpp::IntegerVector& at,
                                        const Rcpp::NumericVector& level,
                                        int b, R_xlen_t nb) {
  Rcpp::NumericVector out(nb);
  const double* v = x.begin();
  double* o = out.begin();
  Segments seg(at, level);
  R_xlen_t i = 0;
  for (R_xlen_t j = 0; j < nb; ++j) {
    long double s = 0;
    const R_xlen_t stop = i + b;
    while (i < stop) {
      const double L = seg.at_sample(i);
      const R_xlen_t e = std::min(stop, seg.end);
      for (; i < e; ++i) s += v[i] - L;
    }
    s /= b;
    o[j] = static_cast<double>(s);
    if ((j & 4095) == 4095) Rcpp::checkUserInterrupt();
  }
  return out;
}

// c(0, cumsum(x - level))[lo:hi] (1-based, hi <= n + 1): the running sum
// in long double from the first sample, kept from lo on.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector shifted_prefix(const Rcpp::NumericVector& x,
                                   const Rcpp::IntegerVector& at,
                                   const Rcpp::NumericVector& level,
                                   R_xlen_t lo, R_xlen_t hi) {
  Rcpp::NumericVector out(std::max<R_xlen_t>(0, hi - lo + 1));
  const double* v = x.begin();
  double* o = out.begin();
  Segments seg(at, level);
  // cs[p] (1-based) is the sum of the first p - 1 samples: samples
  // 0..lo - 3 (0-based) are summed only, the rest also kept
  if (lo <= 1 && hi >= 1) o[1 - lo] = 0.0;
  long double s = 0;
  R_xlen_t i = 0;
  const R_xlen_t quiet = std::max<R_xlen_t>(0, lo - 2), last = hi - 1;
  while (i < quiet) {
    const double L = seg.at_sample(i);
    const R_xlen_t e = std::min(quiet, seg.end);
    for (; i < e; ++i) s += v[i] - L;
  }
  while (i < last) {
    const double L = seg.at_sample(i);
    const R_xlen_t e = std::min(last, seg.end);
    for (; i < e; ++i) {
      s += v[i] - L;
      o[i + 2 - lo] = static_cast<double>(s);
    }
  }
  return out;
}

// The data half of warmup_whiten() (R/nonstationary.R): every column of Y
// through the Kalman filter whose gains K (m x nb) and innovation sds sF
// are given. Per row j, as the R loop it replaces: v = Y[j, ] - colSums of
// the state a (summed in order from 0, as BLAS dgemv does one %*% a),
// E[j, ] = v / sF[j], a = phi * a + (0 + K[, j] v) (tcrossprod()'s product
// added to 0). Returns E without its first row.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericMatrix warmup_whiten_data(const Rcpp::NumericMatrix& Y,
                                       const Rcpp::NumericMatrix& K,
                                       const Rcpp::NumericVector& sF,
                                       const Rcpp::NumericVector& phi) {
  const R_xlen_t nb = Y.nrow(), nc = Y.ncol(), m = phi.size();
  Rcpp::NumericMatrix E(nb > 0 ? nb - 1 : 0, nc);
  if (nb < 1) return E;
  const double* y = Y.begin();
  const double* k = K.begin();
  const double* f = sF.begin();
  const double* p = phi.begin();
  double* e = E.begin();
  std::vector<double> a(m * nc, 0.0);      // the states, column c at a[c m]
  for (R_xlen_t j = 0; j < nb; ++j) {
    const double* kj = k + j * m;
    for (R_xlen_t c = 0; c < nc; ++c) {
      double* ac = a.data() + c * m;
      double s = 0.0;
      for (R_xlen_t l = 0; l < m; ++l) s = s + ac[l] * 1.0;
      const double v = y[j + c * nb] - s;
      if (j > 0) e[(j - 1) + c * (nb - 1)] = v / f[j];
      for (R_xlen_t l = 0; l < m; ++l) ac[l] = p[l] * ac[l] + (0.0 + v * kj[l]);
    }
    if ((j & 255) == 255) Rcpp::checkUserInterrupt();
  }
  return E;
}

// The gain half of warmup_whiten(): the Kalman gains K (m x nb) and the
// innovation sds sF from the initial covariance P (m x m), PP = phi phi',
// the state noise Q and the white variance h, as the R loop made them:
// Pz = rowSums(P) and F = sum(Pz) + h in long double sums, K = phi Pz / F,
// stopped at the steady state (the remaining gains are the last one).
// [[Rcpp::export(rng = false)]]
Rcpp::List warmup_gains(const Rcpp::NumericMatrix& P0, const Rcpp::NumericMatrix& PP,
                        const Rcpp::NumericVector& Q, const Rcpp::NumericVector& phi,
                        double h, R_xlen_t nb) {
  const R_xlen_t m = phi.size();
  std::vector<double> P(P0.begin(), P0.end()), Pz(m);
  const double* pp = PP.begin();
  Rcpp::NumericMatrix K(m, nb);
  Rcpp::NumericVector sF(nb);
  double* k = K.begin();
  for (R_xlen_t j = 0; j < nb; ++j) {
    for (R_xlen_t i = 0; i < m; ++i) {
      long double r = 0;
      for (R_xlen_t c = 0; c < m; ++c) r += P[i + c * m];
      Pz[i] = static_cast<double>(r);
    }
    long double t = 0;
    for (R_xlen_t i = 0; i < m; ++i) t += Pz[i];
    const double F = static_cast<double>(t) + h;
    double* kj = k + j * m;
    for (R_xlen_t i = 0; i < m; ++i) kj[i] = phi[i] * Pz[i] / F;
    sF[j] = std::sqrt(F);
    if (j > 1 && std::fabs(sF[j] / sF[j - 1] - 1) < 1e-12) {
      double dmax = 0, kmax = 0;
      for (R_xlen_t i = 0; i < m; ++i) {
        dmax = std::max(dmax, std::fabs(kj[i] - kj[i - m]));
        kmax = std::max(kmax, std::fabs(kj[i]));
      }
      if (dmax < 1e-12 * kmax) {
        for (R_xlen_t q = j + 1; q < nb; ++q) {
          std::copy(kj, kj + m, k + q * m);
          sF[q] = sF[j];
        }
        break;
      }
    }
    for (R_xlen_t c = 0; c < m; ++c) {
      for (R_xlen_t i = 0; i < m; ++i) {
        P[i + c * m] = pp[i + c * m] * (P[i + c * m] - (Pz[i] * Pz[c]) / F);
      }
    }
    for (R_xlen_t i = 0; i < m; ++i) P[i + i * m] = P[i + i * m] + Q[i];
  }
  return Rcpp::List::create(Rcpp::Named("K") = K, Rcpp::Named("sF") = sF);
}
