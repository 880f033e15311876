// Windowed Allan-family sums: for every window of a sliding set and every
// cluster size m, the sum of the squared differences (dynamic_allan()) or of
// the products of two series' differences (groslambert()).
//
// One pass per m over the record: the terms are accumulated as a running
// (compensated) sum, and the running sum is recorded where a window's terms
// begin and end; a window's sum is the difference of the two records. So the
// whole time x tau surface costs O(N) per tau, whatever the window length
// and step (Galleani & Tavella, "The dynamic Allan variance", IEEE Trans.
// UFFC 56(3), 2009, define the estimator; the prefix-sum evaluation is ours).
//
// Accuracy: the phase X is built as a double-double prefix sum and stored on
// a grid, hi = a multiple of q = 2^k with |hi| <= 2^50 q, lo = the rest.
// The differences below have integer weights of total size <= 8, so their hi
// part is exact in double whatever the bias or length of the record, and lo
// (|lo| <= q/2) carries the remainder. The running sums are kept as a pair
// (sum, compensation), so a quiet window after a loud stretch keeps its
// digits.
#include "buffer.h"
#include "dd.h"
#include "opts-dynamic.h"
#include "parallel.h"
#include "types.h"
#include <Rcpp.h>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <new>
#include <vector>
#if defined(__linux__)
#include <sys/mman.h>
#endif

using allanvar::Buffer;

