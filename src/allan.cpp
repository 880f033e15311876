// allan(): the Allan-family estimators from exact-grid prefix sums.
//
// Every estimator is a sum of squares of small integer combinations of a
// phase sequence X (the running sum of the rate samples, or the integrated
// input itself). X is held as hi + q lo, where hi lies on a grid of step q
// with |hi| <= 2^50 q: any combination with integer weights of total size
// <= 8 is then exact in double. lo is the rest in units of q (at most 1/2
// and a rounding: each point's grid part is moved into hi) stored as a float,
// 12 bytes a point instead of 16 (the far taus' streams come from memory).
// The float rounds q lo by at most 2^-25 q, about 2^-75 of the largest |X|
// (for rate data up to N times the samples' half-range): a term's
// difference moves by at most 2^-22 q (weights of total size 8), e.g. 1e-14
// of a white-FM term at m = 1 and 1e7 samples, with a sign that varies from
// term to term, so the sums of squares move far less. Differences of
// huge, nearly equal prefix sums therefore lose nothing, whatever the bias,
// drift or length of the record.
#include "buffer.h"
#include "checks.h"
#include "dd.h"
#include "local-phase.h"
#include "noise_id.h"
#include "scratch.h"
#include "opts-allan.h"
#include "parallel.h"
#include "types.h"
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <memory>
#include <type_traits>
#include <vector>
#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace {

using allanvar::AllanOptions;
using allanvar::Buffer;
using allanvar::FloatBuffer;
using allanvar::STANDARD;
using allanvar::OVERLAPPING;
using allanvar::MODIFIED;
using allanvar::HADAMARD;
using allanvar::OHADAMARD;
using allanvar::TOTAL;

// a + b = s + e exactly (Knuth's TwoSum, src/dd.h).
using allanvar::two_sum;
using allanvar::fast_two_sum;

// Sum of many squares: four interleaved chains, folded into a compensated
// total block by block, keep the rounding far below 1e-15 relative.
using Acc = allanvar::CompSum;

// Runs f(i) for i in [0, n): from the main thread through parallel_for
// (which polls for interrupts between items), serially and without any R
// API inside a worker.
template <class F>
void run_items(R_xlen_t n, int threads, bool main, F f) {
  if (main) {
    allanvar::parallel_for(n, threads, [&](R_xlen_t i, int) { f(i); });
  } else {
    for (R_xlen_t i = 0; i < n; ++i) f(i);
  }
}

// X = hi + q lo (the file's head). The modified type's extra level of sums
// (the prefix sums of X for rate data, of the phase for integrated input)
// keeps lo in double (wlo, in absolute units, q = 1 here: the running
// remainders as they are): its grid step, 2^-50 of N times the summed
// sequence's range, can be near a term's size at m = 1 (N^2 times the
// samples' range, or a phase with a slope), too coarse for a float's 24 bits.
struct Split {
  Buffer hi;
  FloatBuffer lo;
  Buffer wlo;
  double q = 1;
  bool wide = false;
  // f(lo) with the lo array in use
  template <class F>
  auto with_lo(F f) const -> decltype(f(lo.data())) {
    return wide ? f(wlo.data()) : f(lo.data());
  }
  double lo_at(R_xlen_t i) const {
    return wide ? wlo[i] : static_cast<double>(lo[i]);
  }
};

// Single passes over the samples ask for interrupts every 2^20 samples.
const R_xlen_t kPoll = (static_cast<R_xlen_t>(1) << 20) - 1;

// Grid step q = 2^k with bound <= 2^50 q.
inline double grid_step(double bound) {
  if (!(bound > 0) || !std::isfinite(bound)) return 1.0;
  int e;
  std::frexp(bound, &e);
  // at least the smallest normal double: 1 / q stays finite
  return std::max(std::ldexp(1.0, e - 50), 2.2250738585072014e-308);
}

// x - c as a on the grid of C (C = 1.5 q 2^52: ulp(C) = q) plus the rest
// rem = (r - a) + re (at most q/2 and an ulp; r + re = x - c exactly).
inline void grid_split(double x, double c, double C, double& a, double& rem) {
  double r, re;
  two_sum(x, -c, r, re);
  a = (r + C) - C;
  rem = (r - a) + re;
}

// Prefix sums with a leading zero of (v - c): levels = 1 gives X (n + 1
// points), levels = 2 the prefix sums of X (n + 2 points). `bound` bounds
// |v - c|.
const R_xlen_t kPrefixBlock = static_cast<R_xlen_t>(1) << 16;

// One block [i0, i1) of build_prefix(levels = 1): the exact sum of its grid
// parts and the sum of its remainders in four lanes (i mod 4 from i0; the
// last (i1 - i0) % 4 in lane 0: the same additions whether or not the values
// are stored), and with Store its X values from h + (l0 + l) on, the grid
// part of l0 + l moved into hi (exact: both on the grid) and the rest, at
// most q/2, times rq = 1/q into a float lo (a double lo takes l0 + l as it
// is, hi the running grid sum). Four samples a step in vectors: the running
// sums carried in every lane and each step's prefix by two shifted
// additions (GCC and Clang vector extensions). The order of the remainders'
// additions is fixed: the result does not depend on the threads or the
// instruction set. One serial chain a sample was the build's cost.
typedef double pv4 __attribute__((vector_size(32)));
typedef float pv4f __attribute__((vector_size(16)));
#if defined(__clang__)
#define ALLANVAR_SHUF(a, b, i, j, k, l) \
  __builtin_shufflevector(a, b, i, j, k, l)
#else
typedef long long pv4i __attribute__((vector_size(32)));
#define ALLANVAR_SHUF(a, b, i, j, k, l) \
  __builtin_shuffle(a, b, pv4i{i, j, k, l})
#endif

inline void store_lo(float* p, pv4 x) {
  const pv4f f = __builtin_convertvector(x, pv4f);
  std::memcpy(p, &f, sizeof f);
}
inline void store_lo(double* p, pv4 x) { std::memcpy(p, &x, sizeof x); }

template <bool Store, class L>
inline __attribute__((always_inline)) void prefix_body(
    const double* v, R_xlen_t i0, R_xlen_t i1, double c, double C, double rq,
    double h, double l0, double* hi, L* lo, double& hsum, double& lsum) {
  const pv4 cv = {-c, -c, -c, -c}, Cv = {C, C, C, C}, z = {0, 0, 0, 0};
  const pv4 rqv = {rq, rq, rq, rq}, l0v = {l0, l0, l0, l0};
  pv4 hl = z, ll = z, hb = {h, h, h, h}, lb = z;
  R_xlen_t i = i0;
  for (; i + 4 <= i1; i += 4) {
    pv4 x;
    std::memcpy(&x, v + i, sizeof x);
    // grid_split(x, c, C) lane by lane
    const pv4 r = x + cv;
    const pv4 bb = r - x;
    const pv4 re = (x - (r - bb)) + (cv - bb);
    const pv4 a = (r + Cv) - Cv;
    const pv4 rem = (r - a) + re;
    hl += a;
    ll += rem;
    if (Store) {
      // inclusive prefix sums of the step (z's lanes are 4..7)
      pv4 pa = a + ALLANVAR_SHUF(a, z, 4, 0, 1, 2);
      pa += ALLANVAR_SHUF(pa, z, 4, 5, 0, 1);
      pv4 pr = rem + ALLANVAR_SHUF(rem, z, 4, 0, 1, 2);
      pr += ALLANVAR_SHUF(pr, z, 4, 5, 0, 1);
      const pv4 hv = hb + pa;
      const pv4 t = l0v + (lb + pr);
      hb += ALLANVAR_SHUF(pa, pa, 3, 3, 3, 3);
      lb += ALLANVAR_SHUF(pr, pr, 3, 3, 3, 3);
      if (std::is_same<L, double>::value) {
        // a double lo keeps the running remainder as it is (Split)
        std::memcpy(hi + i + 1, &hv, sizeof hv);
        store_lo(lo + i + 1, t);
      } else {
        const pv4 g = (t + Cv) - Cv;
        const pv4 hx = hv + g;
        std::memcpy(hi + i + 1, &hx, sizeof hx);
        store_lo(lo + i + 1, (t - g) * rqv);
      }
    }
  }
  double hs = hl[0], ls = ll[0], hh = hb[0], l = lb[0];
  for (; i < i1; ++i) {
    double a, rem;
    grid_split(v[i], c, C, a, rem);
    hs += a;
    ls += rem;
    if (Store) {
      hh += a;
      l += rem;
      const double t = l0 + l;
      if (std::is_same<L, double>::value) {
        hi[i + 1] = hh;
        lo[i + 1] = static_cast<L>(t);
      } else {
        const double g = (t + C) - C;
        hi[i + 1] = hh + g;
        lo[i + 1] = static_cast<L>((t - g) * rq);
      }
    }
  }
  hsum = (hs + hl[1]) + (hl[2] + hl[3]);
  lsum = (ls + ll[1]) + (ll[2] + ll[3]);
}

template <bool Store, class L>
void prefix_block_sse2(const double* v, R_xlen_t i0, R_xlen_t i1, double c,
                       double C, double rq, double h, double l0, double* hi,
                       L* lo, double& hsum, double& lsum) {
  prefix_body<Store, L>(v, i0, i1, c, C, rq, h, l0, hi, lo, hsum, lsum);
}

#if defined(__x86_64__)
// the same operations in one AVX2 instruction each (no FMA: the same bits)
template <bool Store, class L>
__attribute__((target("avx2"))) void prefix_block_avx2(
    const double* v, R_xlen_t i0, R_xlen_t i1, double c, double C, double rq,
    double h, double l0, double* hi, L* lo, double& hsum, double& lsum) {
  prefix_body<Store, L>(v, i0, i1, c, C, rq, h, l0, hi, lo, hsum, lsum);
}
#endif

template <bool Store, class L>
void prefix_block(const double* v, R_xlen_t i0, R_xlen_t i1, double c,
                  double C, double rq, double h, double l0, double* hi,
                  L* lo, double& hsum, double& lsum) {
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2) {
    prefix_block_avx2<Store, L>(v, i0, i1, c, C, rq, h, l0, hi, lo, hsum,
                                lsum);
    return;
  }
#endif
  prefix_block_sse2<Store, L>(v, i0, i1, c, C, rq, h, l0, hi, lo, hsum, lsum);
}

// The samples' range on [i0, i1) (i1 > i0) and the sum of v * 0 (NaN when a
// sample is not finite: NaN compares false and keeps the running bound) in
// four lanes, the tail in lane 0; r = {min, max, z}. Exact in any grouping:
// blocks on the threads give the same result.
inline __attribute__((always_inline)) void range_body(const double* v,
                                                      R_xlen_t i0, R_xlen_t i1,
                                                      double* r) {
  pv4 lo = {v[i0], v[i0], v[i0], v[i0]}, hi = lo, z = {0, 0, 0, 0};
  R_xlen_t i = i0;
  for (; i + 4 <= i1; i += 4) {
    pv4 a;
    std::memcpy(&a, v + i, sizeof a);
    lo = a < lo ? a : lo;
    hi = a > hi ? a : hi;
    z += a * 0.0;
  }
  double l = lo[0], h = hi[0], zz = z[0];
  for (; i < i1; ++i) {
    l = v[i] < l ? v[i] : l;
    h = v[i] > h ? v[i] : h;
    zz += v[i] * 0.0;
  }
  r[0] = std::min(std::min(l, lo[1]), std::min(lo[2], lo[3]));
  r[1] = std::max(std::max(h, hi[1]), std::max(hi[2], hi[3]));
  r[2] = (zz + z[1]) + (z[2] + z[3]);
}

