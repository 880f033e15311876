# Estimators of K tried against GMWM's K error in bench-gmwm.R's "weak K"
# case (N 0.01, K 2e-4, GM sigma 0.02, tc 2 s, 100 Hz, 1e5 samples), on
# the same generator and seeds. A record of what does and does not move the
# relative RMSE of K (issue 9), not package code: the alternatives are
# written here, on the exact second-moment structure of the overlapping AV
# estimator for the N + K + GM model. The Cramer-Rao bounds of the same
# cases and the exact maximum-likelihood estimator of the raw series (the
# best an unbiased estimator can do) are in bench/gmwm-mle.R.
#
#   R CMD INSTALL --preclean . && Rscript bench/gmwm-k-variants.R [seeds] [n] [K] [extend]
#
# extend = 1 adds two cluster sizes above the last octave (m = 2^15.25,
# 2^15.5 at 1e5), where K dominates the curve.
#
# The covariance of the AV estimates follows Greenhall & Riley (2003/2004):
# the estimator at cluster size m is the mean of squared second differences
# d_i = x_{i+2m} - 2 x_{i+m} + x_i of the phase, so its variance and the
# covariance between two cluster sizes are sums of squared cross-covariances
# of the d sequences. For a sum of independent terms those come from each
# term's phase structure function V(l) = Var(sum of l rate samples)
# (generalised for the random walk: -(K^2 tau0) (l^3 - l) / 6):
#   Cov(d^(m1)_0, d^(m2)_k) = -1/2 sum_ab c_a c_b V(k + o2_b - o1_a),
#   c = (1, -2, 1), o = (0, m, 2m).
# The sums over lags are exact on short stretches and trapezoidal (401
# nodes between the kinks at multiples of m) on long ones.
library(allanvar)
source("bench/common.R")
args <- commandArgs(TRUE)
S <- if (length(args) >= 1L) as.integer(args[1L]) else 20L
n <- if (length(args) >= 2L) as.numeric(args[2L]) else 1e5
Kt <- if (length(args) >= 3L) as.numeric(args[3L]) else 2e-4
extend <- length(args) >= 4L && args[4L] == "1"
freq <- 100
tau0 <- 1 / freq
truth <- c(N = 0.01, K = Kt, sigma = 0.02, tc = 2)

# bench-gmwm.R's generator (bench/common.R; same seeds: 1000 k + s)
gen <- function(n, seed) composite_series(n, seed, truth, tau0)

# V(l) in rate^2 units (tau0^2 x rate^2 = phase^2)
Vfun <- function(l, p) {
  l <- abs(l)
  phi <- exp(-tau0 / p[["tc"]])
  p[["N"]]^2 / tau0 * l - p[["K"]]^2 * tau0 * (l^3 - l) / 6 +
    p[["sigma"]]^2 * (l * (1 + phi) / (1 - phi) - 2 * phi * (1 - phi^l) / (1 - phi)^2)
}
# exact discrete AV: (4 V(m) - V(2m)) / (2 m^2)
avm <- function(m, p) (4 * Vfun(m, p) - Vfun(2 * m, p)) / (2 * m^2)

# Covariance matrix of the overlapping AV estimates at cluster sizes m,
# L phase points.
avcov <- function(m, L, p) {
  J <- length(m)
  C <- matrix(0, J, J)
  tail <- ceiling(12 * p[["tc"]] / tau0)
  c1 <- c(1, -2, 1)
  for (i in 1:J) for (j in i:J) {
    m1 <- m[i]; m2 <- m[j]; M1 <- L - 2 * m1; M2 <- L - 2 * m2
    o1 <- c(0, m1, 2 * m1); o2 <- c(0, m2, 2 * m2)
    C12 <- function(k) {
      s <- 0
      for (a in 1:3) for (b in 1:3) s <- s + c1[a] * c1[b] * Vfun(k + o2[b] - o1[a], p)
      -0.5 * s
    }
    cnt <- function(k) pmax(0, pmin(M1, M2 - k) - pmax(0, -k))
    lo <- max(-(M1 - 1), -2 * m2 - tail)
    hi <- min(M2 - 1, 2 * m1 + tail)
    kinks <- outer(o1, o2, function(a, b) a - b)
    br <- sort(unique(c(lo, hi, pmin(pmax(c(0, kinks), lo), hi))))
    tot <- 0
    for (s in seq_len(length(br) - 1L)) {
      a <- br[s]; b <- br[s + 1L]
      k <- if (b - a <= 400) a:b else unique(round(seq(a, b, length.out = 401)))
      f <- cnt(k) * C12(k)^2
      tot <- tot + if (length(k) == b - a + 1) sum(f[-length(f)]) else
        sum(diff(k) * (f[-1] + f[-length(f)]) / 2) + (f[1] - f[length(f)]) / 2
    }
    tot <- tot + cnt(hi) * C12(hi)^2
    C[i, j] <- C[j, i] <- 2 * tot / (M1 * M2 * 4 * m1^2 * m2^2)
  }
  C
}

