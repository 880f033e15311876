// Theo1 of allan(type = "theo1" / "theobr" / "theoh"): NIST SP 1065
// sec. 5.2.15, eq. (30); D.A. Howe & T.K. Peppler, "Very long-term
// frequency stability: estimation using a special-purpose statistic",
// IFCS 2003. For even m = 2k and N phase points,
//   Theo1(0.75 m tau0) = T_k / (0.75 (N - m) (m tau0)^2),
//   T_k = sum_{i < N-m} sum_{L=1..k} (1/L) (x(i) - x(i+L) + x(i+m) - x(i+m-L))^2
// (L = m/2 - delta of SP 1065's inner index).
//
// Four evaluations:
//  * theo1_sums_cpp: T_k at the requested m, per m the cheaper of
//    - the definition: for each L one pass of a four-point stencil over the
//      phase split hi + lo (src/local-phase.h), exact on the hi grid;
//      O(N k) per m;
//    - the blocked expansion (theo_block below): FFT correlations of
//      locally detrended blocks of 6k to 12k points plus two triangle sums
//      by divide and conquer; O(N log^2 k) per m, within about 1e-12 of
//      the definition whatever the noise type.
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
//    direct evaluation to about 1e-15 whatever the noise type. Kept as the
//    tests' reference; O(N kmax) double-double products.
//  * theo1_incr_cpp: T_k at many k (TheoBR's factor, Theo1 at many taus)
//    in O(N log^2 N + kmax^2) plain double operations: the same recurrence
//    on squared increments, which cancel far less (see its section).
#include "dd.h"
#include "fft.h"
#include "local-phase.h"
#include "parallel.h"
#include <algorithm>
#include <cmath>
#include <vector>

