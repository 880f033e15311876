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
    allanvar::two_sum(s2, s1, t, te);
    s2 = t;
    e2 += te + e1;
    G.hi[j + 1] = s2;
    G.lo[j + 1] = e2;
    big = std::max(big, std::fabs(s2));
    // P(j + 1) = P(j) + x(j)
    allanvar::two_sum(s1, X.hi[j], t, te);
    s1 = t;
    e1 += te + X.lo[j];
  }
  {
    double t, te;
    allanvar::two_sum(s2, s1, t, te);
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

// ---- Octave m (powers of two): a doubling recursion, no prefix sums ----
//
// With G_m(i) = sum_{k<m} ((m - 1)/2 - k) x(i + k) and A_m(i) = sum_{k<m}
// x(i + k), S_i = G_m(i) - G_m(i + m) (S of the header), and splitting a
// window of 2m into two of m gives G_2m(i) = G_m(i) + m/2 A_m(i) +
// G_m(i + m) - m/2 A_m(i + m). In differences, with E_m(i) = A_m(i) -
// A_m(i + m):
//   S_2m(i) = S_m(i) + 2 S_m(i + m) + S_m(i + 2m) + m/2 (E_m(i) - E_m(i + 2m)),
//   E_2m(i) = E_m(i) + 2 E_m(i + m) + E_m(i + 2m),
// from S_1 = 0 and E_1(i) = x(i) - x(i + 1) = -(increment i) less the mean
// increment (PVAR ignores a linear phase term; any constant would do). Every
// value is of the size of the statistic itself (no running sum of the
// phase), each level costs a few operations per term, and the levels run
// over tiles that stay in cache (below). Level j (m = 2^j)
// holds indices [0, L - 2^(j+1) + 1); its terms are i < L - 2^(j+1).

// Level j + 1 at [0, len) from level j (m = 2^j) read at i, i + m, i + 2m
// (pointers s0, s1, s2 and e0, e1, e2; Z: S_m = 0, s* unused); returns the
// sum of squares of os[0, nsq), nsq <= len. In place (os == s0, oe == e0)
// is allowed: the position i is written after its three reads, and the
// reads lie at or after i.
template <bool Z>
inline double double_level(const double* s0, const double* s1,
                           const double* s2, const double* e0,
                           const double* e1, const double* e2, double h,
                           R_xlen_t len, R_xlen_t nsq, double* os,
                           double* oe) {
  R_xlen_t k = 0;
  double acc = 0;
#if defined(__GNUC__)
  using allanvar::v2d;
  using allanvar::ld2;
  using allanvar::st2;
  const v2d hv = {h, h};
  v2d q0 = {0, 0}, q1 = {0, 0};
  auto one = [&](R_xlen_t i) {
    const v2d a = ld2(e0 + i), b = ld2(e1 + i), c = ld2(e2 + i);
    v2d o = hv * (a - c);
    if (!Z) {
      const v2d t = ld2(s1 + i);
      o = ((ld2(s0 + i) + ld2(s2 + i)) + (t + t)) + o;
    }
    st2(os + i, o);
    st2(oe + i, (a + c) + (b + b));
    return o;
  };
  for (; k + 4 <= nsq; k += 4) {
    const v2d o0 = one(k), o1 = one(k + 2);
    q0 += o0 * o0;
    q1 += o1 * o1;
  }
  q0 += q1;
  acc = q0[0] + q0[1];
  for (; k + 2 <= nsq; k += 2) {
    const v2d o = one(k);
    acc += o[0] * o[0] + o[1] * o[1];
  }
#endif
  auto scalar = [&](R_xlen_t i) {
    const double a = e0[i], b = e1[i], c = e2[i];
    const double sv = Z ? 0.0 : (s0[i] + s2[i]) + (s1[i] + s1[i]);
    const double o = sv + h * (a - c);
    os[i] = o;
    oe[i] = (a + c) + (b + b);
    return o;
  };
  for (; k < nsq; ++k) {
    const double o = scalar(k);
    acc += o * o;
  }
#if defined(__GNUC__)
  for (; k + 2 <= len; k += 2) one(k);
#endif
  for (; k < len; ++k) scalar(k);
  return acc;
}

// Two stages, both in place (level j + 1 at i overwrites level j at i: its
// reads lie at i, i + m, i + 2m):
//  * levels 0..J as a wavefront over steps of kStep indices, level j + 1
//    trailing level j by 2m, so that every level meets the values in cache;
//    the record is cut in two parts (threads), each computing the margin
//    past its end that its upper levels read;
//  * from level J on, the indices congruent modulo D = 2^J never mix with
//    the others, so blocks of B residues (a tile: i = r0 + g + p D, g < B,
//    at position p B + g) are gathered and carried through the remaining
//    levels alone, within a core's cache (position q then reads q, q + G,
//    q + 2G, G = B m / D).
// The values are those of the flat recursion (the same operations on the
// same operands); only the order of the sums of squares differs, and it is
// fixed (it depends neither on the threads nor on the machine).

const R_xlen_t kStep = 2048;

// Level 0 (E_1 less the centre c) at [i0, i1) into out.
void level0(const allanvar::PhaseInput& in, double c, R_xlen_t i0,
            R_xlen_t i1, double* out) {
  if (in.rate) {
    for (R_xlen_t i = i0; i < i1; ++i) out[i - i0] = c - in.v[i];
  } else {
    for (R_xlen_t i = i0; i < i1; ++i) {
      double h, lo, r, re;
      in.increment(i, h, lo);
      allanvar::two_sum(h, -c, r, re);
      out[i - i0] = -(r + (re + lo));
    }
  }
}

struct OctaveLayout {
  R_xlen_t L = 0;
  int K = 0, J = 0;  // levels asked; levels of the first stage
  R_xlen_t n(int j) const { return L - (R_xlen_t(2) << j) + 1; }
};

// Levels 0..J of the indices [a, b) and the margin above b that they need,
// in place in S, E (index i at i - a); adds the squares of the terms in
// [a, b) to sq[j] (sq[0]: squared differences of level 0).
void octave_top(const allanvar::PhaseInput& in, double c,
                const OctaveLayout& O, R_xlen_t a, R_xlen_t b, double* S,
                double* E, double* sq) {
  const int J = O.J;
  std::vector<R_xlen_t> F(J + 1, a), end(J + 1);
  for (int j = 0; j <= J; ++j) {
    end[j] = std::min(O.n(j), b + (R_xlen_t(2) << J) - (R_xlen_t(2) << j) +
                                   (j == 0 ? 1 : 0));
  }
  const R_xlen_t q0 = std::min(b, O.n(0) - 1);  // level 0's terms end
  long sweeps = 0;
  for (;;) {
    if ((++sweeps & 63) == 0 && allanvar::interrupted()) return;
    bool moved = false;
    if (F[0] < end[0]) {
      const R_xlen_t t = std::min(end[0], F[0] + kStep);
      level0(in, c, F[0], t, E + (F[0] - a));
      // level 0 at F[0] - 1 is still there: level 1 trails by 2
      double s0 = 0, s1 = 0;
      const R_xlen_t i1 = std::min(t - 1, q0);
      R_xlen_t i = std::max(a, F[0] - 1);
      for (; i + 2 <= i1; i += 2) {
        const double d0 = E[i - a] - E[i + 1 - a];
        const double d1 = E[i + 1 - a] - E[i + 2 - a];
        s0 += d0 * d0;
        s1 += d1 * d1;
      }
      if (i < i1) {
        const double d = E[i - a] - E[i + 1 - a];
        s0 += d * d;
      }
      sq[0] += s0 + s1;
      F[0] = t;
      moved = true;
    }
    for (int j = 0; j < J; ++j) {
      const R_xlen_t m = R_xlen_t(1) << j;
      const R_xlen_t t = std::min(end[j + 1], F[j] - 2 * m);
      const R_xlen_t f = F[j + 1];
      if (t <= f) continue;
      const R_xlen_t p = f - a;
      const R_xlen_t nsq =
          std::max<R_xlen_t>(0, std::min(t, std::min(b, O.n(j + 1) - 1)) - f);
      const double h = 0.5 * static_cast<double>(m);
      sq[j + 1] +=
          j == 0 ? double_level<true>(nullptr, nullptr, nullptr, E + p,
                                      E + p + m, E + p + 2 * m, h, t - f, nsq,
                                      S + p, E + p)
                 : double_level<false>(S + p, S + p + m, S + p + 2 * m, E + p,
                                       E + p + m, E + p + 2 * m, h, t - f,
                                       nsq, S + p, E + p);
      F[j + 1] = t;
      moved = true;
    }
    if (!moved) break;
  }
}

// #{q : r0 + (q mod B) + (q div B) D < n}: the positions of a tile below
// index n (a prefix, the index growing with q).
inline R_xlen_t tile_count(R_xlen_t n, R_xlen_t r0, R_xlen_t B, R_xlen_t D) {
  const R_xlen_t k = n - r0;
  if (k <= 0) return 0;
  const R_xlen_t p = k / D;
  return p * B + std::min(B, k - p * D);
}

// Levels J + 1 .. K of the tile of residues [r0, r0 + B) (level J in S, E),
// in place; adds the squares of the terms to sq[j].
void octave_tile(double* S, double* E, R_xlen_t r0, R_xlen_t B,
                 const OctaveLayout& O, double* sq) {
  const R_xlen_t D = R_xlen_t(1) << O.J;
  for (int j = O.J; j < O.K; ++j) {
    const R_xlen_t n1 = O.n(j + 1);
    const R_xlen_t cnt = tile_count(n1, r0, B, D);
    if (cnt == 0) return;
    const R_xlen_t nsq = tile_count(n1 - 1, r0, B, D);
    const R_xlen_t G = B << (j - O.J);
    const double h = 0.5 * static_cast<double>(R_xlen_t(1) << j);
    sq[j + 1] += double_level<false>(S, S + G, S + 2 * G, E, E + G, E + 2 * G,
                                     h, cnt, nsq, S, E);
  }
}

// Sums of (2 S_i)^2 for m = 2^j, j = 1..K (sums[j]) and of squared second
// differences (sums[0]); every level is needed up to K. cap: values per
// tile of the second stage.
std::vector<double> octave_sums(const allanvar::PhaseInput& in, int K,
                                int nw, R_xlen_t cap) {
  OctaveLayout O;
  O.L = in.length();
  O.K = K;
  const R_xlen_t n0 = O.n(0);
  std::vector<double> sums(K + 1, 0.0);
  // E_1 centred by the mean increment: any constant would do (S ignores
  // it exactly), so a plain sum is enough; each E_1 is then the rounded
  // exact increment less c
  double c = 0;
  {
    double a0 = 0, a1 = 0, a2 = 0, a3 = 0;
    R_xlen_t i = 0;
    if (in.rate) {
      for (; i + 4 <= n0; i += 4) {
        if ((i & 0xFFFFF) == 0 && allanvar::interrupted()) return sums;
        a0 += in.v[i];
        a1 += in.v[i + 1];
        a2 += in.v[i + 2];
        a3 += in.v[i + 3];
      }
    }
    for (; i < n0; ++i) {
      if ((i & 0xFFFFF) == 0 && allanvar::interrupted()) return sums;
      double h, lo;
      in.increment(i, h, lo);
      a0 += h;
    }
    c = ((a0 + a1) + (a2 + a3)) / static_cast<double>(n0);
  }
  // the second stage: 2^tb tiles of B = 8 residues modulo D = 2^J
  const R_xlen_t ntile = (n0 + cap - 1) / cap;
  int tb = 0;
  while ((R_xlen_t(1) << tb) < ntile) ++tb;
  O.J = ntile > 1 ? std::min(K, tb + 3) : K;
  const bool tiles = O.J < K;
  // the first stage in two parts when long enough (fixed: the sums do not
  // depend on the number of threads)
  const int P = n0 >= (R_xlen_t(1) << 16) ? 2 : 1;
  const R_xlen_t nJ = std::max<R_xlen_t>(0, O.n(O.J));
  std::vector<R_xlen_t> a(P + 1);
  for (int p = 0; p <= P; ++p) a[p] = n0 * p / P;
  const R_xlen_t margin = (R_xlen_t(2) << O.J) + 1;
  std::vector<allanvar::Scratch> S(P), E(P);
  std::vector<std::vector<double> > sq(P);
  for (int p = 0; p < P; ++p) {
    const R_xlen_t len = std::min(n0, a[p + 1] + margin) - a[p];
    S[p].resize(len);
    E[p].resize(len);
    sq[p].assign(K + 1, 0.0);
  }
  allanvar::parallel_for(P, nw, [&](R_xlen_t p, int) {
    octave_top(in, c, O, a[p], a[p + 1], S[p].data(), E[p].data(),
               sq[p].data());
  });
  if (allanvar::interrupted()) return sums;
  for (int p = 0; p < P; ++p)
    for (int j = 0; j <= O.J; ++j) sums[j] += sq[p][j];
  if (tiles) {
    const R_xlen_t D = R_xlen_t(1) << O.J;
    const R_xlen_t nb = R_xlen_t(1) << tb;
    const R_xlen_t B = D / nb;
    std::vector<double> tsq(static_cast<size_t>(nb) * (K + 1), 0.0);
    const R_xlen_t tlen = tile_count(nJ, 0, B, D);
    std::vector<allanvar::Scratch> ts(nw), te(nw);
    allanvar::parallel_for(nb, nw, [&](R_xlen_t k, int w) {
      const R_xlen_t r0 = k * B;
      allanvar::Scratch& ST = ts[w];
      allanvar::Scratch& ET = te[w];
      if (static_cast<R_xlen_t>(ST.size()) < tlen) {
        ST.resize(tlen);
        ET.resize(tlen);
      }
      // gather level J's residues [r0, r0 + B) from the parts
      R_xlen_t q = 0;
      int p = 0;
      for (R_xlen_t i = r0; i < nJ; i += D) {
        for (R_xlen_t g = 0; g < B && i + g < nJ;) {
          const R_xlen_t x = i + g;
          while (x >= a[p + 1]) ++p;
          const R_xlen_t run =
              std::min(std::min(B - g, nJ - x), a[p + 1] - x);
          const double* ss = S[p].data() + (x - a[p]);
          const double* se = E[p].data() + (x - a[p]);
          std::copy(ss, ss + run, ST.data() + q);
          std::copy(se, se + run, ET.data() + q);
          q += run;
          g += run;
        }
      }
      octave_tile(ST.data(), ET.data(), r0, B, O, tsq.data() + k * (K + 1));
    });
    if (allanvar::interrupted()) return sums;
    for (R_xlen_t k = 0; k < nb; ++k)
      for (int j = O.J + 1; j <= K; ++j) sums[j] += tsq[k * (K + 1) + j];
  }
  for (int j = 1; j <= K; ++j) sums[j] *= 4.0;
  return sums;
}

// values per tile of the second stage: S and E, 256 KiB, within a core's L2
const R_xlen_t kTileCap = 16384;
const R_xlen_t kChunk = 1 << 16;  // terms per parallel item (global kernel)
const R_xlen_t kBlock = 4096;     // terms per cache block, every tau in turn

}  // namespace

