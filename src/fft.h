// A small radix-2 FFT for the correlations of the fast Theo1 kernel
// (src/theo.cpp). Iterative Cooley-Tukey (Cooley & Tukey 1965) with the
// twiddles computed directly by cos/sin for every index (no recurrence, so
// the rounding error grows only as log n), and correlation of two real
// sequences by packing them into one complex transform (Press et al.,
// Numerical Recipes, sec. 12.3 "FFT of two real functions simultaneously").
// A correlation runs the forward transform by decimation in frequency
// (Gentleman & Sande 1966), leaving the spectrum in bit-reversed order, and
// the inverse by decimation in time from that order: no permutation.
// Stages run two at a time (radix-4 order of the same butterflies), those
// below 2^13 points block by block in cache, on SSE2 vectors.
#ifndef ALLANVAR_FFT_H
#define ALLANVAR_FFT_H

#include <Rcpp.h>
#include "scratch.h"
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstring>
#include <deque>
#include <mutex>
#include <vector>

namespace allanvar {

using cplx = std::complex<double>;
// transform buffers: 32 MB each at 2^21 points, huge pages and not
// initialised (src/scratch.h): every user writes all n values it reads
using cvec = BasicScratch<cplx>;

#if defined(__GNUC__)
// A complex number as two doubles of an SSE2 vector; x w computed as
// x (wr, wr) + swap(x) (-wi, wi): the scalar code's products and sums
// (the same values, bit for bit).
typedef double fft_v2 __attribute__((vector_size(16)));
// (std::complex<double> is laid out as an array of two doubles)
inline fft_v2 fft_ld(const cplx* p) {
  fft_v2 v;
  std::memcpy(&v, reinterpret_cast<const double*>(p), sizeof v);
  return v;
}
inline void fft_st(cplx* p, fft_v2 v) {
  std::memcpy(reinterpret_cast<double*>(p), &v, sizeof v);
}
inline fft_v2 fft_swap(fft_v2 x) {
#if defined(__clang__)
  return __builtin_shufflevector(x, x, 1, 0);
#else
  typedef long long v2i __attribute__((vector_size(16)));
  return __builtin_shuffle(x, v2i{1, 0});
#endif
}
inline fft_v2 fft_mul(fft_v2 x, double wr, double wi) {
  const fft_v2 a = {wr, wr}, b = {-wi, wi};
  return x * a + fft_swap(x) * b;
}
#endif

class FFTPlan {
 public:
  explicit FFTPlan(size_t n = 1) { reset(n); }
  size_t size() const { return n_; }
  void reset(size_t n) {
    n_ = n;
    // the twiddles of each stage contiguous (the stage of half-length h at
    // offset h - 1), so that a stage reads them in order; the last stage's
    // are every twiddle, the others every step-th of those
    w_.resize(n > 1 ? n - 1 : 0);
    if (n < 2) return;
    const double pi = 3.14159265358979323846;
    cplx* w = w_.data() + (n / 2 - 1);
    for (size_t j = 0; j < n / 2; ++j) {
      const double a = -2.0 * pi * static_cast<double>(j) / static_cast<double>(n);
      w[j] = cplx(std::cos(a), std::sin(a));
    }
    for (size_t half = 1; half < n / 2; half <<= 1) {
      const size_t step = n / (2 * half);
      for (size_t j = 0; j < half; ++j) w_[half - 1 + j] = w[j * step];
    }
  }
  // e^{-2 pi i j / n} for j < n / 2 (the last stage's twiddles).
  const cplx* twiddles() const { return w_.data() + (n_ / 2 - 1); }
  // In place, natural order in and out; inverse without the 1/n factor.
  void run(cplx* a, bool inverse) const {
    const size_t n = n_;
    for (size_t i = 1, j = 0; i < n; ++i) {
      size_t bit = n >> 1;
      for (; j & bit; bit >>= 1) j ^= bit;
      j ^= bit;
      if (i < j) std::swap(a[i], a[j]);
    }
    dit(a, inverse);
  }
  // Forward transform, natural order in, bit-reversed order out
  // (decimation in frequency: the stages of run() in reverse, each
  // butterfly (u, v) -> (u + v, (u - v) w)); with inverse_from_br() a
  // correlation needs no permutation (the swaps of the bit reversal were
  // a tenth of Theo1's time at 2^21 points).
  void forward_to_br(cplx* a) const {
    const size_t n = n_;
    const size_t C = std::min(n, static_cast<size_t>(1) << 13);
    // the stages above C over the whole array, then blocks of C in cache
    // (two stages at a time where two remain, as in dit())
    size_t len = n;
    for (; len / 2 > C; len >>= 2) dif_stage2(a, len, 0, n);
    if (len > C) dif_stage(a, len, 0, n);
    for (size_t b = 0; b < n; b += C) {
      size_t l = C;
      for (; l >= 4; l >>= 2) dif_stage2(a, l, b, b + C);
      if (l == 2) dif_stage(a, l, b, b + C);
    }
  }
  // Inverse transform (without 1/n), bit-reversed order in, natural out.
  void inverse_from_br(cplx* a) const { dit(a, true); }

