// avfit(): the inner loop of the noise-model fit. For fixed nonlinear
// parameters the model AV is linear in the squared amplitudes c >= 0:
//   AV_j = offset_j + sum_k B_jk c_k.
// The fit minimises S(c) = sum_j ((y_j - ln AV_j) / s_j)^2 (log domain, EDF
// weights) by Gauss-Newton steps, each an NNLS problem, with step halving.
// It is called once per grid point of the profiled nonlinear parameters.
#include <RcppEigen.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

using CRefM = Eigen::Ref<const MatrixXd>;
using CRefV = Eigen::Ref<const VectorXd>;

// The buffers of one amplitude solve, kept between solves of the same
// sizes (the search makes thousands of small solves; allocating each
// product's result cost about as much as the arithmetic). The arithmetic
// is the same as with fresh objects.
struct NnlsWork {
  MatrixXd A, Ap;
  VectorXd scale, x, w, r, x_prev, zp;
  std::vector<bool> passive;
  std::vector<int> idx;
  Eigen::ColPivHouseholderQR<MatrixXd> qr;
};

// The least squares of b on A's columns in the passive set: their indices
// in `idx`, the coefficients in `zp`; true when every one is positive.
bool passive_ls(const MatrixXd& A, const CRefV& b,
                const std::vector<bool>& passive, std::vector<int>& idx,
                VectorXd& zp, NnlsWork& ws) {
  idx.clear();
  for (int k = 0; k < static_cast<int>(passive.size()); ++k) {
    if (passive[k]) idx.push_back(k);
  }
  const int q = static_cast<int>(idx.size());
  ws.Ap.resize(A.rows(), q);
  for (int i = 0; i < q; ++i) ws.Ap.col(i) = A.col(idx[i]);
  ws.qr.compute(ws.Ap);
  zp = ws.qr.solve(b);
  for (int i = 0; i < q; ++i) if (!(zp(i) > 0)) return false;
  return true;
}

// Lawson-Hanson non-negative least squares: min ||A x - b||, x >= 0.
// Columns are scaled to unit norm first (the bases span many decades).
// `warm` (optional): the passive set of a previous, nearby problem (the
// Gauss-Newton steps of one solve keep it): when the least squares on it
// are strictly positive the search starts there instead of from the empty
// set. The result is the least squares on the final passive set, so a
// warm start that ends on the same set gives the same x to the bit; the
// final set is written back. The result is left in ws.x.
void nnls_ws(const CRefM& A0, const CRefV& b, NnlsWork& ws, int maxit = 500,
             std::vector<bool>* warm = nullptr) {
  const int p = static_cast<int>(A0.cols());
  ws.scale.resize(p);
  ws.A = A0;
  MatrixXd& A = ws.A;
  for (int k = 0; k < p; ++k) {
    double nk = A.col(k).norm();
    ws.scale(k) = nk > 0 ? nk : 1.0;
    A.col(k) /= ws.scale(k);
  }
  VectorXd& x = ws.x;
  x.setZero(p);
  std::vector<bool>& passive = ws.passive;
  passive.assign(p, false);
  const double tol = 1e-12 * (1.0 + b.norm());
  std::vector<int>& idx = ws.idx;
  VectorXd& zp = ws.zp;
  if (warm != nullptr && static_cast<int>(warm->size()) == p &&
      std::find(warm->begin(), warm->end(), true) != warm->end() &&
      passive_ls(A, b, *warm, idx, zp, ws)) {
    for (int i = 0; i < static_cast<int>(idx.size()); ++i) x(idx[i]) = zp(i);
    passive = *warm;
  }
  for (int it = 0; it < maxit; ++it) {
    ws.r.noalias() = b - A * x;
    ws.w.noalias() = A.transpose() * ws.r;
    const VectorXd& w = ws.w;
    int t = -1;
    double wmax = tol;
    for (int k = 0; k < p; ++k) {
      if (!passive[k] && w(k) > wmax) { wmax = w(k); t = k; }
    }
    if (t < 0) break;
    passive[t] = true;
    ws.x_prev = x;
    for (int inner = 0; inner < 3 * p + 3; ++inner) {
      const bool ok = passive_ls(A, b, passive, idx, zp, ws);
      const int q = static_cast<int>(idx.size());
      if (ok) {
        x.setZero();
        for (int i = 0; i < q; ++i) x(idx[i]) = zp(i);
        break;
      }
      double alpha = 1.0;
      for (int i = 0; i < q; ++i) {
        if (!(zp(i) > 0)) {
          double denom = x(idx[i]) - zp(i);
          double a = denom > 0 ? x(idx[i]) / denom : 0.0;
          if (a < alpha) alpha = a;
        }
      }
      for (int i = 0; i < q; ++i) {
        x(idx[i]) += alpha * (zp(i) - x(idx[i]));
        if (x(idx[i]) <= 1e-15 * (1.0 + std::fabs(zp(i)))) {
          x(idx[i]) = 0.0;
          passive[idx[i]] = false;
        }
      }
    }
    // Degenerate step (the variable just added was dropped again and x did
    // not move): Lawson-Hanson would cycle; x is optimal to rounding.
    if ((x - ws.x_prev).norm() <= 1e-14 * (1.0 + x.norm())) break;
  }
  for (int k = 0; k < p; ++k) x(k) /= ws.scale(k);
  if (warm != nullptr) *warm = passive;
}

