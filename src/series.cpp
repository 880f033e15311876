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

// The spike pass's AR model (R/nonstationary.R, spike_ao_z()): Burg's
// coefficients of order p, the operations of R's stats burg.c in their
// order, so that they are those of ar.burg(x, aic = FALSE, order.max = p,
// demean = FALSE)$ar; without the residuals ar.burg() builds through
// embed() (an n x (p + 1) matrix the pass never reads). numeric(0) where
// ar.burg() stops: a NaN variance ("zero-variance series").
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector spike_burg(const Rcpp::NumericVector& x, int pmax) {
  const R_xlen_t n = x.size();
  // ar.burg() stops here too ("'order.max' must be >= 1" or "< 'n.used'")
  if (pmax < 1 || pmax >= n) return Rcpp::NumericVector(0);
  std::vector<double> u(n), v(n), u0(n), coefs(size_t(pmax) * pmax, 0.0),
      var2(pmax + 1);
  double sum = 0.0, d, phii;
  for (R_xlen_t t = 0; t < n; t++) {
    u[t] = v[t] = x[n - 1 - t];
    sum += x[t] * x[t];
  }
  var2[0] = sum / static_cast<double>(n);
  for (int p = 1; p <= pmax; p++) {
    sum = 0.0;
    d = 0;
    for (R_xlen_t t = p; t < n; t++) {
      sum += v[t] * u[t - 1];
      d += v[t] * v[t] + u[t - 1] * u[t - 1];
    }
    phii = 2 * sum / d;
    coefs[pmax * (p - 1) + (p - 1)] = phii;
    if (p > 1)
      for (int j = 1; j < p; j++)
        coefs[p - 1 + pmax * (j - 1)] =
            coefs[p - 2 + pmax * (j - 1)] - phii * coefs[p - 2 + pmax * (p - j - 1)];
    for (R_xlen_t t = 0; t < n; t++) u0[t] = u[t];
    for (R_xlen_t t = p; t < n; t++) {
      u[t] = u0[t - 1] - phii * v[t];
      v[t] = v[t] - phii * u0[t - 1];
    }
    d = 0.0;
    for (R_xlen_t t = p; t < n; t++) d += v[t] * v[t] + u[t] * u[t];
    var2[p] = d / (2.0 * static_cast<double>(n - p));
  }
  for (int p = 0; p <= pmax; p++)
    if (std::isnan(var2[p])) return Rcpp::NumericVector(0);
  Rcpp::NumericVector ar(pmax);
  for (int j = 0; j < pmax; j++) ar[j] = coefs[pmax - 1 + size_t(pmax) * j];
  return ar;
}

// The AR filter f over x as stats::filter(x, f, sides = 1) computes it
// (R's cfilter: z = 0, then z += f[j] * x[i - j] for j = 0, 1, ...; NA for
// the first length(f) - 1 samples and wherever a term is NaN), or with
// `backward` as rev(filter(rev(x), f, sides = 1)): sum_j f[j] x[i + j], NA
// for the last length(f) - 1. Without the ts and its reversed copies; in
// blocks of outputs, each output's sum still in the order of j (one
// running sum per output: the compiler may then run outputs side by side).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector ar_filter(const Rcpp::NumericVector& x,
                              const Rcpp::NumericVector& f, bool backward) {
  const R_xlen_t n = x.size(), nf = f.size();
  Rcpp::NumericVector out(n, NA_REAL);
  if (nf > n) return out;
  const double* xp = x.begin();
  const double* fp = f.begin();
  double* op = out.begin();
  bool finite = true;
  for (R_xlen_t i = 0; i < n && finite; i++) finite = !ISNAN(xp[i]);
  // the outputs defined: i = lo .. hi - 1
  const R_xlen_t lo = backward ? 0 : nf - 1, hi = backward ? n - nf + 1 : n;
  if (!finite) {
    for (R_xlen_t i = lo; i < hi; i++) {
      double z = 0;
      bool ok = true;
      for (R_xlen_t j = 0; j < nf; j++) {
        const double tmp = backward ? xp[i + j] : xp[i - j];
        if (ISNAN(tmp)) {
          ok = false;
          break;
        }
        z += fp[j] * tmp;
      }
      op[i] = ok ? z : NA_REAL;
    }
    return out;
  }
  const R_xlen_t B = 512;
  double acc[512];
  for (R_xlen_t b0 = lo; b0 < hi; b0 += B) {
    const R_xlen_t m = std::min(B, hi - b0);
    for (R_xlen_t k = 0; k < m; k++) acc[k] = 0;
    for (R_xlen_t j = 0; j < nf; j++) {
      const double fj = fp[j];
      const double* xs = backward ? xp + b0 + j : xp + b0 - j;
      for (R_xlen_t k = 0; k < m; k++) acc[k] += fj * xs[k];
    }
    for (R_xlen_t k = 0; k < m; k++) op[b0 + k] = acc[k];
  }
  return out;
}
