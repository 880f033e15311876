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
#include <memory>
#include <vector>
#include "warmup_kalman.h"
#ifdef __SSE2__
#include <emmintrin.h>
#endif

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

// warmup_whiten() (R/nonstationary.R): the columns of Y through the
// warm-up's Kalman filter under the noise model (h, q, phis, s)
// (warmup_filter()); E without its first row, the log-determinant of the
// innovations in its attribute "logdet".
// [[Rcpp::export(rng = false)]]
Rcpp::NumericMatrix warmup_whiten_cpp(const Rcpp::NumericMatrix& Y, double h, double q,
                                      const Rcpp::NumericVector& phis,
                                      const Rcpp::NumericVector& s) {
  const R_xlen_t nb = Y.nrow(), nc = Y.ncol();
  if (nb < 1 || s.size() != phis.size()) {
    Rcpp::stop("warmup_whiten_cpp: Y needs a row, s one value per phi");
  }
  Rcpp::NumericMatrix E(nb - 1, nc);
  const double logdet = warmup_filter(Y.begin(), nb, nc, h, q, phis.begin(), s.begin(),
                                      phis.size(), E.begin());
  E.attr("logdet") = logdet;
  return E;
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
static void ar_filter_to(const double* xp, R_xlen_t n, const double* fp, R_xlen_t nf,
                         bool backward, double* op) {
  std::fill(op, op + n, NA_REAL);
  if (nf > n) return;
  bool finite = true;
  for (R_xlen_t i = 0; i < n && finite; i++) finite = !std::isnan(xp[i]);
  // the outputs defined: i = lo .. hi - 1
  const R_xlen_t lo = backward ? 0 : nf - 1, hi = backward ? n - nf + 1 : n;
  if (!finite) {
    for (R_xlen_t i = lo; i < hi; i++) {
      double z = 0;
      bool ok = true;
      for (R_xlen_t j = 0; j < nf; j++) {
        const double tmp = backward ? xp[i + j] : xp[i - j];
        if (std::isnan(tmp)) {
          ok = false;
          break;
        }
        z += fp[j] * tmp;
      }
      op[i] = ok ? z : NA_REAL;
    }
    return;
  }
  R_xlen_t start = lo;
#ifdef __SSE2__
  // eight outputs at a time in four registers, each lane's sum over j in
  // order: the same multiplications and additions as below
  for (; start + 8 <= hi; start += 8) {
    __m128d s0 = _mm_setzero_pd(), s1 = s0, s2 = s0, s3 = s0;
    for (R_xlen_t j = 0; j < nf; j++) {
      const __m128d fj = _mm_set1_pd(fp[j]);
      const double* xs = backward ? xp + start + j : xp + start - j;
      s0 = _mm_add_pd(s0, _mm_mul_pd(fj, _mm_loadu_pd(xs)));
      s1 = _mm_add_pd(s1, _mm_mul_pd(fj, _mm_loadu_pd(xs + 2)));
      s2 = _mm_add_pd(s2, _mm_mul_pd(fj, _mm_loadu_pd(xs + 4)));
      s3 = _mm_add_pd(s3, _mm_mul_pd(fj, _mm_loadu_pd(xs + 6)));
    }
    _mm_storeu_pd(op + start, s0);
    _mm_storeu_pd(op + start + 2, s1);
    _mm_storeu_pd(op + start + 4, s2);
    _mm_storeu_pd(op + start + 6, s3);
  }
#endif
  const R_xlen_t B = 512;
  double acc[512];
  for (R_xlen_t b0 = start; b0 < hi; b0 += B) {
    const R_xlen_t m = std::min(B, hi - b0);
    for (R_xlen_t k = 0; k < m; k++) acc[k] = 0;
    for (R_xlen_t j = 0; j < nf; j++) {
      const double fj = fp[j];
      const double* xs = backward ? xp + b0 + j : xp + b0 - j;
      for (R_xlen_t k = 0; k < m; k++) acc[k] += fj * xs[k];
    }
    for (R_xlen_t k = 0; k < m; k++) op[b0 + k] = acc[k];
  }
}

// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector ar_filter(const Rcpp::NumericVector& x,
                              const Rcpp::NumericVector& f, bool backward) {
  Rcpp::NumericVector out(x.size());
  ar_filter_to(x.begin(), x.size(), f.begin(), f.size(), backward, out.begin());
  return out;
}

