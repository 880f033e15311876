// Time interval error statistics of allan(type = "mtie" / "tierms").
//  * MTIE(m): the largest peak-to-peak phase excursion within any window of
//    m + 1 consecutive phase points (ITU-T G.810; NIST SP 1065 sec. 5.2.18;
//    Stable32's "MTIE"), by a sparse table of window maxima and minima:
//    level k holds max/min over 2^k points, built from level k - 1 in one
//    pass, and a window of m + 1 points is the union of two level-k windows,
//    k = floor(log2(m + 1)) (Bregni & Maccabruni's binary decomposition,
//    generalised to any m). O(N log N) for a whole grid, O(N) memory.
//  * TIE rms(m): sqrt of the mean of (x(i + m) - x(i))^2 over the N - m
//    pairs (SP 1065 sec. 5.2.19; Stable32's "TIE rms").
#include "local-phase.h"
#include "parallel.h"
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace {

#if defined(__GNUC__)
using allanvar::v2d;
using allanvar::ld2;
using allanvar::st2;
#endif

// Compensated total of block sums.
struct Total {
  double s = 0, c = 0;
  void add(double v) {
    double t, e;
    allanvar::two_sum(s, v, t, e);
    s = t;
    c += e;
  }
  double value() const { return s + c; }
};

}  // namespace

// MTIE at cluster sizes m (sorted ascending, 1 <= m <= L - 1) of one
// channel: the peak-to-peak phase over windows of m + 1 points, in the
// phase unit (rate input: sums of samples; the caller scales by tau0).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector mtie_cpp(const Rcpp::NumericVector& v, bool rate,
                             const Rcpp::NumericVector& m) {
  const allanvar::InterruptScope scope;
  const allanvar::PhaseInput in{v.begin(), v.size(), rate};
  const R_xlen_t L = in.length();
  // the phase X(j) + c j (src/local-phase.h), straight into the two tables
  allanvar::Scratch mx(L), mn(L);
  if (L > 0) mx[0] = mn[0] = 0.0;
  {
    double* px = mx.data();
    double* pn = mn.data();
    allanvar::split_phase_each(
        in, [px, pn](R_xlen_t j, double h, double l, double c) {
          px[j] = pn[j] = (h + l) + c * static_cast<double>(j);
        });
  }
  const R_xlen_t nt = m.size();
  Rcpp::NumericVector out(nt, NA_REAL);
  int level = 0;  // mx/mn hold max/min over 2^level points
  for (R_xlen_t t = 0; t < nt; ++t) {
    const R_xlen_t w = static_cast<R_xlen_t>(m[t]) + 1;  // window points
    if (w < 2 || w > L) continue;
    // each tau is one O(L) pass
    if (allanvar::interrupted()) scope.finish();
    while ((static_cast<R_xlen_t>(2) << level) <= w) {
      if (allanvar::interrupted()) scope.finish();
      const R_xlen_t h = static_cast<R_xlen_t>(1) << level;
      const R_xlen_t end = L - 2 * h + 1;  // windows of 2h points
      double* px = mx.data();
      double* pn = mn.data();
      R_xlen_t i = 0;
#if defined(__GNUC__)
      // two lanes at a time (ascending i reads i + h before it is written)
      for (; i + 2 <= end && h >= 2; i += 2) {
        const v2d a = ld2(px + i), b = ld2(px + i + h);
        const v2d c = ld2(pn + i), d = ld2(pn + i + h);
        st2(px + i, a > b ? a : b);
        st2(pn + i, c < d ? c : d);
      }
#endif
      for (; i < end; ++i) {
        px[i] = std::max(px[i], px[i + h]);
        pn[i] = std::min(pn[i], pn[i + h]);
      }
      ++level;
    }
    const R_xlen_t s = w - (static_cast<R_xlen_t>(1) << level);
    const double* px = mx.data();
    const double* pn = mn.data();
    const R_xlen_t nwin = L - w + 1;
    double best = 0;
    R_xlen_t i = 0;
#if defined(__GNUC__)
    v2d vb = {0, 0};
    for (; i + 2 <= nwin; i += 2) {
      const v2d a = ld2(px + i), b = ld2(px + i + s);
      const v2d c = ld2(pn + i), d = ld2(pn + i + s);
      const v2d r = (a > b ? a : b) - (c < d ? c : d);
      vb = r > vb ? r : vb;
    }
    best = std::max(vb[0], vb[1]);
#endif
    for (; i < nwin; ++i) {
      const double hi = std::max(px[i], px[i + s]);
      const double lo = std::min(pn[i], pn[i + s]);
      best = std::max(best, hi - lo);
    }
    out[t] = best;
  }
  return out;
}

// Sums of (x(i + m) - x(i))^2 over i in [0, L - m) for every m of one
// channel (the caller divides by L - m and scales by tau0^2 for rate input).
// x is split hi + lo (src/local-phase.h), so each difference is exact on the
// hi grid; taus are shared between threads.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector tierms_sums_cpp(const Rcpp::NumericVector& v, bool rate,
                                    const Rcpp::NumericVector& m, int threads) {
  const allanvar::PhaseInput in{v.begin(), v.size(), rate};
  allanvar::SplitPhase X;
  allanvar::split_phase(in, X);
  const R_xlen_t L = in.length();
  const std::vector<double> ms(m.begin(), m.end());
  const R_xlen_t nt = m.size();
  std::vector<double> res(nt, NA_REAL);
  const double* h = X.hi.data();
  const double* l = X.lo.data();
  const double c = X.c;
  allanvar::parallel_for(nt, threads, [&](R_xlen_t t, int) {
    const R_xlen_t mm = static_cast<R_xlen_t>(ms[t]);
    if (mm < 1 || mm >= L) return;
    const double cm = c * static_cast<double>(mm);
    Total tot;
    const R_xlen_t n = L - mm;
    for (R_xlen_t b0 = 0; b0 < n; b0 += 8192) {
      const R_xlen_t b1 = std::min(n, b0 + 8192);
      double s0 = 0, s1 = 0;
      R_xlen_t i = b0;
      for (; i + 2 <= b1; i += 2) {
        const double d0 = ((h[i + mm] - h[i]) + (l[i + mm] - l[i])) + cm;
        const double d1 =
            ((h[i + 1 + mm] - h[i + 1]) + (l[i + 1 + mm] - l[i + 1])) + cm;
        s0 += d0 * d0;
        s1 += d1 * d1;
      }
      for (; i < b1; ++i) {
        const double d = ((h[i + mm] - h[i]) + (l[i + mm] - l[i])) + cm;
        s0 += d * d;
      }
      tot.add(s0 + s1);
    }
    res[t] = tot.value();
  });
  return Rcpp::NumericVector(res.begin(), res.end());
}