void range_block_sse2(const double* v, R_xlen_t i0, R_xlen_t i1, double* r) {
  range_body(v, i0, i1, r);
}

#if defined(__x86_64__)
__attribute__((target("avx2"))) void range_block_avx2(const double* v,
                                                       R_xlen_t i0,
                                                       R_xlen_t i1, double* r) {
  range_body(v, i0, i1, r);
}
#endif

// {min, max, z} of v[0, n) (n > 0) in blocks of 2^20 on the threads (one
// pass over the samples on the main thread was 5-10% of an overlapping AV)
void sample_range(const double* v, R_xlen_t n, int threads, bool main,
                  double* r) {
  const R_xlen_t B = static_cast<R_xlen_t>(1) << 20;
  const R_xlen_t nb = (n + B - 1) / B;
  std::vector<double> part(3 * nb);
  run_items(nb, threads, main, [&](R_xlen_t k) {
    const R_xlen_t i0 = k * B, i1 = std::min(n, i0 + B);
#if defined(__x86_64__)
    static const bool avx2 = __builtin_cpu_supports("avx2");
    if (avx2) {
      range_block_avx2(v, i0, i1, &part[3 * k]);
      return;
    }
#endif
    range_block_sse2(v, i0, i1, &part[3 * k]);
  });
  r[0] = part[0];
  r[1] = part[1];
  r[2] = part[2];
  for (R_xlen_t k = 1; k < nb; ++k) {
    r[0] = std::min(r[0], part[3 * k]);
    r[1] = std::max(r[1], part[3 * k + 1]);
    r[2] += part[3 * k + 2];
  }
}

// build_prefix(levels = 1) into hi and lo (float, or double when wide).
template <class L>
void rate_prefix(const double* v, R_xlen_t n, double c, double C, double rq,
                 double* hi, L* lo, int threads, bool main) {
  // X_{i+1} = X_i + (v_i - c). Each increment v_i - c = r + re (TwoSum)
  // is split into a on the grid q and the remainder (r - a) + re (at most
  // q/2 and an ulp): hi sums the a exactly (multiples of q below 2^50 q,
  // in any order), lo the remainders in plain double (rounding about
  // eps n q, far below q), whose running grid part is stored in hi and
  // the rest in lo. hi being exact, the record is cut into fixed
  // blocks: on two threads their sums first, then each block's prefix
  // from its start; on one, a single pass making the same additions. The
  // result does not depend on the thread count.
  const R_xlen_t nb = (n + kPrefixBlock - 1) / kPrefixBlock;
  auto ends = [n](R_xlen_t k, R_xlen_t& i0, R_xlen_t& i1) {
    i0 = k * kPrefixBlock;
    i1 = std::min(n, i0 + kPrefixBlock);
  };
  if (threads < 2 || nb < 2) {
    // one pass: each block from the running sums of those before it
    double h = 0, l0 = 0;
    for (R_xlen_t k = 0; k < nb; ++k) {
      if ((k & 15) == 15 && allanvar::interrupted()) return;
      R_xlen_t i0, i1;
      ends(k, i0, i1);
      double hs, ls;
      prefix_block<true>(v, i0, i1, c, C, rq, h, l0, hi, lo, hs, ls);
      h += hs;
      l0 += ls;
    }
    return;
  }
  // two passes on the threads: block sums, then each block from its start
  std::vector<double> hbase(nb + 1, 0.0), lbase(nb + 1, 0.0);
  run_items(nb, threads, main, [&](R_xlen_t k) {
    R_xlen_t i0, i1;
    ends(k, i0, i1);
    prefix_block<false>(v, i0, i1, c, C, rq, 0, 0, hi, lo, hbase[k + 1],
                        lbase[k + 1]);
  });
  if (allanvar::interrupt_state().stop.load()) return;
  for (R_xlen_t k = 0; k < nb; ++k) {
    hbase[k + 1] += hbase[k];
    lbase[k + 1] += lbase[k];
  }
  run_items(nb, threads, main, [&](R_xlen_t k) {
    R_xlen_t i0, i1;
    ends(k, i0, i1);
    double hs, ls;
    prefix_block<true>(v, i0, i1, c, C, rq, hbase[k], lbase[k], hi, lo, hs,
                       ls);
  });
}

// wide: lo in double (the modified type's extra level of sums, Split).
void build_prefix(const double* v, R_xlen_t n, double c, double bound,
                  int levels, bool wide, Split& out, int threads, bool main) {
  const R_xlen_t len = n + levels;
  out.hi.resize(len);
  out.wide = wide || levels == 2;
  if (out.wide) {
    out.wlo.resize(len);
  } else {
    out.lo.resize(len);
  }
  double* hi = out.hi.data();
  float* lo = out.lo.data();
  double* wlo = out.wlo.data();
  hi[0] = 0;
  if (out.wide) {
    wlo[0] = 0;
  } else {
    lo[0] = 0;
  }
  if (levels == 2) hi[1] = wlo[1] = 0;
  const double nn = static_cast<double>(n);
  double b = bound * nn * (1 + 1e-9);
  if (levels == 2) b *= nn + 1;
  // room for the grid's rounding of n increments (n q/2 <= n b 2^-50)
  if (levels == 1) b *= 1 + nn * 1.7763568394002505e-15;  // 2^-49
  const double q = grid_step(b);
  const double C = 1.5 * q * 4503599627370496.0;  // 1.5 q 2^52: ulp(C) = q
  const double rq = 1 / q;  // exact: q is a power of two
  out.q = out.wide ? 1.0 : q;  // a double lo in absolute units (Split)
  if (levels == 1) {
    if (out.wide) {
      rate_prefix(v, n, c, C, rq, hi, wlo, threads, main);
    } else {
      rate_prefix(v, n, c, C, rq, hi, lo, threads, main);
    }
    return;
  }
  // levels == 2: P_{i+1} = P_i + X_i, then X_{i+1} = X_i + (v_i - c)
  double s1 = 0, e1 = 0, s2 = 0, e2 = 0;
  auto put = [&](R_xlen_t i) {
    const double h = (s2 + C) - C;
    hi[i] = h;
    wlo[i] = (s2 - h) + e2;
  };
  for (R_xlen_t i = 0; i < n; ++i) {
    if ((i & kPoll) == kPoll && allanvar::interrupted()) return;
    double r, re, t, te;
    two_sum(v[i], -c, r, re);
    two_sum(s2, s1, t, te);
    s2 = t;
    e2 += te + e1;
    put(i + 1);
    two_sum(s1, r, t, te);
    s1 = t;
    e1 += te + re;
  }
  {
    double t, te;
    two_sum(s2, s1, t, te);
    s2 = t;
    e2 += te + e1;
    put(n + 1);
  }
}

// The input itself split on a grid (integrated input, levels = 0).
void build_split(const double* v, R_xlen_t n, double c, double bound,
                 Split& out) {
  out.hi.resize(n);
  out.lo.resize(n);
  out.wide = false;
  const double q = grid_step(bound * (1 + 1e-9));
  const double C = 1.5 * q * 4503599627370496.0;
  const double rq = 1 / q;
  out.q = q;
  for (R_xlen_t i = 0; i < n; ++i) {
    double rem;
    grid_split(v[i], c, C, out.hi[i], rem);
    out.lo[i] = static_cast<float>(rem * rq);
  }
}

// Sum of squared second (D = 2) or third (D = 3) differences at stride 1,
// for k in [k0, k1): each difference is the hi parts' (exact) plus q times
// the lo parts' (floats widened to double).
#if defined(__GNUC__)
using allanvar::v2d;
using allanvar::ld2;
#endif

template <int D, class L>
inline double diff_at(const double* h, const L* f, double q, R_xlen_t m,
                      R_xlen_t k) {
  auto l = [f](R_xlen_t i) { return static_cast<double>(f[i]); };
  if (D == 2) {
    return ((h[k + 2 * m] + h[k]) - 2.0 * h[k + m]) +
           q * ((l(k + 2 * m) + l(k)) - 2.0 * l(k + m));
  }
  return ((h[k + 3 * m] - h[k]) + 3.0 * (h[k + m] - h[k + 2 * m])) +
         q * ((l(k + 3 * m) - l(k)) + 3.0 * (l(k + m) - l(k + 2 * m)));
}

// Sum of squared differences for k in [k0, k1): eight terms per step in
// eight lanes (k mod 8 within the step), folded as
// ((l0 + l4) + (l2 + l6)) + ((l1 + l5) + (l3 + l7)) (the vector extensions
// SSE2 uses four vectors of two, AVX2 two of four: the same lanes, the same
// additions and no fused multiply-add, so both give the same bits), then the
// last k1 - k0 mod 8 terms one by one.
#if defined(__GNUC__)
typedef float v2f __attribute__((vector_size(8)));

inline v2d ldf2(const float* p) {
  v2f v;
  std::memcpy(&v, p, sizeof v);
  return __builtin_convertvector(v, v2d);
}
inline v2d ldf2(const double* p) { return ld2(p); }

template <int D, class L>
inline v2d diff_vec(const double* h, const L* l, v2d q, R_xlen_t m,
                    R_xlen_t k) {
  if (D == 2) {
    return ((ld2(h + 2 * m + k) + ld2(h + k)) - 2.0 * ld2(h + m + k)) +
           q * ((ldf2(l + 2 * m + k) + ldf2(l + k)) - 2.0 * ldf2(l + m + k));
  }
  return ((ld2(h + 3 * m + k) - ld2(h + k)) +
          3.0 * (ld2(h + m + k) - ld2(h + 2 * m + k))) +
         q * ((ldf2(l + 3 * m + k) - ldf2(l + k)) +
              3.0 * (ldf2(l + m + k) - ldf2(l + 2 * m + k)));
}

template <int D, class L>
inline double sumsq8_sse2(const double* h, const L* l, double q,
                          R_xlen_t m, R_xlen_t& k, R_xlen_t k1) {
  const v2d qv = {q, q};
  v2d a0 = {0, 0}, a1 = {0, 0}, a2 = {0, 0}, a3 = {0, 0};
  for (; k + 8 <= k1; k += 8) {
    const v2d d0 = diff_vec<D, L>(h, l, qv, m, k);
    const v2d d1 = diff_vec<D, L>(h, l, qv, m, k + 2);
    const v2d d2 = diff_vec<D, L>(h, l, qv, m, k + 4);
    const v2d d3 = diff_vec<D, L>(h, l, qv, m, k + 6);
    a0 += d0 * d0;
    a1 += d1 * d1;
    a2 += d2 * d2;
    a3 += d3 * d3;
  }
  return ((a0[0] + a2[0]) + (a1[0] + a3[0])) +
         ((a0[1] + a2[1]) + (a1[1] + a3[1]));
}

#if defined(__x86_64__)
#define ALLANVAR_AVX2 1
typedef double v4d __attribute__((vector_size(32)));
typedef float v4f __attribute__((vector_size(16)));

