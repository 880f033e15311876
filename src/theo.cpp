// Theo1 of allan(type = "theo1" / "theobr" / "theoh"): NIST SP 1065
// sec. 5.2.15, eq. (30); D.A. Howe & T.K. Peppler, "Very long-term
// frequency stability: estimation using a special-purpose statistic",
// IFCS 2003. For even m = 2k and N phase points,
//   Theo1(0.75 m tau0) = T_k / (0.75 (N - m) (m tau0)^2),
//   T_k = sum_{i < N-m} sum_{L=1..k} (1/L) (x(i) - x(i+L) + x(i+m) - x(i+m-L))^2
// (L = m/2 - delta of SP 1065's inner index).
//
// Two evaluations:
//  * theo1_sums_cpp: T_k at the requested m, straight from the definition:
//    for each L one pass of a four-point stencil over the phase split hi +
//    lo (src/local-phase.h), exact on the hi grid. O(N k) per m.
//  * theo1_all_cpp: T_k for every k = 1..kmax in O(N kmax + kmax^2), the
//    complexity of the all-tau Allan variance, by the recurrence idea of
//    B. Lewis, "A fast algorithm for calculation of Theo1" (IEEE TUFFC
//    2021, arXiv:2106.04542): T_k expands into lag products of x, which are
//    full autocorrelations minus partial sums over the first and last 2k
//    points and over the pairs centred within k of either end; those
//    partial sums grow by O(k) products from k to k + 1. The expansion
//    cancels heavily (terms of size N var(x) for a result of size N k
//    var(dx)), so every product and sum is carried in double-double
//    (src/dd.h) on the exact hi + lo phase: the result agrees with the
//    direct evaluation to about 1e-15 whatever the noise type.
#include "dd.h"
#include "local-phase.h"
#include "parallel.h"
#include <algorithm>
#include <cmath>
#include <vector>

namespace {

using allanvar::DD;

struct Item {
  size_t tau;
  R_xlen_t l0, l1;  // L in [l0, l1)
};

}  // namespace

// T_k for each even m = 2k of one channel (NA where m > L - 1).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector theo1_sums_cpp(const Rcpp::NumericVector& v, bool rate,
                                   const Rcpp::NumericVector& m, int threads) {
  const allanvar::PhaseInput in{v.begin(), v.size(), rate};
  allanvar::SplitPhase X;
  allanvar::split_phase(in, X);
  const R_xlen_t N = in.length();
  const std::vector<double> ms(m.begin(), m.end());
  std::vector<Item> items;
  for (size_t t = 0; t < ms.size(); ++t) {
    const R_xlen_t mm = static_cast<R_xlen_t>(ms[t]);
    if (mm < 2 || mm % 2 != 0 || mm > N - 1) continue;
    const R_xlen_t k = mm / 2;
    // about 2^22 stencil terms per item, for interrupt latency and balance
    const R_xlen_t per =
        std::max<R_xlen_t>(1, (R_xlen_t(1) << 22) / std::max<R_xlen_t>(1, N - mm));
    for (R_xlen_t l0 = 1; l0 <= k; l0 += per)
      items.push_back(Item{t, l0, std::min(k + 1, l0 + per)});
  }
  std::vector<double> part(items.size(), 0.0);
  const double* h = X.hi.data();
  const double* l = X.lo.data();
  allanvar::parallel_for(static_cast<R_xlen_t>(items.size()),
                         std::max(1, threads), [&](R_xlen_t it, int) {
    const Item& I = items[it];
    const R_xlen_t mm = static_cast<R_xlen_t>(ms[I.tau]);
    const R_xlen_t n = N - mm;
    double acc = 0;
    for (R_xlen_t b0 = 0; b0 < n; b0 += 4096) {
      const R_xlen_t b1 = std::min(n, b0 + 4096);
      for (R_xlen_t L = I.l0; L < I.l1; ++L) {
        const R_xlen_t a = L, b = mm, c = mm - L;
        double s0 = 0, s1 = 0;
        R_xlen_t i = b0;
        for (; i + 2 <= b1; i += 2) {
          const double d0 = ((h[i] - h[i + a]) + (h[i + b] - h[i + c])) +
                            ((l[i] - l[i + a]) + (l[i + b] - l[i + c]));
          const double d1 =
              ((h[i + 1] - h[i + 1 + a]) + (h[i + 1 + b] - h[i + 1 + c])) +
              ((l[i + 1] - l[i + 1 + a]) + (l[i + 1 + b] - l[i + 1 + c]));
          s0 += d0 * d0;
          s1 += d1 * d1;
        }
        for (; i < b1; ++i) {
          const double d = ((h[i] - h[i + a]) + (h[i + b] - h[i + c])) +
                           ((l[i] - l[i + a]) + (l[i + b] - l[i + c]));
          s0 += d * d;
        }
        acc += (s0 + s1) / static_cast<double>(L);
      }
    }
    part[it] = acc;
  });
  Rcpp::NumericVector out(ms.size(), NA_REAL);
  std::vector<DD> tot(ms.size());
  std::vector<bool> any(ms.size(), false);
  for (size_t it = 0; it < items.size(); ++it) {
    tot[items[it].tau] += DD(part[it]);
    any[items[it].tau] = true;
  }
  for (size_t t = 0; t < ms.size(); ++t)
    if (any[t]) out[t] = tot[t].value();
  return out;
}

