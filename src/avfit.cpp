// avfit(): the inner loop of the noise-model fit. For fixed nonlinear
// parameters the model AV is linear in the squared amplitudes c >= 0:
//   AV_j = offset_j + sum_k B_jk c_k.
// The fit minimises S(c) = sum_j ((y_j - ln AV_j) / s_j)^2 (log domain, EDF
// weights) by Gauss-Newton steps, each an NNLS problem, with step halving.
// It is called once per grid point of the profiled nonlinear parameters.
#include <RcppEigen.h>
#include <cmath>
#include <limits>
#include <vector>

using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

// Lawson-Hanson non-negative least squares: min ||A x - b||, x >= 0.
// Columns are scaled to unit norm first (the bases span many decades).
VectorXd nnls(const MatrixXd& A0, const VectorXd& b, int maxit = 500) {
  const int p = static_cast<int>(A0.cols());
  VectorXd scale(p);
  MatrixXd A = A0;
  for (int k = 0; k < p; ++k) {
    double nk = A.col(k).norm();
    scale(k) = nk > 0 ? nk : 1.0;
    A.col(k) /= scale(k);
  }
  VectorXd x = VectorXd::Zero(p);
  std::vector<bool> passive(p, false);
  const double tol = 1e-12 * (1.0 + b.norm());
  for (int it = 0; it < maxit; ++it) {
    VectorXd w = A.transpose() * (b - A * x);
    int t = -1;
    double wmax = tol;
    for (int k = 0; k < p; ++k) {
      if (!passive[k] && w(k) > wmax) { wmax = w(k); t = k; }
    }
    if (t < 0) break;
    passive[t] = true;
    for (int inner = 0; inner < 3 * p + 3; ++inner) {
      std::vector<int> idx;
      for (int k = 0; k < p; ++k) if (passive[k]) idx.push_back(k);
      const int q = static_cast<int>(idx.size());
      MatrixXd Ap(A.rows(), q);
      for (int i = 0; i < q; ++i) Ap.col(i) = A.col(idx[i]);
      VectorXd zp = Ap.colPivHouseholderQr().solve(b);
      bool ok = true;
      for (int i = 0; i < q; ++i) if (!(zp(i) > 0)) { ok = false; break; }
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
  }
  for (int k = 0; k < p; ++k) x(k) /= scale(k);
  return x;
}

double objective(const MatrixXd& B, const VectorXd& offset, const VectorXd& y,
                 const VectorXd& s, const VectorXd& c) {
  VectorXd av = offset + B * c;
  double S = 0.0;
  for (R_xlen_t j = 0; j < av.size(); ++j) {
    if (!(av(j) > 0)) return std::numeric_limits<double>::infinity();
    double r = (y(j) - std::log(av(j))) / s(j);
    S += r * r;
  }
  return S;
}

}  // namespace

// Squared amplitudes c >= 0 minimising the log-domain weighted objective.
// y = ln(AV-hat) minus the chi-square log bias; s = sqrt(psi'(edf/2)).
// [[Rcpp::export(rng = false)]]
Rcpp::List avfit_log_nnls(const Eigen::Map<Eigen::MatrixXd> B,
                          const Eigen::Map<Eigen::VectorXd> offset,
                          const Eigen::Map<Eigen::VectorXd> y,
                          const Eigen::Map<Eigen::VectorXd> s,
                          const Eigen::Map<Eigen::VectorXd> start,
                          int maxit, double tol) {
  const R_xlen_t J = B.rows();
  const int p = static_cast<int>(B.cols());
  VectorXd c = start;
  double S = objective(B, offset, y, s, c);
  if (!std::isfinite(S) || c.sum() <= 0) {
    // Linear-domain start: min sum ((offset + B c) / AV-hat - 1)^2 / s^2.
    MatrixXd A(J, p);
    VectorXd t(J);
    for (R_xlen_t j = 0; j < J; ++j) {
      double avh = std::exp(y(j));
      A.row(j) = B.row(j) / (avh * s(j));
      t(j) = (1.0 - offset(j) / avh) / s(j);
    }
    c = nnls(A, t);
    S = objective(B, offset, y, s, c);
    if (!std::isfinite(S)) {
      // Keep every term slightly on so that ln AV is finite everywhere.
      for (int k = 0; k < p; ++k) {
        double bk = B.col(k).cwiseAbs().maxCoeff();
        double floor_k = bk > 0 ? 1e-8 * std::exp(y.maxCoeff()) / bk : 0.0;
        if (c(k) < floor_k) c(k) = floor_k;
      }
      S = objective(B, offset, y, s, c);
    }
  }
  int it = 0;
  bool converged = false;
  for (; it < maxit && std::isfinite(S); ++it) {
    VectorXd av = offset + B * c;
    VectorXd bc = B * c;
    MatrixXd A(J, p);
    VectorXd t(J);
    for (R_xlen_t j = 0; j < J; ++j) {
      A.row(j) = B.row(j) / (av(j) * s(j));
      t(j) = (y(j) - std::log(av(j)) + bc(j) / av(j)) / s(j);
    }
    VectorXd cn = nnls(A, t);
    VectorXd d = cn - c;
    double lambda = 1.0, Sn = objective(B, offset, y, s, c + d);
    while (!(Sn <= S) && lambda > 1e-10) {
      lambda *= 0.5;
      Sn = objective(B, offset, y, s, c + lambda * d);
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