// The rest of spike_ao_z() (R/nonstationary.R) in one pass of buffers, the
// R lines' operations in their order: xs = x / sc - mu; e = ar_filter(xs,
// pi) with its first p values 0; a = ar_filter(e, pi, backward), NA as 0,
// its first and last 2 p values 0; a / denom. For p >= 1 and n > 4 p.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector spike_ao_values(const Rcpp::NumericVector& x, double sc, double mu,
                                    const Rcpp::NumericVector& pi, double denom) {
  const R_xlen_t n = x.size(), nf = pi.size(), p = nf - 1;
  Rcpp::NumericVector out(n);
  if (p < 1 || n <= 4 * p) Rcpp::stop("spike_ao_values(): needs p >= 1 and n > 4 p");
  const double* v = x.begin();
  std::unique_ptr<double[]> xs(new double[n]), e(new double[n]);
  for (R_xlen_t i = 0; i < n; i++) {
    const double y = v[i] / sc;
    xs[i] = y - mu;
  }
  ar_filter_to(xs.get(), n, pi.begin(), nf, false, e.get());
  for (R_xlen_t i = 0; i < p; i++) e[i] = 0;
  double* a = out.begin();
  ar_filter_to(e.get(), n, pi.begin(), nf, true, a);
  for (R_xlen_t i = 0; i < n; i++)
    if (std::isnan(a[i])) a[i] = 0;
  for (R_xlen_t i = 0; i < 2 * p; i++) a[i] = a[n - 1 - i] = 0;
  for (R_xlen_t i = 0; i < n; i++) a[i] = a[i] / denom;
  return out;
}

// The centred moving mean of x over the 2 h + 1 samples around each (fewer
// at the ends), the spike pass's slow part (R/nonstationary.R,
// spike_slow_part()): a running sum of x less its mean, in long double so
// that n updates do not drift.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector centred_moving_mean(const Rcpp::NumericVector& x, R_xlen_t h) {
  const R_xlen_t n = x.size();
  Rcpp::NumericVector out(n);
  if (n == 0) return out;
  if (h < 0) h = 0;
  const double* v = x.begin();
  long double mu = 0;
  for (R_xlen_t i = 0; i < n; i++) mu += v[i];
  mu /= n;
  long double sum = 0;
  R_xlen_t lo = 0, hi = -1;             // the window [lo, hi] summed
  for (R_xlen_t i = 0; i < n; i++) {
    const R_xlen_t want_hi = std::min(n - 1, i + h), want_lo = std::max<R_xlen_t>(0, i - h);
    while (hi < want_hi) sum += v[++hi] - mu;
    while (lo < want_lo) sum -= v[lo++] - mu;
    out[i] = static_cast<double>(mu + sum / (hi - lo + 1));
  }
  return out;
}

// min(q, p) and max(p, q) as SSE2's minpd and maxpd take them (the window
// network of running_median_keep())
static inline double median7_min(double q, double p) { return q < p ? q : p; }
static inline double median7_max(double p, double q) { return q < p ? p : q; }