// Sums of (2 S_i)^2 (m >= 2) or of squared second differences (m = 1) over
// the terms of every m, for one channel. method: 0 chooses (the global
// kernel, and the blocked one for the m where the global kernel's rounding
// bound exceeds 1e-13 relative; the doubling recursion for the powers of
// two when most levels up to the largest are asked for), 1 the blocked
// kernel, 2 the global one, 3 the doubling recursion for the powers of two
// (the global kernel for the other m), 4 as 3 with tiles of 64 values (to
// test the splitting on short records).
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
  std::vector<R_xlen_t> mv(nt, 0), nterm(nt, 0);
  std::vector<bool> glob(nt, false);
  std::vector<double> res(nt, 0.0);
  for (size_t t = 0; t < nt; ++t) {
    const R_xlen_t mm = static_cast<R_xlen_t>(ms[t]);
    const R_xlen_t M = mm == 1 ? L - 2 : L - 2 * mm;
    if (mm < 1 || M < 1) continue;
    mv[t] = mm;
    nterm[t] = M;
    glob[t] = method != 1 && mm >= 2 && mm < (R_xlen_t(1) << 26);
  }
  // powers of two by the doubling recursion when it pays: it walks every
  // level up to the largest, so it is chosen when at least half of them
  // are asked for (method 3: always)
  std::vector<bool> oct(nt, false);
  int K = -1, nask = 0;
  if (method == 0 || method == 3 || method == 4) {
    for (size_t t = 0; t < nt; ++t) {
      const R_xlen_t mm = mv[t];
      if (mm < 1 || (mm & (mm - 1)) != 0) continue;
      int j = 0;
      while ((R_xlen_t(1) << j) < mm) ++j;
      K = std::max(K, j);
      ++nask;
    }
    if (K >= 0 && (method >= 3 || 2 * nask >= K + 1)) {
      const std::vector<double> os =
          octave_sums(in, K, nw, method == 4 ? 64 : kTileCap);
      if (allanvar::interrupted()) scope.finish();
      for (size_t t = 0; t < nt; ++t) {
        const R_xlen_t mm = mv[t];
        if (mm < 1 || (mm & (mm - 1)) != 0) continue;
        int j = 0;
        while ((R_xlen_t(1) << j) < mm) ++j;
        oct[t] = true;
        glob[t] = false;
        res[t] = os[j];
      }
    }
  }
  Rcpp::NumericVector out(nt, NA_REAL);
  std::vector<bool> redo(nt, false);
  // the phase once, split hi + lo, for the other m; each block re-centres
  // it (its first point and the chord's slope removed), exact differences
  // on the hi grid
  allanvar::SplitPhase X;
  bool any_other = false;
  for (size_t t = 0; t < nt; ++t) any_other = any_other || (mv[t] >= 1 && !oct[t]);
  if (any_other) allanvar::split_phase(in, X);
  const double* hx = X.hi.data();
  const double* lx = X.lo.data();
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
    if (mm < 1 || oct[t] || (glob[t] && !redo[t])) continue;
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
    } else if (glob[t] || oct[t]) {
      out[t] = res[t];
    }
  }
  return out;
}
