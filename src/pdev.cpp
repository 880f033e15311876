// Parabolic deviation of allan(type = "pdev") (Vernotte, Lenczner,
// Bourgeois & Rubiola 2016, "The parabolic variance (PVAR): a wavelet
// variance based on the least-square fit", IEEE TUFFC 63(4), eq. 16 as
// rewritten by Vernotte et al. 2020):
//   PVAR(m tau0) = 72 / (M m^4 (m tau0)^2) sum_{i<M} S_i^2,  M = L - 2m,
//   S_i = sum_{k<m} ((m - 1)/2 - k) (x(i + k) - x(i + m + k)),
// and PVAR(tau0) = AVAR(tau0) (the weights vanish at m = 1).
// With P the prefix sums of x and PP those of P, 2 S_i = F(i) - F(i + m),
// F(i) = 2 (PP(i + m) - PP(i + 1)) - (m - 1) (P(i) + P(i + m)): O(1) per
// term. P and PP are built per block of about 2m terms from the phase
// re-centred on the block (PVAR ignores a linear phase term), so they stay
// of the size of the local wander and the differences lose nothing.
#include "local-phase.h"
#include "parallel.h"
#include <algorithm>
#include <cmath>
#include <vector>

namespace {

struct Item {
  size_t tau;
  R_xlen_t i0, i1;  // terms [i0, i1)
};

// The phase of the global kernel: PP, the prefix sums of the prefix sums
// of x (x re-centred: its mean increment removed), held as hi + lo with hi
// on a grid of step q = 2^k and |hi| <= 2^50 q (as src/allan.cpp holds the
// phase): 2 S_i = 2 (PP(i+m) + PP(i+m+1) - PP(i+1) - PP(i+2m)) + (m - 1)
// (P(i+2m) - P(i)), P(j) = PP(j+1) - PP(j), so the hi part of each term is
// an exact integer combination of weight 8 plus (m - 1) times an exact
// difference, whose product Dekker's split makes exact too. Only lo
// (|lo| <= q/2) is rounded: an error of at most about 12 m eps q per term,
// checked against the size of the terms after the sum (pdev_sums_cpp).
struct Grid {
  std::vector<double> hi, lo;
  double q = 0;
};

void build_pp(const allanvar::SplitPhase& X, Grid& G) {
  const R_xlen_t L = X.size();
  G.hi.assign(L + 2, 0.0);
  G.lo.assign(L + 2, 0.0);
  // compensated running sums: P = s1 + e1, PP = s2 + e2; hi[] holds s2 and
  // lo[] e2 until the grid is known
  double s1 = 0, e1 = 0, s2 = 0, e2 = 0, big = 0;
  for (R_xlen_t j = 0; j < L; ++j) {
    if ((j & 0xFFFFF) == 0xFFFFF && allanvar::interrupted()) return;
    double t, te;
    // PP(j + 1) = PP(j) + P(j)
    allanvar::phase_two_sum(s2, s1, t, te);
    s2 = t;
    e2 += te + e1;
    G.hi[j + 1] = s2;
    G.lo[j + 1] = e2;
    big = std::max(big, std::fabs(s2));
    // P(j + 1) = P(j) + x(j)
    allanvar::phase_two_sum(s1, X.hi[j], t, te);
    s1 = t;
    e1 += te + X.lo[j];
  }
  {
    double t, te;
    allanvar::phase_two_sum(s2, s1, t, te);
    G.hi[L + 1] = t;
    G.lo[L + 1] = e2 + te + e1;
    big = std::max(big, std::fabs(t));
  }
  int ex;
  std::frexp(big * (1 + 1e-9) + 1e-300, &ex);
  G.q = std::ldexp(1.0, ex - 50);
  const double C = 1.5 * G.q * 4503599627370496.0;  // ulp(C) = q
  for (R_xlen_t j = 0; j < L + 2; ++j) {
    const double s = G.hi[j], h = (s + C) - C;
    G.hi[j] = h;
    G.lo[j] = (s - h) + G.lo[j];
  }
}

// 2 S_j from the grid, for one term (V = double, Ld reads one value) or two
// (V = v2d, Ld reads two): the same arithmetic either way.
template <class V, class Ld>
inline V grid_term(const double* h, const double* l, R_xlen_t j, R_xlen_t m,
                   V k1, Ld ld) {
  const double* a = h + j;
  const double* b = h + j + m;
  const double* c = h + j + 2 * m;
  const V A = 2.0 * ((ld(b) + ld(b + 1)) - (ld(a + 1) + ld(c)));  // exact
  const V D = (ld(c + 1) - ld(c)) - (ld(a + 1) - ld(a));          // exact
  // D k1 = p + e exactly (k1 has at most 26 bits; Veltkamp's split of D)
  const V p = D * k1;
  const V sp = 134217729.0 * D;
  const V dh = sp - (sp - D);
  const V e = (dh * k1 - p) + (D - dh) * k1;
  // A + p rounds by at most eps |A + p| (exactly when they cancel)
  const V s = A + p;
  const double* la = l + j;
  const double* lb = l + j + m;
  const double* lc = l + j + 2 * m;
  const V lo = 2.0 * ((ld(lb) + ld(lb + 1)) - (ld(la + 1) + ld(lc))) +
               k1 * ((ld(lc + 1) - ld(lc)) - (ld(la + 1) - ld(la)));
  return s + (e + lo);
}

// Sum of (2 S_i)^2 for i in [i0, i1) from the grid (m >= 2, m - 1 < 2^26).
double global_terms(const Grid& G, R_xlen_t m, R_xlen_t i0, R_xlen_t i1) {
  const double* h = G.hi.data();
  const double* l = G.lo.data();
  const double k1 = static_cast<double>(m - 1);
  double s0 = 0, s1 = 0;
  R_xlen_t i = i0;
#if defined(__GNUC__)
  using allanvar::v2d;
  v2d a0 = {0, 0}, a1 = {0, 0};
  const v2d k1v = {k1, k1};
  auto ld2 = [](const double* p) { return allanvar::ld2(p); };
  for (; i + 4 <= i1; i += 4) {
    const v2d d0 = grid_term(h, l, i, m, k1v, ld2);
    const v2d d1 = grid_term(h, l, i + 2, m, k1v, ld2);
    a0 += d0 * d0;
    a1 += d1 * d1;
  }
  s0 = a0[0] + a1[0];
  s1 = a0[1] + a1[1];
#endif
  auto ld1 = [](const double* p) { return *p; };
  for (; i + 2 <= i1; i += 2) {
    const double d0 = grid_term(h, l, i, m, k1, ld1);
    const double d1 = grid_term(h, l, i + 1, m, k1, ld1);
    s0 += d0 * d0;
    s1 += d1 * d1;
  }
  for (; i < i1; ++i) {
    const double d = grid_term(h, l, i, m, k1, ld1);
    s0 += d * d;
  }
  return s0 + s1;
}

// The blocked kernel: P and PP rebuilt per block of about 2m terms from the
// phase re-centred on the block; its rounding is relative to the local
// wander, whatever the record.
double local_terms(const double* hx, const double* lx, R_xlen_t mm,
                   R_xlen_t a, R_xlen_t nb, std::vector<double>& P,
                   std::vector<double>& PP, std::vector<double>& F) {
  const R_xlen_t len = nb + 2 * mm - 1;  // phase points used
  const double slope = ((hx[a + len - 1] - hx[a]) + (lx[a + len - 1] - lx[a])) /
                       static_cast<double>(len - 1);
  P.resize(len + 1);
  PP.resize(len + 1);
  P[0] = PP[0] = 0;
  for (R_xlen_t j = 0; j < len; ++j) {
    const double r = ((hx[a + j] - hx[a]) + (lx[a + j] - lx[a])) -
                     slope * static_cast<double>(j);
    P[j + 1] = P[j] + r;
    PP[j + 1] = PP[j] + P[j];
  }
  const double k1 = static_cast<double>(mm - 1);
  const R_xlen_t nf = nb + mm;
  F.resize(nf);
  for (R_xlen_t i = 0; i < nf; ++i)
    F[i] = 2.0 * (PP[i + mm] - PP[i + 1]) - k1 * (P[i] + P[i + mm]);
  double s0 = 0, s1 = 0;
  R_xlen_t i = 0;
  for (; i + 2 <= nb; i += 2) {
    const double d0 = F[i] - F[i + mm];
    const double d1 = F[i + 1] - F[i + 1 + mm];
    s0 += d0 * d0;
    s1 += d1 * d1;
  }
  for (; i < nb; ++i) {
    const double d = F[i] - F[i + mm];
    s0 += d * d;
  }
  return s0 + s1;
}

const R_xlen_t kChunk = 1 << 16;  // terms per parallel item (global kernel)
const R_xlen_t kBlock = 4096;     // terms per cache block, every tau in turn

}  // namespace

