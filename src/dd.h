// Double-double arithmetic (about 106 significant bits) for sums of
// products that cancel heavily: Dekker's exact product without FMA (the
// package is built with baseline flags) and Knuth's TwoSum. See Dekker
// (1971), "A floating-point technique for extending the available
// precision", Numer. Math. 18; Ogita, Rump & Oishi (2005), "Accurate sum
// and dot product", SIAM J. Sci. Comput. 26.
#ifndef ALLANVAR_DD_H
#define ALLANVAR_DD_H

namespace allanvar {

struct DD {
  double hi = 0, lo = 0;
  DD() {}
  DD(double h, double l = 0) : hi(h), lo(l) {}
  double value() const { return hi + lo; }
};

// a + b = s + e exactly (Knuth's TwoSum): the one TwoSum of the kernels
// (allan.cpp, dynamic.cpp, theo.cpp, local-phase.h and the double-double
// sums here).
inline void two_sum(double a, double b, double& s, double& e) {
  s = a + b;
  const double bb = s - a;
  e = (a - (s - bb)) + (b - bb);
}

// a + b = s + e exactly when |a| >= |b| (Dekker's FastTwoSum).
inline void fast_two_sum(double a, double b, double& s, double& e) {
  s = a + b;
  e = b - (s - a);
}

// A running sum kept unevaluated as s + c: each addition's rounding error
// (TwoSum) collected in c (allan.cpp's sums of squares, dynamic.cpp's
// windowed sums).
struct CompSum {
  double s = 0, c = 0;
  void add(double v) {
    double t, e;
    two_sum(s, v, t, e);
    s = t;
    c += e;
  }
  void add(const CompSum& p) {
    add(p.s);
    c += p.c;
  }
  double value() const { return s + c; }
};

// a = ah + al with ah holding the upper 26 bits (Veltkamp's split).
inline void dd_split(double a, double& ah, double& al) {
  const double t = 134217729.0 * a;  // 2^27 + 1
  ah = t - (t - a);
  al = a - ah;
}

// a * b = p + e exactly (barring overflow).
inline void dd_two_prod(double a, double b, double& p, double& e) {
  p = a * b;
  double ah, al, bh, bl;
  dd_split(a, ah, al);
  dd_split(b, bh, bl);
  e = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
}

inline DD operator+(const DD& a, const DD& b) {
  double s, e, t, f;
  two_sum(a.hi, b.hi, s, e);
  two_sum(a.lo, b.lo, t, f);
  e += t;
  fast_two_sum(s, e, s, e);
  e += f;
  fast_two_sum(s, e, s, e);
  return DD(s, e);
}

inline DD operator-(const DD& a) { return DD(-a.hi, -a.lo); }
inline DD operator-(const DD& a, const DD& b) { return a + (-b); }

inline DD operator*(const DD& a, const DD& b) {
  double p, e;
  dd_two_prod(a.hi, b.hi, p, e);
  e += a.hi * b.lo + a.lo * b.hi;
  fast_two_sum(p, e, p, e);
  return DD(p, e);
}

inline DD operator*(const DD& a, double b) { return a * DD(b); }

inline DD& operator+=(DD& a, const DD& b) {
  a = a + b;
  return a;
}

inline DD& operator-=(DD& a, const DD& b) {
  a = a - b;
  return a;
}

}  // namespace allanvar

#endif
