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
#include "local-phase.h"
#include "parallel.h"
#include <algorithm>
#include <cmath>
#include <vector>

namespace {

struct Item {
  size_t tau;
  R_xlen_t n0, n1;  // windows [n0, n1)
};

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

}  // namespace

// Sum over windows of Q for every m (MTOT when hadamard is FALSE: windows of
// phase, L - 3m + 1 of them; HTOT when TRUE: windows of frequency (phase
// increments), L - 3m of them), one channel.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector total_sums_cpp(const Rcpp::NumericVector& v, bool rate,
                                   const Rcpp::NumericVector& m, bool hadamard,
                                   int threads) {
  const allanvar::PhaseInput in{v.begin(), v.size(), rate};
  const R_xlen_t L = in.length();
  const std::vector<double> ms(m.begin(), m.end());
  std::vector<Item> items;
  for (size_t t = 0; t < ms.size(); ++t) {
    const R_xlen_t mm = static_cast<R_xlen_t>(ms[t]);
    const R_xlen_t nwin = hadamard ? L - 3 * mm : L - 3 * mm + 1;
    if (mm < 1 || nwin < 1) continue;
    const R_xlen_t B = std::max<R_xlen_t>(1, (R_xlen_t(1) << 16) / mm);
    for (R_xlen_t n0 = 0; n0 < nwin; n0 += B)
      items.push_back(Item{t, n0, std::min(nwin, n0 + B)});
  }
  std::vector<double> part(items.size(), 0.0);
  const int nw = std::max(1, threads);
  std::vector<Scratch> scratch(nw);
  allanvar::parallel_for(static_cast<R_xlen_t>(items.size()), nw,
                         [&](R_xlen_t it, int w) {
    const Item& I = items[it];
    const R_xlen_t mm = static_cast<R_xlen_t>(ms[I.tau]);
    const R_xlen_t nb = I.n1 - I.n0;
    Scratch& sc = scratch[w];
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
