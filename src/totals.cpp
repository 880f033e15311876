// The Total family of allan(): modified total (MTOT, and TTOT = tau^2/3
// MTOT) and Hadamard total (HTOT) variances, NIST SP 1065 sec. 5.2.12-14,
// eqs. (27)-(29); D.A. Howe & F. Vernotte, "Generalization of the total
// variance approach to the modified Allan variance", PTTI 1999; D.A. Howe et
// al., "A total estimator of the Hadamard function used for GPS
// operations", PTTI 2000.
//
// For each window of 3m consecutive points s (phase for MTOT, frequency for
// HTOT): a line through the means of its two halves is removed, the result
// s0 is extended at both ends by uninverted even reflection to 9m points,
// and the 6m overlapping third differences (at spacing m) of its prefix
// sums E are squared and summed: Q = sum_j (E(j+3m) - 3E(j+2m) + 3E(j+m) -
// E(j))^2. The kernel returns sum over windows of Q; R/allan-types.R
// normalises (MTOT: / (12 m^5 n tau^2/m^2), HTOT: / (36 m^3 n)).
// O(m) per window; windows are processed in blocks of local phase
// (src/local-phase.h; both statistics ignore a linear phase term).
#include "dd.h"
#include "local-phase.h"
#include "parallel.h"
#include "scratch.h"
#include <algorithm>
#include <cmath>
#include <vector>