// Sums of (2 S_i)^2 (m >= 2) or of squared second differences (m = 1) over
// the terms of every m, for one channel. method: 0 chooses (the global
// kernel, and the blocked one for the m where the global kernel's rounding
// bound exceeds 1e-13 relative), 1 the blocked kernel, 2 the global one.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector pdev_sums_cpp(const Rcpp::NumericVector& v, bool rate,
                                  const Rcpp::NumericVector& m, int threads,
                                  int method = 0) {
  const allanvar::InterruptScope scope;
  const allanvar::PhaseInput in{v.begin(), v.size(), rate};
  const R_xlen_t L = in.length();
  const std::vector<double> ms(m.begin(), m.end());
  const size_t nt = ms.size();
  const int nw = std::max(1, threads);
  // the phase once, split hi + lo; each block re-centres it (its first
  // point and the chord's slope removed), exact differences on the hi grid
  allanvar::SplitPhase X;
  allanvar::split_phase(in, X);
  const double* hx = X.hi.data();
  const double* lx = X.lo.data();
  std::vector<R_xlen_t> mv(nt, 0), nterm(nt, 0);
  std::vector<bool> glob(nt, false);
  for (size_t t = 0; t < nt; ++t) {
    const R_xlen_t mm = static_cast<R_xlen_t>(ms[t]);
    const R_xlen_t M = mm == 1 ? L - 2 : L - 2 * mm;
    if (mm < 1 || M < 1) continue;
    mv[t] = mm;
    nterm[t] = M;
    glob[t] = method != 1 && mm >= 2 && mm < (R_xlen_t(1) << 26);
  }
  Rcpp::NumericVector out(nt, NA_REAL);
  std::vector<double> res(nt, 0.0);
  std::vector<bool> redo(nt, false);
  bool any_glob = false;
  for (size_t t = 0; t < nt; ++t) any_glob = any_glob || glob[t];
  if (any_glob) {
    Grid G;
    build_pp(X, G);
    if (allanvar::interrupted()) scope.finish();
    R_xlen_t K = 0;
    for (size_t t = 0; t < nt; ++t) if (glob[t]) K = std::max(K, nterm[t]);
    const R_xlen_t nchunks = (K + kChunk - 1) / kChunk;
    std::vector<double> part(static_cast<size_t>(nchunks) * nt, 0.0);
    // chunks of terms; inside a chunk every tau walks the same block
    allanvar::parallel_for(nchunks, nw, [&](R_xlen_t c, int) {
      const R_xlen_t c0 = c * kChunk, c1 = std::min(K, c0 + kChunk);
      double* p = part.data() + c * nt;
      for (R_xlen_t b0 = c0; b0 < c1; b0 += kBlock) {
        const R_xlen_t b1 = std::min(c1, b0 + kBlock);
        for (size_t t = 0; t < nt; ++t) {
          if (!glob[t]) continue;
          const R_xlen_t e = std::min(b1, nterm[t]);
          if (e <= b0) continue;
          p[t] += global_terms(G, mv[t], b0, e);
        }
      }
    });
    if (allanvar::interrupted()) scope.finish();
    for (size_t t = 0; t < nt; ++t) {
      if (!glob[t]) continue;
      allanvar::TauSums one(1);
      for (R_xlen_t c = 0; c < nchunks; ++c) one.add(0, part[c * nt + t]);
      res[t] = one.value(0);
      // each term's error is below (8 + 4 k1) eps q (the lo part, the
      // final additions); the sum of squares then errs by at most twice
      // that over the rms term, relatively (Cauchy-Schwarz)
      const double err = (12.0 + 4.0 * static_cast<double>(mv[t])) *
                         2.220446049250313e-16 * G.q;
      const double rms = std::sqrt(res[t] / static_cast<double>(nterm[t]));
      if (method == 0 && !(2 * err <= 1e-13 * rms)) redo[t] = true;
    }
  }
  std::vector<Item> items;
  for (size_t t = 0; t < nt; ++t) {
    const R_xlen_t mm = mv[t], M = nterm[t];
    if (mm < 1 || (glob[t] && !redo[t])) continue;
    // blocks of a few m: the prefix sums then cancel by at most (span/m)^2.5
    const R_xlen_t B = std::max<R_xlen_t>(2 * mm, std::min<R_xlen_t>(1024, 32 * mm));
    for (R_xlen_t i0 = 0; i0 < M; i0 += B)
      items.push_back(Item{t, i0, std::min(M, i0 + B)});
  }
  std::vector<double> part(items.size(), 0.0);
  std::vector<std::vector<double> > pbuf(nw), ppbuf(nw), fbuf(nw);
  allanvar::parallel_for(static_cast<R_xlen_t>(items.size()), nw,
                         [&](R_xlen_t it, int w) {
    const Item& I = items[it];
    const R_xlen_t mm = mv[I.tau];
    const R_xlen_t nb = I.i1 - I.i0;
    const R_xlen_t a = I.i0;
    if (mm == 1) {
      double s = 0;
      for (R_xlen_t i = a; i < a + nb; ++i) {
        const double d = ((hx[i + 2] + hx[i]) - 2.0 * hx[i + 1]) +
                         ((lx[i + 2] + lx[i]) - 2.0 * lx[i + 1]);
        s += d * d;
      }
      part[it] = s;
      return;
    }
    part[it] = local_terms(hx, lx, mm, a, nb, pbuf[w], ppbuf[w], fbuf[w]);
  });
  if (allanvar::interrupted()) scope.finish();
  allanvar::TauSums sums(nt);
  for (size_t it = 0; it < items.size(); ++it) sums.add(items[it].tau, part[it]);
  for (size_t t = 0; t < nt; ++t) {
    if (sums.any(t)) {
      out[t] = sums.value(t);
    } else if (glob[t]) {
      out[t] = res[t];
    }
  }
  return out;
}