__attribute__((target("avx2"))) inline v4d ld4(const double* p) {
  v4d v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// one vcvtps2pd (__builtin_convertvector gave two halves and a shuffle)
__attribute__((target("avx2"))) inline v4d ldf4(const float* p) {
  v4f v;
  std::memcpy(&v, p, sizeof v);
#if defined(__clang__)
  return __builtin_convertvector(v, v4d);  // Clang has no cvtps2pd builtin
#else
  return __builtin_ia32_cvtps2pd256(v);
#endif
}
__attribute__((target("avx2"))) inline v4d ldf4(const double* p) {
  return ld4(p);
}

template <int D, class L>
__attribute__((target("avx2"))) inline v4d diff4(const double* h,
                                                 const L* l, v4d q,
                                                 R_xlen_t m, R_xlen_t k) {
  if (D == 2) {
    return ((ld4(h + 2 * m + k) + ld4(h + k)) - 2.0 * ld4(h + m + k)) +
           q * ((ldf4(l + 2 * m + k) + ldf4(l + k)) - 2.0 * ldf4(l + m + k));
  }
  return ((ld4(h + 3 * m + k) - ld4(h + k)) +
          3.0 * (ld4(h + m + k) - ld4(h + 2 * m + k))) +
         q * ((ldf4(l + 3 * m + k) - ldf4(l + k)) +
              3.0 * (ldf4(l + m + k) - ldf4(l + 2 * m + k)));
}

template <int D, class L>
__attribute__((target("avx2"))) double sumsq8_avx2(const double* h,
                                                   const L* l, double q,
                                                   R_xlen_t m, R_xlen_t& k,
                                                   R_xlen_t k1) {
  const v4d qv = {q, q, q, q};
  v4d a0 = {0, 0, 0, 0}, a1 = {0, 0, 0, 0};
  for (; k + 8 <= k1; k += 8) {
    const v4d d0 = diff4<D, L>(h, l, qv, m, k);
    const v4d d1 = diff4<D, L>(h, l, qv, m, k + 4);
    a0 += d0 * d0;
    a1 += d1 * d1;
  }
  // lanes: a0 = (l0 l1 l2 l3), a1 = (l4 l5 l6 l7)
  return ((a0[0] + a1[0]) + (a0[2] + a1[2])) +
         ((a0[1] + a1[1]) + (a0[3] + a1[3]));
}

// The same lanes with fused multiply-adds where the CPU has them: six
// floating-point operations a term (and three widenings) instead of ten. The hi
// parts' weights are exact either way, and 2 l is exact, so the hi and lo
// differences are the same numbers; hi + q lo, the squares' sum (and
// 3 (l1 - l2) for D = 3) round once less, a last-bit change of the sum (not
// the SSE2 path's bits).
__attribute__((target("avx2,fma"))) inline v4d fma4(v4d a, v4d b, v4d c) {
  return __builtin_ia32_vfmaddpd256(a, b, c);
}

template <int D, class L>
__attribute__((target("avx2,fma"))) inline v4d diff4_fma(const double* h,
                                                        const L* l,
                                                        v4d q, R_xlen_t m,
                                                        R_xlen_t k) {
  if (D == 2) {
    const v4d w = {-2.0, -2.0, -2.0, -2.0};
    return fma4(q,
                fma4(w, ldf4(l + m + k), ldf4(l + 2 * m + k) + ldf4(l + k)),
                fma4(w, ld4(h + m + k), ld4(h + 2 * m + k) + ld4(h + k)));
  }
  const v4d w = {3.0, 3.0, 3.0, 3.0};
  return fma4(q,
              fma4(w, ldf4(l + m + k) - ldf4(l + 2 * m + k),
                   ldf4(l + 3 * m + k) - ldf4(l + k)),
              fma4(w, ld4(h + m + k) - ld4(h + 2 * m + k),
                   ld4(h + 3 * m + k) - ld4(h + k)));
}

template <int D, class L>
__attribute__((target("avx2,fma"))) double sumsq8_fma(const double* h,
                                                     const L* l, double q,
                                                     R_xlen_t m, R_xlen_t& k,
                                                     R_xlen_t k1) {
  const v4d qv = {q, q, q, q};
  v4d a0 = {0, 0, 0, 0}, a1 = {0, 0, 0, 0};
  for (; k + 8 <= k1; k += 8) {
    const v4d d0 = diff4_fma<D, L>(h, l, qv, m, k);
    const v4d d1 = diff4_fma<D, L>(h, l, qv, m, k + 4);
    a0 = fma4(d0, d0, a0);
    a1 = fma4(d1, d1, a1);
  }
  return ((a0[0] + a1[0]) + (a0[2] + a1[2])) +
         ((a0[1] + a1[1]) + (a0[3] + a1[3]));
}

inline bool have_fma() {
  static const bool ok =
      __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return ok;
}

inline bool have_avx2() {
  static const bool ok = __builtin_cpu_supports("avx2");
  return ok;
}
#endif
#endif

template <int D, class L>
inline double sumsq1(const double* h, const L* l, double q, R_xlen_t m,
                     R_xlen_t k0, R_xlen_t k1) {
  double tail = 0;
  R_xlen_t k = k0;
#if defined(ALLANVAR_AVX2)
  tail = have_fma()    ? sumsq8_fma<D, L>(h, l, q, m, k, k1)
         : have_avx2() ? sumsq8_avx2<D, L>(h, l, q, m, k, k1)
                       : sumsq8_sse2<D, L>(h, l, q, m, k, k1);
#elif defined(__GNUC__)
  tail = sumsq8_sse2<D, L>(h, l, q, m, k, k1);
#endif
  for (; k < k1; ++k) {
    const double d = diff_at<D, L>(h, l, q, m, k);
    tail += d * d;
  }
  return tail;
}

const R_xlen_t kBlock = 8192;  // terms per cache block (measured best of 512..8192)
const R_xlen_t kChunk = 1 << 17;  // terms per parallel item

// Stride-1 estimators: out[j] = sum over k < nterms[j] of f_j(k)^2. The k
// range is cut into fixed chunks (so the result does not depend on the
// thread count); inside a chunk every tau walks the same cache-resident
// block before the next block is loaded.
template <int D>
void overlapped(const Split& X, const std::vector<R_xlen_t>& ms,
                const std::vector<R_xlen_t>& nterms, int threads, bool main,
                double* out) {
  const size_t nt = ms.size();
  R_xlen_t K = 0;
  for (size_t j = 0; j < nt; ++j) K = std::max(K, nterms[j]);
  const R_xlen_t nchunks = (K + kChunk - 1) / kChunk;
  // nchunks x nt partial sums: gigabytes for taus = "all" at 1e7, so left
  // uninitialised here (a zero fill took 5-30 s with no interrupt poll) and
  // zeroed row by row inside the items, which poll
  std::unique_ptr<double[]> part(new double[static_cast<size_t>(nchunks) * nt]);
  run_items(nchunks, threads, main, [&](R_xlen_t c) {
    const R_xlen_t c0 = c * kChunk, c1 = std::min(K, c0 + kChunk);
    double* p = part.get() + c * nt;
    std::fill(p, p + nt, 0.0);
    for (R_xlen_t b0 = c0; b0 < c1; b0 += kBlock) {
      const R_xlen_t b1 = std::min(c1, b0 + kBlock);
      for (size_t j = 0; j < nt; ++j) {
        // a block of every tau of a long grid is seconds of work
        if ((j & 63) == 63 && allanvar::interrupted()) return;
        const R_xlen_t e = std::min(b1, nterms[j]);
        if (e <= b0) continue;
        p[j] += X.with_lo([&](const auto* l) {
          return sumsq1<D>(X.hi.data(), l, X.q, ms[j], b0, e);
        });
      }
    }
  });
  if (allanvar::interrupt_state().stop.load()) return;  // rows not all set
  for (size_t j = 0; j < nt; ++j) {
    if ((j & 4095) == 4095 && allanvar::interrupted()) return;
    Acc a;
    for (R_xlen_t c = 0; c < nchunks; ++c) a.add(part[c * nt + j]);
    out[j] = a.value();
  }
}

// Stride-m sum of squared differences of order D (2 or 3) over n terms: each
// term loads one new point and reuses the previous ones.
template <int D, class L>
double strided_sum(const double* h, const L* l, double q, R_xlen_t m,
                   R_xlen_t n) {
  Acc a;
  double s0 = 0, s1 = 0;
  double h0 = h[0], l0 = l[0], h1 = h[m], l1 = l[m];
  double h2 = D == 3 ? h[2 * m] : 0, l2 = D == 3 ? l[2 * m] : 0;
  const double* ph = h + D * m;
  const L* pl = l + D * m;
  for (R_xlen_t i = 0; i < n; ++i, ph += m, pl += m) {
    const double hn = *ph, ln = *pl;
    double d;
    if (D == 2) {
      d = ((hn + h0) - 2.0 * h1) + q * ((ln + l0) - 2.0 * l1);
      h0 = h1;
      l0 = l1;
      h1 = hn;
      l1 = ln;
    } else {
      d = ((hn - h0) + 3.0 * (h1 - h2)) + q * ((ln - l0) + 3.0 * (l1 - l2));
      h0 = h1;
      l0 = l1;
      h1 = h2;
      l1 = l2;
      h2 = hn;
      l2 = ln;
    }
    if (i & 1) {
      s1 += d * d;
    } else {
      s0 += d * d;
    }
    if ((i & 16383) == 16383) {
      a.add(s0 + s1);
      s0 = s1 = 0;
    }
  }
  a.add(s0 + s1);
  return a.value();
}

// Cuts taus into about 64 runs of similar work (work[j] terms each), so that
// a grid of every m does not pay one thread hand-off per tau.
std::vector<size_t> work_runs(const std::vector<R_xlen_t>& work) {
  double total = 0;
  for (R_xlen_t w : work) total += static_cast<double>(w) + 64;
  std::vector<size_t> cut(1, 0);
  double acc = 0;
  for (size_t j = 0; j < work.size(); ++j) {
    acc += static_cast<double>(work[j]) + 64;
    if (acc >= total / 64 || j + 1 == work.size()) {
      cut.push_back(j + 1);
      acc = 0;
    }
  }
  return cut;
}

// Stride-m estimators (standard, Hadamard).
template <int D>
void strided(const Split& X, const std::vector<R_xlen_t>& ms,
             const std::vector<R_xlen_t>& nterms, int threads, bool main,
             double* out) {
  const std::vector<size_t> cut = work_runs(nterms);
  run_items(static_cast<R_xlen_t>(cut.size() - 1), threads, main,
            [&](R_xlen_t r) {
              for (size_t j = cut[r]; j < cut[r + 1]; ++j) {
                if (allanvar::interrupted()) return;
                out[j] = X.with_lo([&](const auto* l) {
                  return strided_sum<D>(X.hi.data(), l, X.q, ms[j], nterms[j]);
                });
              }
            });
}

// Total variance (NIST SP 1065 eq. 25): second differences centred on
// i = 1 .. L-2 of the phase extended by point reflection at both ends,
// x*(-j) = 2x(0) - x(j), x*(L-1+j) = 2x(L-1) - x(L-1-j). The centres
// i in [m, L-1-m] reflect nothing: they are the overlapping estimator's
// terms, summed by its cache-blocked kernel; only the (at most 2m) centres
// near the ends are evaluated here.
void total(const Split& X, const std::vector<R_xlen_t>& ms, int threads,
           bool main, double* out) {
  const R_xlen_t L = static_cast<R_xlen_t>(X.hi.size());
  const double* h = X.hi.data();
  const double q = X.q;
  const size_t nt = ms.size();
  std::vector<R_xlen_t> inner(nt, 0);
  for (size_t j = 0; j < nt; ++j) inner[j] = std::max<R_xlen_t>(0, L - 2 * ms[j]);
  overlapped<2>(X, ms, inner, threads, main, out);
  if (allanvar::interrupt_state().stop.load()) return;
  std::vector<double> edge(nt, 0.0);
  // lo's type fixed outside the loops (a branch a point cost a third of the
  // end terms)
  X.with_lo([&](const auto* lp) {
    auto l = [lp](R_xlen_t i) { return static_cast<double>(lp[i]); };
    run_items(static_cast<R_xlen_t>(nt), threads, main, [&](R_xlen_t j) {
      if (allanvar::interrupted()) return;
      const R_xlen_t m = ms[j];
      // one term has at most 5 points, total weight 8: exact on the hi grid
      auto term = [&](R_xlen_t i) {
        double dh = -2.0 * h[i], dl = -2.0 * l(i);
        const R_xlen_t a0 = i - m;
        if (a0 >= 0) {
          dh += h[a0];
          dl += l(a0);
        } else {
          dh += 2.0 * h[0] - h[-a0];
          dl += 2.0 * l(0) - l(-a0);
        }
        const R_xlen_t a1 = i + m;
        if (a1 <= L - 1) {
          dh += h[a1];
          dl += l(a1);
        } else {
          const R_xlen_t r = 2 * (L - 1) - a1;
          dh += 2.0 * h[L - 1] - h[r];
          dl += 2.0 * l(L - 1) - l(r);
        }
        return dh + q * dl;
      };
      // the centres outside [m, L-1-m]
      R_xlen_t r0[2] = {1, std::max(m, L - m)};
      R_xlen_t r1[2] = {std::min(m - 1, L - 2), L - 2};
      if (inner[j] == 0) {
        r1[0] = L - 2;
        r1[1] = -1;
      }
      Acc a;
      double s = 0;
      R_xlen_t cnt = 0;
      for (int z = 0; z < 2; ++z) {
        for (R_xlen_t i = r0[z]; i <= r1[z]; ++i) {
          const double d = term(i);
          s += d * d;
          if (++cnt == kBlock) {
            a.add(s);
            s = 0;
            cnt = 0;
            if (allanvar::interrupted()) return;
          }
        }
      }
      a.add(s);
      edge[j] = a.value();
    });
    return 0;
  });
  for (size_t j = 0; j < nt; ++j) {
    Acc a;
    a.add(out[j]);
    a.add(edge[j]);
    out[j] = a.value();
  }
}

// Highest difference order whose squares the octave pass sums for the ACF
// (dmax + 1: Hadamard types difference up to three times).
const int kMaxOrder = 4;

// Non-overlapping AV at m = 2^j straight from the rate samples: cluster sums
// are built pairwise in double-double, level by level, inside cache-sized
// blocks, so the data are read once. `lev` carries, per level, the last
// cluster sum and the running sum of squared differences.
struct Level {
  double ph = 0, pl = 0;  // the last cluster sum
  double fh = 0, fl = 0;  // the first one
  bool has = false;
  Acc acc;
  double s = 0;
  R_xlen_t cnt = 0;
  bool keep = false;     // keep every cluster sum (a noise id is asked here)
  // the cluster sums, for noise id: zn of them written at z, which points
  // into `store` of the joined level (a part writes at its own offset, so
  // the halves need no joining copy; uninitialised, huge pages: zero fills,
  // growth copies and page faults of vectors took most of an octave call
  // at 1e7)
  double* z = nullptr;
  R_xlen_t zn = 0;
  allanvar::Scratch store;
  // the lag-1 ACF's line (noise_id.h, acf_line_from()) read in the same
  // pass, so the ACF needs one more pass, not three: s0 = sum z and
  // sp = sum (i - cc) z over this level's values (centred cluster sums),
  // i counted over the whole level from i0, cc its centre; `keep` levels
  // are stored in that loop, so they need `line` too
  bool line = false;
  double s0 = 0, sp = 0, i0 = 0, cc = 0;
  // Hadamard at m = 2^j (had): squared second differences of the cluster
  // sums, each difference of dd values through TwoSum (as exact as the
  // first differences above), in hacc.
  bool had = false;
  Acc hacc;
  // The lag-1 ACF from moments read in this pass (acf_from_moments()):
  // K > 0 sums q[k] of squared k-th differences, k = 0, 2 .. K (plain
  // double; k = 1 is acc), over the values z = h + l.
  int K = 0;
  double q[kMaxOrder + 1] = {0, 0, 0, 0, 0};
  // the first and last kMaxOrder values (dd), nv of them seen
  double fh2[kMaxOrder] = {0, 0, 0, 0}, fl2[kMaxOrder] = {0, 0, 0, 0};
  double lh2[kMaxOrder] = {0, 0, 0, 0}, ll2[kMaxOrder] = {0, 0, 0, 0};
  R_xlen_t nv = 0;
};

// Consume n dd values at level j: accumulate squared differences, keep the
// cluster sums for noise id when asked, and pair them into level j+1 in
// place.
// A level's value at k, and the difference of its values at a and b: hi +
// lo, or (Exact = false) h alone.
template <bool Exact>
inline double level_at(const double* h, const double* l, R_xlen_t k) {
  return Exact ? h[k] + l[k] : h[k];
}
template <bool Exact>
inline double level_diff(const double* h, const double* l, R_xlen_t a,
                         R_xlen_t b) {
  return Exact ? (h[a] - h[b]) + (l[a] - l[b]) : h[a] - h[b];
}

// Exact = false (noise id alone): plain double sums in h, l unused; their
// rounding (1e-16 of a sum) is far below what a noise type can feel.
// Second difference c - 2 b + a of dd values: each first difference by
// TwoSum, so drift that the difference cancels leaves no rounding behind.
// T: double or (GCC/Clang) a vector of two.
template <bool Exact, class T>
inline T second_diff(T ah, T al, T bh, T bl, T ch, T cl) {
  if (!Exact) return (ch - bh) - (bh - ah);
  const T t1 = ch - bh, c1 = t1 - ch, e1 = (ch - (t1 - c1)) - (bh + c1);
  const T t0 = bh - ah, c0 = t0 - bh, e0 = (bh - (t0 - c0)) - (ah + c0);
  return ((t1 - t0) + (e1 - e0)) + ((cl - bl) - (bl - al));
}

#if defined(ALLANVAR_AVX2)
// level_extra()'s Hadamard terms at [i, i + 4 k) in AVX2: the lanes and
// additions of its SSE2 loop (two vectors of two there), the same bits.
template <bool Exact>
__attribute__((target("avx2"))) double had_avx2(const double* h,
                                                const double* l, R_xlen_t& i,
                                                R_xlen_t n) {
  v4d a = {0, 0, 0, 0};
  const v4d zero = {0, 0, 0, 0};
  for (; i + 4 <= n; i += 4) {
    const v4d ah = ld4(h + i - 2), bh = ld4(h + i - 1), ch = ld4(h + i);
    v4d d;
    if (Exact) {
      const v4d al = ld4(l + i - 2), bl = ld4(l + i - 1), cl = ld4(l + i);
      const v4d t1 = ch - bh, c1 = t1 - ch, e1 = (ch - (t1 - c1)) - (bh + c1);
      const v4d t0 = bh - ah, c0 = t0 - bh, e0 = (bh - (t0 - c0)) - (ah + c0);
      d = ((t1 - t0) + (e1 - e0)) + ((cl - bl) - (bl - al));
    } else {
      d = ((ch - bh) - (bh - ah)) + zero;
    }
    a += d * d;
  }
  return (a[0] + a[2]) + (a[1] + a[3]);
}
#endif

// The k-th difference (k < kMaxOrder) at the end of the last values of L.
inline double last_diff(const Level& L, int k) {
  double t[kMaxOrder];
  for (int i = 0; i <= k; ++i) {
    t[i] = L.lh2[kMaxOrder - 1 - k + i] + L.ll2[kMaxOrder - 1 - k + i];
  }
  for (int o = 1; o <= k; ++o)
    for (int i = 0; i + o <= k; ++i) t[i] = t[i + 1] - t[i];
  return t[0];
}

// level_extra()'s moments and level_step()'s two loops four values a
// vector, the same operations in every lane: AVX2 where the CPU has it,
// else the same vectors in SSE2 halves (the same bits). Scalar (or two a
// vector) they bounded the standard octave pass.
#if defined(__GNUC__)
#define ALLANVAR_LEVEL_VEC 1
typedef double vd4 __attribute__((vector_size(32)));
// the even and odd lanes of two vectors (Clang spells GCC's shuffle its
// own way; macros, since a vector argument's ABI differs between SSE2 and AVX)
#if defined(__clang__)
#define ALLANVAR_EVEN(x, y) __builtin_shufflevector(x, y, 0, 2, 4, 6)
#define ALLANVAR_ODD(x, y) __builtin_shufflevector(x, y, 1, 3, 5, 7)
#else
typedef long long vi4 __attribute__((vector_size(32)));
#define ALLANVAR_EVEN(x, y) __builtin_shuffle(x, y, vi4{0, 2, 4, 6})
#define ALLANVAR_ODD(x, y) __builtin_shuffle(x, y, vi4{1, 3, 5, 7})
#endif
// (no vector passed by value: the ABI of a vector argument differs
// between SSE2 and AVX)
typedef double vd4u __attribute__((vector_size(32), aligned(8), may_alias));
inline const vd4u& ldv4(const double* p) {
  return *reinterpret_cast<const vd4u*>(p);
}
inline void stv4(double* p, const vd4& v) { std::memcpy(p, &v, sizeof v); }

// Squared first differences at [i, n) (i >= 1), eight a step in two
// accumulators (lanes k mod 8); i is advanced past them.
template <bool Exact>
__attribute__((always_inline)) inline double diffsq8_body(const double* h,
                                                          const double* l,
                                                          R_xlen_t& i,
                                                          R_xlen_t n) {
  vd4 a0 = {0, 0, 0, 0}, a1 = {0, 0, 0, 0};
  for (; i + 8 <= n; i += 8) {
    vd4 d0 = ldv4(h + i) - ldv4(h + i - 1);
    vd4 d1 = ldv4(h + i + 4) - ldv4(h + i + 3);
    if (Exact) {
      d0 += ldv4(l + i) - ldv4(l + i - 1);
      d1 += ldv4(l + i + 4) - ldv4(l + i + 3);
    }
    a0 += d0 * d0;
    a1 += d1 * d1;
  }
  return ((a0[0] + a1[0]) + (a0[2] + a1[2])) +
         ((a0[1] + a1[1]) + (a0[3] + a1[3]));
}

// Pairs 2k, 2k + 1 into k for k in [0, n2), four a step, in place (each
// step reads its eight values before it writes four below them): TwoSum
// of the hi parts, the lo parts added to its error, FastTwoSum back (Exact),
// or the plain sum of h. Returns the first k not done.
template <bool Exact>
__attribute__((always_inline)) inline R_xlen_t pair4_body(double* h, double* l,
                                                          R_xlen_t n2) {
  R_xlen_t k = 0;
  for (; k + 4 <= n2; k += 4) {
    const vd4 hA = ldv4(h + 2 * k), hB = ldv4(h + 2 * k + 4);
    const vd4 a = ALLANVAR_EVEN(hA, hB);
    const vd4 b = ALLANVAR_ODD(hA, hB);
    if (!Exact) {
      stv4(h + k, a + b);
      continue;
    }
    const vd4 lA = ldv4(l + 2 * k), lB = ldv4(l + 2 * k + 4);
    const vd4 t = a + b, bb = t - a;
    vd4 e = (a - (t - bb)) + (b - bb);
    e += ALLANVAR_EVEN(lA, lB) + ALLANVAR_ODD(lA, lB);
    const vd4 hs = t + e;
    stv4(h + k, hs);
    stv4(l + k, e - (hs - t));
  }
  return k;
}

// level_extra()'s moments of the values at [i, n) (i >= 4): sums of z,
// (t + k) z, z^2 and the squared 2nd, 3rd (and with K4 4th) differences,
// four values a vector (lanes k mod 4); i is advanced past them.
template <bool K4>
__attribute__((always_inline)) inline void moments4_body(const double* h,
                                                         R_xlen_t& i,
                                                         R_xlen_t n, double t,
                                                         double* out) {
  const vd4 zero = {0, 0, 0, 0};
  vd4 a0 = zero, pp = zero, s2 = zero, a2 = zero, a3 = zero, a4 = zero;
  vd4 tv = {t, t + 1, t + 2, t + 3};
  for (; i + 4 <= n; i += 4) {
    const vd4 z0 = ldv4(h + i), z1 = ldv4(h + i - 1), z2 = ldv4(h + i - 2),
              z3 = ldv4(h + i - 3);
    const vd4 d2 = (z0 + z2) - 2.0 * z1;
    const vd4 d3 = (z0 - z3) + 3.0 * (z2 - z1);
    a0 += z0;
    pp += tv * z0;
    tv += 4.0;
    s2 += z0 * z0;
    a2 += d2 * d2;
    a3 += d3 * d3;
    if (K4) {
      const vd4 d4 = ((z0 + ldv4(h + i - 4)) + 6.0 * z2) - 4.0 * (z1 + z3);
      a4 += d4 * d4;
    }
  }
  const vd4* v[6] = {&s2, &a0, &pp, &a2, &a3, &a4};
  for (int u = 0; u < 6; ++u) {
    out[u] = ((*v[u])[0] + (*v[u])[2]) + ((*v[u])[1] + (*v[u])[3]);
  }
}

#if defined(ALLANVAR_AVX2)
template <bool Exact>
__attribute__((target("avx2"))) double diffsq8_avx2(const double* h,
                                                    const double* l,
                                                    R_xlen_t& i, R_xlen_t n) {
  return diffsq8_body<Exact>(h, l, i, n);
}
template <bool K4>
__attribute__((target("avx2"))) void moments4_avx2(const double* h,
                                                   R_xlen_t& i, R_xlen_t n,
                                                   double t, double* out) {
  moments4_body<K4>(h, i, n, t, out);
}
template <bool Exact>
__attribute__((target("avx2"))) R_xlen_t pair4_avx2(double* h, double* l,
                                                    R_xlen_t n2) {
  return pair4_body<Exact>(h, l, n2);
}
#endif

template <bool Exact>
inline double diffsq8(const double* h, const double* l, R_xlen_t& i,
                      R_xlen_t n) {
#if defined(ALLANVAR_AVX2)
  if (have_avx2()) return diffsq8_avx2<Exact>(h, l, i, n);
#endif
  return diffsq8_body<Exact>(h, l, i, n);
}
// out: z^2, z, (t + k) z, squared 2nd, 3rd, 4th differences (0 without K4)
inline void moments4(const double* h, R_xlen_t& i, R_xlen_t n, double t,
                     bool k4, double* out) {
#if defined(ALLANVAR_AVX2)
  if (have_avx2()) {
    if (k4) {
      moments4_avx2<true>(h, i, n, t, out);
    } else {
      moments4_avx2<false>(h, i, n, t, out);
    }
    return;
  }
#endif
  if (k4) {
    moments4_body<true>(h, i, n, t, out);
  } else {
    moments4_body<false>(h, i, n, t, out);
  }
}
template <bool Exact>
inline R_xlen_t pair4(double* h, double* l, R_xlen_t n2) {
#if defined(ALLANVAR_AVX2)
  if (have_avx2()) return pair4_avx2<Exact>(h, l, n2);
#endif
  return pair4_body<Exact>(h, l, n2);
}
#endif

// The Hadamard sum and the moments of the values [0, n) of a level, with
// the last values of earlier calls carried in L; called before the values
// are paired. The terms reaching back into earlier calls are summed one by
// one, the others from this call's values in vectors.
template <bool Exact>
inline void level_extra(const double* h, const double* l, R_xlen_t n,
                        Level& L) {
  if (n <= 0) return;
  const R_xlen_t nv = L.nv;
  auto H = [h](R_xlen_t i) { return h[i]; };
  auto Lo = [l](R_xlen_t i) { return Exact ? l[i] : 0.0; };
  if (L.had) {
    double s0 = 0, s1 = 0;
    const double* lh = L.lh2 + kMaxOrder - 2;
    const double* ll = L.ll2 + kMaxOrder - 2;
    if (nv >= 2) {
      const double d = second_diff<Exact>(lh[0], ll[0], lh[1], ll[1], H(0), Lo(0));
      s0 += d * d;
    }
    if (nv >= 1 && n >= 2) {
      const double d = second_diff<Exact>(lh[1], ll[1], H(0), Lo(0), H(1), Lo(1));
      s0 += d * d;
    }
    R_xlen_t i = 2;
#if defined(ALLANVAR_AVX2)
    if (have_avx2()) {
      s1 = had_avx2<Exact>(h, l, i, n);
    } else
#endif
#if defined(__GNUC__)
    {
    v2d a0 = {0, 0}, a1 = {0, 0};
    const v2d zero = {0, 0};
    auto Lv = [l, zero](R_xlen_t k) { return Exact ? ld2(l + k) : zero; };
    for (; i + 4 <= n; i += 4) {
      const v2d d0 = second_diff<Exact>(ld2(h + i - 2), Lv(i - 2), ld2(h + i - 1),
                                        Lv(i - 1), ld2(h + i), Lv(i));
      const v2d d1 = second_diff<Exact>(ld2(h + i), Lv(i), ld2(h + i + 1),
                                        Lv(i + 1), ld2(h + i + 2), Lv(i + 2));
      a0 += d0 * d0;
      a1 += d1 * d1;
    }
    s1 = (a0[0] + a1[0]) + (a0[1] + a1[1]);
    }
#endif
    for (; i < n; ++i) {
      const double d = second_diff<Exact>(H(i - 2), Lo(i - 2), H(i - 1),
                                          Lo(i - 1), H(i), Lo(i));
      s0 += d * d;
    }
    L.hacc.add(s0 + s1);
  }
  if (L.K > 0) {
    // h alone: l is below an ulp of h, far below what a noise type feels;
    // the line's sums s0, sp (acf_line_from()) are read here too
    double q0 = 0, q2 = 0, q3 = 0, q4 = 0, a = 0, p = 0;
    const double t0 = L.i0 - L.cc;
    // the first values of this call: differences reaching back
    double p0 = 0, p1 = 0, p2 = 0, p3 = 0;
    if (nv >= 1) p0 = last_diff(L, 0);
    if (nv >= 2) p1 = last_diff(L, 1);
    if (nv >= 3) p2 = last_diff(L, 2);
    if (nv >= 4) p3 = last_diff(L, 3);
    const bool k4 = L.K >= 4;
    R_xlen_t i = 0;
    for (; i < n && i < kMaxOrder; ++i) {
      const double z = h[i];
      a += z;
      p += (t0 + static_cast<double>(i)) * z;
      q0 += z * z;
      const R_xlen_t c = nv + i;
      const double d1 = c >= 1 ? z - p0 : 0;
      const double d2 = c >= 2 ? d1 - p1 : 0;
      const double d3 = c >= 3 ? d2 - p2 : 0;
      const double d4 = c >= 4 ? d3 - p3 : 0;
      q2 += d2 * d2;
      q3 += d3 * d3;
      if (k4) q4 += d4 * d4;
      p0 = z;
      p1 = d1;
      p2 = d2;
      p3 = d3;
    }
    // the rest from this call's values alone
#if defined(ALLANVAR_LEVEL_VEC)
    if (i >= 4) {
      double mo[6];
      moments4(h, i, n, t0 + static_cast<double>(i), k4, mo);
      q0 += mo[0];
      a += mo[1];
      p += mo[2];
      q2 += mo[3];
      q3 += mo[4];
      q4 += mo[5];
    }
#endif
    for (; i < n; ++i) {
      const double z0 = h[i], z1 = h[i - 1], z2 = h[i - 2], z3 = h[i - 3];
      const double d2 = (z0 + z2) - 2.0 * z1;
      const double d3 = (z0 - z3) + 3.0 * (z2 - z1);
      a += z0;
      p += (t0 + static_cast<double>(i)) * z0;
      q0 += z0 * z0;
      q2 += d2 * d2;
      q3 += d3 * d3;
      if (k4) {
        const double d4 = ((z0 + h[i - 4]) + 6.0 * z2) - 4.0 * (z1 + z3);
        q4 += d4 * d4;
      }
    }
    L.s0 += a;
    L.sp += p;
    L.q[0] += q0;
    L.q[2] += q2;
    L.q[3] += q3;
    L.q[4] += q4;
  }
  // the first and last kMaxOrder values
  for (R_xlen_t i = 0; i < n && nv + i < kMaxOrder; ++i) {
    L.fh2[nv + i] = h[i];
    L.fl2[nv + i] = Exact ? l[i] : 0.0;
  }
  const R_xlen_t keep_old = n >= kMaxOrder ? 0 : kMaxOrder - n;
  for (R_xlen_t k = 0; k < keep_old; ++k) {
    L.lh2[k] = L.lh2[k + n];
    L.ll2[k] = L.ll2[k + n];
  }
  for (R_xlen_t k = keep_old; k < kMaxOrder; ++k) {
    const R_xlen_t i = n - (kMaxOrder - k);
    L.lh2[k] = h[i];
    L.ll2[k] = Exact ? l[i] : 0.0;
  }
  L.nv += n;
}

template <bool Exact>
inline R_xlen_t level_step(double* h, double* l, R_xlen_t n, Level& L,
                           bool pair) {
  level_extra<Exact>(h, l, n, L);
  double s = 0, s1 = 0;  // two chains: the add latency bounds one
  if (n > 0) {
    if (!L.has) {
      L.fh = h[0];
      L.fl = l[0];
      L.has = true;
    } else {
      const double d = Exact ? (h[0] - L.ph) + (l[0] - L.pl) : h[0] - L.ph;
      s = d * d;
    }
    R_xlen_t i = 1;
#if defined(ALLANVAR_LEVEL_VEC)
    s1 = diffsq8<Exact>(h, l, i, n);
#endif
    for (; i + 2 <= n; i += 2) {
      const double d0 = level_diff<Exact>(h, l, i, i - 1);
      const double d1 = level_diff<Exact>(h, l, i + 1, i);
      s += d0 * d0;
      s1 += d1 * d1;
    }
    if (i < n) {
      const double d = level_diff<Exact>(h, l, i, i - 1);
      s += d * d;
    }
    L.ph = h[n - 1];
    L.pl = Exact ? l[n - 1] : 0.0;
  }
  L.acc.add(s + s1);
  if (L.line && L.K > 0 && !L.keep) {
    L.i0 += static_cast<double>(n);  // s0 and sp read by level_extra()
  } else if (L.line) {
    double* z = L.z + L.zn;
    const double t = L.i0 - L.cc;
    double a0 = 0, a1 = 0, q0 = 0, q1 = 0;
    R_xlen_t k = 0;
    for (; k + 2 <= n; k += 2) {
      const double z0 = level_at<Exact>(h, l, k);
      const double z1 = level_at<Exact>(h, l, k + 1);
      if (L.keep) {
        z[k] = z0;
        z[k + 1] = z1;
      }
      const double tk = t + static_cast<double>(k);
      a0 += z0;
      a1 += z1;
      q0 += tk * z0;
      q1 += (tk + 1) * z1;
    }
    if (k < n) {
      const double z0 = level_at<Exact>(h, l, k);
      if (L.keep) z[k] = z0;
      a0 += z0;
      q0 += (t + static_cast<double>(k)) * z0;
    }
    L.s0 += a0 + a1;
    L.sp += q0 + q1;
    L.i0 += static_cast<double>(n);
    if (L.keep) L.zn += n;
  }
  if (!pair) return 0;
  const R_xlen_t n2 = n / 2;
  R_xlen_t k0 = 0;
#if defined(ALLANVAR_LEVEL_VEC)
  k0 = pair4<Exact>(h, l, n2);
#endif
  if (!Exact) {
    for (R_xlen_t k = k0; k < n2; ++k) h[k] = h[2 * k] + h[2 * k + 1];
    return n2;
  }
  for (R_xlen_t k = k0; k < n2; ++k) {
    double t, e;
    two_sum(h[2 * k], h[2 * k + 1], t, e);
    e += l[2 * k] + l[2 * k + 1];
    fast_two_sum(t, e, h[k], l[k]);
  }
  return n2;
}

// Levels 0..jin of the samples [s0, s1) (s0 a multiple of the block), and
// the level-b sums of its full blocks appended to th/tl.
// Also the range of the samples when `range` is given (NaN left out; the
// sums carry it), which spares the other kernels their own pass.
template <bool Exact>
void octave_part(const double* y, R_xlen_t s0, R_xlen_t s1, double c, int J,
                 int jin, int b, std::vector<Level>& lev,
                 std::vector<double>& th, std::vector<double>& tl,
                 double* range, std::vector<double>* tr) {
  const R_xlen_t B = static_cast<R_xlen_t>(1) << b;
  std::vector<double> h(B), l(B);
  double lo = y[s0], hi = y[s0];
  for (R_xlen_t k0 = s0; k0 < s1; k0 += B) {
    if (((k0 / B) & 511) == 511 && allanvar::interrupted()) return;
    const R_xlen_t n = std::min(B, s1 - k0);
    if (range) {  // a separate loop: the plain one vectorises
      for (R_xlen_t i = 0; i < n; ++i) {
        const double yi = y[k0 + i];
        if (Exact) {
          two_sum(yi, -c, h[i], l[i]);
        } else {
          h[i] = yi - c;
        }
        lo = yi < lo ? yi : lo;
        hi = yi > hi ? yi : hi;
      }
      range[0] = lo;
      range[1] = hi;
    } else if (Exact) {
      for (R_xlen_t i = 0; i < n; ++i) two_sum(y[k0 + i], -c, h[i], l[i]);
    } else {
      for (R_xlen_t i = 0; i < n; ++i) h[i] = y[k0 + i] - c;
    }
    // R(n)'s block sums (RnCache::build_from_blocks()): sum (B-1-i) z_i
    double ramp = 0;
    if (tr && n == B) {
      double r[4] = {0, 0, 0, 0};
      for (R_xlen_t i = 0; i < n; i += 4) {
        const double w = static_cast<double>(B - 1 - i);
        r[0] += w * level_at<Exact>(h.data(), l.data(), i);
        r[1] += (w - 1) * level_at<Exact>(h.data(), l.data(), i + 1);
        r[2] += (w - 2) * level_at<Exact>(h.data(), l.data(), i + 2);
        r[3] += (w - 3) * level_at<Exact>(h.data(), l.data(), i + 3);
      }
      ramp = (r[0] + r[1]) + (r[2] + r[3]);
    }
    R_xlen_t cur = n;
    for (int j = 0; j <= jin; ++j)
      cur = level_step<Exact>(h.data(), l.data(), cur, lev[j], j < J);
    if (J >= b && cur == 1) {
      if (tr) tr->push_back(ramp);
      th.push_back(h[0]);
      tl.push_back(Exact ? l[0] : 0.0);
    }
  }
}

// The k-th difference of w at s (k <= kMaxOrder).
inline double diff_k(const double* w, int s, int k) {
  double t[kMaxOrder + 1];
  for (int i = 0; i <= k; ++i) t[i] = w[s + i];
  for (int o = 1; o <= k; ++o)
    for (int i = 0; i + o <= k; ++i) t[i] = t[i + 1] - t[i];
  return t[0];
}

// Joins level_extra()'s sums of the right part R into those of the left
// part L: the terms that straddle the cut, from L's last and R's first
// values.
void join_extra(Level& L, const Level& R, bool exact) {
  if (R.nv == 0) return;
  const int nl = static_cast<int>(std::min<R_xlen_t>(L.nv, kMaxOrder));
  const int nr = static_cast<int>(std::min<R_xlen_t>(R.nv, kMaxOrder));
  double wh[2 * kMaxOrder], wl[2 * kMaxOrder], wz[2 * kMaxOrder];
  for (int i = 0; i < nl; ++i) {
    wh[i] = L.lh2[kMaxOrder - nl + i];
    wl[i] = L.ll2[kMaxOrder - nl + i];
  }
  for (int i = 0; i < nr; ++i) {
    wh[nl + i] = R.fh2[i];
    wl[nl + i] = R.fl2[i];
  }
  const int nw = nl + nr;
  for (int i = 0; i < nw; ++i) wz[i] = wh[i] + wl[i];
  if (L.had) {
    double s = 0;
    for (int a = std::max(0, nl - 2); a < nl && a + 2 < nw; ++a) {
      const double d =
          exact ? second_diff<true>(wh[a], wl[a], wh[a + 1], wl[a + 1],
                                    wh[a + 2], wl[a + 2])
                : second_diff<false>(wh[a], 0.0, wh[a + 1], 0.0, wh[a + 2], 0.0);
      s += d * d;
    }
    L.hacc.add(s);
    L.hacc.add(R.hacc.value());
  }
  if (L.K > 0) {
    L.q[0] += R.q[0];
    for (int k = 2; k <= L.K; ++k) {
      double s = 0;
      for (int a = std::max(0, nl - k); a < nl && a + k < nw; ++a) {
        const double d = diff_k(wz, a, k);
        s += d * d;
      }
      L.q[k] += s + R.q[k];
    }
  }
  // first values: L's, completed by R's; last values: R's, preceded by L's
  for (int i = nl; i < kMaxOrder && i < nw; ++i) {
    L.fh2[i] = wh[i];
    L.fl2[i] = wl[i];
  }
  for (int k = 0; k < kMaxOrder; ++k) {
    if (R.nv >= kMaxOrder) {
      L.lh2[k] = R.lh2[k];
      L.ll2[k] = R.ll2[k];
      continue;
    }
    const int i = nw - kMaxOrder + k;  // R's few values are its first ones
    if (i < 0) continue;
    L.lh2[k] = wh[i];
    L.ll2[k] = wl[i];
  }
  L.nv += R.nv;
}

// Per block of B samples: its sum of v - c and sum (B-1-i)(v_i - c).
struct RnBlocks {
  R_xlen_t B = 0;
  std::vector<double> sum, ramp;
};

// Non-overlapping AV at m = 2^j, j = 0..J: the record is cut in two halves
// at a block boundary (one per thread), whose per-level sums are then
// joined with the one difference that straddles the cut.
// exact = false: noise id alone (no sums reported; plain double cluster
// sums, about a third of the work).
// had: the Hadamard sums too (hacc); K: the ACF's moments at the `line`
// levels (level_extra()); rnb: R(n)'s sums per block of 2^b samples (J >= b).
void standard_octave(const double* y, R_xlen_t N, double c, int J,
                     const std::vector<bool>& keep,
                     const std::vector<bool>& line, std::vector<Level>& lev,
                     double* range, bool exact, bool had, int K,
                     RnBlocks* rnb, int threads, bool main) {
  const int b = 11;
  const R_xlen_t B = static_cast<R_xlen_t>(1) << b;
  const int jin = std::min(J, b - 1);  // levels handled inside blocks
  const R_xlen_t nblocks = (N + B - 1) / B;
  const int P = (threads > 1 && nblocks >= 8) ? 2 : 1;
  const R_xlen_t cut[3] = {0, P == 2 ? (nblocks / 2) * B : N, N};
  // each kept level's sums in one array, floor(N / 2^j) of them, owned by
  // part 0's level; part p writes from (its first sample) / 2^j, a whole
  // number (cut at a block)
  std::vector<std::vector<Level> > part(P);
  for (int p = 0; p < P; ++p) part[p].resize(jin + 1);
  // level j holds floor(N / 2^j) values (blocks are powers of two)
  auto set_line = [N](Level& L, int j, R_xlen_t first) {
    L.line = true;
    L.i0 = static_cast<double>(first >> j);
    L.cc = (static_cast<double>(N >> j) - 1) / 2;
  };
  for (int j = 0; j <= jin; ++j) {
    for (int p = 0; p < P; ++p) {
      part[p][j].had = had;
      part[p][j].K = line[j] ? K : 0;
    }
    if (line[j] || keep[j]) {  // level_step() stores in the line's loop
      for (int p = 0; p < P; ++p) set_line(part[p][j], j, cut[p]);
    }
    if (!keep[j]) continue;
    part[0][j].store.resize(static_cast<size_t>(N >> j));
    for (int p = 0; p < P; ++p) {
      part[p][j].keep = true;
      part[p][j].z = part[0][j].store.data() + (cut[p] >> j);
    }
  }
  std::vector<std::vector<double> > th(P), tl(P), tr(P);
  double pr[2][2] = {{y[0], y[0]}, {y[0], y[0]}};
  run_items(P, threads, main, [&](R_xlen_t p) {
    double* rp = range ? pr[p] : nullptr;
    if (exact) {
      octave_part<true>(y, cut[p], cut[p + 1], c, J, jin, b, part[p], th[p],
                        tl[p], rp, rnb ? &tr[p] : nullptr);
    } else {
      octave_part<false>(y, cut[p], cut[p + 1], c, J, jin, b, part[p], th[p],
                         tl[p], rp, rnb ? &tr[p] : nullptr);
    }
  });
  if (range) {
    range[0] = std::min(pr[0][0], pr[P - 1][0]);
    range[1] = std::max(pr[0][1], pr[P - 1][1]);
  }
  lev.clear();
  lev.resize(J + 1);
  for (int j = 0; j <= J; ++j) lev[j].keep = keep[j];
  for (int j = 0; j <= jin; ++j) {
    Level& L = lev[j];
    L = std::move(part[0][j]);  // z stays valid: the store moves with it
    if (P == 2) {
      const Level& R = part[1][j];
      join_extra(L, R, exact);
      L.acc.add(R.acc.value());
      if (L.has && R.has) {
        const double d = (R.fh - L.ph) + (R.fl - L.pl);
        L.acc.add(d * d);
      }
      L.zn += R.zn;
      L.s0 += R.s0;
      L.sp += R.sp;
      if (R.has) {
        L.ph = R.ph;
        L.pl = R.pl;
        L.has = true;
      }
    }
  }
  if (J >= b) {
    std::vector<double> h(th[0]), l(tl[0]);
    if (P == 2) {
      h.insert(h.end(), th[1].begin(), th[1].end());
      l.insert(l.end(), tl[1].begin(), tl[1].end());
    }
    if (rnb) {
      rnb->B = B;
      rnb->ramp = tr[0];
      if (P == 2) rnb->ramp.insert(rnb->ramp.end(), tr[1].begin(), tr[1].end());
      rnb->sum.resize(h.size());
      for (size_t k = 0; k < h.size(); ++k) rnb->sum[k] = h[k] + l[k];
    }
    R_xlen_t cur = static_cast<R_xlen_t>(h.size());
    for (int j = b; j <= J; ++j) {
      if (lev[j].keep) {
        lev[j].store.resize(static_cast<size_t>(cur));
        lev[j].z = lev[j].store.data();
      }
      if (line[j] || lev[j].keep) set_line(lev[j], j, 0);
      lev[j].had = had;
      lev[j].K = line[j] ? K : 0;
      cur = exact ? level_step<true>(h.data(), l.data(), cur, lev[j], j < J)
                  : level_step<false>(h.data(), l.data(), cur, lev[j], j < J);
    }
  }
}

// ---- noise identification (src/noise_id.h) at the rows `mid` ----

struct Channel {
  double* sums = nullptr;  // nt values: the result matrix's column
  std::vector<double> alpha;
  std::vector<int> alpha_int, id_method;
  R_xlen_t bad = 0;  // 1-based position of the first NA/NaN/Inf, or 0
  // min and max of the samples where the sums' kernel read them, else NaN
  double range[2] = {std::nan(""), std::nan("")};
};

inline void store_id(const allanvar::NoiseId& id, Channel& out, size_t j) {
  out.alpha[j] = id.alpha;
  out.alpha_int[j] = id.alpha_int;
  out.id_method[j] = id.method;
}

// Noise id of the standard octave kernel: from the cluster sums it kept
// (level 0: the samples themselves); R(n) from the running sum of v - c.
void octave_noise_id(const double* v, R_xlen_t N, double c,
                     const std::vector<Level>& lev,
                     const std::vector<R_xlen_t>& mid,
                     const std::vector<double>& mid_n, int dmax,
                     bool modified, const allanvar::NoiseIdRules& rules,
                     const RnBlocks& rnb, int threads, bool main,
                     Channel& out) {
  auto build = [&rnb, v, N, c](allanvar::RnCache& r) {
    if (!r.build_from_blocks(rnb.sum.data(), rnb.ramp.data(),
                             static_cast<R_xlen_t>(rnb.sum.size()), rnb.B, N))
      r.build_from_rate(v, N, c);
  };
  allanvar::LazyRn<decltype(build)> rn(build);
  // taus are independent: shared between the threads
  run_items(static_cast<R_xlen_t>(mid.size()), threads, main, [&](R_xlen_t j) {
    if (allanvar::interrupted()) return;
    const R_xlen_t m = mid[j];
    int lj = 0;
    while ((static_cast<R_xlen_t>(1) << lj) < m) ++lj;
    const R_xlen_t n = N >> lj;
    const double* z = lj == 0 ? v : lev[lj].z;
    allanvar::NoiseId id;
    if (n >= rules.acf_min) {
      // from the moments read in the octave pass (sums of v - c)
      const Level& L = lev[lj];
      allanvar::AcfMoments mo;
      mo.s0 = L.s0;
      mo.sp = L.sp;
      mo.q[0] = L.q[0];
      mo.q[1] = L.acc.value();
      for (int k = 2; k <= kMaxOrder; ++k) mo.q[k] = L.q[k];
      for (int k = 0; k < kMaxOrder; ++k) {
        mo.first[k] = L.fh2[k] + L.fl2[k];
        mo.last[k] = L.lh2[k] + L.ll2[k];
      }
      bool ok = false;
      if (L.K > dmax) id = allanvar::acf_noise_id_moments(mo, n, dmax, ok);
      if (!ok) {
        // a strong mean or line: the values read again (the line in the
        // pass: level 0's sums are of v - c)
        const allanvar::AcfLine ln =
            allanvar::acf_line_from(L.s0, L.sp, lj == 0 ? c : 0.0, n, false);
        if (lj == 0) {
          id = allanvar::acf_noise_id_line([v](R_xlen_t i) { return v[i]; },
                                           n, false, dmax, ln);
        } else {
          id = allanvar::acf_noise_id_line(
              [v, c, m](R_xlen_t i) {
                double a = 0;
                const double* p = v + i * m;
                for (R_xlen_t u = 0; u < m; ++u) a += p[u] - c;
                return a;
              },
              n, false, dmax, ln);
        }
      }
      allanvar::rn_refine_pm(id, m, rules, [&]() { return rn.ratio(m); });
    } else {
      id = allanvar::b1_noise_id(z, n, false, m, mid_n[j], modified, rules,
                                 [&]() { return rn.ratio(m); });
    }
    store_id(id, out, j);
  });
}

// One channel: sums of squares for every m, and the noise id per m.
void one_channel(const double* v, R_xlen_t N, const std::vector<R_xlen_t>& ms,
                 const std::vector<R_xlen_t>& nterms,
                 const std::vector<R_xlen_t>& mid, const AllanOptions& opts,
                 int threads, bool main, Channel& out) {
  const int type = opts.type;
  const bool rate = opts.rate, octave = opts.octave;
  const size_t nt = ms.size(), ni = mid.size();
  std::fill(out.sums, out.sums + nt, 0.0);
  out.alpha.assign(ni, NA_REAL);
  out.alpha_int.assign(ni, NA_INTEGER);
  out.id_method.assign(ni, allanvar::NOISE_ID_NONE);
  const int dmax = allanvar::estimator_info(type).d;
  allanvar::NoiseIdRules rules;
  rules.acf_min = opts.acf_min;
  rules.b1_rw_own = opts.b1_rw_own;
  rules.rn_stable32 = opts.rn_stable32;
  rules.rn_check_wfm = opts.rn_check_wfm;
  // the statistic's number of terms at each noise-id row (B1's N)
  std::vector<double> mid_n(ni, 0.0);
  for (size_t j = 0; j < ni; ++j) {
    const auto it = std::lower_bound(ms.begin(), ms.end(), mid[j]);
    if (it != ms.end() && *it == mid[j]) {
      mid_n[j] = static_cast<double>(nterms[it - ms.begin()]);
    } else {
      for (size_t k = 0; k < nt; ++k) {
        if (ms[k] == mid[j]) mid_n[j] = static_cast<double>(nterms[k]);
      }
    }
  }
  // Noise id at octave m of frequency data, whatever the type, reads the
  // cluster sums of the standard octave kernel: one pass over the samples
  // (two threads) and one more per level for the ACF, where reading every
  // m-th point of the phase took three passes over it per m.
  bool octave_id = rate && ni > 0;
  for (R_xlen_t m : mid) {
    if (m < 1 || m > N || (m & (m - 1)) != 0) octave_id = false;
  }
  // the standard and Hadamard sums at m = 2^j from the octave pass
  const bool std_octave = (type == STANDARD || type == HADAMARD) && rate &&
                          octave;
  double range[2] = {v[0], v[0]};
  bool have_range = false;
  if (std_octave || octave_id) {
    // Any constant works as the centre here (constants cancel; the cluster
    // sums are double-double where the standard sums are reported); NaN or
    // Inf shows up in the sums.
    R_xlen_t top = 1;
    if (std_octave) for (R_xlen_t m : ms) top = std::max(top, m);
    for (R_xlen_t m : mid) top = std::max(top, m);
    int J = 0;
    while ((static_cast<R_xlen_t>(1) << (J + 1)) <= top) ++J;
    // ACF rows sum their line in the pass; every level but 0 (the samples)
    // and 1 (pairs of them, read from the samples again: a store of N/2
    // values, written, zeroed by the kernel and read, cost more) is stored.
    std::vector<bool> keep(J + 1, false), line(J + 1, false);
    for (R_xlen_t m : mid) {
      int lj = 0;
      while ((static_cast<R_xlen_t>(1) << lj) < m) ++lj;
      if (lj > J) continue;
      const bool acf = (N >> lj) >= rules.acf_min;
      line[lj] = acf;
      keep[lj] = lj >= 1 && !acf;  // B1 reads the few values
    }
    std::vector<Level> lev;
    // R(n)'s block sums where B1 may ask for it on a long record
    // (RnCache::build_from_blocks())
    bool b1 = false;
    for (R_xlen_t m : mid) b1 = b1 || (m > 1 && N / m < rules.acf_min);
    RnBlocks rnb;
    const bool want_rnb =
        b1 && J >= 11 && allanvar::RnCache::blocks_usable(2048, N);
    // the range only where the sums' kernel below needs it
    have_range = !std_octave && opts.sums;
    standard_octave(v, N, v[0], J, keep, line, lev,
                    have_range ? range : nullptr, std_octave,
                    std_octave && type == HADAMARD && opts.sums, dmax + 1,
                    want_rnb ? &rnb : nullptr, threads, main);
    if (!std::isfinite(lev[0].acc.value())) {
      out.bad = allanvar::first_nonfinite(v, N);
      if (out.bad > 0) return;
    }
    if (std_octave && opts.sums) {
      for (size_t j = 0; j < nt; ++j) {
        int lj = 0;
        while ((static_cast<R_xlen_t>(1) << lj) < ms[j]) ++lj;
        out.sums[j] = type == HADAMARD ? lev[lj].hacc.value()
                                       : lev[lj].acc.value();
      }
    }
    octave_noise_id(v, N, v[0], lev, mid, mid_n, dmax, type == MODIFIED,
                    rules, rnb, threads, main, out);
    if (std_octave || !opts.sums) return;
  }

  // centre (mid-range) and bound of the data; NaN/Inf poison z (the octave
  // pass above has both already)
  if (!have_range) {
    double r[3];
    sample_range(v, N, threads, main, r);
    if (allanvar::interrupt_state().stop.load()) return;
    range[0] = r[0];
    range[1] = r[1];
    if (r[2] != 0) {
      out.bad = allanvar::first_nonfinite(v, N);
      return;
    }
  }
  const double vmin = range[0], vmax = range[1];
  out.range[0] = vmin;
  out.range[1] = vmax;
  const double c = 0.5 * vmin + 0.5 * vmax;
  const double bound = std::max(std::fabs(vmax - c), std::fabs(vmin - c));

  Split X;
  // identification alone reads the phase: MODIFIED's extra level of sums
  // (serial, the costliest pass) is built only for its sums
  const bool two = type == MODIFIED && opts.sums;
  const int level = (two ? 1 : 0) + (rate ? 1 : 0);
  if (level == 0) {
    build_split(v, N, c, bound, X);
  } else {
    build_prefix(v, N, c, bound, level, two, X, threads, main);
  }
  double* o = out.sums;
  // identification alone (other statistics' noise type) needs no sums
  if (opts.sums) switch (type) {
    case STANDARD: strided<2>(X, ms, nterms, threads, main, o); break;
    case OVERLAPPING: overlapped<2>(X, ms, nterms, threads, main, o); break;
    case MODIFIED: overlapped<3>(X, ms, nterms, threads, main, o); break;
    case HADAMARD: strided<3>(X, ms, nterms, threads, main, o); break;
    case OHADAMARD: overlapped<3>(X, ms, nterms, threads, main, o); break;
    case TOTAL: total(X, ms, threads, main, o); break;
  }
  if (octave_id) return;  // identified above
  // Noise id from the phase: X itself, or its first differences when
  // MODIFIED's sums built one more level. Frequency data at m = 1 are the
  // samples.
  const double* h = X.hi.data();
  const double q = X.q;
  const Split* Xp = &X;
  auto phase = [h, Xp, q, two](R_xlen_t k) -> double {
    const double lk = Xp->lo_at(k);
    return two ? (h[k + 1] - h[k]) + q * (Xp->lo_at(k + 1) - lk)
               : h[k] + q * lk;
  };
  const R_xlen_t Lp = rate ? N + 1 : N;
  auto build = [&phase, Lp](allanvar::RnCache& r) { r.build(phase, Lp); };
  allanvar::LazyRn<decltype(build)> rn(build);
  // taus are independent: shared between the threads
  run_items(static_cast<R_xlen_t>(ni), threads, main, [&](R_xlen_t j) {
    if (allanvar::interrupted()) return;
    const R_xlen_t m = mid[j];
    allanvar::NoiseId id;
    if (m == 1 && N >= rules.acf_min) {
      id = allanvar::acf_noise_id(v, N, !rate, dmax);
    } else {
      id = allanvar::identify_noise(phase, Lp, m, dmax, !rate, rn, mid_n[j],
                                    type == MODIFIED, rules);
    }
    store_id(id, out, j);
  });
}

}  // namespace