namespace {

struct Item {
  size_t tau;
  R_xlen_t n0, n1;  // windows [n0, n1)
};

// From this m on, the closed form (below) is faster than the direct sum.
const R_xlen_t kFastFrom = 8;

struct Scratch {
  std::vector<double> r, s, S, E;
};

// Q of one window s[0, 3m) (overwritten).
double window_q(double* s, R_xlen_t m, Scratch& w) {
  const R_xlen_t n3 = 3 * m;
  const R_xlen_t h = n3 / 2;
  double a = 0, b = 0;
  for (R_xlen_t t = 0; t < h; ++t) a += s[t];
  for (R_xlen_t t = n3 - h; t < n3; ++t) b += s[t];
  const double slope = (b - a) / static_cast<double>(h) /
                       static_cast<double>(n3 - h);
  // remove the line through the half means, centred to keep values small
  const double mid = 0.5 * static_cast<double>(n3 - 1);
  std::vector<double>& S = w.S;
  S.resize(n3 + 1);
  S[0] = 0;
  for (R_xlen_t t = 0; t < n3; ++t)
    S[t + 1] = S[t] + (s[t] - slope * (static_cast<double>(t) - mid));
  const double T = S[n3];
  std::vector<double>& E = w.E;
  E.resize(9 * m + 1);
  for (R_xlen_t t = 0; t <= n3; ++t) E[t] = T - S[n3 - t];
  for (R_xlen_t t = 1; t <= n3; ++t) E[n3 + t] = T + S[t];
  for (R_xlen_t t = 1; t <= n3; ++t) E[2 * n3 + t] = 3 * T - S[n3 - t];
  double q0 = 0, q1 = 0;
  const double* e = E.data();
  R_xlen_t j = 0;
  for (; j + 2 <= 6 * m; j += 2) {
    const double d0 = (e[j + 3 * m] - e[j]) + 3.0 * (e[j + m] - e[j + 2 * m]);
    const double d1 = (e[j + 1 + 3 * m] - e[j + 1]) +
                      3.0 * (e[j + 1 + m] - e[j + 1 + 2 * m]);
    q0 += d0 * d0;
    q1 += d1 * d1;
  }
  for (; j < 6 * m; ++j) {
    const double d = (e[j + 3 * m] - e[j]) + 3.0 * (e[j + m] - e[j + 2 * m]);
    q0 += d * d;
  }
  return q0 + q1;
}

// ---- O(1) per window: the quadratic form in closed form ----
//
// With s0 the detrended window and S_k = s0_0 + ... + s0_k (S_k = 0 for
// k < 0, T = S_{3m-1} for k >= 3m - 1), Q equals 2 (Toep + Hank) with
//   Toep = sum_ab s0_a s0_b rho(a - b),  Hank = sum_ab s0_a s0_b rho(a + b + 1),
// rho the circular autocorrelation (period 6m) of the kernel (1, -2, 1) x m
// (the 9m-point extension is a window of the even periodic extension, and
// the 6m differences cover one period). rho is piecewise linear with knots
// at multiples of m, so both sums are combinations of
//   sum_ab s_a s_b |a - b - c| = sum_t [T S_t + T S_{t-c} - 2 S_t S_{t-c}],
//   sum_ab s_a s_b |a + b + 1 - c| = sum_t [T^2 - T S_t - T S_{e-t} + 2 S_t S_{e-t}]
// (e = c - 2; sums over the t where a term is non-zero). On a block of
// windows, S_k = Z(n+k+1) - Z(n) - beta_n k(k+1)/2 with Z the prefix sums of
// the local series and beta_n the slope of the line through the half means,
// so every sum over t is a difference of prefix sums (of Z, of u^j Z(u), of
// Z(u) Z(u-c)); the products S_t S_{e-t} across a whole block of windows
// are anti-diagonal sums of Z, one pass with prefix sums over every other
// index. The block spans a few m, so prefix sums stay of the size of the
// local wander and nothing cancels beyond a factor of about 50.

enum ItemKind { ITEM_TS, ITEM_SAME, ITEM_ANTI };

struct PlanItem {
  int kind;
  double coef;
  R_xlen_t a, b;  // TS: k in [a, b]; SAME/ANTI: t in [a, b]
  R_xlen_t c;     // SAME: lag c (S_t S_{t-c}); ANTI: e (S_t S_{e-t})
  double q1, q2, qq;  // sums of q over the item's ranges (n-free parts)
};

struct Plan {
  double tt = 0;  // coefficient of T^2
  std::vector<PlanItem> items;
  // the TS items merged: sum over them of coef T (sum of S_k, k in [a, b])
  // = T (sum_o ts_w[o] ZZ(n + ts_off[o]) - ts_c1 Z(n) - ts_c2 beta); their
  // dozens of ranges share six end points
  std::vector<R_xlen_t> ts_off;
  std::vector<double> ts_w;
  double ts_c1 = 0, ts_c2 = 0;
  // the SAME and ANTI items merged (all but their anti-diagonal products):
  // per window, zn sum_o zn_z ZZ(n+o) + beta (S0 + n S1 + n^2 S2) with
  // S0 = sum_o (b_m2 M2 + b_m10 M1 + b_z0 ZZ)(n+o), S1 = sum_o (b_m11 M1 +
  // b_z1 ZZ)(n+o), S2 = sum_o b_z2 ZZ(n+o), plus the lag products
  // sum l_w LP[l_lag](n + l_off) and czz zn^2 + cbz beta zn + cbb beta^2.
  // Their ranges share about seven end points.
  std::vector<R_xlen_t> off;
  std::vector<double> zn_z, b_z0, b_z1, b_z2, b_m10, b_m11, b_m2;
  std::vector<int> l_lag;
  std::vector<R_xlen_t> l_off;
  std::vector<double> l_w;
  double czz = 0, cbz = 0, cbb = 0;
  size_t slot(R_xlen_t o) {
    size_t k = 0;
    while (k < off.size() && off[k] != o) ++k;
    if (k == off.size()) {
      off.push_back(o);
      for (std::vector<double>* v : {&zn_z, &b_z0, &b_z1, &b_z2, &b_m10,
                                     &b_m11, &b_m2})
        v->push_back(0.0);
    }
    return k;
  }
  // coef times MQ(n + alpha, sg, n + lo, n + hi - 1) (see block_q_fast),
  // multiplied by -beta: the sum over u of q(sg (u - A)) Z(u) is half of
  // dM2 + (sg - 2A) dM1 + (A^2 - sg A) dZZ, A = n + alpha
  void add_mq(double coef, double alpha, int sg, R_xlen_t lo, R_xlen_t hi) {
    const double f = -0.5 * coef;
    for (int z = 0; z < 2; ++z) {
      const size_t k = slot(z == 0 ? hi : lo);
      const double sf = z == 0 ? f : -f;
      b_m2[k] += sf;
      b_m10[k] += sf * (sg - 2 * alpha);
      b_m11[k] += sf * -2.0;
      b_z0[k] += sf * (alpha * alpha - sg * alpha);
      b_z1[k] += sf * (2 * alpha - sg);
      b_z2[k] += sf;
    }
  }
  // -coef zn (ZZ(n + hi) - ZZ(n + lo))
  void add_zn(double coef, R_xlen_t lo, R_xlen_t hi) {
    zn_z[slot(hi)] -= coef;
    zn_z[slot(lo)] += coef;
  }
};

inline double qk(R_xlen_t k) { return 0.5 * static_cast<double>(k) * (k + 1); }

// a b exactly, as a double-double
inline allanvar::DD dd_prod(double a, double b) {
  double p, e;
  allanvar::dd_two_prod(a, b, p, e);
  return allanvar::DD(p, e);
}

// sum over t in [a, b] of the polynomial f of degree <= d (d <= 4) in
// O(d^2) instead of O(b - a): Newton's forward differences at a times
// binomial coefficients, sum_j Delta^j f(a) C(b - a + 1, j + 1), in
// double-double (f's values are integers below 2^100, so the differences
// are exact and the result is the correctly rounded sum but for ~1e-30)
template <class F>
double poly_sum(R_xlen_t a, R_xlen_t b, int d, F f) {
  using allanvar::DD;
  if (b < a) return 0.0;
  const double n = static_cast<double>(b - a + 1);
  DD v[5];
  for (int i = 0; i <= d; ++i) v[i] = f(a + i);
  for (int j = 1; j <= d; ++j)
    for (int i = d; i >= j; --i) v[i] = v[i] - v[i - 1];
  DD tot, ff(1.0);
  double fact = 1;
  for (int j = 0; j <= d; ++j) {
    ff = ff * (n - j);      // n (n - 1) ... (n - j), exact below 2^106
    fact *= (j + 1);        // (j + 1)!
    DD t = v[j] * ff;
    // t / fact to double-double accuracy
    const double q1 = t.hi / fact;
    const DD r = t - dd_prod(q1, fact);
    tot = tot + (DD(q1) + DD(r.hi / fact));
  }
  return tot.value();
}

// index state: 0 below 0 (S = 0), 1 inside [0, 3m-1], 2 above (S = T)
inline int state(R_xlen_t i, R_xlen_t n3) { return i < 0 ? 0 : (i < n3 ? 1 : 2); }

// Adds w * sum_t [T S_{i1} + T S_{i2} - 2 S_{i1} S_{i2}] over t in [t0, t1],
// i1 = t, i2 = sgn * t + off (sgn = 1: SAME with lag c = -off; -1: ANTI,
// e = off), splitting t where an index changes state.
void add_gf(Plan& P, double w, R_xlen_t t0, R_xlen_t t1, int sgn, R_xlen_t off,
            R_xlen_t n3) {
  std::vector<R_xlen_t> cut = {t0, t1 + 1, 0, n3};
  if (sgn == 1) {
    cut.push_back(-off);
    cut.push_back(n3 - off);
  } else {
    cut.push_back(off + 1);
    cut.push_back(off - n3 + 1);
  }
  std::sort(cut.begin(), cut.end());
  cut.erase(std::unique(cut.begin(), cut.end()), cut.end());
  for (size_t z = 0; z + 1 < cut.size(); ++z) {
    const R_xlen_t a = std::max(cut[z], t0), b = std::min(cut[z + 1] - 1, t1);
    if (a > b) continue;
    const R_xlen_t cnt = b - a + 1;
    const int s1 = state(a, n3), s2 = state(sgn * a + off, n3);
    // i2's k-range over the piece
    const R_xlen_t k2a = std::min(sgn * a + off, sgn * b + off);
    const R_xlen_t k2b = std::max(sgn * a + off, sgn * b + off);
    auto ts = [&](double cf, R_xlen_t ka, R_xlen_t kb) {
      PlanItem it{ITEM_TS, cf, ka, kb, 0, 0, 0, 0};
      P.items.push_back(it);
    };
    // T S_{i1} + T S_{i2}
    if (s1 == 1) ts(w, a, b);
    if (s1 == 2) P.tt += w * cnt;
    if (s2 == 1) ts(w, k2a, k2b);
    if (s2 == 2) P.tt += w * cnt;
    // -2 S_{i1} S_{i2}
    if (s1 == 0 || s2 == 0) continue;
    if (s1 == 2 && s2 == 2) {
      P.tt -= 2 * w * cnt;
    } else if (s1 == 2) {
      ts(-2 * w, k2a, k2b);
    } else if (s2 == 2) {
      ts(-2 * w, a, b);
    } else {
      PlanItem it{sgn == 1 ? ITEM_SAME : ITEM_ANTI, -2 * w, a, b,
                  sgn == 1 ? -off : off, 0, 0, 0};
      P.items.push_back(it);
    }
  }
}

Plan make_plan(R_xlen_t m) {
  const R_xlen_t n3 = 3 * m;
  Plan P;
  P.tt = 2.0 * (3.0 * m - 24.0 * m);
  const double wf[3] = {-10, 15, -6};
  for (int i = 0; i < 3; ++i) {
    const R_xlen_t c = i * m;
    add_gf(P, 2 * wf[i], 0, n3 - 1 + c, 1, -c, n3);
  }
  const double wh[5] = {7.5, -3, 1, -3, 7.5};
  for (int i = 1; i <= 5; ++i) {
    const R_xlen_t e = i * m - 2;
    const R_xlen_t t0 = std::min<R_xlen_t>(0, e - n3 + 1);
    const R_xlen_t t1 = std::max<R_xlen_t>(n3 - 1, e);
    P.tt += 2 * wh[i - 1] * (t1 - t0 + 1);
    add_gf(P, -2 * wh[i - 1], t0, t1, -1, e, n3);
  }
  for (PlanItem& it : P.items) {
    if (it.kind == ITEM_TS) {
      it.q1 = poly_sum(it.a, it.b, 2, [](R_xlen_t k) { return allanvar::DD(qk(k)); });
      P.ts_c1 += it.coef * static_cast<double>(it.b - it.a + 1);
      P.ts_c2 += it.coef * it.q1;
      // W(n + a + 1, n + b + 1) = ZZ(n + b + 2) - ZZ(n + a + 1)
      for (int z = 0; z < 2; ++z) {
        const R_xlen_t o = z == 0 ? it.b + 2 : it.a + 1;
        const double wv = z == 0 ? it.coef : -it.coef;
        size_t k = 0;
        while (k < P.ts_off.size() && P.ts_off[k] != o) ++k;
        if (k == P.ts_off.size()) {
          P.ts_off.push_back(o);
          P.ts_w.push_back(0.0);
        }
        P.ts_w[k] += wv;
      }
    } else if (it.kind == ITEM_SAME) {
      const R_xlen_t c = it.c;
      it.q1 = poly_sum(it.a, it.b, 2, [](R_xlen_t t) { return allanvar::DD(qk(t)); });
      it.q2 = poly_sum(it.a, it.b, 2, [c](R_xlen_t t) { return allanvar::DD(qk(t - c)); });
      it.qq = poly_sum(it.a, it.b, 4, [c](R_xlen_t t) { return dd_prod(qk(t), qk(t - c)); });
    } else {
      const R_xlen_t c = it.c;
      it.q1 = poly_sum(it.a, it.b, 2, [](R_xlen_t t) { return allanvar::DD(qk(t)); });
      it.q2 = poly_sum(it.a, it.b, 2, [c](R_xlen_t t) { return allanvar::DD(qk(c - t)); });
      it.qq = poly_sum(it.a, it.b, 4, [c](R_xlen_t t) { return dd_prod(qk(t), qk(c - t)); });
    }
  }
  std::vector<PlanItem> rest;
  for (const PlanItem& it : P.items)
    if (it.kind != ITEM_TS) rest.push_back(it);
  P.items.swap(rest);
  for (const PlanItem& it : P.items) {
    const double K = it.coef, cnt = static_cast<double>(it.b - it.a + 1);
    const R_xlen_t a = it.a, b = it.b;
    P.czz += K * cnt;
    P.cbb += K * it.qq;
    P.cbz += K * (it.q1 + it.q2);
    if (it.kind == ITEM_SAME) {
      const R_xlen_t c = it.c;
      P.l_lag.push_back(static_cast<int>(c / m));
      P.l_off.push_back(b + 2);
      P.l_w.push_back(K);
      P.l_lag.push_back(static_cast<int>(c / m));
      P.l_off.push_back(a + 1);
      P.l_w.push_back(-K);
      P.add_zn(K, a + 1, b + 2);
      P.add_zn(K, a + 1 - c, b + 2 - c);
      P.add_mq(K, static_cast<double>(1 - c), 1, a + 1 - c, b + 2 - c);
      P.add_mq(K, static_cast<double>(1 + c), 1, a + 1, b + 2);
    } else {
      const R_xlen_t e = it.c;
      P.add_zn(K, a + 1, b + 2);
      P.add_zn(K, e + 1 - b, e + 2 - a);
      P.add_mq(K, static_cast<double>(e + 1), -1, e + 1 - b, e + 2 - a);
      P.add_mq(K, static_cast<double>(e + 1), -1, a + 1, b + 2);
    }
  }
  // offsets whose weights cancelled exactly (integers) are dropped
  std::vector<R_xlen_t> off;
  std::vector<double> wt;
  for (size_t k = 0; k < P.ts_off.size(); ++k) {
    if (P.ts_w[k] != 0) {
      off.push_back(P.ts_off[k]);
      wt.push_back(P.ts_w[k]);
    }
  }
  P.ts_off.swap(off);
  P.ts_w.swap(wt);
  return P;
}

#if defined(__GNUC__)
using allanvar::v2d;
using allanvar::ld2;
inline double hsum(v2d v) { return v[0] + v[1]; }
#endif

// d = sums over n < nb of T T, T Z, T B, Z Z, Z B, B B
inline void dots6(const double* T, const double* Z, const double* B,
                  R_xlen_t nb, double* d) {
  for (int k = 0; k < 6; ++k) d[k] = 0;
  R_xlen_t n = 0;
#if defined(__GNUC__)
  v2d a[6] = {};
  for (; n + 2 <= nb; n += 2) {
    const v2d t = ld2(T + n), z = ld2(Z + n), b = ld2(B + n);
    a[0] += t * t;
    a[1] += t * z;
    a[2] += t * b;
    a[3] += z * z;
    a[4] += z * b;
    a[5] += b * b;
  }
  for (int k = 0; k < 6; ++k) d[k] = hsum(a[k]);
#endif
  for (; n < nb; ++n) {
    d[0] += T[n] * T[n];
    d[1] += T[n] * Z[n];
    d[2] += T[n] * B[n];
    d[3] += Z[n] * Z[n];
    d[4] += Z[n] * B[n];
    d[5] += B[n] * B[n];
  }
}

// d = sums over n < nb of Z zz, B zz, B1 zz, B2 zz, B m1, B1 m1, B m2
inline void dots7(const double* Z, const double* B, const double* B1,
                  const double* B2, const double* zz, const double* m1,
                  const double* m2, R_xlen_t nb, double* d) {
  for (int k = 0; k < 7; ++k) d[k] = 0;
  R_xlen_t n = 0;
#if defined(__GNUC__)
  v2d a[7] = {};
  for (; n + 2 <= nb; n += 2) {
    const v2d q = ld2(zz + n), p = ld2(m1 + n), b = ld2(B + n),
              b1 = ld2(B1 + n);
    a[0] += ld2(Z + n) * q;
    a[1] += b * q;
    a[2] += b1 * q;
    a[3] += ld2(B2 + n) * q;
    a[4] += b * p;
    a[5] += b1 * p;
    a[6] += b * ld2(m2 + n);
  }
  for (int k = 0; k < 7; ++k) d[k] = hsum(a[k]);
#endif
  for (; n < nb; ++n) {
    d[0] += Z[n] * zz[n];
    d[1] += B[n] * zz[n];
    d[2] += B1[n] * zz[n];
    d[3] += B2[n] * zz[n];
    d[4] += B[n] * m1[n];
    d[5] += B1[n] * m1[n];
    d[6] += B[n] * m2[n];
  }
}

inline double dot(const double* x, const double* y, R_xlen_t n) {
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  R_xlen_t i = 0;
  for (; i + 4 <= n; i += 4) {
    s0 += x[i] * y[i];
    s1 += x[i + 1] * y[i + 1];
    s2 += x[i + 2] * y[i + 2];
    s3 += x[i + 3] * y[i + 3];
  }
  for (; i < n; ++i) s0 += x[i] * y[i];
  return (s0 + s1) + (s2 + s3);
}

// Uninitialised, huge-page backed (src/scratch.h), sized once per call for
// the largest sub-block: growing std::vectors tau by tau cost as much in
// copies, zero fills and page faults as the sums themselves at 1e6.
struct FastScratch {
  allanvar::Scratch r, Z, ZZ, M1, M2, PE, T, B, B1, B2;
  allanvar::Scratch LP[3];  // lags 0, m, 2m
  void reserve(R_xlen_t len) {  // a sub-block of len local phase points
    const std::size_t n = static_cast<std::size_t>(len) + 3;
    for (allanvar::Scratch* v : {&r, &Z, &ZZ, &M1, &M2, &PE, &T, &B, &B1, &B2,
                                 &LP[0], &LP[1], &LP[2]})
      v->resize(n);
  }
};

// Sum of Q over windows n in [0, nb) of the local series z (3m values per
// window).
double block_q_fast(const double* z, R_xlen_t nb, R_xlen_t m, const Plan& P,
                    FastScratch& w) {
  const R_xlen_t n3 = 3 * m, Lz = nb + n3 - 1;
  const R_xlen_t h = n3 / 2;
  // every prefix array in one pass (independent chains side by side):
  // Z, and over u <= Lz: ZZ, M1, M2 (sums of u^j Z(u)), PE (every other
  // index, two zeros first: PE[v + 2] = Z(v) + Z(v - 2) + ...) and the lag
  // products Z(u) Z(u - c), c = 0, m, 2m
  w.Z.resize(Lz + 1);
  w.ZZ.resize(Lz + 2);
  w.M1.resize(Lz + 2);
  w.M2.resize(Lz + 2);
  w.PE.resize(Lz + 3);
  for (int i = 0; i < 3; ++i) w.LP[i].resize(Lz + 2);
  {
    double* Zp = w.Z.data();
    double* zz = w.ZZ.data();
    double* m1 = w.M1.data();
    double* m2 = w.M2.data();
    double* pe = w.PE.data();
    double* l0 = w.LP[0].data();
    double* l1 = w.LP[1].data();
    double* l2 = w.LP[2].data();
    Zp[0] = zz[0] = m1[0] = m2[0] = pe[0] = pe[1] = 0;
    l0[0] = l1[0] = l2[0] = 0;
    for (R_xlen_t u = 0; u <= Lz; ++u) {
      if (u < Lz) Zp[u + 1] = Zp[u] + z[u];
      const double zu = Zp[u], du = static_cast<double>(u);
      zz[u + 1] = zz[u] + zu;
      m1[u + 1] = m1[u] + du * zu;
      m2[u + 1] = m2[u] + du * du * zu;
      pe[u + 2] = zu + pe[u];
      l0[u + 1] = l0[u] + zu * zu;
      l1[u + 1] = l1[u] + (u >= m ? zu * Zp[u - m] : 0.0);
      l2[u + 1] = l2[u] + (u >= 2 * m ? zu * Zp[u - 2 * m] : 0.0);
    }
  }
  const allanvar::Scratch& Z = w.Z;
  const double* ZZ = w.ZZ.data();
  const double* M1 = w.M1.data();
  const double* M2 = w.M2.data();
  const double bden = static_cast<double>(h) * static_cast<double>(n3 - h);
  // per window: Z(n), the slope beta_n and T_n; the merged plan is a sum
  // over windows of these (and of beta_n n, beta_n n^2) times a few dozen
  // places of ZZ, M1, M2 and the lag products at about seven distinct
  // offsets, so it is summed as dot products over the windows, one pass per
  // offset (vectorised), and combined with the plan's weights once
  w.T.resize(nb);
  w.B.resize(nb);
  w.B1.resize(nb);
  w.B2.resize(nb);
  double* Tn = w.T.data();
  double* Bn = w.B.data();
  double* B1 = w.B1.data();
  double* B2 = w.B2.data();
  const double q3 = qk(n3 - 1);
  for (R_xlen_t n = 0; n < nb; ++n) {
    const double beta =
        ((Z[n + n3] - Z[n + n3 - h]) - (Z[n + h] - Z[n])) / bden;
    const double dn = static_cast<double>(n);
    Bn[n] = beta;
    B1[n] = beta * dn;
    B2[n] = B1[n] * dn;
    Tn[n] = (Z[n + n3] - Z[n]) - beta * q3;
  }
  const double* Zn = Z.data();
  double total = 0;
  {
    // the per-window quadratic terms
    double d[6];
    dots6(Tn, Zn, Bn, nb, d);
    total += P.tt * d[0] - P.ts_c1 * d[1] - P.ts_c2 * d[2] + P.czz * d[3] +
             P.cbz * d[4] + P.cbb * d[5];
  }
  for (size_t k = 0; k < P.ts_off.size(); ++k)
    total += P.ts_w[k] * dot(Tn, ZZ + P.ts_off[k], nb);
  for (size_t k = 0; k < P.off.size(); ++k) {
    const double* zo = ZZ + P.off[k];
    const double* m1o = M1 + P.off[k];
    const double* m2o = M2 + P.off[k];
    double d[7];
    dots7(Zn, Bn, B1, B2, zo, m1o, m2o, nb, d);
    total += P.zn_z[k] * d[0] + P.b_z0[k] * d[1] + P.b_z1[k] * d[2] +
             P.b_z2[k] * d[3] + P.b_m10[k] * d[4] + P.b_m11[k] * d[5] +
             P.b_m2[k] * d[6];
  }
  for (size_t k = 0; k < P.l_off.size(); ++k) {
    const double* lp = w.LP[P.l_lag[k]].data() + P.l_off[k];
    double s0 = 0, s1 = 0;
    R_xlen_t n = 0;
    for (; n + 2 <= nb; n += 2) {
      s0 += lp[n];
      s1 += lp[n + 1];
    }
    if (n < nb) s0 += lp[n];
    total += P.l_w[k] * (s0 + s1);
  }
  // anti-diagonal sums: sum_n sum_{t in [a,b]} Z(n+t+1) Z(n+e+1-t) =
  // sum_u Z(u) (Z(v0) + Z(v0 + 2) + ... + Z(v1)), n = u - 1 - t in
  // [lo, hi] = [max(0, u - 1 - b), min(nb - 1, u - 1 - a)], v = 2n + e + 2 - u:
  // both ends linear in u between the cuts u = b + 1 and u = nb + a + 1
  const double* PE = w.PE.data();
  const double* Zd = Z.data();
  for (const PlanItem& it : P.items) {
    if (it.kind != ITEM_ANTI) continue;
    const R_xlen_t a = it.a, b = it.b, e = it.c;
    const R_xlen_t u_end = nb + b + 1;
    R_xlen_t cuts[4] = {a + 1, std::min(b + 1, u_end), std::min(nb + a + 1, u_end),
                        u_end};
    if (cuts[1] > cuts[2]) std::swap(cuts[1], cuts[2]);
    double s = 0;
    for (int g = 0; g < 3; ++g) {
      const R_xlen_t u0 = std::max(cuts[g], a + 1), u1 = cuts[g + 1];
      if (u0 >= u1) continue;
      // lo = 0 below u = b + 1, hi = u - 1 - a up to u = nb + a
      const bool lo0 = u0 <= b, hil = u0 <= nb + a;
      // PE[v1 + 2] - PE[v0] with v0 = k0 + d0 u, v1 + 2 = k1 + d1 u
      const R_xlen_t k0 = lo0 ? e + 2 : e - 2 * b, d0 = lo0 ? -1 : 1;
      const R_xlen_t k1 = hil ? e - 2 * a + 2 : 2 * nb + e + 2, d1 = hil ? 1 : -1;
      double s0 = 0, s1 = 0;
      R_xlen_t u = u0;
      for (; u + 2 <= u1; u += 2) {
        s0 += Zd[u] * (PE[k1 + d1 * u] - PE[k0 + d0 * u]);
        s1 += Zd[u + 1] * (PE[k1 + d1 * (u + 1)] - PE[k0 + d0 * (u + 1)]);
      }
      if (u < u1) s0 += Zd[u] * (PE[k1 + d1 * u] - PE[k0 + d0 * u]);
      s += s0 + s1;
    }
    total += it.coef * s;
  }
  return total;
}

}  // namespace