namespace {

using allanvar::DD;

// ---- Fast T_k for one k (m = 2k): O(N log^2 k) instead of O(N k). ----
// The starting indices i are cut into blocks; a block of Mb indices needs
// the W = Mb + 2k phase points z = x(a + j), taken with a line removed
// (local_phase(): T_k ignores a constant and a linear term), so the
// expansion below cancels only as much as the local wander of the phase
// over 4 to 5 k points allows, whatever the noise type. With
// s_i = z_i + z_{i+m}, g the kernel of weights of the inner points
// (g(t) = 1/t for t < k, 2/k at t = k, 1/(m - t) above) and
// w(d) = 1/(k - d), the block's part of T_k is
//   H_k sum_i s_i^2 - 2 sum_t g(t) sum_i s_i z_{i+t}
//   + sum_t g(t) sum_i z_{i+t}^2 + 2 sum_{d<k} w(d) P(d),
//   P(d) = sum_{c = k}^{W-k-1} z_{c-d} z_{c+d}
// (expand d_i(L)^2 = (s_i - z_{i+L} - z_{i+m-L})^2 and sum over L with
// weight 1/L; d = k - L). The correlations come from FFTs of the block
// (src/fft.h); P(d) is the full autocorrelation at lag 2d minus the pairs
// centred within k of either end of the block, two triangles summed by
// divide and conquer: a square of the triangle by one FFT, two half
// triangles recursively.

struct FastScratch {
  allanvar::FFTPlans* plans = nullptr;  // the call's, shared by the workers
  allanvar::cvec buf, buf2;
  allanvar::Scratch z, zr, s, c, c2, p2;
};

// The squares of the triangles below this many products are summed
// directly (2^16 was tried: slower at m = 1024 and 8192, no gain at 2^19).
const R_xlen_t kTriDirect = 4096;

// sum over p + d < n (p, d >= 0) of z[p0 + p] z[p0 + p + 2 (d0 + d)] / (k - d0 - d)
double theo_triangle(const double* z, R_xlen_t k, R_xlen_t p0, R_xlen_t d0,
                     R_xlen_t n, FastScratch& S) {
  if (n <= 0) return 0.0;
  if (n <= 48) {
    double acc = 0;
    for (R_xlen_t d = 0; d < n; ++d) {
      const R_xlen_t lag = 2 * (d0 + d);
      double t = 0;
      for (R_xlen_t p = p0; p < p0 + n - d; ++p) t += z[p] * z[p + lag];
      acc += t / static_cast<double>(k - d0 - d);
    }
    return acc;
  }
  const R_xlen_t h = (n + 1) / 2, q = n - h;
  // square: p in [p0, p0 + h), d in [d0, d0 + q)
  double sq = 0;
  if (h * q <= kTriDirect) {
    for (R_xlen_t d = 0; d < q; ++d) {
      const R_xlen_t lag = 2 * (d0 + d);
      double t = 0;
      for (R_xlen_t p = p0; p < p0 + h; ++p) t += z[p] * z[p + lag];
      sq += t / static_cast<double>(k - d0 - d);
    }
  } else {
    const size_t nt = static_cast<size_t>(2 * q - 1);
    S.c.resize(nt);
    allanvar::real_correlation(z + p0, h, z + p0 + 2 * d0, h + nt - 1, nt,
                               S.c.data(), *S.plans, S.buf, S.buf2);
    for (R_xlen_t d = 0; d < q; ++d)
      sq += S.c[2 * d] / static_cast<double>(k - d0 - d);
  }
  if (allanvar::interrupted()) return 0.0;  // the result is thrown away
  return sq + theo_triangle(z, k, p0 + h, d0, q, S) +
         theo_triangle(z, k, p0, d0 + q, h, S);
}

// theo_triangle() of two series at once (the block and its reverse): the
// same recursion, each square's two correlations from one set of three
// transforms (real_correlation_pair); out[0], out[1] get the two sums.
void theo_triangle2(const double* z, const double* zr, R_xlen_t k,
                    R_xlen_t p0, R_xlen_t d0, R_xlen_t n, FastScratch& S,
                    double* out) {
  if (n <= 0) return;
  const R_xlen_t h = (n + 1) / 2, q = n - h;
  if (n <= 48 || h * q <= kTriDirect) {
    out[0] += theo_triangle(z, k, p0, d0, n, S);
    out[1] += theo_triangle(zr, k, p0, d0, n, S);
    return;
  }
  const size_t nt = static_cast<size_t>(2 * q - 1);
  S.c.resize(nt);
  S.c2.resize(nt);
  allanvar::real_correlation_pair(z + p0, zr + p0, h, z + p0 + 2 * d0,
                                  zr + p0 + 2 * d0, h + nt - 1, nt,
                                  S.c.data(), S.c2.data(), *S.plans, S.buf,
                                  S.buf2);
  double sq0 = 0, sq1 = 0;
  for (R_xlen_t d = 0; d < q; ++d) {
    sq0 += S.c[2 * d] / static_cast<double>(k - d0 - d);
    sq1 += S.c2[2 * d] / static_cast<double>(k - d0 - d);
  }
  out[0] += sq0;
  out[1] += sq1;
  if (allanvar::interrupted()) return;  // the result is thrown away
  theo_triangle2(z, zr, k, p0 + h, d0, q, S, out);
  theo_triangle2(z, zr, k, p0, d0 + q, h, S, out);
}

// The block's part of T_k (see above); z has W = Mb + 2k points.
double theo_block(const double* z, R_xlen_t W, R_xlen_t k, FastScratch& S) {
  const R_xlen_t m = 2 * k, Mb = W - m;
  double H = 0;
  for (R_xlen_t L = k; L >= 1; --L) H += 1.0 / static_cast<double>(L);
  auto g = [k, m](R_xlen_t t) {
    if (t < k) return 1.0 / static_cast<double>(t);
    if (t == k) return 2.0 / static_cast<double>(k);
    return 1.0 / static_cast<double>(m - t);
  };
  S.s.resize(Mb);
  double ss = 0;
  for (R_xlen_t i = 0; i < Mb; ++i) {
    S.s[i] = z[i] + z[i + m];
    ss += S.s[i] * S.s[i];
  }
  S.p2.resize(W + 1);
  S.p2[0] = 0;
  for (R_xlen_t j = 0; j < W; ++j) S.p2[j + 1] = S.p2[j] + z[j] * z[j];
  // sum_t g(t) sum_i s_i z_{i+t}, t in [1, m), and the autocorrelation of
  // z at lags 2d < m, from one pair of transforms
  S.c.resize(m);
  S.c2.resize(m - 1);
  allanvar::real_correlation2(S.s.data(), Mb, z, W, m, S.c.data(), m - 1,
                              S.c2.data(), *S.plans, S.buf, S.buf2);
  double cross = 0, sq = 0;
  for (R_xlen_t t = 1; t < m; ++t) {
    cross += g(t) * S.c[t];
    sq += g(t) * (S.p2[t + Mb] - S.p2[t]);
  }
  // sum_d w(d) P(d)
  double pd = 0;
  for (R_xlen_t d = 0; d < k; ++d)
    pd += S.c2[2 * d] / static_cast<double>(k - d);
  S.zr.resize(W);
  std::reverse_copy(z, z + W, S.zr.begin());
  double tri[2] = {0, 0};
  theo_triangle2(z, S.zr.data(), k, 0, 0, k, S, tri);
  pd -= tri[0];
  pd -= tri[1];
  return H * ss - 2 * cross + sq + 2 * pd;
}

// Rough costs (arbitrary units) of the two evaluations of one k.
double theo_direct_cost(R_xlen_t N, R_xlen_t k) {
  return 1.0 * static_cast<double>(N - 2 * k) * static_cast<double>(k);
}

// Blocks of 6k to 12k starting indices, so that the autocorrelation's
// transform (B + 4k points) fills a power of two; longer blocks would
// cancel more (the local phase wander grows with the block).
R_xlen_t theo_block_len(R_xlen_t N, R_xlen_t k) {
  const R_xlen_t n = static_cast<R_xlen_t>(allanvar::fft_size(10 * k));
  return std::min(N - 2 * k, n - 4 * k);
}

double theo_fast_cost(R_xlen_t N, R_xlen_t k) {
  const R_xlen_t B = theo_block_len(N, k);
  const double nb = std::ceil(static_cast<double>(N - 2 * k) / B);
  const double n = static_cast<double>(allanvar::fft_size(B + 4 * k));
  const double lk = std::log2(static_cast<double>(k) + 2);
  // calibrated against the direct stencil (one thread, N = 2^17)
  return nb * (3.0 * n * std::log2(n) + 8.0 * k * lk * lk);
}

struct Item {
  size_t tau;
  R_xlen_t l0, l1;  // direct: L in [l0, l1); fast: l0 = block start, l1 = -1
  double cost;      // for the order of the work
};

}  // namespace