cf4 <- function(f) {
  cf <- coef(f)
  c(N = cf[["N"]], K = cf[["K"]], sigma = cf[["gm1.sigma"]], tc = cf[["gm1.tc"]])
}
th2p <- function(th) {
  th <- unname(th)
  c(N = exp(th[1]), K = exp(th[2]), sigma = exp(th[3]), tc = exp(th[4]))
}
# Nelder-Mead on log parameters from avfit's estimate (K started off 0)
fitobj <- function(obj, p0) {
  p0[["K"]] <- max(p0[["K"]], 1e-3 * Kt)
  o <- stats::optim(log(p0), function(th) obj(th2p(th)),
                    control = list(maxit = 3000, reltol = 1e-12))
  th2p(o$par)
}

res <- vector("list", S)
for (s in seq_len(S)) {
  x <- gen(n, 1000L * (if (n == 1e5) 1 else 2) + s)
  a <- if (extend) {
    top <- 2^floor(log2((n - 1) / 2))
    allan(x, freq, taus = I(c(2^(0:log2(top)), round(top * 2^c(0.25, 0.5))) / freq))
  } else allan(x, freq)
  m <- round(a$tau * freq)
  y <- a$avar
  L <- n + 1
  f0 <- avfit(a, c("N", "K", "gm"))
  p0 <- cf4(f0)
  out <- list(avfit = p0)
  # avfit's log fit, EDF exact for the model (iterated from the fit, and
  # with the true parameters: the best the EDF can do)
  tab <- data.frame(tau = a$tau, avar = y)
  p <- p0
  for (it in 1:2) {
    tab$edf <- 2 * avm(m, p)^2 / diag(avcov(m, L, p))
    p <- cf4(avfit(tab, c("N", "K", "gm"), n = n, freq = freq))
  }
  out$exact_edf <- p
  tab$edf <- 2 * avm(m, truth)^2 / diag(avcov(m, L, truth))
  out$true_edf <- cf4(avfit(tab, c("N", "K", "gm"), n = n, freq = freq))
  # chi-square (Gamma) likelihood, exact EDF
  p <- p0
  for (it in 1:2) {
    nu <- 2 * avm(m, p)^2 / diag(avcov(m, L, p))
    p <- fitobj(function(q) { A <- avm(m, q); sum(nu / 2 * (y / A + log(A))) }, p)
  }
  out$gamma <- p
  # linear GLS, exact model covariance of all tau pairs (iterated GMM)
  p <- p0
  for (it in 1:3) {
    Ci <- solve(avcov(m, L, p))
    p <- fitobj(function(q) { r <- y - avm(m, q); sum(r * (Ci %*% r)) }, p)
  }
  out$lin_gls <- p
  # log GLS: chi-square log bias and variance per tau, exact correlation
  p <- p0
  for (it in 1:2) {
    C <- avcov(m, L, p)
    nu <- 2 * avm(m, p)^2 / diag(C)
    sd <- sqrt(trigamma(nu / 2))
    Si <- solve(stats::cov2cor(C) * outer(sd, sd))
    b <- digamma(nu / 2) - log(nu / 2)
    p <- fitobj(function(q) { r <- log(y) - log(avm(m, q)) - b; sum(r * (Si %*% r)) }, p)
  }
  out$log_gls <- p
  # Neyman weighting (variance from the observed AV, as a data-estimated
  # weight matrix does): biased low by construction
  p <- p0
  for (it in 1:3) {
    C <- avcov(m, L, p)
    sdo <- y * sqrt(diag(C)) / avm(m, p)
    Ci <- solve(stats::cov2cor(C) * outer(sdo, sdo))
    p <- fitobj(function(q) { r <- y - avm(m, q); sum(r * (Ci %*% r)) }, p)
  }
  out$neyman <- p
  res[[s]] <- out
}

cat(sprintf("n = %g, K = %g, %d seeds%s\n", n, Kt, S,
            if (extend) ", two taus above the last octave" else ""))
cat("method      relative RMSE %: N K sigma tc | mean estimate/truth | median |err| %\n")
for (meth in names(res[[1L]])) {
  E <- do.call(rbind, lapply(res, `[[`, meth))
  rel <- sweep(E, 2L, truth, "/") - 1
  cat(sprintf("%-10s %s | %s | %s\n", meth,
    paste(sprintf("%6.2f", 100 * sqrt(colMeans(rel^2))), collapse = " "),
    paste(sprintf("%5.3f", colMeans(E / rep(truth, each = nrow(E)))), collapse = " "),
    paste(sprintf("%6.2f", 100 * apply(abs(rel), 2L, stats::median)), collapse = " ")))
}
