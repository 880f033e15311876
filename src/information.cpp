// Exact Fisher information of a stationary Gaussian series d_t given in
// state-space form (x_{t+1} = T x_t + w_t, Var w = Q; d_t = Z'x_t + e_t,
// Var e = H; x_1 ~ N(0, P1)), accumulated step by step from the Kalman
// filter (Harvey 1989, Forecasting, Structural Time Series Models and the
// Kalman Filter, sec. 3.4.6):
//   I_ij = sum_t dF_i dF_j / (2 F^2) + E(dv_i dv_j) / F.
// F_t, the gain and their derivatives are deterministic (the Riccati
// recursion and its derivative). The innovations' derivatives are
// dv_i = -Z' da_i, with da_i the derivative of the predicted state, a
// linear function of past data: the stacked (a, da_1, ..., da_p) follows
//   a' = T a + K v,  da_i' = dT_i a + (T - K Z') da_i + dK_i v,
// and v_t is independent of the stack (an innovation), so the stack's
// covariance follows exactly with v's variance F. Once the increment of the
// information stops changing (the filter settled) every later sample adds
// the same, and the caller extrapolates. R/information.R builds the system
// from the catalogue; this kernel reads only numbers.
#include <RcppEigen.h>
#include <cmath>
#include <vector>

namespace {

// The state has two entries per stationary term and two for the white
// noise. Small matrices live on the stack (no allocation in the loop), of
// fixed size for the common models (one or two Gauss-Markov terms).
constexpr int kMaxState = 16;
using MatrixXd = Eigen::MatrixXd;
using VectorXd = Eigen::VectorXd;
using InfoMatrix = Eigen::MatrixXd;
template <int S> using SmallMatrix =
    Eigen::Matrix<double, S, S, Eigen::ColMajor, S == Eigen::Dynamic ? kMaxState : S,
                  S == Eigen::Dynamic ? kMaxState : S>;
template <int S> using SmallVector =
    Eigen::Matrix<double, S, 1, Eigen::ColMajor, S == Eigen::Dynamic ? kMaxState : S, 1>;

struct InfoOptions {
  R_xlen_t max_steps;  // differences to take at most
  double tol;          // relative change of the increment that counts as settled
  R_xlen_t every;      // steps between two checks of the increment
  R_xlen_t keep;       // keep the cumulative information every `keep` steps
};

struct InfoSystem {
  MatrixXd T, Q, P1;
  VectorXd Z;
  double H;
  std::vector<MatrixXd> dT, dQ, dP1;  // derivatives per parameter
  std::vector<double> dH;
  std::vector<bool> moves_T;          // dT_i != 0
};

struct InfoTrace {
  std::vector<double> cum;   // cumulative information, p * p per kept step
  std::vector<double> at;    // the steps kept
  InfoMatrix stationary;     // the settled increment (empty if not settled)
  R_xlen_t steps = 0;
};

template <int S>
InfoTrace info_run(const InfoSystem& m, const InfoOptions& opt) {
  using MatrixXd = SmallMatrix<S>;
  using VectorXd = SmallVector<S>;
  const Eigen::Index s = m.T.rows();
  const std::size_t p = m.dT.size();
  struct {
    MatrixXd T, Q;
    VectorXd Z;
    double H;
    std::vector<MatrixXd> dT, dQ;
    std::vector<double> dH;
    std::vector<bool> moves_T;
  } sys{m.T, m.Q, m.Z, m.H, {}, {}, m.dH, m.moves_T};
  for (std::size_t i = 0; i < p; ++i) {
    sys.dT.push_back(m.dT[i]);
    sys.dQ.push_back(m.dQ[i]);
  }
  InfoTrace out;
  MatrixXd P = m.P1;
  std::vector<MatrixXd> dP;
  for (std::size_t i = 0; i < p; ++i) dP.push_back(m.dP1[i]);
  // covariances of the stack: Saa, Sai[i] = Cov(a, da_i), Sij[i * p + j]
  MatrixXd Saa = MatrixXd::Zero(s, s);
  std::vector<MatrixXd> Sai(p, MatrixXd::Zero(s, s));
  std::vector<MatrixXd> Sij(p * p, MatrixXd::Zero(s, s));
  InfoMatrix I = InfoMatrix::Zero(p, p), inc(p, p), inc_old;
  VectorXd PZ(s), M(s), K(s), dPZ(s);
  Eigen::VectorXd dF(p);
  std::vector<VectorXd> dK(p, VectorXd::Zero(s)), dM(p, VectorXd::Zero(s));
  MatrixXd G(s, s), TP(s, s), tmp(s, s);
  std::vector<MatrixXd> nSai(p), nSij(p * p), GSia(p), dTSaa(p);
  for (R_xlen_t t = 0; t < opt.max_steps; ++t) {
    if ((t & 0x3FFF) == 0) Rcpp::checkUserInterrupt();
    PZ.noalias() = P * sys.Z;
    const double F = sys.Z.dot(PZ) + sys.H;
    M.noalias() = sys.T * PZ;
    K = M / F;
    for (std::size_t i = 0; i < p; ++i) {
      dPZ.noalias() = dP[i] * sys.Z;
      dF[i] = sys.Z.dot(dPZ) + sys.dH[i];
      dM[i].noalias() = sys.T * dPZ;
      if (sys.moves_T[i]) dM[i].noalias() += sys.dT[i] * PZ;
      dK[i] = dM[i] / F - M * (dF[i] / (F * F));
    }
    for (std::size_t i = 0; i < p; ++i) {
      for (std::size_t j = i; j < p; ++j) {
        const double e = dF[i] * dF[j] / (2 * F * F) + sys.Z.dot(Sij[i * p + j] * sys.Z) / F;
        inc(i, j) = inc(j, i) = e;
      }
    }
    I += inc;
    out.steps = t + 1;
    if (out.steps % opt.keep == 0) {
      out.cum.insert(out.cum.end(), I.data(), I.data() + p * p);
      out.at.push_back(static_cast<double>(out.steps));
    }
    if (out.steps % opt.every == 0) {
      if (inc_old.size()) {
        double worst = 0;
        for (std::size_t i = 0; i < p; ++i)
          for (std::size_t j = 0; j < p; ++j)
            worst = std::max(worst, std::abs(inc(i, j) - inc_old(i, j)) /
                                        std::sqrt(inc(i, i) * inc(j, j)));
        if (worst < opt.tol) {
          out.stationary = inc;
          break;
        }
      }
      inc_old = inc;
    }
    // the stack's covariance at t + 1
    G = sys.T - K * sys.Z.transpose();
    for (std::size_t i = 0; i < p; ++i) {
      GSia[i].noalias() = G * Sai[i].transpose();
      if (sys.moves_T[i]) dTSaa[i].noalias() = sys.dT[i] * Saa;
    }
    for (std::size_t i = 0; i < p; ++i) {
      for (std::size_t j = i; j < p; ++j) {
        // Cov(da_i', da_j')
        MatrixXd& n = nSij[i * p + j];
        n.noalias() = G * Sij[i * p + j] * G.transpose();
        if (sys.moves_T[j]) n.noalias() += GSia[i] * sys.dT[j].transpose();
        if (sys.moves_T[i]) {
          n.noalias() += sys.dT[i] * Sai[j] * G.transpose();
          if (sys.moves_T[j]) n.noalias() += dTSaa[i] * sys.dT[j].transpose();
        }
        n.noalias() += F * dK[i] * dK[j].transpose();
      }
      // Cov(a', da_i')
      nSai[i].noalias() = sys.T * Sai[i] * G.transpose();
      if (sys.moves_T[i]) nSai[i].noalias() += sys.T * Saa * sys.dT[i].transpose();
      nSai[i].noalias() += F * K * dK[i].transpose();
    }
    for (std::size_t i = 0; i < p; ++i) {
      Sai[i] = nSai[i];
      for (std::size_t j = i; j < p; ++j) {
        Sij[i * p + j] = nSij[i * p + j];
        if (j != i) Sij[j * p + i] = nSij[i * p + j].transpose();
      }
    }
    Saa = sys.T * Saa * sys.T.transpose() + F * K * K.transpose();
    // the Riccati recursion and its derivatives
    TP.noalias() = sys.T * P;
    for (std::size_t i = 0; i < p; ++i) {
      tmp.noalias() = sys.T * dP[i] * sys.T.transpose();
      if (sys.moves_T[i]) {
        tmp.noalias() += sys.dT[i] * TP.transpose();
        tmp.noalias() += TP * sys.dT[i].transpose();
      }
      tmp += sys.dQ[i];
      tmp.noalias() -= (dM[i] * M.transpose() + M * dM[i].transpose()) / F;
      tmp.noalias() += M * M.transpose() * (dF[i] / (F * F));
      dP[i] = tmp;
    }
    P = TP * sys.T.transpose() + sys.Q - M * M.transpose() / F;
  }
  if (out.at.empty() || out.at.back() != static_cast<double>(out.steps)) {
    out.cum.insert(out.cum.end(), I.data(), I.data() + p * p);
    out.at.push_back(static_cast<double>(out.steps));
  }
  return out;
}

MatrixXd as_matrix(const Rcpp::NumericVector& v, Eigen::Index s) {
  if (v.size() != s * s) Rcpp::stop("internal: information matrix of the wrong size");
  return Eigen::Map<const Eigen::MatrixXd>(v.begin(), s, s);
}

}  // namespace