VectorXd nnls(const CRefM& A0, const CRefV& b, int maxit = 500,
              std::vector<bool>* warm = nullptr) {
  NnlsWork ws;
  nnls_ws(A0, b, ws, maxit, warm);
  return ws.x;
}

// W applied to a vector or a matrix. W is either the whitening matrix
// (J x J) or, when the points are independent, its diagonal as one column
// (J x 1): a dense J x J diagonal would cost O(J^2) memory and O(J^2 p)
// time per product, 800 MB and seconds on a 10,000-tau curve.
bool w_is_diag(const CRefM& W, R_xlen_t J) {
  return W.cols() == 1 && W.rows() == J && J > 1;
}
void w_times_to(const CRefM& W, const VectorXd& v, VectorXd& out) {
  if (w_is_diag(W, v.size())) {
    out = W.col(0).cwiseProduct(v);
  } else {
    out.noalias() = W * v;
  }
}
void w_times_to(const CRefM& W, const MatrixXd& A, MatrixXd& out) {
  if (w_is_diag(W, A.rows())) {
    out.noalias() = W.col(0).asDiagonal() * A;
  } else {
    out.noalias() = W * A;
  }
}

// S = || W (y - ln AV) ||^2; W whitens the log-AV errors (diag(1/s) when
// the points are taken as independent, the inverse Cholesky factor of their
// covariance otherwise). `av`, `r`, `wr`: buffers.
double objective(const CRefM& B, const CRefV& offset, const CRefV& y,
                 const CRefM& W, const VectorXd& c, VectorXd& av, VectorXd& r,
                 VectorXd& wr) {
  av.noalias() = offset + B * c;
  r.resize(av.size());
  for (R_xlen_t j = 0; j < av.size(); ++j) {
    if (!(av(j) > 0)) return std::numeric_limits<double>::infinity();
    r(j) = y(j) - std::log(av(j));
  }
  w_times_to(W, r, wr);
  return wr.squaredNorm();
}

// The buffers of avfit_log_nnls(), one set per thread.
struct SolveWork {
  NnlsWork nn;
  MatrixXd A, WA;
  VectorXd av, bc, t, Wt, d, ctry, oav, or_, owr;
};

}  // namespace