// The spike pass's running median (R/nonstationary.R, spike_runmed()):
// the median of the k samples centred on each sample, the first and last
// k %/% 2 samples kept, as stats::runmed(endrule = "keep") returns them
// (a median of an odd window is one of its samples, whatever the
// algorithm). A zero-length result where x has a NaN (runmed's own NA
// rules apply there).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector running_median_keep(const Rcpp::NumericVector& x, int k) {
  const R_xlen_t n = x.size(), h = k / 2;
  const double* v = x.begin();
  for (R_xlen_t i = 0; i < n; i++)
    if (std::isnan(v[i])) return Rcpp::NumericVector(0);
  Rcpp::NumericVector out(n);
  double* o = out.begin();
  std::copy(v, v + n, o);
  if (n < k) return out;
  if (k == 7) {
    // the detector's window: a sorting network of 7 (16 exchanges, each a
    // swap or not, so the window's values are kept), without branches:
    // min(q, p) is q < p ? q : p and max(p, q) is q < p ? p : q, two
    // samples at once where SSE2 is there (every x86-64)
    R_xlen_t i = 3;
#define SORT7(T, MIN, MAX)                                              \
  {                                                                     \
    auto cx = [](T& p, T& q) { const T l = MIN(q, p); q = MAX(p, q); p = l; }; \
    cx(a0, a6); cx(a2, a3); cx(a4, a5);                                 \
    cx(a0, a2); cx(a1, a4); cx(a3, a6);                                 \
    cx(a0, a1); cx(a2, a5); cx(a3, a4);                                 \
    cx(a1, a2); cx(a4, a6);                                             \
    cx(a2, a3); cx(a4, a5);                                             \
    cx(a1, a2); cx(a3, a4); cx(a5, a6);                                 \
  }
#ifdef __SSE2__
    for (; i + 4 < n; i += 2) {
      const double* c = v + i - 3;
      __m128d a0 = _mm_loadu_pd(c), a1 = _mm_loadu_pd(c + 1), a2 = _mm_loadu_pd(c + 2),
              a3 = _mm_loadu_pd(c + 3), a4 = _mm_loadu_pd(c + 4), a5 = _mm_loadu_pd(c + 5),
              a6 = _mm_loadu_pd(c + 6);
      SORT7(__m128d, _mm_min_pd, _mm_max_pd)
      _mm_storeu_pd(o + i, a3);
    }
#endif
    for (; i + 3 < n; i++) {
      const double* c = v + i - 3;
      double a0 = c[0], a1 = c[1], a2 = c[2], a3 = c[3], a4 = c[4], a5 = c[5], a6 = c[6];
      SORT7(double, median7_min, median7_max)
      o[i] = a3;
    }
#undef SORT7
    return out;
  }
  // the window kept sorted: each step the sample leaving is replaced by the
  // one entering, moved to its place (O(k) a sample, no sort)
  std::vector<double> w(v, v + k);
  std::sort(w.begin(), w.end());
  o[h] = w[h];
  for (R_xlen_t i = h + 1; i + h < n; i++) {
    const double gone = v[i - h - 1], in = v[i + h];
    int p = 0;
    while (w[p] != gone) p++;
    if (in >= gone) {
      while (p + 1 < k && w[p + 1] < in) { w[p] = w[p + 1]; p++; }
    } else {
      while (p > 0 && w[p - 1] > in) { w[p] = w[p - 1]; p--; }
    }
    w[p] = in;
    o[i] = w[h];
    if ((i & 65535) == 0) Rcpp::checkUserInterrupt();
  }
  return out;
}

// mean() of double values as R's real_mean() makes it: the sum in long
// double over n, then the mean residual added. false where the sum is not
// finite (R then takes another path; the caller falls back to R).
template <typename Get>
static bool r_mean(R_xlen_t n, Get get, double* out) {
  long double s = 0;
  for (R_xlen_t i = 0; i < n; i++) s += get(i);
  if (!std::isfinite(static_cast<double>(s))) return false;
  s /= n;
  if (std::isfinite(static_cast<double>(s))) {
    long double t = 0;
    for (R_xlen_t i = 0; i < n; i++) t += (get(i) - s);
    s += t / n;
  }
  *out = static_cast<double>(s);
  return true;
}

