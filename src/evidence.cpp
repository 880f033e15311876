// Raw-data evidence (R/evidence.R): the autocovariance of a series at the
// first few lags, by direct sums. For a few dozen lags this is cheaper than
// an FFT of the whole record (O(n L) with L ~ 50 against two transforms of
// n points) and exact to rounding.
#include <Rcpp.h>
#include "fft.h"
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
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

// The Welch sums of welch_psd() (R/spectrum.R): over the segments
// x[s .. s + seg - 1] (1-based starts), each minus its mean (a long double
// sum over seg, as R's colMeans()) and times the window, the sum of
// |A_f|^2 for f = 0..seg/2. Two real segments go into one complex
// transform, z = a + i b (Press et al., Numerical Recipes, sec. 12.3, "FFT
// of two real functions simultaneously"), by the package's FFT (src/fft.h;
// `seg` a power of two), and |A_f|^2 + |B_f|^2 = (|Z_f|^2 + |Z_(seg-f)|^2)
// / 2; an odd last segment has b = 0. One segment pair in memory at a time.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector welch_sums(const Rcpp::NumericVector& x,
                               const Rcpp::IntegerVector& starts,
                               const Rcpp::NumericVector& win) {
  const R_xlen_t seg = win.size();
  if (seg < 2 || (seg & (seg - 1)) != 0) Rcpp::stop("welch_sums: seg must be a power of two");
  const R_xlen_t k = starts.size();
  const R_xlen_t h = seg / 2 + 1;
  const double* v = x.begin();
  const double* w = win.begin();
  const allanvar::FFTPlan plan(static_cast<size_t>(seg));
  allanvar::cvec z(static_cast<size_t>(seg));
  std::vector<double> rs(h, 0.0);
  for (R_xlen_t j = 0; j < k; j += 2) {
    for (int q = 0; q < 2; ++q) {
      if (j + q >= k) break;  // an odd last segment: b = 0, set with a
      const double* s = v + (static_cast<R_xlen_t>(starts[j + q]) - 1);
      long double sum = 0;
      for (R_xlen_t i = 0; i < seg; ++i) sum += s[i];
      sum /= static_cast<long double>(seg);
      const double m = static_cast<double>(sum);
      if (q == 0) {
        for (R_xlen_t i = 0; i < seg; ++i) z[i] = allanvar::cplx((s[i] - m) * w[i], 0.0);
      } else {
        for (R_xlen_t i = 0; i < seg; ++i) z[i].imag((s[i] - m) * w[i]);
      }
    }
    plan.run(z.data(), false);
    for (R_xlen_t f = 0; f < h; ++f) {
      const allanvar::cplx a = z[f];
      const allanvar::cplx b = z[f == 0 ? 0 : seg - f];
      rs[f] += 0.5 * (std::norm(a) + std::norm(b));
    }
    if ((j & 0xFFE) == 0) Rcpp::checkUserInterrupt();
  }
  return Rcpp::NumericVector(rs.begin(), rs.end());
}

// Median as R's median() computes it: the middle value, or for an even count
// the mean of the two middle values (R's mean(): long double sum / 2 plus
// the long double correction pass). Reorders v.
static double median_r(std::vector<double>& v) {
  const size_t n = v.size();
  const size_t h = (n + 1) / 2;  // R's half, 1-based
  std::nth_element(v.begin(), v.begin() + (h - 1), v.end());
  const double a = v[h - 1];
  if (n % 2 == 1) return a;
  const double b = *std::min_element(v.begin() + h, v.end());
  long double s = (static_cast<long double>(a) + b) / 2.0L;
  long double t = ((a - s) + (b - s)) / 2.0L;
  return static_cast<double>(s + t);
}