// Squared amplitudes c >= 0 minimising the log-domain weighted objective.
// y = ln(AV-hat) minus the chi-square log bias; W the whitening matrix, or
// its diagonal as a one-column matrix (see w_times_to()).
// [[Rcpp::export(rng = false)]]
Rcpp::List avfit_log_nnls(const Eigen::Map<Eigen::MatrixXd> B,
                          const Eigen::Map<Eigen::VectorXd> offset,
                          const Eigen::Map<Eigen::VectorXd> y,
                          const Eigen::Map<Eigen::MatrixXd> W,
                          const Eigen::Map<Eigen::VectorXd> start,
                          int maxit, double tol) {
  static thread_local SolveWork ws;
  const R_xlen_t J = B.rows();
  const int p = static_cast<int>(B.cols());
  auto obj = [&](const VectorXd& cc) {
    return objective(B, offset, y, W, cc, ws.oav, ws.or_, ws.owr);
  };
  VectorXd c = start;
  double S = obj(c);
  if (!std::isfinite(S) || c.sum() <= 0) {
    // Linear-domain start: min || W ((offset + B c) / AV-hat - 1) ||^2.
    MatrixXd A(J, p);
    VectorXd t(J);
    for (R_xlen_t j = 0; j < J; ++j) {
      double avh = std::exp(y(j));
      A.row(j) = B.row(j) / avh;
      t(j) = 1.0 - offset(j) / avh;
    }
    w_times_to(W, A, ws.WA);
    w_times_to(W, t, ws.Wt);
    c = nnls(ws.WA, ws.Wt);
    S = obj(c);
    if (!std::isfinite(S)) {
      // Keep every term slightly on so that ln AV is finite everywhere.
      for (int k = 0; k < p; ++k) {
        double bk = B.col(k).cwiseAbs().maxCoeff();
        double floor_k = bk > 0 ? 1e-8 * std::exp(y.maxCoeff()) / bk : 0.0;
        if (c(k) < floor_k) c(k) = floor_k;
      }
      S = obj(c);
    }
  }
  int it = 0;
  bool converged = false;
  // the NNLS of each Gauss-Newton step starts from the previous step's
  // passive set (nnls(): the same result when the set is the same)
  std::vector<bool> pset;
  for (; it < maxit && std::isfinite(S); ++it) {
    ws.av.noalias() = offset + B * c;
    ws.bc.noalias() = B * c;
    const VectorXd& av = ws.av;
    const VectorXd& bc = ws.bc;
    ws.A.resize(J, p);
    ws.t.resize(J);
    for (R_xlen_t j = 0; j < J; ++j) {
      ws.A.row(j) = B.row(j) / av(j);
      ws.t(j) = y(j) - std::log(av(j)) + bc(j) / av(j);
    }
    w_times_to(W, ws.A, ws.WA);
    w_times_to(W, ws.t, ws.Wt);
    nnls_ws(ws.WA, ws.Wt, ws.nn, 500, &pset);
    ws.d = ws.nn.x - c;
    const VectorXd& d = ws.d;
    ws.ctry = c + d;
    double lambda = 1.0, Sn = obj(ws.ctry);
    while (!(Sn <= S) && lambda > 1e-10) {
      lambda *= 0.5;
      ws.ctry = c + lambda * d;
      Sn = obj(ws.ctry);
    }
    if (!(Sn <= S)) { converged = true; break; }  // no descent: at optimum
    c += lambda * d;
    double dS = S - Sn;
    S = Sn;
    if (dS <= tol * (S + tol)) { converged = true; break; }
  }
  return Rcpp::List::create(Rcpp::Named("c") = c,
                            Rcpp::Named("objective") = S,
                            Rcpp::Named("iterations") = it,
                            Rcpp::Named("converged") = converged);
}

// Plain NNLS, exposed for tests against a reference solution.
// [[Rcpp::export(rng = false)]]
Eigen::VectorXd avfit_nnls(const Eigen::Map<Eigen::MatrixXd> A,
                           const Eigen::Map<Eigen::VectorXd> b) {
  return nnls(A, b);
}

// ---- covariance of Allan variance estimates for white rate noise ------------
// D_{m,k} = (mean of y over [k+m, k+2m)) - (mean over [k, k+m)); AV-hat_m =
// sum_k D^2 / (2 M). For i.i.d. y of unit variance, by Isserlis,
//   Cov(AV-hat_i, AV-hat_j) = 1/(2 M_i M_j) sum_k sum_l X_ij(l - k)^2,
// where X_ij(h) = sum_t w_i(t) w_j(t - h) is the cross-correlation of the
// two difference-of-boxcar kernels, computed in closed form from interval
// overlaps. Overlapping: k = 0..M-1, M = n - 2m + 1; non-overlapping:
// k = 0, m, .., (M-1)m, M = floor(n/m) - 1.
#include "parallel.h"
#include "structure_fn.h"