// The order statistics lo..hi (1-based, lo <= hi <= n) of v[0..n), in
// ascending order, into `out`; false where v has a NaN. A long v is first
// cut to the values between two of a sorted sample's (every (n / 4096)th
// value) placed well outside the ranks, whose count below is kept: a
// selection of a few percent of v instead of all of it. Exact whatever the
// sample: where the cut misses the ranks the whole of v is selected.
static bool order_stats(const double* v, R_xlen_t n, R_xlen_t lo, R_xlen_t hi,
                        std::vector<double>& out) {
  std::vector<double> w;
  R_xlen_t below = 0;
  bool cut = false;
  const R_xlen_t m = 4096, margin = 128;
  if (n >= 16 * m) {
    std::vector<double> sm(m);
    const R_xlen_t stride = n / m;
    for (R_xlen_t i = 0; i < m; i++) sm[i] = v[i * stride];
    for (R_xlen_t i = 0; i < m; i++)
      if (std::isnan(sm[i])) return false;
    std::sort(sm.begin(), sm.end());
    const R_xlen_t ia = static_cast<R_xlen_t>(std::floor(double(lo - 1) / n * m)) - margin,
                   ib = static_cast<R_xlen_t>(std::ceil(double(hi) / n * m)) + margin;
    const double ta = ia >= 0 ? sm[ia] : -INFINITY, tb = ib < m ? sm[ib] : INFINITY;
    w.reserve(static_cast<size_t>((double(hi - lo + 1) / n + 3.0 * margin / m) * n) + 16);
    for (R_xlen_t i = 0; i < n; i++) {
      const double x = v[i];
      if (x < ta) below++;
      else if (x <= tb) w.push_back(x);
      else if (std::isnan(x)) return false;  // (a NaN fails both tests)
    }
    cut = below < lo && below + R_xlen_t(w.size()) >= hi;
  }
  if (!cut) {
    for (R_xlen_t i = 0; i < n; i++)
      if (std::isnan(v[i])) return false;
    w.assign(v, v + n);
    below = 0;
  }
  const R_xlen_t a = lo - below - 1, b = hi - below - 1;  // 0-based in w
  std::nth_element(w.begin(), w.begin() + a, w.end());
  if (b > a) std::nth_element(w.begin() + a + 1, w.begin() + b, w.end());
  std::sort(w.begin() + a, w.begin() + b + 1);
  out.assign(w.begin() + a, w.begin() + b + 1);
  return true;
}

// robust_scale()'s mean square (R/nonstationary.R): with q1, q2 the order
// statistics k1 <= k2 (1-based) of r (those stats::quantile(type = 1)
// returns), keep = r[r >= q1 & r <= q2] and mean((keep - mean(keep))^2),
// each mean() as R makes it, without sorting r. NA where r has a NaN or a
// sum is not finite: the caller computes it in R then.
// [[Rcpp::export(rng = false)]]
double trimmed_mean_square(const Rcpp::NumericVector& r, R_xlen_t k1, R_xlen_t k2) {
  const R_xlen_t n = r.size();
  if (n < 1 || k1 < 1 || k2 < k1 || k2 > n) return NA_REAL;
  const double* v = r.begin();
  std::vector<double> q;
  if (!order_stats(v, n, k1, k1, q)) return NA_REAL;
  const double q1 = q[0];
  if (!order_stats(v, n, k2, k2, q)) return NA_REAL;
  const double q2 = q[0];
  // the kept values in their order
  std::unique_ptr<double[]> w(new double[n]);
  R_xlen_t m = 0;
  for (R_xlen_t i = 0; i < n; i++) {
    const double x = v[i];
    if (x >= q1 && x <= q2) w[m++] = x;
  }
  const double* kp = w.get();
  double mu, ms;
  if (!r_mean(m, [kp](R_xlen_t i) { return kp[i]; }, &mu)) return NA_REAL;
  // (keep - mu)^2 as R computes x^2: x * x in double
  if (!r_mean(m, [kp, mu](R_xlen_t i) { const double d = kp[i] - mu; return d * d; }, &ms))
    return NA_REAL;
  return ms;
}

// spike_tail_level()'s band (R/nonstationary.R): mean(sort(a[lo:hi])) of
// a = abs(z) placed by sort(partial = c(lo, hi)), i.e. the mean of the
// order statistics lo..hi (1-based) of |z| in ascending order, as R's
// mean() makes it. NA where z has a NaN or the sum is not finite.
// [[Rcpp::export(rng = false)]]
double abs_rank_band_mean(const Rcpp::NumericVector& z, R_xlen_t lo, R_xlen_t hi) {
  const R_xlen_t n = z.size();
  if (lo < 1 || hi < lo || hi > n) return NA_REAL;
  std::vector<double> a(n), band;
  const double* v = z.begin();
  for (R_xlen_t i = 0; i < n; i++) a[i] = std::fabs(v[i]);
  if (!order_stats(a.data(), n, lo, hi, band)) return NA_REAL;
  const double* b = band.data();
  double mu;
  if (!r_mean(hi - lo + 1, [b](R_xlen_t i) { return b[i]; }, &mu)) return NA_REAL;
  return mu;
}

