// bench/fft.R's C++ half: the package's FFT (src/fft.h) against Eigen's
// unsupported FFT (kissfft back end, from RcppEigen) on the job the package
// gives it, the correlation c[t] = sum_j a[j] b[j + t] of two real
// sequences (the Theo kernels' blocks), and on a bare complex transform.
// [[Rcpp::depends(RcppEigen)]]
#include <RcppEigen.h>
#include <unsupported/Eigen/FFT>
#include "fft.h"

#include <algorithm>
#include <chrono>
#include <vector>

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t k = v.size();
  return k % 2 ? v[k / 2] : 0.5 * (v[k / 2 - 1] + v[k / 2]);
}

// Eigen's correlation: real-to-half-spectrum transforms of a and b, the
// product conj(A) B, the inverse (scaled by Eigen), the first nt values.
void eigen_correlation(Eigen::FFT<double>& fft, const std::vector<double>& a,
                       const std::vector<double>& b, size_t n, size_t nt,
                       std::vector<double>& c) {
  std::vector<double> pa(n, 0.0), pb(n, 0.0), out;
  std::copy(a.begin(), a.end(), pa.begin());
  std::copy(b.begin(), b.end(), pb.begin());
  std::vector<std::complex<double>> A, B;
  fft.fwd(A, pa);
  fft.fwd(B, pb);
  for (size_t k = 0; k < A.size(); ++k) A[k] = std::conj(A[k]) * B[k];
  fft.inv(out, A, n);
  c.assign(out.begin(), out.begin() + nt);
}

}  // namespace

// Median seconds of one correlation by each FFT (`reps` runs each, the
// first not counted) and the largest difference between their results.
// [[Rcpp::export]]
Rcpp::List bench_correlation(Rcpp::NumericVector a, Rcpp::NumericVector b,
                             int nt, int reps) {
  const size_t na = a.size(), nb = b.size();
  std::vector<double> av(a.begin(), a.end()), bv(b.begin(), b.end());
  allanvar::FFTPlans plans;
  allanvar::cvec buf, C;
  std::vector<double> c_own(nt), c_eig;
  std::vector<double> t_own, t_eig;
  for (int r = 0; r <= reps; ++r) {
    const double t0 = now();
    allanvar::real_correlation(av.data(), na, bv.data(), nb, nt, c_own.data(), plans, buf, C);
    if (r) t_own.push_back(now() - t0);
  }
  const size_t n = allanvar::fft_size(std::max(nb, na + nt - 1));
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  for (int r = 0; r <= reps; ++r) {
    const double t0 = now();
    eigen_correlation(fft, av, bv, n, nt, c_eig);
    if (r) t_eig.push_back(now() - t0);
  }
  double diff = 0, scale = 0;
  for (int t = 0; t < nt; ++t) {
    diff = std::max(diff, std::abs(c_own[t] - c_eig[t]));
    scale = std::max(scale, std::abs(c_own[t]));
  }
  return Rcpp::List::create(Rcpp::Named("n") = static_cast<double>(n),
                            Rcpp::Named("own") = median(t_own),
                            Rcpp::Named("eigen") = median(t_eig),
                            Rcpp::Named("rel_diff") = diff / scale);
}

// Median seconds of a complex forward plus inverse transform of n points.
// [[Rcpp::export]]
Rcpp::List bench_complex(int n, int reps) {
  std::vector<std::complex<double>> x(n);
  for (int j = 0; j < n; ++j) x[j] = std::complex<double>(std::sin(0.1 * j), std::cos(0.37 * j));
  allanvar::FFTPlan P(static_cast<size_t>(n));
  std::vector<std::complex<double>> y = x;
  std::vector<double> t_own, t_eig;
  for (int r = 0; r <= reps; ++r) {
    y = x;
    const double t0 = now();
    P.forward_to_br(y.data());
    P.inverse_from_br(y.data());
    if (r) t_own.push_back(now() - t0);
  }
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> X, z;
  for (int r = 0; r <= reps; ++r) {
    const double t0 = now();
    fft.fwd(X, x);
    fft.inv(z, X);
    if (r) t_eig.push_back(now() - t0);
  }
  return Rcpp::List::create(Rcpp::Named("own") = median(t_own),
                            Rcpp::Named("eigen") = median(t_eig));
}