namespace {

// a + b = s + e exactly (Knuth's TwoSum, src/dd.h).
using allanvar::two_sum;

// A running sum kept unevaluated as s + c.
using Pair = allanvar::CompSum;

// (a - b) evaluated once, to the last bit of the difference.
inline double pair_diff(const Pair& a, const Pair& b) {
  double s, e;
  two_sum(a.s, -b.s, s, e);
  return s + ((a.c - b.c) + e);
}

// A sequence on the grid described above.
struct Grid {
  Buffer hi, lo;
};

// Grid step: the power of two q with bound <= 2^50 q.
double grid_step(double bound) {
  if (!(bound > 0) || !std::isfinite(bound)) return 1.0;
  int e;
  std::frexp(bound * (1 + 1e-9), &e);
  return std::ldexp(1.0, e - 50);
}

// Stores s + e (|s| <= 2^50 q) on the grid of step q: hi the nearest
// multiple of q, lo the rest. Adding and removing 1.5 * 2^52 rounds s / q to
// an integer (std::nearbyint saves and restores the FP environment).
inline void put(Grid& g, R_xlen_t i, double s, double e, double q) {
  const double big = 6755399441055744.0;
  const double h = ((s / q + big) - big) * q;
  g.hi.data()[i] = h;
  g.lo.data()[i] = (s - h) + e;  // s - h is exact: |s - h| <= q / 2
}

// The phase X of a series (L points): the running sum of the rate samples
// minus their mean (a constant rate does not change any difference), or the
// integrated values minus the first; with `second`, also Q, the running sum
// of X (L + 1 points), which the modified variance needs. A running sum is
// s + e, e gathering the exact rounding errors of s (|e| <= n eps max|s|,
// far below what the lo part resolves), so the dependency chain is one
// addition per sample. The grid step comes from a bound on |X| known
// before the pass: sum |v - c| (or max |v - c|).
void build_phase(const double* v, R_xlen_t n, bool rate, bool second, Grid& X,
                 Grid& Q) {
  const R_xlen_t L = rate ? n + 1 : n;
  X.hi.resize(L);
  X.lo.resize(L);
  double bound = 0;
  if (rate) {
    Pair mean;
    double abs_sum = 0;
    for (R_xlen_t i = 0; i < n; ++i) {
      mean.add(v[i]);
      abs_sum += std::fabs(v[i]);
    }
    const double c = (mean.s + mean.c) / static_cast<double>(n);
    bound = (abs_sum + static_cast<double>(n) * std::fabs(c)) * (1 + 1e-9);
    const double q = grid_step(bound);
    put(X, 0, 0.0, 0.0, q);
    double s = 0, e = 0;
    for (R_xlen_t i = 0; i < n; ++i) {
      double d, de, t, te;
      two_sum(v[i], -c, d, de);
      two_sum(s, d, t, te);
      s = t;
      e += te + de;
      put(X, i + 1, s, e, q);
    }
  } else {
    const double c = v[0];
    for (R_xlen_t i = 0; i < n; ++i) {
      bound = std::max(bound, std::fabs(v[i] - c));
    }
    bound *= 1 + 1e-9;
    const double q = grid_step(bound);
    for (R_xlen_t i = 0; i < n; ++i) {
      double d, de;
      two_sum(v[i], -c, d, de);
      put(X, i, d, de, q);
    }
  }
  if (!second) return;
  Q.hi.resize(L + 1);
  Q.lo.resize(L + 1);
  const double* xh = X.hi.data();
  const double* xl = X.lo.data();
  const double q = grid_step(bound * static_cast<double>(L) * (1 + 1e-9));
  put(Q, 0, 0.0, 0.0, q);
  double s = 0, e = 0;
  for (R_xlen_t i = 0; i < L; ++i) {
    double t, te;
    two_sum(s, xh[i], t, te);
    s = t;
    e += te + xl[i];
    put(Q, i + 1, s, e, q);
  }
}

// The difference behind each term at index k: order 2 (1, -2, 1) or order 3
// (1, -3, 3, -1) at lag m. For the modified variance the order-3 difference
// of Q equals the sum of m consecutive order-2 differences of X.
template <int D>
inline double diff(const double* h, const double* l, R_xlen_t k, R_xlen_t m) {
  if (D == 2) {
    return (h[k + 2 * m] - 2 * h[k + m] + h[k]) +
           (l[k + 2 * m] - 2 * l[k + m] + l[k]);
  }
  return (h[k + 3 * m] - 3 * h[k + 2 * m] + 3 * h[k + m] - h[k]) +
         (l[k + 3 * m] - 3 * l[k + 2 * m] + 3 * l[k + m] - l[k]);
}

struct Source {
  const double *h1, *l1, *h2, *l2;  // h2 == nullptr: squares, else products
};

// Adds the terms at k = k0, k0 + st, ... (count of them) to acc, in blocks of
// 256 summed in two plain chains and folded into the compensated pair.
template <int D, bool CROSS>
void add_terms(const Source& src, R_xlen_t k0, R_xlen_t count, R_xlen_t st,
               R_xlen_t m, Pair& acc) {
  R_xlen_t k = k0;
  while (count > 0) {
    const R_xlen_t nb = std::min<R_xlen_t>(256, count);
    double a0 = 0, a1 = 0;
    R_xlen_t i = 0;
    for (; i + 1 < nb; i += 2, k += 2 * st) {
      const double d0 = diff<D>(src.h1, src.l1, k, m);
      const double d1 = diff<D>(src.h1, src.l1, k + st, m);
      if (CROSS) {
        a0 += d0 * diff<D>(src.h2, src.l2, k, m);
        a1 += d1 * diff<D>(src.h2, src.l2, k + st, m);
      } else {
        a0 += d0 * d0;
        a1 += d1 * d1;
      }
    }
    if (i < nb) {
      const double d0 = diff<D>(src.h1, src.l1, k, m);
      a0 += CROSS ? d0 * diff<D>(src.h2, src.l2, k, m) : d0 * d0;
      k += st;
    }
    acc.add(a0 + a1);
    count -= nb;
  }
}

// Order-3 differences: the Hadamard types, and the modified type on Q.
void add_range(bool third, bool cross, const Source& src, R_xlen_t k0,
               R_xlen_t count, R_xlen_t st, R_xlen_t m, Pair& acc) {
  if (count <= 0) return;
  if (third) {
    if (cross) add_terms<3, true>(src, k0, count, st, m, acc);
    else add_terms<3, false>(src, k0, count, st, m, acc);
  } else {
    if (cross) add_terms<2, true>(src, k0, count, st, m, acc);
    else add_terms<2, false>(src, k0, count, st, m, acc);
  }
}

// The windows of one cluster size that share a residue of their start
// modulo the stride: their terms lie on one stream k = r + j * st.
struct Group {
  R_xlen_t tau, r, st, m, nt;
  std::vector<R_xlen_t> win;  // window indices, increasing
  std::vector<R_xlen_t> ja;   // first term of each window, in j
  R_xlen_t j_first, j_last;   // the stream's first and one-past-last term
  R_xlen_t chunk0, nchunk;    // its work items
};

struct Item {
  R_xlen_t group, j0, j1;
  bool last;
};

const R_xlen_t kChunk = R_xlen_t(1) << 18;

}  // namespace