namespace {

inline double overlap(double a1, double b1, double a2, double b2) {
  double lo = a1 > a2 ? a1 : a2, hi = b1 < b2 ? b1 : b2;
  return hi > lo ? hi - lo : 0.0;
}

// X_ij(h), kernel i at 0, kernel j shifted by h.
inline double kernel_xcorr(double mi, double mj, double h) {
  double s = overlap(0, mi, h, h + mj) - overlap(0, mi, h + mj, h + 2 * mj) -
             overlap(mi, 2 * mi, h, h + mj) + overlap(mi, 2 * mi, h + mj, h + 2 * mj);
  return s / (mi * mj);
}

// X(h) is nonzero only while one of the three jumps of the longer kernel
// (at h, h + mj, h + 2 mj) lies inside the shorter one ([0, 2 mi)), so only
// h near those jumps are visited: O(mi) work per pair instead of O(mj).
double white_cov_pair(double mi, double mj, double n, bool overlapping) {
  if (mi > mj) std::swap(mi, mj);  // the covariance is symmetric in (i, j)
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (overlapping) {
    const double Mi = n - 2 * mi + 1, Mj = n - 2 * mj + 1;
    if (Mi < 1 || Mj < 1) return nan;
    auto term = [&](double h) {
      // pairs (k, l = k + h) with 0 <= k < Mi, 0 <= l < Mj
      double lo = h < 0 ? -h : 0.0;
      double hi = Mi < Mj - h ? Mi : Mj - h;
      double cnt = hi - lo;
      if (cnt <= 0) return 0.0;
      double x = kernel_xcorr(mi, mj, h);
      return cnt * x * x;
    };
    // X is piecewise linear in h with pieces >= ~mi long: a stride of mi/200
    // keeps the sum accurate to ~1e-4 (checked against the full sum).
    const double st = mi >= 400 ? std::floor(mi / 200) : 1.0;
    double sum = 0.0;
    auto range = [&](double a, double b) {
      if (a < -2 * mj + 1) a = -2 * mj + 1;
      if (b > 2 * mi - 1) b = 2 * mi - 1;
      for (double h = a; h <= b; h += st) sum += st * term(h);
    };
    if (mj <= 4 * mi + 8) {
      range(-2 * mj + 1, 2 * mi - 1);
    } else {
      for (int c = 0; c < 3; ++c) range(-c * mj - 2, 2 * mi - c * mj + 2);
    }
    return sum / (2 * Mi * Mj);
  }
  const double Mi = std::floor(n / mi) - 1, Mj = std::floor(n / mj) - 1;
  if (Mi < 1 || Mj < 1) return nan;
  // Outer loop over the (fewer) long clusters b, inner over the short
  // clusters a with -2 mj < b mj - a mi < 2 mi (exact sums).
  auto inner = [&](double b) {
    const double k = b * mj;
    double amin = std::floor((k - 2 * mi) / mi) + 1;
    double amax = std::ceil((k + 2 * mj) / mi) - 1;
    if (amin < 0) amin = 0;
    if (amax > Mi - 1) amax = Mi - 1;
    double sum = 0.0;
    auto add = [&](double a0, double a1) {
      if (a0 < amin) a0 = amin;
      if (a1 > amax) a1 = amax;
      for (double a = a0; a <= a1; a += 1.0) {
        double x = kernel_xcorr(mi, mj, k - a * mi);
        sum += x * x;
      }
    };
    if (amax - amin <= 64) {
      add(amin, amax);
    } else {
      for (int c = 0; c < 3; ++c) {
        double centre = (k + c * mj) / mi;
        add(std::floor(centre) - 3, std::ceil(centre) + 1);
      }
    }
    return sum;
  };
  // Away from the ends the inner sum depends only on b mj mod mi, which has
  // period Q = mi / gcd(mi, mj) in b: sum one period and multiply.
  long long gi = static_cast<long long>(mi), gj = static_cast<long long>(mj);
  while (gj) { long long t = gi % gj; gi = gj; gj = t; }
  const double Q = mi / static_cast<double>(gi);
  const double edge = 4;
  double sum = 0.0;
  if (Mj <= 2 * edge + 2 * Q) {
    for (double b = 0; b < Mj; b += 1.0) sum += inner(b);
  } else {
    for (double b = 0; b < edge; b += 1.0) sum += inner(b) + inner(Mj - 1 - b);
    const double q = std::floor((Mj - 2 * edge) / Q);
    double per = 0.0;
    for (double b = edge; b < edge + Q; b += 1.0) per += inner(b);
    sum += q * per;
    for (double b = edge + q * Q; b < Mj - edge; b += 1.0) sum += inner(b);
  }
  return sum / (2 * Mi * Mj);
}

}  // namespace