// The quantization grid of R/evidence.R's quantization_grid() from the
// series x (sorted here), in two passes and without R's temporaries: the distinct values u, the step (median gap, then the median
// of the gaps below 1.5 times it) and the fraction of samples within 1e-3
// steps of the grid u[1] + k step. Returns c(levels, step, on_grid); step
// is NA with fewer than two levels.
// The values of x in increasing order by an LSD radix sort on their bit
// patterns (sign-flipped so that unsigned order is numeric order), four
// passes of 16 bits: O(n), a few times faster than R's sort() on long
// records. x holds no NaN (the callers' check_values()); -0 sorts before
// +0, which compare equal, so nothing computed from the order changes.
static std::vector<double> radix_sorted(const Rcpp::NumericVector& x) {
  const R_xlen_t n = x.size();
  if (n == 0) return std::vector<double>();
  std::vector<uint64_t> a(n), b(n);
  for (R_xlen_t i = 0; i < n; ++i) {
    uint64_t u;
    std::memcpy(&u, &x[i], sizeof u);
    a[i] = (u >> 63) ? ~u : (u | (uint64_t(1) << 63));
  }
  std::vector<R_xlen_t> count(65536);
  for (int pass = 0; pass < 4; ++pass) {
    const int shift = 16 * pass;
    std::fill(count.begin(), count.end(), 0);
    for (R_xlen_t i = 0; i < n; ++i) ++count[(a[i] >> shift) & 0xFFFF];
    // a pass whose digit is the same for every value moves nothing
    if (count[(a[0] >> shift) & 0xFFFF] == n) continue;
    R_xlen_t pos = 0;
    for (auto& c : count) { const R_xlen_t k = c; c = pos; pos += k; }
    for (R_xlen_t i = 0; i < n; ++i) b[count[(a[i] >> shift) & 0xFFFF]++] = a[i];
    a.swap(b);
    Rcpp::checkUserInterrupt();
  }
  std::vector<uint64_t>().swap(b);  // free the buffer before the output
  std::vector<double> out(n);
  for (R_xlen_t i = 0; i < n; ++i) {
    const uint64_t k = a[i];
    const uint64_t u = (k >> 63) ? (k & ~(uint64_t(1) << 63)) : ~k;
    std::memcpy(&out[i], &u, sizeof u);
  }
  return out;
}

// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector grid_stats(const Rcpp::NumericVector& x) {
  const std::vector<double> xs = radix_sorted(x);
  const R_xlen_t n = static_cast<R_xlen_t>(xs.size());
  std::vector<double> d;
  R_xlen_t levels = n ? 1 : 0;
  for (R_xlen_t i = 1; i < n; ++i) {
    if (xs[i] != xs[i - 1]) {
      // gaps between distinct values: u[levels] - u[levels - 1]
      d.push_back(0.0);
      ++levels;
    }
  }
  if (levels < 2) {
    return Rcpp::NumericVector::create(static_cast<double>(levels), NA_REAL, NA_REAL);
  }
  // second pass: the gaps themselves (the count first keeps one allocation)
  {
    R_xlen_t j = 0;
    double prev = xs[0];
    for (R_xlen_t i = 1; i < n; ++i) {
      if (xs[i] != xs[i - 1]) {
        d[j++] = xs[i] - prev;
        prev = xs[i];
      }
    }
  }
  std::vector<double> pos;
  pos.reserve(d.size());
  for (double g : d) if (g > 0) pos.push_back(g);
  double step = median_r(pos);
  std::vector<double> small;
  for (double g : d) if (g < 1.5 * step) small.push_back(g);
  if (!small.empty()) step = median_r(small);
  const double u1 = xs[0];
  R_xlen_t on = 0;
  for (R_xlen_t i = 0; i < n; ++i) {
    const double off = (x[i] - u1) / step;
    const double dev = std::fabs(off - std::nearbyint(off));
    // an overflow (NaN) makes R's mean() of the comparisons NA
    if (std::isnan(dev)) {
      return Rcpp::NumericVector::create(static_cast<double>(levels), step, NA_REAL);
    }
    if (dev < 1e-3) ++on;
  }
  // mean() of a logical: a long double quotient rounded once
  const long double frac = static_cast<long double>(on) / static_cast<long double>(n);
  return Rcpp::NumericVector::create(static_cast<double>(levels), step,
                                     static_cast<double>(frac));
}
