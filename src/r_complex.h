// R's complex arithmetic for the C++ kernels that give R's values to the
// bit (src/resonance.cpp, src/basis.cpp): products, sums and quotients are
// the C99 operations R uses (std::complex<double> compiles to the same),
// powers are R's mycpow(), and geometric_av() of R/filter-noise.R is its
// expression's operations in their order.
#ifndef ALLANVAR_R_COMPLEX_H
#define ALLANVAR_R_COMPLEX_H

#include <Rcpp.h>
#include <cmath>
#include <complex>

namespace allanvar {

// R's complex power X^Y (src/main/complex.c, mycpow(), R 4.2): powers by
// repeated products for whole exponents up to 65536, else the C library's
// cpow; 0^Y is R_pow(0, Re Y).
inline std::complex<double> r_cpow(std::complex<double> X, double yr) {
  typedef std::complex<double> cplx;
  if (X == cplx(0.0, 0.0)) {
    const double z = yr == 0 ? 1.0 : (yr > 0 ? 0.0 : R_PosInf);
    return cplx(ISNAN(yr) ? yr : z, 0.0);
  }
  if (std::fabs(yr) <= 65536 && yr == static_cast<double>(static_cast<int>(yr))) {
    int k = static_cast<int>(yr);
    if (k == 0) return cplx(1.0, 0.0);
    if (k == 1) return X;
    const bool neg = k < 0;
    if (neg) k = -k;
    cplx z(1.0, 0.0);
    while (k > 0) {
      if (k & 1) z = z * X;
      if (k == 1) break;
      k >>= 1;
      X = X * X;
    }
    return neg ? cplx(1.0, 0.0) / z : z;
  }
  return std::pow(X, cplx(yr, 0.0));
}

// geometric_av(m, A, p) = A (m - 3p - m p^2 + 4 p^(m+1) - p^(2m+1)) /
// (m^2 (1 - p)^2) at one m, each real promoted to complex before a product
// or sum as R does; the parts that do not depend on m made once.
class GeometricAv {
 public:
  GeometricAv(std::complex<double> A, std::complex<double> p)
      : A_(A), p_(p), p2_(r_cpow(p, 2.0)), p3_(std::complex<double>(3.0, 0.0) * p),
        q2_(r_cpow(std::complex<double>(1.0, 0.0) - p, 2.0)) {}
  std::complex<double> operator()(double m) const {
    typedef std::complex<double> cplx;
    const cplx mc(m, 0.0);
    cplx t = mc - p3_;
    t = t - mc * p2_;
    t = t + cplx(4.0, 0.0) * r_cpow(p_, m + 1);
    t = t - r_cpow(p_, 2 * m + 1);
    const cplx num = A_ * t;
    const cplx den = cplx(m * m, 0.0) * q2_;
    return num / den;
  }

 private:
  std::complex<double> A_, p_, p2_, p3_, q2_;
};

}  // namespace allanvar

#endif
