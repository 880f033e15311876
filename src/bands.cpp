// The per-bin arithmetic of a whole record's spectrum in R/spectrum.R: its
// periodogram's power (record_periodogram(), remove_bands()) and the bands
// brought to their background (remove_bands(): the smoothed power and each
// band's gain). Half a million bins a pass; R's expressions' operations in
// their order (Mod() as hypot(), x^2 as x * x, cumsum() in long double,
// pmin()/pmax() as R compares), so the values are R's.
#include <Rcpp.h>
#include <cmath>
#include <vector>

// The power of each bin of X: Mod(X)^2 / scale (`twice = FALSE`; the
// one-sided bins 2..length - 1 then doubled, as record_periodogram()), or
// 2 * Mod(X)^2 / scale (`twice = TRUE`, as remove_bands()).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector bin_power_cpp(const Rcpp::ComplexVector& X, double scale, bool twice) {
  const R_xlen_t h = X.size();
  Rcpp::NumericVector out(h);
  for (R_xlen_t k = 0; k < h; k++) {
    const double a = std::hypot(X[k].r, X[k].i);
    if (twice) {
      out[k] = 2 * (a * a) / scale;
    } else {
      const double p = a * a / scale;
      out[k] = (k > 0 && k < h - 1) ? 2 * p : p;
    }
    if ((k & 0xFFFFF) == 0) Rcpp::checkUserInterrupt();
  }
  return out;
}

// The running mean of P = Ph * G^2 (G of length 1 or of Ph) over the k
// bins centred on each (fewer at the ends), from the prefix sums
// c(0, cumsum(P)); its R form is bin_smoother() in
// tests/testthat/test-spectrum.R.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector bin_mean_cpp(const Rcpp::NumericVector& Ph, const Rcpp::NumericVector& G,
                                 int k) {
  const R_xlen_t n = Ph.size();
  const R_xlen_t ng = G.size();
  if (k < 1 || (ng != 1 && ng != n)) Rcpp::stop("bin_mean_cpp: bad arguments");
  std::vector<double> cs(static_cast<size_t>(n) + 1);
  cs[0] = 0;
  long double sum = 0.0;
  for (R_xlen_t i = 0; i < n; i++) {
    const double g = G[ng == 1 ? 0 : i];
    sum += Ph[i] * (g * g);
    cs[i + 1] = static_cast<double>(sum);
  }
  const R_xlen_t half = k / 2;
  Rcpp::NumericVector out(n);
  for (R_xlen_t i = 0; i < n; i++) {
    // lo = max(1, i - h), hi = min(n, i + h) + 1 (1-based), cs[hi] - cs[lo]
    const R_xlen_t lo = i + 1 - half < 1 ? 1 : i + 1 - half;
    const R_xlen_t hi = (i + 1 + half > n ? n : i + 1 + half) + 1;
    out[i] = (cs[hi - 1] - cs[lo - 1]) / static_cast<double>(hi - lo);
    if ((i & 0xFFFFF) == 0) Rcpp::checkUserInterrupt();
  }
  return out;
}

// G * sqrt(B / (B + pmin(M, pmax(S - B, 0)))) (G of length 1 or of B).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector band_gain_cpp(const Rcpp::NumericVector& G, const Rcpp::NumericVector& B,
                                  const Rcpp::NumericVector& M, const Rcpp::NumericVector& S) {
  const R_xlen_t n = B.size();
  const R_xlen_t ng = G.size();
  if ((ng != 1 && ng != n) || M.size() != n || S.size() != n) {
    Rcpp::stop("band_gain_cpp: lengths differ");
  }
  Rcpp::NumericVector out(n);
  for (R_xlen_t i = 0; i < n; i++) {
    double e = S[i] - B[i];
    if (0.0 > e) e = 0.0;                 // pmax(S - B, 0)
    double c = M[i];
    if (std::isnan(e) || e < c) c = e;    // pmin(M, .)
    out[i] = G[ng == 1 ? 0 : i] * std::sqrt(B[i] / (B[i] + c));
    if ((i & 0xFFFFF) == 0) Rcpp::checkUserInterrupt();
  }
  return out;
}