// Covariance matrix of AV-hat at cluster sizes m (whole numbers) for n
// i.i.d. unit-variance rate samples. Rows are independent: parallel.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericMatrix avar_white_cov(const Rcpp::NumericVector& m, double n,
                                   bool overlapping, int threads) {
  const R_xlen_t J = m.size();
  Rcpp::NumericMatrix out(J, J);
  std::vector<double> mm(m.begin(), m.end()), res(J * J, 0.0);
  allanvar::parallel_for(J, threads, [&](R_xlen_t i, int) {
    for (R_xlen_t j = i; j < J; ++j) {
      res[i * J + j] = white_cov_pair(mm[i], mm[j], n, overlapping);
    }
  });
  for (R_xlen_t i = 0; i < J; ++i)
    for (R_xlen_t j = i; j < J; ++j) out(i, j) = out(j, i) = res[i * J + j];
  return out;
}

// ---- exact EDF of the AV estimator for the fitted model --------------------
// Greenhall & Riley (2003, "Uncertainty of stability variances based on
// finite differences"): the AV estimate at cluster size m is the mean of
// M squared second differences d_i = x_{i+2m} - 2 x_{i+m} + x_i of the
// phase, so for Gaussian noise
//   EDF = 2 E^2 / Var = M^2 R(0)^2 / sum_{|k|<M} (M - |k|) R(k)^2,
// R the autocovariance of d (lags k for the overlapping estimator, k m for
// the non-overlapping one). For a sum of independent terms R is the sum of
// the terms' R, each from its structure function V(l) = Var(sum of l
// consecutive rate samples):
//   R(k) = -1/2 [6 V(k) - 4 V(k + m) - 4 V(k - m) + V(k + 2m) + V(k - 2m)].
// The cross terms between noises are thereby included; a sum of per-term
// EDFs ((sum AV)^2 / sum AV_k^2 / nu_k) leaves them out and overstates the
// EDF up to twofold where two terms are level.

namespace {

using allanvar::StructureFn;
using allanvar::segment_sum;

double exact_edf_one(const StructureFn& V, double m, double M, bool overlapping,
                     double tail) {
  if (!(M >= 1)) return NA_REAL;
  const double r0 = V.acov_d(0.0, m);
  if (!(r0 > 0)) return NA_REAL;
  double s = 0.0;  // sum_{k >= 0} (M - k) R(k)^2 over the support
  if (overlapping) {
    const double kmax = std::min(M - 1.0, 2.0 * m + tail);
    // white phase adds to R only at lags 0, m, 2m (spikes the trapezoid
    // would smear): the smooth part is summed without it, the spikes added
    StructureFn Vs = V;
    Vs.p = 0.0;
    auto f = [&](double k) { double r = Vs.acov_d(k, m); return (M - k) * r * r; };
    double br[4] = {0.0, std::min(m, kmax), std::min(2.0 * m, kmax), kmax};
    for (int i = 0; i < 3; ++i) s += segment_sum(br[i], br[i + 1], f, 64);
    s += f(kmax);
    if (V.p > 0) {
      for (double k : {0.0, m, 2.0 * m}) {
        if (k > kmax) break;
        const double r = V.acov_d(k, m), rs = Vs.acov_d(k, m);
        s += (M - k) * (r * r - rs * rs);
      }
    }
  } else {
    const double jmax = std::min(M - 1.0, 2.0 + std::ceil(tail / m));
    for (double j = 0; j <= jmax; j += 1.0) {
      double r = V.acov_d(j * m, m);
      s += (M - j) * r * r;
    }
  }
  const double den = 2.0 * s - M * r0 * r0;
  return den > 0 ? M * M * r0 * r0 / den : NA_REAL;
}

}  // namespace

// EDF of the AV estimates at cluster sizes m (M second differences each)
// for a model given as parts of its structure function, one per entry of
// `shape` (0: coef * l, 1: -coef (l^3 - l) / 6, 2: 2 coef for l > 0,
// 3: an AR(1) part, coef = sigma^2 with its `phi`), as the catalogue's
// entries describe their terms; NA where undefined.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector avfit_exact_edf(const Rcpp::NumericVector& m,
                                    const Rcpp::NumericVector& M,
                                    bool overlapping,
                                    const Rcpp::IntegerVector& shape,
                                    const Rcpp::NumericVector& coef,
                                    const Rcpp::NumericVector& phi) {
  double tail = 0.0;
  const StructureFn V = allanvar::structure_from_parts(shape, coef, phi, tail);
  const R_xlen_t J = m.size();
  Rcpp::NumericVector out(J);
  allanvar::InterruptScope scope;
  for (R_xlen_t j = 0; j < J; ++j) {
    if (allanvar::interrupted()) break;
    out[j] = exact_edf_one(V, m[j], M[j], overlapping, tail);
  }
  scope.finish();
  return out;
}