// Sums of squared differences (the estimator numerators) for every channel
// (column of x, nrow samples each) and cluster size m, and the noise id at
// the cluster sizes `mid`; `opts` from allan_opts() (R/allan.R).
// [[Rcpp::export(rng = false)]]
Rcpp::List allan_sums_cpp(const Rcpp::NumericVector& x, double nrow,
                          const Rcpp::NumericVector& m,
                          const Rcpp::NumericVector& nterms,
                          const Rcpp::NumericVector& mid,
                          const Rcpp::List& options) {
  const AllanOptions opts = allanvar::allan_options(options);
  const allanvar::InterruptScope scope;
  const int threads = opts.threads;
  const R_xlen_t N = static_cast<R_xlen_t>(nrow);
  const R_xlen_t nc = x.size() / N;
  const size_t nt = m.size();
  const size_t ni = mid.size();
  // converted as they are copied (no zero fill first: pages of a long grid)
  const std::vector<R_xlen_t> ms(m.begin(), m.end()),
      nts(nterms.begin(), nterms.end()), mids(mid.begin(), mid.end());
  std::vector<Channel> ch;
  const double* p = x.begin();
  // the sums go straight into the result (no copy of a 500,000-row curve)
  Rcpp::NumericMatrix sums(Rcpp::no_init(nt, nc));
  try {
    ch.resize(nc);
    for (R_xlen_t i = 0; i < nc; ++i) ch[i].sums = sums.begin() + i * nt;
    if (nc == 1) {
      one_channel(p, N, ms, nts, mids, opts, threads, true, ch[0]);
    } else {
      allanvar::parallel_for(nc, threads, [&](R_xlen_t i, int) {
        one_channel(p + i * N, N, ms, nts, mids, opts, 1, false, ch[i]);
      });
    }
  } catch (const std::bad_alloc&) {
    // R/allan.R turns this into a classed error
    Rcpp::stop("allanvar_out_of_memory");
  }
  scope.finish();
  Rcpp::NumericMatrix alpha(ni, nc);
  Rcpp::IntegerMatrix alpha_int(ni, nc), id_method(ni, nc);
  for (R_xlen_t i = 0; i < nc; ++i) {
    for (size_t j = 0; j < ni; ++j) {
      alpha(j, i) = ch[i].alpha[j];
      alpha_int(j, i) = ch[i].alpha_int[j];
      id_method(j, i) = ch[i].id_method[j];
    }
  }
  Rcpp::NumericVector bad(nc);
  Rcpp::NumericMatrix range(2, nc);
  for (R_xlen_t i = 0; i < nc; ++i) {
    bad[i] = static_cast<double>(ch[i].bad);
    range(0, i) = ch[i].range[0];
    range(1, i) = ch[i].range[1];
  }
  return Rcpp::List::create(Rcpp::Named("sums") = sums,
                            Rcpp::Named("alpha") = alpha,
                            Rcpp::Named("alpha_int") = alpha_int,
                            Rcpp::Named("id_method") = id_method,
                            Rcpp::Named("bad") = bad,
                            Rcpp::Named("range") = range);
}