// Sum over windows of Q for every m (MTOT when hadamard is FALSE: windows of
// phase, L - 3m + 1 of them; HTOT when TRUE: windows of frequency (phase
// increments), L - 3m of them), one channel. method: 0 chooses (the closed
// form from m = kFastFrom), 1 the direct O(m) per window, 2 the closed form.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector total_sums_cpp(const Rcpp::NumericVector& v, bool rate,
                                   const Rcpp::NumericVector& m, bool hadamard,
                                   int threads, int method = 0) {
  const allanvar::InterruptScope scope;
  const allanvar::PhaseInput in{v.begin(), v.size(), rate};
  const R_xlen_t L = in.length();
  const std::vector<double> ms(m.begin(), m.end());
  std::vector<Item> items;
  for (size_t t = 0; t < ms.size(); ++t) {
    const R_xlen_t mm = static_cast<R_xlen_t>(ms[t]);
    const R_xlen_t nwin = hadamard ? L - 3 * mm : L - 3 * mm + 1;
    if (mm < 1 || nwin < 1) continue;
    // direct: about 2^16 m work per item; closed form: whole sub-blocks
    // of 4m windows (its cost per sub-block is O(m))
    const bool fst = method == 2 || (method == 0 && mm >= kFastFrom);
    const R_xlen_t B = fst ? 4 * mm * std::max<R_xlen_t>(1, 4096 / mm)
                           : std::max<R_xlen_t>(1, (R_xlen_t(1) << 16) / mm);
    for (R_xlen_t n0 = 0; n0 < nwin; n0 += B)
      items.push_back(Item{t, n0, std::min(nwin, n0 + B)});
  }
  std::vector<double> part(items.size(), 0.0);
  const int nw = std::max(1, threads);
  std::vector<Scratch> scratch(nw);
  std::vector<FastScratch> fscratch(nw);
  std::vector<Plan> plans(ms.size());
  std::vector<bool> fast(ms.size(), false);
  for (size_t t = 0; t < ms.size(); ++t) {
    const R_xlen_t mm = static_cast<R_xlen_t>(ms[t]);
    fast[t] = method == 2 || (method == 0 && mm >= kFastFrom);
    // a plan costs O(m): with taus = "all" the plans alone take minutes
    if (allanvar::interrupted()) scope.finish();
    if (fast[t] && mm >= 1) plans[t] = make_plan(mm);
  }
  // the phase once, split hi + lo, for the closed form's sub-blocks
  allanvar::SplitPhase X;
  bool any_fast = false;
  for (const Item& I : items) any_fast = any_fast || fast[I.tau];
  if (any_fast) allanvar::split_phase(in, X);
  R_xlen_t fast_len = 0;  // the longest sub-block's local phase
  for (const Item& I : items) {
    if (!fast[I.tau]) continue;
    const R_xlen_t mm = static_cast<R_xlen_t>(ms[I.tau]);
    fast_len = std::max(fast_len, std::min(I.n1 - I.n0, 4 * mm) + 3 * mm);
  }
  if (fast_len > 0)
    for (FastScratch& fs : fscratch) fs.reserve(fast_len);
  allanvar::parallel_for(static_cast<R_xlen_t>(items.size()), nw,
                         [&](R_xlen_t it, int w) {
    const Item& I = items[it];
    const R_xlen_t mm = static_cast<R_xlen_t>(ms[I.tau]);
    const R_xlen_t nb = I.n1 - I.n0;
    Scratch& sc = scratch[w];
    if (fast[I.tau]) {
      // sub-blocks of 4m windows, each on its own local phase
      FastScratch& fs = fscratch[w];
      double acc = 0;
      for (R_xlen_t b0 = I.n0; b0 < I.n1; b0 += 4 * mm) {
        const R_xlen_t nsub = std::min(I.n1 - b0, 4 * mm);
        const R_xlen_t len = nsub + 3 * mm - (hadamard ? 0 : 1);
        fs.r.resize(len);
        allanvar::local_from_split(X, b0, len, fs.r.data());
        if (hadamard) {
          // frequency, with its least-squares line removed: each window's
          // own line absorbs it (HTOT ignores a linear frequency term), and
          // a drift then leaves no large offsets to cancel
          const R_xlen_t nz = len - 1;
          for (R_xlen_t i = 0; i < nz; ++i) fs.r[i] = fs.r[i + 1] - fs.r[i];
          const double mid = 0.5 * static_cast<double>(nz - 1);
          double s0 = 0, s1 = 0, s2 = 0;
          for (R_xlen_t i = 0; i < nz; ++i) {
            const double t = static_cast<double>(i) - mid;
            s0 += fs.r[i];
            s1 += t * fs.r[i];
            s2 += t * t;
          }
          const double a = s0 / static_cast<double>(nz), b = s2 > 0 ? s1 / s2 : 0;
          for (R_xlen_t i = 0; i < nz; ++i)
            fs.r[i] -= a + b * (static_cast<double>(i) - mid);
        }
        acc += block_q_fast(fs.r.data(), nsub, mm, plans[I.tau], fs);
      }
      part[it] = acc;
      return;
    }
    const R_xlen_t len = nb + 3 * mm - (hadamard ? 0 : 1);
    sc.r.resize(len);
    allanvar::local_phase(in, I.n0, len, sc.r.data());
    sc.s.resize(3 * mm);
    double acc = 0;
    for (R_xlen_t n = 0; n < nb; ++n) {
      const double* r = sc.r.data() + n;
      if (hadamard) {
        for (R_xlen_t t = 0; t < 3 * mm; ++t) sc.s[t] = r[t + 1] - r[t];
      } else {
        for (R_xlen_t t = 0; t < 3 * mm; ++t) sc.s[t] = r[t];
      }
      acc += window_q(sc.s.data(), mm, sc);
    }
    part[it] = acc;
  });
  Rcpp::NumericVector out(ms.size(), NA_REAL);
  allanvar::TauSums sums(ms.size());
  for (size_t it = 0; it < items.size(); ++it) sums.add(items[it].tau, part[it]);
  for (size_t t = 0; t < ms.size(); ++t)
    if (sums.any(t)) out[t] = sums.value(t);
  return out;
}