// Internal entry point (R/information.R). `sys`: T, Q, P1 (s x s), Z (s), H;
// `deriv`: a list per parameter of dT, dQ, dP1, dH; `opts`: max_steps, tol,
// every, keep. Returns list(cum = p*p x kept steps, at = the steps kept (the
// last step always), stationary = p x p or NULL).
// [[Rcpp::export]]
Rcpp::List info_kalman(Rcpp::List sys, Rcpp::List deriv, Rcpp::List opts) {
  InfoSystem m;
  const Rcpp::NumericVector Z = sys["Z"];
  const Eigen::Index s = Z.size();
  if (s < 1 || s > kMaxState) Rcpp::stop("internal: information state of size %d", static_cast<int>(s));
  m.Z = Eigen::Map<const Eigen::VectorXd>(Z.begin(), s);
  m.T = as_matrix(sys["T"], s);
  m.Q = as_matrix(sys["Q"], s);
  m.P1 = as_matrix(sys["P1"], s);
  m.H = Rcpp::as<double>(sys["H"]);
  for (R_xlen_t i = 0; i < deriv.size(); ++i) {
    const Rcpp::List d = deriv[i];
    m.dT.push_back(as_matrix(d["T"], s));
    m.dQ.push_back(as_matrix(d["Q"], s));
    m.dP1.push_back(as_matrix(d["P1"], s));
    m.dH.push_back(Rcpp::as<double>(d["H"]));
    m.moves_T.push_back(m.dT.back().cwiseAbs().maxCoeff() > 0);
  }
  InfoOptions opt;
  opt.max_steps = static_cast<R_xlen_t>(Rcpp::as<double>(opts["max_steps"]));
  opt.tol = Rcpp::as<double>(opts["tol"]);
  opt.every = static_cast<R_xlen_t>(Rcpp::as<double>(opts["every"]));
  opt.keep = static_cast<R_xlen_t>(Rcpp::as<double>(opts["keep"]));
  if (opt.max_steps < 1 || opt.every < 1 || opt.keep < 1 || !(opt.tol >= 0))
    Rcpp::stop("internal: bad information options");
  const InfoTrace tr = s == 4 ? info_run<4>(m, opt) : s == 6 ? info_run<6>(m, opt)
                                                 : info_run<Eigen::Dynamic>(m, opt);
  const std::size_t p = m.dT.size();
  Rcpp::NumericMatrix cum(static_cast<int>(p * p), static_cast<int>(tr.at.size()));
  std::copy(tr.cum.begin(), tr.cum.end(), cum.begin());
  SEXP st = R_NilValue;
  if (tr.stationary.size()) {
    Rcpp::NumericMatrix sm(static_cast<int>(p), static_cast<int>(p));
    std::copy(tr.stationary.data(), tr.stationary.data() + p * p, sm.begin());
    st = sm;
  }
  return Rcpp::List::create(Rcpp::Named("cum") = cum,
                            Rcpp::Named("at") = Rcpp::wrap(tr.at),
                            Rcpp::Named("stationary") = st);
}