// ---- test reference: direct evaluation in quadruple precision ----
#if defined(__SIZEOF_FLOAT128__) && !defined(__clang__)
__extension__ typedef __float128 ref_real;
const bool kRefQuad = true;
#else
typedef long double ref_real;
const bool kRefQuad = false;
#endif

// The same estimator numerators (sums of squares) by their textbook
// formulas, in quadruple precision where the compiler offers it (else long
// double). Used only by the tests, as the exact reference.
// [[Rcpp::export(rng = false)]]
Rcpp::List allan_reference_cpp(const Rcpp::NumericVector& v,
                               const Rcpp::NumericVector& m, int type,
                               bool rate) {
  if (!allanvar::valid_estimator(type))
    Rcpp::stop("internal: unknown estimator code %d", type);
  const R_xlen_t N = v.size();
  ref_real mean = 0;
  for (R_xlen_t i = 0; i < N; ++i) mean += static_cast<ref_real>(v[i]);
  mean /= static_cast<ref_real>(N);
  // phase x: rate -> [0, cumsum(y - mean)], integrated -> the input
  const R_xlen_t L = rate ? N + 1 : N;
  std::vector<ref_real> x(L);
  if (rate) {
    x[0] = 0;
    for (R_xlen_t i = 0; i < N; ++i) x[i + 1] = x[i] + (static_cast<ref_real>(v[i]) - mean);
  } else {
    for (R_xlen_t i = 0; i < N; ++i) x[i] = static_cast<ref_real>(v[i]) - mean;
  }
  std::vector<ref_real> P;
  if (type == MODIFIED) {
    P.assign(L + 1, 0);
    for (R_xlen_t i = 0; i < L; ++i) P[i + 1] = P[i] + x[i];
  }
  Rcpp::NumericVector out(m.size()), cnt(m.size());
  for (R_xlen_t j = 0; j < m.size(); ++j) {
    const R_xlen_t mm = static_cast<R_xlen_t>(m[j]);
    ref_real s = 0;
    R_xlen_t n = 0;
    auto xs = [&](R_xlen_t i) -> ref_real {  // reflected phase for TOTAL
      if (i < 0) return 2 * x[0] - x[-i];
      if (i > L - 1) return 2 * x[L - 1] - x[2 * (L - 1) - i];
      return x[i];
    };
    switch (type) {
      case STANDARD:
      case OVERLAPPING: {
        const R_xlen_t st = type == STANDARD ? mm : 1;
        for (R_xlen_t k = 0; k + 2 * mm <= L - 1; k += st, ++n) {
          const ref_real d = x[k + 2 * mm] - 2 * x[k + mm] + x[k];
          s += d * d;
        }
        break;
      }
      case HADAMARD:
      case OHADAMARD: {
        const R_xlen_t st = type == HADAMARD ? mm : 1;
        for (R_xlen_t k = 0; k + 3 * mm <= L - 1; k += st, ++n) {
          const ref_real d = x[k + 3 * mm] - 3 * x[k + 2 * mm] + 3 * x[k + mm] - x[k];
          s += d * d;
        }
        break;
      }
      case MODIFIED: {
        for (R_xlen_t k = 0; k + 3 * mm <= L; ++k, ++n) {
          const ref_real d = P[k + 3 * mm] - 3 * P[k + 2 * mm] + 3 * P[k + mm] - P[k];
          s += d * d;
        }
        break;
      }
      case TOTAL: {
        for (R_xlen_t i = 1; i <= L - 2; ++i, ++n) {
          const ref_real d = xs(i - mm) - 2 * x[i] + xs(i + mm);
          s += d * d;
        }
        break;
      }
    }
    out[j] = static_cast<double>(s);
    cnt[j] = static_cast<double>(n);
  }
  return Rcpp::List::create(Rcpp::Named("sums") = out, Rcpp::Named("n") = cnt,
                            Rcpp::Named("quad") = kRefQuad);
}

