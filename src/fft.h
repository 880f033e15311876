// A small radix-2 FFT for the correlations of the fast Theo1 kernel
// (src/theo.cpp). Iterative Cooley-Tukey (Cooley & Tukey 1965) with the
// twiddles computed directly by cos/sin for every index (no recurrence, so
// the rounding error grows only as log n), and correlation of two real
// sequences by packing them into one complex transform (Press et al.,
// Numerical Recipes, sec. 12.3 "FFT of two real functions simultaneously").
#ifndef ALLANVAR_FFT_H
#define ALLANVAR_FFT_H

#include <Rcpp.h>
#include <algorithm>
#include <cmath>
#include <complex>
#include <deque>
#include <vector>

namespace allanvar {

using cplx = std::complex<double>;

class FFTPlan {
 public:
  explicit FFTPlan(size_t n = 1) { reset(n); }
  size_t size() const { return n_; }
  void reset(size_t n) {
    n_ = n;
    std::vector<cplx> w(n / 2);
    const double pi = 3.14159265358979323846;
    for (size_t j = 0; j < n / 2; ++j) {
      const double a = -2.0 * pi * static_cast<double>(j) / static_cast<double>(n);
      w[j] = cplx(std::cos(a), std::sin(a));
    }
    // the twiddles of each stage contiguous (the stage of half-length h at
    // offset h - 1), so that a stage reads them in order
    w_.resize(n > 1 ? n - 1 : 0);
    for (size_t half = 1; half < n; half <<= 1) {
      const size_t step = n / (2 * half);
      for (size_t j = 0; j < half; ++j) w_[half - 1 + j] = w[j * step];
    }
  }
  // In place; inverse without the 1/n factor.
  void run(cplx* a, bool inverse) const {
    const size_t n = n_;
    for (size_t i = 1, j = 0; i < n; ++i) {
      size_t bit = n >> 1;
      for (; j & bit; bit >>= 1) j ^= bit;
      j ^= bit;
      if (i < j) std::swap(a[i], a[j]);
    }
    // The stages up to len = C run block by block (each block of C points
    // stays in cache through them); the same butterflies in another order,
    // so the result is unchanged.
    const size_t C = std::min(n, static_cast<size_t>(1) << 13);
    for (size_t b = 0; b < n; b += C) {
      for (size_t len = 2; len <= C; len <<= 1) stage(a, len, b, b + C, inverse);
    }
    for (size_t len = 2 * C; len <= n; len <<= 1) stage(a, len, 0, n, inverse);
  }

 private:
  // the butterflies of one stage over the points [from, to)
  void stage(cplx* a, size_t len, size_t from, size_t to, bool inverse) const {
    const size_t half = len / 2;
    const cplx* w = w_.data() + (half - 1);
    for (size_t i = from; i < to; i += len) {
      for (size_t j = 0; j < half; ++j) {
        // written out: std::complex's operator* checks for NaN (slow)
        const double wr = w[j].real();
        const double wi = inverse ? -w[j].imag() : w[j].imag();
        const double br = a[i + j + half].real(), bi = a[i + j + half].imag();
        const double vr = br * wr - bi * wi, vi = br * wi + bi * wr;
        const double ur = a[i + j].real(), ui = a[i + j].imag();
        a[i + j] = cplx(ur + vr, ui + vi);
        a[i + j + half] = cplx(ur - vr, ui - vi);
      }
    }
  }

  size_t n_;
  std::vector<cplx> w_;
};

inline size_t fft_size(size_t need) {
  size_t n = 1;
  while (n < need) n <<= 1;
  return n;
}

// Plans by size, one set per thread of a kernel (a deque: a plan handed out
// stays valid when later sizes are added).
class FFTPlans {
 public:
  const FFTPlan& get(size_t n) {
    for (const FFTPlan& p : plans_)
      if (p.size() == n) return p;
    plans_.emplace_back(n);
    return plans_.back();
  }

 private:
  std::deque<FFTPlan> plans_;
};

// Both c1[t] = sum_j a[j] b[j + t] (t < nt1) and c2[t] = sum_j b[j] b[j + t]
// (t < nt2) from one forward and one inverse transform: the two products
// are spectra of real sequences, so the inverse of c1's spectrum plus i
// times c2's returns c1 in the real and c2 in the imaginary part.
inline void real_correlation2(const double* a, size_t na, const double* b,
                              size_t nb, size_t nt1, double* c1, size_t nt2,
                              double* c2, FFTPlans& plans,
                              std::vector<cplx>& buf, std::vector<cplx>& C) {
  size_t need = std::max(nb, na + nt1 - 1);
  if (nt2 > 0) need = std::max(need, nb + nt2 - 1);
  const FFTPlan& P = plans.get(fft_size(need));
  const size_t n = P.size();
  buf.assign(n, cplx(0, 0));
  for (size_t j = 0; j < na; ++j) buf[j].real(a[j]);
  for (size_t j = 0; j < nb; ++j) buf[j].imag(b[j]);
  P.run(buf.data(), false);
  C.resize(n);
  for (size_t f = 0; f < n; ++f) {
    const cplx z = buf[f], zr = std::conj(buf[(n - f) & (n - 1)]);
    const double ar = 0.5 * (z.real() + zr.real()), ai = 0.5 * (z.imag() + zr.imag());
    const double br = 0.5 * (z.imag() - zr.imag()), bi = -0.5 * (z.real() - zr.real());
    // conj(A) B (+ i |B|^2 when c2 is wanted)
    const double b2 = c2 ? br * br + bi * bi : 0.0;
    C[f] = cplx(ar * br + ai * bi, ar * bi - ai * br + b2);
  }
  P.run(C.data(), true);
  const double s = 1.0 / static_cast<double>(n);
  for (size_t t = 0; t < nt1; ++t) c1[t] = C[t].real() * s;
  if (c2) {
    for (size_t t = 0; t < nt2; ++t) c2[t] = C[t].imag() * s;
  }
}

// c[t] = sum_j a[j] b[j + t] for t in [0, nt), with b zero beyond nb.
// Exact (no wrap) when the transform size n >= nb and n >= na + nt - 1:
// then j + t < n for every needed term (no wrap) and b fits.
inline void real_correlation(const double* a, size_t na, const double* b,
                             size_t nb, size_t nt, double* c, FFTPlans& plans,
                             std::vector<cplx>& buf, std::vector<cplx>& C) {
  real_correlation2(a, na, b, nb, nt, c, 0, nullptr, plans, buf, C);
}

}  // namespace allanvar

#endif