 private:
  // the stages of the decimation in time, the input bit-reversed
  void dit(cplx* a, bool inverse) const {
    const size_t n = n_;
    // The stages up to len = C run block by block (each block of C points
    // stays in cache through them); the same butterflies in another order,
    // so the result is unchanged.
    // Stages go two at a time (radix-4 order: the points are read and
    // written once for two stages; the same butterflies with the same
    // twiddles, so the same result).
    const size_t C = std::min(n, static_cast<size_t>(1) << 13);
    for (size_t b = 0; b < n; b += C) {
      size_t len = 2;
      for (; 2 * len <= C; len <<= 2) stage2(a, len, b, b + C, inverse);
      if (len <= C) stage(a, len, b, b + C, inverse);
    }
    // the stages above C over the whole array
    size_t len = 2 * C;
    for (; 2 * len <= n; len <<= 2) stage2(a, len, 0, n, inverse);
    if (len <= n) stage(a, len, 0, n, inverse);
  }
  // the stages len and len / 2 of the decimation in frequency: on each
  // block of len points, points j, j + q, j + 2q, j + 3q (q = len / 4)
  void dif_stage2(cplx* a, size_t len, size_t from, size_t to) const {
    const size_t q = len / 4;
    const cplx* wl = w_.data() + (2 * q - 1);  // stage len
    const cplx* wh = w_.data() + (q - 1);      // stage len / 2
    for (size_t i = from; i < to; i += len) {
#if defined(__GNUC__)
      for (size_t j = 0; j < q; ++j) {
        cplx* p = a + i + j;
        const fft_v2 x0 = fft_ld(p), x1 = fft_ld(p + q), x2 = fft_ld(p + 2 * q),
                     x3 = fft_ld(p + 3 * q);
        const fft_v2 a0 = x0 + x2, a1 = x1 + x3;
        const fft_v2 a2 = fft_mul(x0 - x2, wl[j].real(), wl[j].imag());
        const fft_v2 a3 = fft_mul(x1 - x3, wl[j + q].real(), wl[j + q].imag());
        const double wr = wh[j].real(), wi = wh[j].imag();
        fft_st(p, a0 + a1);
        fft_st(p + q, fft_mul(a0 - a1, wr, wi));
        fft_st(p + 2 * q, a2 + a3);
        fft_st(p + 3 * q, fft_mul(a2 - a3, wr, wi));
      }
      continue;
#endif
      for (size_t j = 0; j < q; ++j) {
        cplx* p = a + i + j;
        const double x0r = p[0].real(), x0i = p[0].imag();
        const double x1r = p[q].real(), x1i = p[q].imag();
        const double x2r = p[2 * q].real(), x2i = p[2 * q].imag();
        const double x3r = p[3 * q].real(), x3i = p[3 * q].imag();
        // stage len: (x0, x2) with wl[j], (x1, x3) with wl[j + q]
        const double a0r = x0r + x2r, a0i = x0i + x2i;
        double dr = x0r - x2r, di = x0i - x2i;
        double wr = wl[j].real(), wi = wl[j].imag();
        const double a2r = dr * wr - di * wi, a2i = dr * wi + di * wr;
        const double a1r = x1r + x3r, a1i = x1i + x3i;
        dr = x1r - x3r;
        di = x1i - x3i;
        wr = wl[j + q].real();
        wi = wl[j + q].imag();
        const double a3r = dr * wr - di * wi, a3i = dr * wi + di * wr;
        // stage len / 2: (a0, a1) and (a2, a3) with wh[j]
        wr = wh[j].real();
        wi = wh[j].imag();
        p[0] = cplx(a0r + a1r, a0i + a1i);
        dr = a0r - a1r;
        di = a0i - a1i;
        p[q] = cplx(dr * wr - di * wi, dr * wi + di * wr);
        p[2 * q] = cplx(a2r + a3r, a2i + a3i);
        dr = a2r - a3r;
        di = a2i - a3i;
        p[3 * q] = cplx(dr * wr - di * wi, dr * wi + di * wr);
      }
    }
  }
  // one forward stage of the decimation in frequency over [from, to)
  void dif_stage(cplx* a, size_t len, size_t from, size_t to) const {
    const size_t half = len / 2;
    const cplx* w = w_.data() + (half - 1);
    for (size_t i = from; i < to; i += len) {
#if defined(__GNUC__)
      for (size_t j = 0; j < half; ++j) {
        const fft_v2 u = fft_ld(a + i + j), b = fft_ld(a + i + j + half);
        fft_st(a + i + j, u + b);
        fft_st(a + i + j + half, fft_mul(u - b, w[j].real(), w[j].imag()));
      }
      continue;
#endif
      for (size_t j = 0; j < half; ++j) {
        const double ur = a[i + j].real(), ui = a[i + j].imag();
        const double br = a[i + j + half].real(), bi = a[i + j + half].imag();
        const double dr = ur - br, di = ui - bi;
        const double wr = w[j].real(), wi = w[j].imag();
        a[i + j] = cplx(ur + br, ui + bi);
        a[i + j + half] = cplx(dr * wr - di * wi, dr * wi + di * wr);
      }
    }
  }
 private:
  // the butterflies of one stage over the points [from, to)
  void stage(cplx* a, size_t len, size_t from, size_t to, bool inverse) const {
    const size_t half = len / 2;
    const cplx* w = w_.data() + (half - 1);
    for (size_t i = from; i < to; i += len) {
#if defined(__GNUC__)
      const double sg = inverse ? -1.0 : 1.0;
      for (size_t j = 0; j < half; ++j) {
        const fft_v2 u = fft_ld(a + i + j);
        const fft_v2 v = fft_mul(fft_ld(a + i + j + half), w[j].real(),
                                 sg * w[j].imag());
        fft_st(a + i + j, u + v);
        fft_st(a + i + j + half, u - v);
      }
      continue;
#endif
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

  // the stages of length len and 2 len: on each block of 2 len points,
  // points j, j + h, j + 2h, j + 3h (h = len / 2) go through both
  void stage2(cplx* a, size_t len, size_t from, size_t to, bool inverse) const {
    const size_t h = len / 2;
    const cplx* w1 = w_.data() + (h - 1);    // stage len
    const cplx* w2 = w_.data() + (len - 1);  // stage 2 len
    const double sg = inverse ? -1.0 : 1.0;
    for (size_t i = from; i < to; i += 2 * len) {
#if defined(__GNUC__)
      for (size_t j = 0; j < h; ++j) {
        cplx* p = a + i + j;
        const double wr = w1[j].real(), wi = sg * w1[j].imag();
        const fft_v2 x0 = fft_ld(p), x2 = fft_ld(p + 2 * h);
        const fft_v2 v1 = fft_mul(fft_ld(p + h), wr, wi);
        const fft_v2 v3 = fft_mul(fft_ld(p + 3 * h), wr, wi);
        const fft_v2 b0 = x0 + v1, b1 = x0 - v1, b2 = x2 + v3, b3 = x2 - v3;
        const fft_v2 u = fft_mul(b2, w2[j].real(), sg * w2[j].imag());
        const fft_v2 t = fft_mul(b3, w2[j + h].real(), sg * w2[j + h].imag());
        fft_st(p, b0 + u);
        fft_st(p + 2 * h, b0 - u);
        fft_st(p + h, b1 + t);
        fft_st(p + 3 * h, b1 - t);
      }
      continue;
#endif
      for (size_t j = 0; j < h; ++j) {
        cplx* p = a + i + j;
        // stage len: (p0, p1) and (p2, p3) with twiddle w1[j]
        const double wr = w1[j].real(), wi = sg * w1[j].imag();
        double x0r = p[0].real(), x0i = p[0].imag();
        double x1r = p[h].real(), x1i = p[h].imag();
        double x2r = p[2 * h].real(), x2i = p[2 * h].imag();
        double x3r = p[3 * h].real(), x3i = p[3 * h].imag();
        double vr = x1r * wr - x1i * wi, vi = x1r * wi + x1i * wr;
        const double b0r = x0r + vr, b0i = x0i + vi;
        const double b1r = x0r - vr, b1i = x0i - vi;
        vr = x3r * wr - x3i * wi;
        vi = x3r * wi + x3i * wr;
        const double b2r = x2r + vr, b2i = x2i + vi;
        const double b3r = x2r - vr, b3i = x2i - vi;
        // stage 2 len: (b0, b2) with w2[j], (b1, b3) with w2[j + h]
        const double ur = w2[j].real(), ui = sg * w2[j].imag();
        vr = b2r * ur - b2i * ui;
        vi = b2r * ui + b2i * ur;
        p[0] = cplx(b0r + vr, b0i + vi);
        p[2 * h] = cplx(b0r - vr, b0i - vi);
        const double tr = w2[j + h].real(), ti = sg * w2[j + h].imag();
        vr = b3r * tr - b3i * ti;
        vi = b3r * ti + b3i * tr;
        p[h] = cplx(b1r + vr, b1i + vi);
        p[3 * h] = cplx(b1r - vr, b1i - vi);
      }
    }
  }

  size_t n_;
  cvec w_;  // 32 MB at 2^21 points: huge pages too
};

inline size_t fft_size(size_t need) {
  size_t n = 1;
  while (n < need) n <<= 1;
  return n;
}

// Plans by size, shared by the workers of a kernel: each size's twiddles
// are computed once per call (a deque: a plan handed out stays valid when
// later sizes are added; plans are read only once made).
class FFTPlans {
 public:
  const FFTPlan& get(size_t n) {
    std::lock_guard<std::mutex> lock(mu_);
    for (const FFTPlan& p : plans_)
      if (p.size() == n) return p;
    plans_.emplace_back(n);
    return plans_.back();
  }

 private:
  std::mutex mu_;
  std::deque<FFTPlan> plans_;
};

// Both c1[t] = sum_j a[j] b[j + t] (t < nt1) and c2[t] = sum_j b[j] b[j + t]
// (t < nt2) from one forward and one inverse transform: the two products
// are spectra of real sequences, so the inverse of c1's spectrum plus i
// times c2's returns c1 in the real and c2 in the imaginary part.
inline void real_correlation2(const double* a, size_t na, const double* b,
                              size_t nb, size_t nt1, double* c1, size_t nt2,
                              double* c2, FFTPlans& plans,
                              cvec& buf, cvec& C) {
  size_t need = std::max(nb, na + nt1 - 1);
  if (nt2 > 0) need = std::max(need, nb + nt2 - 1);
  const FFTPlan& P = plans.get(fft_size(need));
  const size_t n = P.size();
  buf.resize(n);
  for (size_t j = 0; j < n; ++j)
    buf[j] = cplx(j < na ? a[j] : 0.0, j < nb ? b[j] : 0.0);
  P.forward_to_br(buf.data());
  C.resize(n);  // every value written below
  // in bit-reversed order the partner of frequency f, n - f, of the
  // position p in [2^k, 2^(k+1)) sits at 3 2^k - 1 - p (and 0 at 0)
  auto one = [&](size_t p, size_t q) {
    const cplx z = buf[p], zr = std::conj(buf[q]);
    const double ar = 0.5 * (z.real() + zr.real()), ai = 0.5 * (z.imag() + zr.imag());
    const double br = 0.5 * (z.imag() - zr.imag()), bi = -0.5 * (z.real() - zr.real());
    // conj(A) B (+ i |B|^2 when c2 is wanted)
    const double b2 = c2 ? br * br + bi * bi : 0.0;
    C[p] = cplx(ar * br + ai * bi, ar * bi - ai * br + b2);
  };
  one(0, 0);
  for (size_t g = 1; g < n; g <<= 1) {
    for (size_t p = g; p < 2 * g; ++p) one(p, 3 * g - 1 - p);
  }
  P.inverse_from_br(C.data());
  const double s = 1.0 / static_cast<double>(n);
  for (size_t t = 0; t < nt1; ++t) c1[t] = C[t].real() * s;
  if (c2) {
    for (size_t t = 0; t < nt2; ++t) c2[t] = C[t].imag() * s;
  }
}

// Two correlations of real sequences at once, c1[t] = sum_j a1[j] b1[j + t]
// and c2[t] = sum_j a2[j] b2[j + t] for t < nt (na points of a1 and a2, nb
// of b1 and b2): the transforms of a1 + i a2 and b1 + i b2 hold all four
// spectra, and one inverse returns c1 + i c2 (three transforms instead of
// four).
inline void real_correlation_pair(const double* a1, const double* a2,
                                  size_t na, const double* b1,
                                  const double* b2, size_t nb, size_t nt,
                                  double* c1, double* c2, FFTPlans& plans,
                                  cvec& buf, cvec& C) {
  const FFTPlan& P = plans.get(fft_size(std::max(nb, na + nt - 1)));
  const size_t n = P.size();
  buf.resize(n);
  for (size_t j = 0; j < na; ++j) buf[j] = cplx(a1[j], a2[j]);
  std::fill(buf.data() + na, buf.data() + n, cplx(0, 0));
  C.resize(n);
  for (size_t j = 0; j < nb; ++j) C[j] = cplx(b1[j], b2[j]);
  std::fill(C.data() + nb, C.data() + n, cplx(0, 0));
  P.forward_to_br(buf.data());
  P.forward_to_br(C.data());
  // at position p (partner q, as in real_correlation2): A1 = (X + conj Xq)
  // / 2, A2 = (X - conj Xq) / 2i, likewise B1, B2 from C; the product
  // conj(A1) B1 + i conj(A2) B2
  auto prod = [&](size_t p, size_t q) {
    const cplx x = buf[p], xq = std::conj(buf[q]);
    const cplx y = C[p], yq = std::conj(C[q]);
    const double a1r = 0.5 * (x.real() + xq.real()), a1i = 0.5 * (x.imag() + xq.imag());
    const double a2r = 0.5 * (x.imag() - xq.imag()), a2i = -0.5 * (x.real() - xq.real());
    const double b1r = 0.5 * (y.real() + yq.real()), b1i = 0.5 * (y.imag() + yq.imag());
    const double b2r = 0.5 * (y.imag() - yq.imag()), b2i = -0.5 * (y.real() - yq.real());
    const double s1r = a1r * b1r + a1i * b1i, s1i = a1r * b1i - a1i * b1r;
    const double s2r = a2r * b2r + a2i * b2i, s2i = a2r * b2i - a2i * b2r;
    return cplx(s1r - s2i, s1i + s2r);
  };
  C[0] = prod(0, 0);
  for (size_t g = 1; g < n; g <<= 1) {
    for (size_t p = g; p < 2 * g; ++p) {
      const size_t q = 3 * g - 1 - p;
      if (q < p) continue;  // done with its partner
      const cplx rp = prod(p, q), rq = prod(q, p);
      C[p] = rp;
      C[q] = rq;
    }
  }
  P.inverse_from_br(C.data());
  const double s = 1.0 / static_cast<double>(n);
  for (size_t t = 0; t < nt; ++t) {
    c1[t] = C[t].real() * s;
    c2[t] = C[t].imag() * s;
  }
}

// c[t] = sum_j a[j] b[j + t] for t in [0, nt), with b zero beyond nb.
// Exact (no wrap) when the transform size n >= nb and n >= na + nt - 1:
// then j + t < n for every needed term (no wrap) and b fits.
inline void real_correlation(const double* a, size_t na, const double* b,
                             size_t nb, size_t nt, double* c, FFTPlans& plans,
                             cvec& buf, cvec& C) {
  real_correlation2(a, na, b, nb, nt, c, 0, nullptr, plans, buf, C);
}

}  // namespace allanvar

#endif