// ---- data with gaps (allan(gaps = "skip")) ----
//
// A term is kept only when every sample (rate input) or phase point
// (integrated input) it is made of is present; the variance is the mean
// square of the kept terms, and their count is returned. Rate input: the
// term at k uses the samples [k, k + 2m) (Allan), [k, k + 3m) (Hadamard) or
// [k, k + 3m - 1) (modified); integrated input: the points k, k + m,
// k + 2m (and k + 3m for Hadamard), or all of [k, k + 3m) (modified).
// Missing values enter the prefix sums as 0: a kept term never spans one.
// The total variance is not defined here (its reflected extension would
// carry a gap to the far end) and is refused by R/allan.R.

// [[Rcpp::export(rng = false)]]
Rcpp::List allan_gap_sums_cpp(const Rcpp::NumericVector& x,
                              const Rcpp::NumericVector& m,
                              const Rcpp::List& options) {
  const AllanOptions opts = allanvar::allan_options(options);
  if (opts.type == TOTAL) Rcpp::stop("internal: no gap kernel for total");
  const allanvar::InterruptScope scope;
  const R_xlen_t N = x.size();
  const bool rate = opts.rate;
  const int type = opts.type;
  // missing flags' prefix count over the input values
  std::vector<R_xlen_t> G(N + 1, 0);
  std::vector<double> v(N);
  double vmin = R_PosInf, vmax = R_NegInf;
  for (R_xlen_t i = 0; i < N; ++i) {
    const bool miss = std::isnan(x[i]);
    G[i + 1] = G[i] + (miss ? 1 : 0);
    v[i] = miss ? 0.0 : x[i];
    if (!miss) {
      vmin = std::min(vmin, x[i]);
      vmax = std::max(vmax, x[i]);
    }
  }
  const R_xlen_t nm = m.size();
  Rcpp::NumericVector sums(nm), counts(nm);
  if (!(vmax >= vmin)) return Rcpp::List::create(Rcpp::Named("sums") = sums,
                                                 Rcpp::Named("n") = counts);
  const double c = 0.5 * vmin + 0.5 * vmax;
  // missing values sit at the centre: 0 after centring
  for (R_xlen_t i = 0; i < N; ++i) if (std::isnan(x[i])) v[i] = c;
  const double bound = std::max(std::fabs(vmax - c), std::fabs(vmin - c));
  Split X;
  // identification alone reads the phase: MODIFIED's extra level of sums
  // (serial, the costliest pass) is built only for its sums
  const bool two = type == MODIFIED && opts.sums;
  const int level = (two ? 1 : 0) + (rate ? 1 : 0);
  try {
    if (level == 0) {
      build_split(v.data(), N, c, bound, X);
    } else {
      build_prefix(v.data(), N, c, bound, level, two, X, 1, true);
    }
  } catch (const std::bad_alloc&) {
    Rcpp::stop("allanvar_out_of_memory");
  }
  const double* h = X.hi.data();
  const double q = X.q;
  const bool stride1 = allanvar::estimator_info(type).overlapping;
  const int d = type == STANDARD || type == OVERLAPPING ? 2 : 3;
  const R_xlen_t L = rate ? N + 1 : N;
  auto missing = [&](R_xlen_t a, R_xlen_t b) { return G[b] - G[a] > 0; };
  for (R_xlen_t j = 0; j < nm; ++j) {
    if (allanvar::interrupted()) break;
    const R_xlen_t mm = static_cast<R_xlen_t>(m[j]);
    const R_xlen_t span = type == MODIFIED ? 3 * mm : d * mm;  // phase points - 1
    const R_xlen_t step = stride1 ? 1 : mm;
    Acc acc;
    double s = 0;
    R_xlen_t cnt = 0, blk = 0;
    for (R_xlen_t k = 0; k + span <= L - (type == MODIFIED ? 0 : 1); k += step) {
      bool skip;
      if (rate) {
        skip = missing(k, k + span - (type == MODIFIED ? 1 : 0));
      } else if (type == MODIFIED) {
        skip = missing(k, k + span);
      } else {
        skip = false;
        for (int t = 0; t <= d; ++t) skip = skip || missing(k + t * mm, k + t * mm + 1);
      }
      if (skip) continue;
      const double dv = X.with_lo([&](const auto* l) {
        return d == 2 ? diff_at<2>(h, l, q, mm, k) : diff_at<3>(h, l, q, mm, k);
      });
      s += dv * dv;
      ++cnt;
      if (++blk == kBlock) {
        acc.add(s);
        s = 0;
        blk = 0;
      }
    }
    acc.add(s);
    sums[j] = acc.value();
    counts[j] = static_cast<double>(cnt);
  }
  scope.finish();
  return Rcpp::List::create(Rcpp::Named("sums") = sums,
                            Rcpp::Named("n") = counts);
}