// For each window w (start sample w * step, terms `nterms[t]` per window for
// cluster size m[t]) and each m, the sum of the squared differences of `x`,
// or, with `y`, of the products of the differences of x and y. Returns an
// nwin x length(m) matrix. Input is checked in R (finite, long enough);
// `options` from dyn_opts() (R/dynamic.R).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericMatrix dynamic_sums_cpp(const Rcpp::NumericVector& x, SEXP y,
                                     const Rcpp::NumericVector& m,
                                     const Rcpp::NumericVector& nterms,
                                     const Rcpp::List& options) {
  const allanvar::DynamicOptions opts = allanvar::dynamic_options(options);
  const allanvar::EstimatorInfo& info = allanvar::estimator_info(opts.type);
  const R_xlen_t n = x.size();
  const bool cross = !Rf_isNull(y);
  const bool rate = opts.rate;
  const bool second = info.modified;
  // the modified variance is an order-3 difference of Q (see diff())
  const bool third = info.d == 3 || info.modified;
  Grid X1, Q1, X2, Q2;
  build_phase(x.begin(), n, rate, second, X1, Q1);
  Source src{nullptr, nullptr, nullptr, nullptr};
  const Grid& g1 = second ? Q1 : X1;
  src.h1 = g1.hi.data();
  src.l1 = g1.lo.data();
  if (cross) {
    Rcpp::NumericVector yy(y);
    if (yy.size() != n) Rcpp::stop("internal: x and y differ in length");
    build_phase(yy.begin(), n, rate, second, X2, Q2);
    const Grid& g2 = second ? Q2 : X2;
    src.h2 = g2.hi.data();
    src.l2 = g2.lo.data();
  }
  const R_xlen_t ntau = m.size();
  const R_xlen_t nw = opts.nwin;
  const R_xlen_t stp = opts.step;
  const bool strided = !info.overlapping;

  // Streams and their chunks.
  std::vector<Group> groups;
  std::vector<Item> items;
  for (R_xlen_t t = 0; t < ntau; ++t) {
    const R_xlen_t mm = static_cast<R_xlen_t>(m[t]);
    const R_xlen_t st = strided ? mm : 1;
    const R_xlen_t nt = static_cast<R_xlen_t>(nterms[t]);
    // windows grouped by the residue of their start (counting sort: no
    // O(nw log nw) pass per tau, and one group when stride divides step)
    std::vector<R_xlen_t> order(nw);
    std::vector<R_xlen_t> res(nw);
    for (R_xlen_t w = 0; w < nw; ++w) res[w] = (w * stp) % st;
    if (st == 1 || stp % st == 0) {
      for (R_xlen_t w = 0; w < nw; ++w) order[w] = w;
    } else {
      std::vector<R_xlen_t> count(st + 1, 0);
      for (R_xlen_t w = 0; w < nw; ++w) ++count[res[w] + 1];
      for (R_xlen_t r = 0; r < st; ++r) count[r + 1] += count[r];
      for (R_xlen_t w = 0; w < nw; ++w) order[count[res[w]]++] = w;
    }
    for (R_xlen_t i = 0; i < nw;) {
      Group g;
      g.tau = t;
      g.r = res[order[i]];
      g.st = st;
      g.m = mm;
      g.nt = nt;
      for (; i < nw && res[order[i]] == g.r; ++i) {
        g.win.push_back(order[i]);
        g.ja.push_back((order[i] * stp - g.r) / st);
      }
      g.j_first = g.ja.front();
      g.j_last = g.ja.back() + nt;
      g.chunk0 = static_cast<R_xlen_t>(items.size());
      R_xlen_t j = g.j_first;
      do {
        const R_xlen_t j1 = std::min(g.j_last, j + kChunk);
        items.push_back({static_cast<R_xlen_t>(groups.size()), j, j1,
                         j1 == g.j_last});
        j = j1;
      } while (j < g.j_last);
      g.nchunk = static_cast<R_xlen_t>(items.size()) - g.chunk0;
      groups.push_back(std::move(g));
    }
  }

  // Per item: its total; per (window, tau): the running sum at the first
  // and one-past-last term, relative to the start of the chunk holding it.
  std::vector<Pair> total(items.size());
  std::vector<Pair> at_a(nw * ntau), at_b(nw * ntau);
  std::vector<R_xlen_t> chunk_a(nw * ntau), chunk_b(nw * ntau);

  allanvar::parallel_for(
      static_cast<R_xlen_t>(items.size()), opts.threads,
      [&](R_xlen_t it, int) {
        const Item& item = items[it];
        const Group& g = groups[item.group];
        const R_xlen_t G = static_cast<R_xlen_t>(g.win.size());
        // windows whose first (a) or one-past-last (b) term is in the chunk
        R_xlen_t ia = std::lower_bound(g.ja.begin(), g.ja.end(), item.j0) -
                      g.ja.begin();
        R_xlen_t ib = std::lower_bound(g.ja.begin(), g.ja.end(),
                                       item.j0 - g.nt) -
                      g.ja.begin();
        const R_xlen_t stop = item.last ? item.j1 : item.j1 - 1;
        Pair acc;
        R_xlen_t j = item.j0;
        for (;;) {
          const R_xlen_t na = ia < G ? g.ja[ia] : -1;
          const R_xlen_t nb = ib < G ? g.ja[ib] + g.nt : -1;
          R_xlen_t next = -1;
          if (na >= 0 && na <= stop) next = na;
          if (nb >= 0 && nb <= stop && (next < 0 || nb < next)) next = nb;
          if (next < 0) break;
          // no window open: the terms before the next start are not needed
          if (ia == ib && next == na) {
            j = next;
          } else {
            add_range(third, cross, src, g.r + j * g.st, next - j, g.st, g.m,
                      acc);
            j = next;
          }
          while (ia < G && g.ja[ia] == j) {
            const R_xlen_t cell = g.tau * nw + g.win[ia];
            at_a[cell] = acc;
            chunk_a[cell] = it;
            ++ia;
          }
          while (ib < G && g.ja[ib] + g.nt == j) {
            const R_xlen_t cell = g.tau * nw + g.win[ib];
            at_b[cell] = acc;
            chunk_b[cell] = it;
            ++ib;
          }
        }
        // the rest of the chunk, unless no window is open
        if (ia != ib) {
          add_range(third, cross, src, g.r + j * g.st, item.j1 - j, g.st,
                    g.m, acc);
        }
        total[it] = acc;
      });

  Rcpp::NumericMatrix out(nw, ntau);
  for (const Group& g : groups) {
    // running sum at the start of each chunk of this stream
    std::vector<Pair> start(g.nchunk);
    for (R_xlen_t c = 1; c < g.nchunk; ++c) {
      start[c] = start[c - 1];
      start[c].add(total[g.chunk0 + c - 1]);
    }
    for (R_xlen_t w : g.win) {
      const R_xlen_t cell = g.tau * nw + w;
      Pair a = start[chunk_a[cell] - g.chunk0];
      a.add(at_a[cell]);
      Pair b = start[chunk_b[cell] - g.chunk0];
      b.add(at_b[cell]);
      out(w, g.tau) = pair_diff(b, a);
    }
  }
  return out;
}