// The step search's scan at one window (R/nonstationary.R, detect_steps()):
// with cs = c(0, cumsum(r)) of nb block means, the Allan differences
// d(i) = (cs[i + w + 1] - 2 * cs[i + 1] + cs[i - w + 1]) / w at the splits
// i = w..nb - w (allan_differences()), 0 where excluded[i]; returns the
// place (1-based among them) and value of the first largest |d|, as
// which.max(abs(d)) finds it.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector steps_largest_difference(const Rcpp::NumericVector& cs, int w,
                                             const Rcpp::LogicalVector& excluded) {
  const R_xlen_t nb = cs.size() - 1;
  const double* c = cs.begin();
  const int* ex = excluded.begin();
  const double wd = w;
  R_xlen_t best = 0;
  double bd = 0, ba = -1;
  for (R_xlen_t i = w; i <= nb - w; i++) {
    // cs[k] (1-based) is c[k - 1]
    const double d = ex[i - 1] ? 0.0 : (c[i + w] - 2 * c[i] + c[i - w]) / wd;
    const double a = std::fabs(d);
    if (a > ba) {
      ba = a;
      bd = d;
      best = i - w + 1;
    }
  }
  return Rcpp::NumericVector::create(static_cast<double>(best), bd);
}

// which(abs(z) > zc) without the two n-value temporaries (the spike
// detector's candidates).
// [[Rcpp::export(rng = false)]]
Rcpp::IntegerVector which_abs_above(const Rcpp::NumericVector& z, double zc) {
  const R_xlen_t n = z.size();
  const double* v = z.begin();
  std::vector<int> out;
  for (R_xlen_t i = 0; i < n; i++)
    if (std::fabs(v[i]) > zc) out.push_back(static_cast<int>(i + 1));
  return Rcpp::IntegerVector(out.begin(), out.end());
}

// stats::median(d^2) of the step search's Allan differences
// (robust_d_scale()): the middle order statistic of the squares (x * x, as
// R's x^2), or R's mean() of the middle two. NA where d has a NaN or is
// empty (the caller asks R then).
// [[Rcpp::export(rng = false)]]
double median_of_squares(const Rcpp::NumericVector& d) {
  const R_xlen_t n = d.size();
  if (n < 1) return NA_REAL;
  std::vector<double> q(n);
  const double* v = d.begin();
  for (R_xlen_t i = 0; i < n; i++) {
    if (std::isnan(v[i])) return NA_REAL;
    q[i] = v[i] * v[i];
  }
  const R_xlen_t half = (n + 1) / 2;
  std::nth_element(q.begin(), q.begin() + (half - 1), q.end());
  if (n % 2 == 1) return q[half - 1];
  const double a = q[half - 1], b = *std::min_element(q.begin() + half, q.end());
  const double two[2] = {a, b};
  double mu = NA_REAL;
  if (!r_mean(2, [&two](R_xlen_t i) { return two[i]; }, &mu)) return NA_REAL;
  return mu;
}

// z[z != 0] in one pass, without the logical index (spike_tail_level()); a
// NaN gives NA there, as R's NA index does.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector drop_zeros(const Rcpp::NumericVector& z) {
  const R_xlen_t n = z.size();
  const double* v = z.begin();
  R_xlen_t m = 0;
  for (R_xlen_t i = 0; i < n; i++) m += v[i] != 0;
  Rcpp::NumericVector out(m);
  double* o = out.begin();
  for (R_xlen_t i = 0, k = 0; i < n; i++)
    if (v[i] != 0) o[k++] = std::isnan(v[i]) ? NA_REAL : v[i];
  return out;
}