// T_k for k = 1..kmax (kmax <= (L - 1) / 2) of one channel, by the
// all-k recurrence (see the head of this file).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector theo1_all_cpp(const Rcpp::NumericVector& v, bool rate,
                                  double kmax_d) {
  const allanvar::PhaseInput in{v.begin(), v.size(), rate};
  allanvar::SplitPhase X;
  allanvar::split_phase(in, X);
  const R_xlen_t N = in.length();
  R_xlen_t kmax = static_cast<R_xlen_t>(kmax_d);
  kmax = std::min(kmax, (N - 1) / 2);
  Rcpp::NumericVector out(std::max<R_xlen_t>(kmax, 0), NA_REAL);
  if (kmax < 1) return out;
  // x as double-double; hi on the grid, lo the remainder
  std::vector<DD> x(N);
  for (R_xlen_t j = 0; j < N; ++j) x[j] = DD(X.hi[j], X.lo[j]);
  auto prod = [&](R_xlen_t a, R_xlen_t b) { return x[a] * x[b]; };
  // C1[j] = sum_{i<j} x_i^2
  std::vector<DD> C1(N + 1);
  for (R_xlen_t j = 0; j < N; ++j) C1[j + 1] = C1[j] + prod(j, j);
  auto Q0 = [&](R_xlen_t a, R_xlen_t b) { return C1[b] - C1[a]; };
  // full autocorrelation r(lag), grown two lags per step
  std::vector<DD> r(2 * kmax + 1);
  auto full = [&](R_xlen_t lag) {
    DD s;
    for (R_xlen_t j = 0; j + lag < N; ++j) s += prod(j, j + lag);
    return s;
  };
  // head[lag]: pairs within x[0, 2k); tail[lag]: within x[N-2k, N);
  // triH[d]: pairs (c-d, c+d) with centre c < k; triT[d]: centre >= N-k.
  std::vector<DD> head(2 * kmax + 1), tail(2 * kmax + 1), triH(kmax + 1),
      triT(kmax + 1);
  R_xlen_t k = 0;  // arrays describe this k
  for (R_xlen_t kn = 1; kn <= kmax; ++kn) {
    if ((kn & 15) == 0 && allanvar::interrupt_pending())
      throw Rcpp::internal::InterruptedException();
    // advance k -> kn = k + 1
    if (k == 0) r[0] = C1[N];
    r[2 * k + 1] = full(2 * k + 1);
    r[2 * k + 2] = full(2 * k + 2);
    const R_xlen_t p = 2 * k, q = 2 * k + 1;  // new head points
    for (R_xlen_t lag = 1; lag <= p; ++lag) head[lag] += prod(p - lag, p);
    for (R_xlen_t lag = 1; lag <= q; ++lag) head[lag] += prod(q - lag, q);
    const R_xlen_t u = N - 2 * k - 1, w = N - 2 * k - 2;  // new tail points
    for (R_xlen_t lag = 1; u + lag < N && lag <= 2 * k + 1; ++lag)
      tail[lag] += prod(u, u + lag);
    for (R_xlen_t lag = 1; w + lag < N && lag <= 2 * k + 2; ++lag)
      tail[lag] += prod(w, w + lag);
    for (R_xlen_t d = 0; d <= k; ++d) {
      triH[d] += prod(k - d, k + d);
      triT[d] += prod(N - k - 1 - d, N - k - 1 + d);
    }
    k = kn;
    // assemble T_k
    const R_xlen_t M = N - 2 * k;
    DD T;
    for (R_xlen_t L = 1; L <= k; ++L) {
      const R_xlen_t d = k - L;
      const DD A = Q0(0, M) + Q0(L, M + L) - DD(2) * (r[L] - tail[L]);
      const DD B = Q0(2 * k - L, N - L) + Q0(2 * k, N) -
                   DD(2) * (r[L] - head[L]);
      const DD mid = d == 0 ? Q0(k, N - k)
                            : r[2 * d] - triH[d] - triT[d];
      const DD C = (r[2 * k - L] - tail[2 * k - L]) - r[2 * k] - mid +
                   (r[2 * k - L] - head[2 * k - L]);
      const DD term = A + B - DD(2) * C;
      T += DD(term.hi / static_cast<double>(L), term.lo / static_cast<double>(L));
    }
    out[k - 1] = T.value();
  }
  return out;
}