// T_k for each even m = 2k of one channel (NA where m > L - 1): for each m
// the cheaper of the direct stencil sum and the fast blocked expansion.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector theo1_sums_cpp(const Rcpp::NumericVector& v, bool rate,
                                   const Rcpp::NumericVector& m, int threads,
                                   int method = 0) {
  const allanvar::InterruptScope scope;
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
    // method: 0 the cheaper, 1 direct, 2 fast (for the tests)
    const bool fast = method == 2 ||
        (method == 0 && theo_fast_cost(N, k) < theo_direct_cost(N, k));
    if (fast) {
      const R_xlen_t B = theo_block_len(N, k);
      const double c = theo_fast_cost(N, k) /
                       std::ceil(static_cast<double>(N - mm) / static_cast<double>(B));
      for (R_xlen_t a = 0; a < N - mm; a += B) items.push_back(Item{t, a, -1, c});
      continue;
    }
    // about 2^22 stencil terms per item, for interrupt latency and balance
    const R_xlen_t per =
        std::max<R_xlen_t>(1, (R_xlen_t(1) << 22) / std::max<R_xlen_t>(1, N - mm));
    for (R_xlen_t l0 = 1; l0 <= k; l0 += per)
      items.push_back(Item{t, l0, std::min(k + 1, l0 + per),
                           static_cast<double>(N - mm) *
                               static_cast<double>(std::min(k + 1, l0 + per) - l0)});
  }
  // the longest items first, so that the last ones to finish are short
  std::stable_sort(items.begin(), items.end(),
                   [](const Item& a, const Item& b) { return a.cost > b.cost; });
  std::vector<double> part(items.size(), 0.0);
  const double* h = X.hi.data();
  const double* l = X.lo.data();
  const int nthr = std::max(1, threads);
  allanvar::FFTPlans plans;
  std::vector<FastScratch> scratch(nthr);
  for (FastScratch& S : scratch) S.plans = &plans;
  allanvar::parallel_for(static_cast<R_xlen_t>(items.size()), nthr,
                         [&](R_xlen_t it, int worker) {
    const Item& I = items[it];
    const R_xlen_t mm = static_cast<R_xlen_t>(ms[I.tau]);
    const R_xlen_t n = N - mm;
    if (I.l1 < 0) {
      FastScratch& S = scratch[worker];
      const R_xlen_t Mb = std::min(theo_block_len(N, mm / 2), n - I.l0);
      const R_xlen_t W = Mb + mm;
      S.z.resize(W);
      allanvar::local_phase(in, I.l0, W, S.z.data());
      part[it] = theo_block(S.z.data(), W, mm / 2, S);
      return;
    }
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


// Exact products of the phase hi + lo for the recurrence: hi is split once
// into 26-bit halves (Veltkamp), so hi_a hi_b = p + e exactly in 7 flops
// (Dekker); the lo terms (2^-50 of the scale) enter e in plain double.
struct PhaseProducts {
  std::vector<double> h, h1, h2, l;
  explicit PhaseProducts(const allanvar::SplitPhase& X)
      : h(X.hi.begin(), X.hi.end()), h1(X.hi.size()), h2(X.hi.size()),
        l(X.lo.begin(), X.lo.end()) {
    for (size_t j = 0; j < h.size(); ++j) allanvar::dd_split(h[j], h1[j], h2[j]);
  }
  // s + c += x_a x_b, compensated (Ogita, Rump & Oishi's Dot2 step)
  inline void add(R_xlen_t a, R_xlen_t b, double& s, double& c) const {
    const double p = h[a] * h[b];
    const double e = ((h1[a] * h1[b] - p) + h1[a] * h2[b] + h2[a] * h1[b]) +
                     h2[a] * h2[b] + (h[a] * l[b] + l[a] * h[b]);
    double t, te;
    allanvar::two_sum(s, p, t, te);
    c += te + e;
    s = t;
  }
  DD prod(R_xlen_t a, R_xlen_t b) const {
    double s = 0, c = 0;
    add(a, b, s, c);
    return DD(s) + DD(c);
  }
};

// T_k for k = 1..kmax (kmax <= (L - 1) / 2) of one channel, by the
// all-k recurrence (see the head of this file); T_k is assembled only at
// the k in `need` (sorted; all k when empty), the other values are NA.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector theo1_all_cpp(const Rcpp::NumericVector& v, bool rate,
                                  double kmax_d,
                                  const Rcpp::NumericVector& need) {
  const allanvar::InterruptScope scope;
  const allanvar::PhaseInput in{v.begin(), v.size(), rate};
  allanvar::SplitPhase X;
  allanvar::split_phase(in, X);
  const R_xlen_t N = in.length();
  R_xlen_t kmax = static_cast<R_xlen_t>(kmax_d);
  kmax = std::min(kmax, (N - 1) / 2);
  Rcpp::NumericVector out(std::max<R_xlen_t>(kmax, 0), NA_REAL);
  if (kmax < 1) return out;
  std::vector<char> want(kmax + 1, need.size() == 0 ? 1 : 0);
  for (R_xlen_t i = 0; i < need.size(); ++i) {
    const R_xlen_t k = static_cast<R_xlen_t>(need[i]);
    if (k >= 1 && k <= kmax) want[k] = 1;
  }
  const PhaseProducts x(X);
  // running sums as (s, c) pairs: value s + c
  struct Sum {
    double s = 0, c = 0;
    DD dd() const { return DD(s) + DD(c); }
  };
  // C1[j] = sum_{i<j} x_i^2
  std::vector<DD> C1(N + 1);
  {
    Sum a;
    for (R_xlen_t j = 0; j < N; ++j) {
      x.add(j, j, a.s, a.c);
      C1[j + 1] = a.dd();
    }
  }
  auto Q0 = [&](R_xlen_t a, R_xlen_t b) { return C1[b] - C1[a]; };
  // full autocorrelation r(lag), grown two lags per step
  std::vector<DD> r(2 * kmax + 1);
  auto full = [&](R_xlen_t lag) {
    Sum a;
    for (R_xlen_t j = 0; j + lag < N; ++j) x.add(j, j + lag, a.s, a.c);
    return a.dd();
  };
  // head[lag]: pairs within x[0, 2k); tail[lag]: within x[N-2k, N);
  // triH[d]: pairs (c-d, c+d) with centre c < k; triT[d]: centre >= N-k.
  std::vector<Sum> head(2 * kmax + 1), tail(2 * kmax + 1), triH(kmax + 1),
      triT(kmax + 1);
  R_xlen_t k = 0;  // arrays describe this k
  for (R_xlen_t kn = 1; kn <= kmax; ++kn) {
    // each step costs O(N) (two full lags): ask every step (interrupted()
    // asks R at most every 20 ms)
    if (allanvar::interrupted()) scope.finish();
    // advance k -> kn = k + 1
    if (k == 0) r[0] = C1[N];
    r[2 * k + 1] = full(2 * k + 1);
    r[2 * k + 2] = full(2 * k + 2);
    const R_xlen_t p = 2 * k, q = 2 * k + 1;  // new head points
    for (R_xlen_t lag = 1; lag <= p; ++lag) x.add(p - lag, p, head[lag].s, head[lag].c);
    for (R_xlen_t lag = 1; lag <= q; ++lag) x.add(q - lag, q, head[lag].s, head[lag].c);
    const R_xlen_t u = N - 2 * k - 1, w = N - 2 * k - 2;  // new tail points
    for (R_xlen_t lag = 1; u + lag < N && lag <= 2 * k + 1; ++lag)
      x.add(u, u + lag, tail[lag].s, tail[lag].c);
    for (R_xlen_t lag = 1; w + lag < N && lag <= 2 * k + 2; ++lag)
      x.add(w, w + lag, tail[lag].s, tail[lag].c);
    for (R_xlen_t d = 0; d <= k; ++d) {
      x.add(k - d, k + d, triH[d].s, triH[d].c);
      x.add(N - k - 1 - d, N - k - 1 + d, triT[d].s, triT[d].c);
    }
    k = kn;
    if (!want[k]) continue;
    // assemble T_k
    const R_xlen_t M = N - 2 * k;
    DD T;
    for (R_xlen_t L = 1; L <= k; ++L) {
      const R_xlen_t d = k - L;
      const DD A = Q0(0, M) + Q0(L, M + L) - DD(2) * (r[L] - tail[L].dd());
      const DD B = Q0(2 * k - L, N - L) + Q0(2 * k, N) -
                   DD(2) * (r[L] - head[L].dd());
      const DD mid = d == 0 ? Q0(k, N - k)
                            : r[2 * d] - triH[d].dd() - triT[d].dd();
      const DD C = (r[2 * k - L] - tail[2 * k - L].dd()) - r[2 * k] - mid +
                   (r[2 * k - L] - head[2 * k - L].dd());
      const DD term = A + B - DD(2) * C;
      T += DD(term.hi / static_cast<double>(L), term.lo / static_cast<double>(L));
    }
    out[k - 1] = T.value();
  }
  return out;
}


// ---- TheoBR's Theo1 values: T_k at many k without double-double. ----
// With s = (+1, -1, +1, -1) on (x_i, x_{i+L}, x_{i+m}, x_{i+m-L}), the
// identity (sum s_j x_j)^2 = -sum_{j<l} s_j s_l (x_j - x_l)^2 (sum s = 0)
// writes each squared term of T_k as six squared increments D(p, q) =
// (x_q - x_p)^2:
//   d_i(L)^2 = D(i, i+L) + D(i+m-L, i+m) + D(i, i+m-L) + D(i+L, i+m)
//            - D(i, i+m) - D(i+L, i+m-L).
// Summed over i < N - m, each is a full structure function
// SF(lag) = sum_p D(p, p + lag) minus the pairs within 2k of either end:
//   T_k = sum_L (1/L) [2 SF(L) + 2 SF(2k-L) - SF(2k) - SF(2k-2L)
//         - head(L) - tail(L) - head(2k-L) - tail(2k-L)
//         + triH(k-L) + triT(k-L)],
// head/tail(lag): pairs within the first/last 2k points; triH/triT(d): the
// pairs (c-d, c+d) centred below k / at or above N-k (the SF(2k-2L) terms
// vanish at L = k). Every sum is of positive terms, so nothing cancels
// inside them; the combination cancels only the global level of the
// frequency (about N/k for random-walk FM, O(1) for white noise), where the
// lag-product expansion of theo1_all_cpp cancelled (N/k)^3. A quadratic
// c (i - i0)^2 is removed first (it adds 2 c L (m - L) to every d_i(L),
// restored exactly below), so a frequency drift cancels nothing either.
// The SF come from FFTs of locally detrended blocks (lags in [D, 2D) from
// blocks of 6D points), the edge sums grow with k by O(k) terms per step
// (the recurrence of Lewis, arXiv:2106.04542, on squared increments).

namespace {

struct TildePhase {
  std::vector<double> h, l, rh, rl;  // x~ = h + l; rh, rl reversed
  R_xlen_t N = 0;
  double c = 0, i0 = 0;              // x = x~ + c (i - i0)^2 (+ a line)
  // x~_q - x~_p
  inline double diff(R_xlen_t p, R_xlen_t q) const {
    return (h[q] - h[p]) + (l[q] - l[p]);
  }
};

void tilde_phase(const allanvar::SplitPhase& X, TildePhase& T) {
  const R_xlen_t N = X.size();
  T.N = N;
  T.h.assign(X.hi.begin(), X.hi.end());
  T.l.assign(X.lo.begin(), X.lo.end());
  T.c = 0;
  T.i0 = 0.5 * static_cast<double>(N - 1);
  const R_xlen_t a = N / 3;
  if (a >= 2) {
    // mean frequencies over the first and last thirds: slope 2c between
    const double f1 = (X.value(a) - X.value(0)) / static_cast<double>(a);
    const double f2 =
        (X.value(N - 1) - X.value(N - 1 - a)) / static_cast<double>(a);
    T.c = (f2 - f1) / (2.0 * static_cast<double>(N - 1 - a));
  }
  if (T.c != 0 && std::isfinite(T.c)) {
    for (R_xlen_t i = 0; i < N; ++i) {
      const double u = static_cast<double>(i) - T.i0;
      double s, e;
      allanvar::two_sum(T.h[i], -T.c * u * u, s, e);
      T.h[i] = s;
      T.l[i] += e;
    }
  } else {
    T.c = 0;
  }
  T.rh.assign(T.h.rbegin(), T.h.rend());
  T.rl.assign(T.l.rbegin(), T.l.rend());
}

// SF(lag) = sum_{p < N - lag} (x~_{p+lag} - x~_p)^2 for lag = 1..lmax
// (sf[0] = 0). Short lags directly; lags in [D, 2D) from blocks of B = 6D
// starting points on the block's phase less the chord through its window,
// z_j = x~(a+j) - x~(a) - s j: with t = x~ increments,
//   sum_j (t_j)^2 = sum_j (z_{j+lag} - z_j)^2 + 2 s lag sum_j (z_{j+lag}
//   - z_j) + B s^2 lag^2,
// the first from one FFT correlation of z; the last window of the record
// by its own autocorrelation.
std::vector<double> theo_full_sf(const TildePhase& X, R_xlen_t lmax,
                                 int threads) {
  const R_xlen_t N = X.N;
  std::vector<double> sf(lmax + 1, 0.0);
  const R_xlen_t L0 = std::min<R_xlen_t>(lmax + 1, 64);
  struct Job {
    R_xlen_t lo, hi, a, len;  // lags [lo, hi); points [a, a + len)
    bool tail;                // autocorrelation of the segment
    size_t out;               // offset into the results
    bool direct;              // one short lag over the whole record
  };
  std::vector<Job> jobs;
  size_t tot = 0;
  for (R_xlen_t lag = 1; lag < L0; ++lag) {
    jobs.push_back(Job{lag, lag + 1, 0, N, false, tot, true});
    tot += 1;
  }
  for (R_xlen_t D = 64; D <= lmax; D *= 2) {
    const R_xlen_t lo = D, hi = std::min(2 * D, lmax + 1);
    const R_xlen_t B = 6 * D, W = B + 2 * D - 1;
    R_xlen_t a = 0;
    for (; a + W <= N; a += B) {
      jobs.push_back(Job{lo, hi, a, W, false, tot, false});
      tot += static_cast<size_t>(hi - lo);
    }
    if (N - a > lo) {
      jobs.push_back(Job{lo, hi, a, N - a, true, tot, false});
      tot += static_cast<size_t>(hi - lo);
    }
  }
  std::vector<double> res(tot, 0.0);
  const int nthr = std::max(1, threads);
  struct SfScratch {
    allanvar::cvec buf, buf2;
    allanvar::Scratch z, zs, qz, c;
  };
  allanvar::FFTPlans plans;  // shared by the workers
  std::vector<SfScratch> scr(nthr);
  allanvar::parallel_for(static_cast<R_xlen_t>(jobs.size()), nthr,
                         [&](R_xlen_t it, int worker) {
    const Job& J = jobs[it];
    if (J.direct) {
      // short lag: directly, in blocks for the rounding
      const R_xlen_t lag = J.lo;
      double acc = 0;
      for (R_xlen_t b0 = 0; b0 < N - lag; b0 += 4096) {
        const R_xlen_t b1 = std::min(N - lag, b0 + 4096);
        double s0 = 0, s1 = 0;
        R_xlen_t p = b0;
        for (; p + 2 <= b1; p += 2) {
          const double d0 = X.diff(p, p + lag), d1 = X.diff(p + 1, p + 1 + lag);
          s0 += d0 * d0;
          s1 += d1 * d1;
        }
        for (; p < b1; ++p) {
          const double d = X.diff(p, p + lag);
          s0 += d * d;
        }
        acc += s0 + s1;
      }
      res[J.out] = acc;
      return;
    }
    SfScratch& S = scr[worker];
    const R_xlen_t n = J.len;
    S.z.resize(n);
    S.zs.resize(n + 1);
    S.qz.resize(n + 1);
    const double s = X.diff(J.a, J.a + n - 1) / static_cast<double>(n - 1);
    S.zs[0] = S.qz[0] = 0;
    for (R_xlen_t j = 0; j < n; ++j) {
      S.z[j] = X.diff(J.a, J.a + j) - s * static_cast<double>(j);
      S.zs[j + 1] = S.zs[j] + S.z[j];
      S.qz[j + 1] = S.qz[j] + S.z[j] * S.z[j];
    }
    const R_xlen_t hi = std::min(J.hi, J.tail ? n : J.hi);
    const size_t nt = static_cast<size_t>(hi);
    S.c.resize(nt);
    const R_xlen_t B = J.tail ? n : n - 2 * J.lo + 1;  // starting points
    allanvar::real_correlation(S.z.data(), J.tail ? n : B, S.z.data(), n, nt,
                               S.c.data(), plans, S.buf, S.buf2);
    for (R_xlen_t lag = J.lo; lag < hi; ++lag) {
      const R_xlen_t cnt = J.tail ? n - lag : B;
      const double sfz = (S.qz[lag + cnt] - S.qz[lag]) + S.qz[cnt] - 2 * S.c[lag];
      const double dz = (S.zs[lag + cnt] - S.zs[lag]) - S.zs[cnt];
      const double g = s * static_cast<double>(lag);
      res[J.out + (lag - J.lo)] =
          sfz + 2 * g * dz + g * g * static_cast<double>(cnt);
    }
  });
  allanvar::TauSums acc(static_cast<size_t>(lmax + 1));
  for (const Job& J : jobs) {
    const R_xlen_t hi = std::min(J.hi, J.tail ? J.len : J.hi);
    for (R_xlen_t lag = J.lo; lag < hi; ++lag)
      acc.add(static_cast<size_t>(lag), res[J.out + (lag - J.lo)]);
  }
  for (R_xlen_t lag = 1; lag <= lmax; ++lag)
    sf[lag] = acc.any(lag) ? acc.value(lag) : 0.0;
  return sf;
}

}  // namespace

// T_k of one channel at the k in `need` (each in [1, (L - 1) / 2]) by the
// squared-increment recurrence above; O(L log^2 L + kmax^2).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector theo1_incr_cpp(const Rcpp::NumericVector& v, bool rate,
                                   const Rcpp::NumericVector& need,
                                   int threads) {
  const allanvar::InterruptScope scope;
  const allanvar::PhaseInput in{v.begin(), v.size(), rate};
  allanvar::SplitPhase Xs;
  allanvar::split_phase(in, Xs);
  const R_xlen_t N = in.length();
  Rcpp::NumericVector out(need.size(), NA_REAL);
  R_xlen_t kmax = 0;
  for (R_xlen_t i = 0; i < need.size(); ++i) {
    const double k = need[i];
    if (k >= 1 && k <= (N - 1) / 2) kmax = std::max(kmax, static_cast<R_xlen_t>(k));
  }
  if (kmax < 1) return out;
  std::vector<std::vector<R_xlen_t>> where(kmax + 1);
  for (R_xlen_t i = 0; i < need.size(); ++i) {
    const double k = need[i];
    if (k >= 1 && k <= kmax) where[static_cast<R_xlen_t>(k)].push_back(i);
  }
  TildePhase X;
  tilde_phase(Xs, X);
  const std::vector<double> sf = theo_full_sf(X, 2 * kmax, threads);
  scope.finish();
  // The quadratic's part, sum_L (1/L) (2 delta_L sum_i d~_i(L) + M delta_L^2)
  // with delta_L = 2 c L (m - L), in O(1) per k from double-double prefix
  // sums: sum_i d~_i(L) = A(L) - (S(M+L) - S(M)) - (S(m) - S(m-L)),
  // A(L) = S(L) + S(N) - S(N-L), S(j) the sum of x~ over [0, j).
  std::vector<DD> S, PS, PJS, PA, PLA;
  if (X.c != 0) {
    S.resize(N + 1);
    PS.resize(N + 1);
    PJS.resize(N + 1);
    DD a, b, e;
    for (R_xlen_t j = 0; j <= N; ++j) {
      if (j > 0) a += DD(X.h[j - 1]) + DD(X.l[j - 1]);
      S[j] = a;
      b += a;
      e += a * static_cast<double>(j);
      PS[j] = b;
      PJS[j] = e;
    }
    PA.resize(kmax + 1);
    PLA.resize(kmax + 1);
    for (R_xlen_t L = 1; L <= kmax; ++L) {
      const DD A = S[L] + S[N] - S[N - L];
      PA[L] = PA[L - 1] + A;
      PLA[L] = PLA[L - 1] + A * static_cast<double>(L);
    }
  }
  auto quad_part = [&](R_xlen_t k) {
    const R_xlen_t m = 2 * k, M = N - m;
    const double kd = static_cast<double>(k), md = static_cast<double>(m);
    const double W1 = md * kd - 0.5 * kd * (kd + 1);
    const DD sdw = PA[k] * md - PLA[k] -
                   (PS[M + k] - PS[M]) * static_cast<double>(N) +
                   (PJS[M + k] - PJS[M]) + (S[M] - S[m]) * W1 +
                   (PJS[m - 1] - PJS[k - 1]);
    const double s1 = 0.5 * kd * (kd + 1), s2 = s1 * (2 * kd + 1) / 3;
    const double p3 = md * md * s1 - 2 * md * s2 + s1 * s1;
    return sdw * (4 * X.c) +
           DD(4 * X.c * X.c * static_cast<double>(M) * p3);
  };
  // ht(lag): the pairs at lag within the first 2k points plus those within
  // the last 2k; tri(d): the pairs (c - d, c + d) centred below k or at or
  // above N - k. Each grows by O(k) pairs from k to k + 1. Their weighted
  // sums at the needed k are formed by items over ranges of lags (of d),
  // each item stepping k from 0 to kmax on its own range: no item waits for
  // another. The items and their kGroups groups (item j in group j mod
  // kGroups, run in order by one worker, summed in compensated totals per
  // group, the groups added in order) depend on N and the k only, never on
  // the threads or their timing: the result is the same bit for bit on any
  // number of threads (per-worker totals differed in the last bits between
  // calls).
  std::vector<double> sfe(kmax + 1, 0.0), inv(kmax + 1, 0.0);
  for (R_xlen_t d = 1; d <= kmax; ++d) {
    sfe[d] = sf[2 * d];
    inv[d] = 1.0 / static_cast<double>(d);
  }
  std::vector<R_xlen_t> slot(kmax + 1, -1), ks;
  for (R_xlen_t kk = 1; kk <= kmax; ++kk) {
    if (!where[kk].empty()) {
      slot[kk] = static_cast<R_xlen_t>(ks.size());
      ks.push_back(kk);
    }
  }
  struct EdgeItem {
    bool tri;
    R_xlen_t a, b;  // lags (or d) in [a, b)
  };
  std::vector<EdgeItem> items;
  {
    // work (squared increments) of lag l: 4 per step from k = (l - 1) / 2
    // on; of d: 2 per step from k = d on
    const double kd = static_cast<double>(kmax);
    const double total = 5.0 * kd * kd;
    const double pieces = std::max(32.0, std::min(512.0, total / 3.3e7));
    const double per = total / pieces;
    double w = 0;
    R_xlen_t a = 1;
    for (R_xlen_t l = 1; l <= 2 * kmax; ++l) {
      w += 4.0 * static_cast<double>(kmax - l / 2);
      if (w >= per || l == 2 * kmax) {
        items.push_back(EdgeItem{false, a, l + 1});
        a = l + 1;
        w = 0;
      }
    }
    a = 1;
    w = 0;
    for (R_xlen_t d = 1; d < kmax; ++d) {
      w += 2.0 * static_cast<double>(kmax - d);
      if (w >= per || d == kmax - 1) {
        items.push_back(EdgeItem{true, a, d + 1});
        a = d + 1;
        w = 0;
      }
    }
  }
  const int nthr = std::max(1, threads);
  const R_xlen_t kGroups = 8;
  std::vector<allanvar::TauSums> edge(kGroups, allanvar::TauSums(ks.size()));
  const double* h = X.h.data();
  const double* l = X.l.data();
  const double* rh = X.rh.data();
  const double* rl = X.rl.data();
  const R_xlen_t nitems = static_cast<R_xlen_t>(items.size());
  // item `it` into the totals of group `worker`
  auto run_item = [&](R_xlen_t it, R_xlen_t worker) {
    const EdgeItem I = items[it];
    std::vector<double> v(I.b - I.a, 0.0);
    double* t = v.data() - I.a;  // t[lag]
    if (!I.tri) {
      // the first 2k points gain q = 2k, 2k + 1 (x(q - lag) is reversed
      // (N - 1 - q + lag)); the last 2k gain p = N - 2k - 1, N - 2k - 2
      for (R_xlen_t k = std::max<R_xlen_t>(0, (I.a - 1) / 2); k < kmax; ++k) {
        if ((k & 63) == 0 && allanvar::interrupted()) return;
        const R_xlen_t q = 2 * k, p = N - 2 * k - 1;
        const double hq = h[q], lq = l[q], hq1 = h[q + 1], lq1 = l[q + 1];
        const double hp = h[p], lp = l[p], hp1 = h[p - 1], lp1 = l[p - 1];
        const double* a1 = rh + (N - 2 - q);  // a1[lag + 1] = x(q - lag)
        const double* b1 = rl + (N - 2 - q);
        const double* c1 = h + p - 1;         // c1[lag + 1] = x(p + lag)
        const double* e1 = l + p - 1;
        R_xlen_t lag = I.a;
        const R_xlen_t top = std::min(I.b, q + 1);
#if defined(__GNUC__)
        using allanvar::ld2;
        using allanvar::v2d;
        const v2d Hq = {hq, hq}, Lq = {lq, lq}, Hq1 = {hq1, hq1},
                  Lq1 = {lq1, lq1}, Hp = {hp, hp}, Lp = {lp, lp},
                  Hp1 = {hp1, hp1}, Lp1 = {lp1, lp1};
        for (; lag + 2 <= top; lag += 2) {
          const v2d d0 = (Hq - ld2(a1 + lag + 1)) + (Lq - ld2(b1 + lag + 1));
          const v2d d1 = (Hq1 - ld2(a1 + lag)) + (Lq1 - ld2(b1 + lag));
          const v2d e0 = (ld2(c1 + lag + 1) - Hp) + (ld2(e1 + lag + 1) - Lp);
          const v2d f1 = (ld2(c1 + lag) - Hp1) + (ld2(e1 + lag) - Lp1);
          allanvar::st2(t + lag, ld2(t + lag) + ((d0 * d0 + d1 * d1) +
                                                 (e0 * e0 + f1 * f1)));
        }
#endif
        for (; lag < top; ++lag) {
          const double d0 = (hq - a1[lag + 1]) + (lq - b1[lag + 1]);
          const double d1 = (hq1 - a1[lag]) + (lq1 - b1[lag]);
          const double e0 = (c1[lag + 1] - hp) + (e1[lag + 1] - lp);
          const double f1 = (c1[lag] - hp1) + (e1[lag] - lp1);
          t[lag] += (d0 * d0 + d1 * d1) + (e0 * e0 + f1 * f1);
        }
        if (q + 1 >= I.a && q + 1 < I.b) {
          const double d = (hq1 - h[0]) + (lq1 - l[0]);
          const double e = (h[N - 1] - hp1) + (l[N - 1] - lp1);
          t[q + 1] += d * d + e * e;
        }
        const R_xlen_t kk = k + 1;
        if (slot[kk] < 0) continue;
        // sum_L (2 SF(L) - ht(L) + 2 SF(2kk - L) - ht(2kk - L)) / L over
        // this item's lags (each SF with the pairs it loses, which cancel
        // most of it when 2kk nears N)
        const R_xlen_t hi = std::min(I.b, 2 * kk);
        double acc = 0;
        for (R_xlen_t g = I.a; g < std::min(hi, kk + 1); ++g)
          acc += (2 * sf[g] - t[g]) * inv[g];
        for (R_xlen_t g = std::max(I.a, kk); g < hi; ++g)
          acc += (2 * sf[g] - t[g]) * inv[2 * kk - g];
        edge[worker].add(static_cast<size_t>(slot[kk]), acc);
      }
    } else {
      // the centres k and N - 1 - k: x(k + d) - x(k - d) and
      // x(N - 1 - k + d) - x(N - 1 - k - d)
      for (R_xlen_t k = I.a; k < kmax; ++k) {
        if ((k & 63) == 0 && allanvar::interrupted()) return;
        const double* ah = h + k;
        const double* al = l + k;
        const double* bh = rh + (N - 1 - k);
        const double* bl = rl + (N - 1 - k);
        const double* ch = h + (N - 1 - k);
        const double* cl = l + (N - 1 - k);
        const double* dh = rh + k;
        const double* dl = rl + k;
        const R_xlen_t top = std::min(I.b, k + 1);
        R_xlen_t d = I.a;
#if defined(__GNUC__)
        using allanvar::ld2;
        using allanvar::v2d;
        for (; d + 2 <= top; d += 2) {
          const v2d e = (ld2(ah + d) - ld2(bh + d)) + (ld2(al + d) - ld2(bl + d));
          const v2d f = (ld2(ch + d) - ld2(dh + d)) + (ld2(cl + d) - ld2(dl + d));
          allanvar::st2(t + d, ld2(t + d) + (e * e + f * f));
        }
#endif
        for (; d < top; ++d) {
          const double e = (ah[d] - bh[d]) + (al[d] - bl[d]);
          const double f = (ch[d] - dh[d]) + (cl[d] - dl[d]);
          t[d] += e * e + f * f;
        }
        const R_xlen_t kk = k + 1;
        if (slot[kk] < 0) continue;
        // sum_{L < kk} (tri(kk - L) - SF(2kk - 2L)) / L over this item's d
        double acc = 0;
        for (R_xlen_t d = I.a; d < std::min(I.b, kk); ++d)
          acc += (t[d] - sfe[d]) * inv[kk - d];
        edge[worker].add(static_cast<size_t>(slot[kk]), acc);
      }
    }
  };
  allanvar::parallel_for(kGroups, nthr, [&](R_xlen_t grp, int) {
    for (R_xlen_t it = grp; it < nitems; it += kGroups) {
      if (allanvar::interrupted()) return;
      run_item(it, grp);
    }
  });
  scope.finish();
  std::vector<DD> harm(kmax + 1);  // harmonic numbers
  for (R_xlen_t L = 1; L <= kmax; ++L) harm[L] = harm[L - 1] + DD(inv[L]);
  for (size_t i = 0; i < ks.size(); ++i) {
    // - H_k SF(2k), the SF(2k) of every L
    double p, e;
    allanvar::dd_two_prod(-harm[ks[i]].value(), sf[2 * ks[i]], p, e);
    DD T(p, e);
    for (R_xlen_t w = 0; w < kGroups; ++w) T += DD(edge[w].value(i));
    if (X.c != 0) T += quad_part(ks[i]);
    for (R_xlen_t j : where[ks[i]]) out[j] = T.value();
  }
  return out;
}
