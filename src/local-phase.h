// Local phase segments for the kernels of the further statistics (TIE,
// PDEV, the Total family, Theo1). Every one of those statistics is built
// from phase differences over a bounded span, so a kernel works block by
// block on x(a + j) - x(a) - c j, accumulated from the increments with
// compensated sums: however large the frequency offset or the record, the
// values stay of the size of the local phase wander and lose nothing to a
// global running sum. The statistics that ignore a linear phase term (PDEV,
// the Total family, Theo1) use the values as they are; TIE adds c j back.
#ifndef ALLANVAR_LOCAL_PHASE_H
#define ALLANVAR_LOCAL_PHASE_H

#include <Rcpp.h>
#include "dd.h"
#include "scratch.h"
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace allanvar {

// Per-tau totals of partial sums (one per work item), each compensated
// (TwoSum), so that the order of the items does not matter beyond 1e-16.
class TauSums {
 public:
  explicit TauSums(size_t nt) : s_(nt, 0.0), e_(nt, 0.0), any_(nt, false) {}
  void add(size_t t, double v) {
    double s, e;
    two_sum(s_[t], v, s, e);
    s_[t] = s;
    e_[t] += e;
    any_[t] = true;
  }
  bool any(size_t t) const { return any_[t]; }
  double value(size_t t) const { return s_[t] + e_[t]; }

 private:
  std::vector<double> s_, e_;
  std::vector<bool> any_;
};

#if defined(__GNUC__)
// Two doubles per SSE2 vector (GCC/Clang vector extensions; baseline
// x86-64 has SSE2), loaded from any address.
typedef double v2d __attribute__((vector_size(16)));
inline v2d ld2(const double* p) {
  v2d v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void st2(double* p, v2d v) { std::memcpy(p, &v, sizeof v); }
#endif

// The input as a phase sequence: rate samples y (x(0) = 0, x(j) = y(0) +
// ... + y(j - 1), L = N + 1 points; the caller scales by tau0) or the
// integrated values themselves (L = N).
struct PhaseInput {
  const double* v;
  R_xlen_t n;  // samples
  bool rate;
  R_xlen_t length() const { return rate ? n + 1 : n; }
  // increment x(i + 1) - x(i) as hi + lo, exactly
  void increment(R_xlen_t i, double& hi, double& lo) const {
    if (rate) {
      hi = v[i];
      lo = 0;
    } else {
      two_sum(v[i + 1], -v[i], hi, lo);
    }
  }
};

// out[j] = x(a + j) - x(a) - c j for j in [0, len), with c the mean
// increment over the segment (returned). The increments are exact
// (TwoSum); the running sum is compensated, so out[] is the rounded exact
// value of that difference.
inline double local_phase(const PhaseInput& in, R_xlen_t a, R_xlen_t len,
                          double* out) {
  if (len <= 0) return 0.0;
  double c = 0;
  if (len > 1) {
    // the mean increment, from the end points (any double c would do)
    double s = 0, e = 0;
    for (R_xlen_t l = 0; l < len - 1; ++l) {
      double h, lo, t, te;
      in.increment(a + l, h, lo);
      two_sum(s, h, t, te);
      s = t;
      e += te + lo;
    }
    c = (s + e) / static_cast<double>(len - 1);
  }
  double s = 0, e = 0;
  out[0] = 0;
  for (R_xlen_t l = 0; l < len - 1; ++l) {
    double h, lo, r, re, t, te;
    in.increment(a + l, h, lo);
    two_sum(h, -c, r, re);
    two_sum(s, r, t, te);
    s = t;
    e += te + re + lo;
    out[l + 1] = s + e;
  }
  return c;
}

// The whole phase as hi + lo with the mean increment c removed:
// X(j) = x(j) - x(0) - c j. hi lies on a grid of step q = 2^k with
// |hi| <= 2^50 q, so integer combinations of hi with total weight <= 8 are
// exact in double; lo (|lo| <= q/2) carries the rest. One compensated pass.
struct SplitPhase {
  Scratch hi, lo;  // 2 x 8 MB at 1e6: huge pages where granted
  double c = 0;  // removed slope per sample
  R_xlen_t size() const { return static_cast<R_xlen_t>(hi.size()); }
  double value(R_xlen_t j) const { return hi[j] + lo[j]; }
};

// The two passes of split_phase(): f(j, hi, lo, c) for j = 1..L-1 (X(0) =
// 0); returns c. Kernels that need X(j) once take it from here without the
// arrays.
template <class F>
inline double split_phase_each(const PhaseInput& in, F f) {
  const R_xlen_t L = in.length();
  if (L < 2) return 0.0;
  double s = 0, e = 0, bmin = 0, bmax = 0;
  for (R_xlen_t l = 0; l < L - 1; ++l) {
    double h, lo, t, te;
    in.increment(l, h, lo);
    if (l == 0 || h < bmin) bmin = h;
    if (l == 0 || h > bmax) bmax = h;
    two_sum(s, h, t, te);
    s = t;
    e += te + lo;
  }
  const double c = (s + e) / static_cast<double>(L - 1);
  double bound = std::max(std::fabs(bmax - c), std::fabs(bmin - c)) + 1e-300;
  bound *= static_cast<double>(L) * (1 + 1e-9);
  int ex;
  std::frexp(bound, &ex);
  const double q = std::ldexp(1.0, ex - 50);
  const double C = 1.5 * q * 4503599627370496.0;  // ulp(C) = q
  s = 0;
  e = 0;
  for (R_xlen_t l = 0; l < L - 1; ++l) {
    double h, lo, r, re, t, te;
    in.increment(l, h, lo);
    two_sum(h, -c, r, re);
    two_sum(s, r, t, te);
    s = t;
    e += te + re + lo;
    const double g = (s + C) - C;
    f(l + 1, g, (s - g) + e, c);
  }
  return c;
}

inline void split_phase(const PhaseInput& in, SplitPhase& out) {
  const R_xlen_t L = in.length();
  out.hi.resize(L);
  out.lo.resize(L);
  out.c = 0;
  if (L < 1) return;
  out.hi[0] = out.lo[0] = 0.0;
  double* hi = out.hi.data();
  double* lo = out.lo.data();
  out.c = split_phase_each(in, [hi, lo](R_xlen_t j, double h, double l,
                                         double) {
    hi[j] = h;
    lo[j] = l;
  });
}

// out[j] = X(a + j) - X(a) - d j, j < len, from the split phase, d the
// chord's slope: local_phase()'s values (a line apart, which the
// statistics ignore; rounded alike) in one vectorisable pass, the
// differences of hi being exact.
inline void local_from_split(const SplitPhase& X, R_xlen_t a, R_xlen_t len,
                             double* out) {
  if (len <= 0) return;
  const double* h = X.hi.data() + a;
  const double* l = X.lo.data() + a;
  const double h0 = h[0], l0 = l[0];
  const double d =
      len > 1 ? ((h[len - 1] - h0) + (l[len - 1] - l0)) /
                    static_cast<double>(len - 1)
              : 0.0;
  for (R_xlen_t j = 0; j < len; ++j)
    out[j] = ((h[j] - h0) + (l[j] - l0)) - d * static_cast<double>(j);
}

}  // namespace allanvar

#endif
