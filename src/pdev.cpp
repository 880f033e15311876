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

}  // namespace

// Sums of (2 S_i)^2 (m >= 2) or of squared second differences (m = 1) over
// the terms of every m, for one channel.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector pdev_sums_cpp(const Rcpp::NumericVector& v, bool rate,
                                  const Rcpp::NumericVector& m, int threads) {
  const allanvar::PhaseInput in{v.begin(), v.size(), rate};
  const R_xlen_t L = in.length();
  const std::vector<double> ms(m.begin(), m.end());
  std::vector<Item> items;
  for (size_t t = 0; t < ms.size(); ++t) {
    const R_xlen_t mm = static_cast<R_xlen_t>(ms[t]);
    const R_xlen_t M = mm == 1 ? L - 2 : L - 2 * mm;
    if (mm < 1 || M < 1) continue;
    // blocks of a few m: the prefix sums then cancel by at most (span/m)^2.5
    const R_xlen_t B = std::max<R_xlen_t>(2 * mm, std::min<R_xlen_t>(1024, 32 * mm));
    for (R_xlen_t i0 = 0; i0 < M; i0 += B)
      items.push_back(Item{t, i0, std::min(M, i0 + B)});
  }
  std::vector<double> part(items.size(), 0.0);
  const int nw = std::max(1, threads);
  std::vector<std::vector<double> > pbuf(nw), ppbuf(nw), fbuf(nw);
  // the phase once, split hi + lo; each block re-centres it (its first
  // point and the chord's slope removed), exact differences on the hi grid
  allanvar::SplitPhase X;
  allanvar::split_phase(in, X);
  const double* hx = X.hi.data();
  const double* lx = X.lo.data();
  allanvar::parallel_for(static_cast<R_xlen_t>(items.size()), nw,
                         [&](R_xlen_t it, int w) {
    const Item& I = items[it];
    const R_xlen_t mm = static_cast<R_xlen_t>(ms[I.tau]);
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
    const R_xlen_t len = nb + 2 * mm - 1;  // phase points used
    const double slope = ((hx[a + len - 1] - hx[a]) + (lx[a + len - 1] - lx[a])) /
                         static_cast<double>(len - 1);
    std::vector<double>& P = pbuf[w];
    std::vector<double>& PP = ppbuf[w];
    std::vector<double>& F = fbuf[w];
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
    part[it] = s0 + s1;
  });
  Rcpp::NumericVector out(ms.size(), NA_REAL);
  std::vector<double> tot(ms.size(), 0.0), cor(ms.size(), 0.0);
  std::vector<bool> any(ms.size(), false);
  for (size_t it = 0; it < items.size(); ++it) {
    const size_t t = items[it].tau;
    double s, e;
    allanvar::phase_two_sum(tot[t], part[it], s, e);
    tot[t] = s;
    cor[t] += e;
    any[t] = true;
  }
  for (size_t t = 0; t < ms.size(); ++t)
    if (any[t]) out[t] = tot[t] + cor[t];
  return out;
}
