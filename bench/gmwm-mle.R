# How well can anyone estimate bench-gmwm.R's composites (white noise N +
# rate random walk K + Gauss-Markov sigma, tc; 100 Hz; 1e5 and 1e6
# samples)? Prints, from one run:
#  1. the Cramer-Rao bound of each parameter (relative SD of an unbiased
#     estimator, = SD of the log-parameter): (a) Whittle's approximation on
#     the first differences with the exact discrete-time PSDs, (b) exact:
#     the expected Fisher information of the exact Gaussian likelihood,
#     computed through the Kalman filter, and (c) a Monte Carlo check of
#     (b): the covariance of the score at the true parameters over
#     simulated series (E[score score'] = Fisher information), with a
#     bootstrap 95% range;
#  2. the exact Gaussian maximum-likelihood estimator of the rate series
#     (Kalman filter: the package's kernel, src/mle.cpp) next to allanvar's avfit(allan())
#     and GMWM (CRAN simts) on bench-gmwm.R's generator and seeds: relative
#     RMSE, median |error| and mean estimate / truth of every parameter.
# A record for issue 9 (is GMWM's K error at 1e5 "weak K" reachable by an
# honest estimator?), not package code.
#
#   R CMD INSTALL --preclean . && Rscript bench/gmwm-mle.R [seeds_1e5] [seeds_1e6] [score_seeds_1e5] [score_seeds_1e6]
# (defaults 20 10 400 100; simts as in bench-gmwm.R: a temporary library or
# $ALLANVAR_BENCH_LIB)
library(allanvar)
source("bench/common.R")
args <- as.integer(commandArgs(TRUE))
arg <- function(i, d) if (length(args) >= i) args[i] else d
seeds <- c(arg(1L, 20L), arg(2L, 10L))
score_seeds <- c(arg(3L, 400L), arg(4L, 100L))

lib <- Sys.getenv("ALLANVAR_BENCH_LIB", tempfile("simts-lib"))
dir.create(lib, showWarnings = FALSE, recursive = TRUE)
.libPaths(c(lib, .libPaths()))
if (!requireNamespace("simts", quietly = TRUE)) {
  utils::install.packages("simts", lib = lib, repos = "https://cloud.r-project.org",
                          Ncpus = 2L, quiet = TRUE)
}
stopifnot(requireNamespace("simts", quietly = TRUE))
# random walk (diffuse start) + GM (stationary start), white noise R:
# c(sum log F, sum v^2 / F, count) from the package's Kalman kernel
kf_sums <- function(y, R, qr, qg, phi) {
  allanvar:::mle_kalman_sums(y, R, c(1, phi), c(qr, qg),
                             c(0, qg / (1 - phi^2)), 0L)
}
cat(sprintf("simts %s, allanvar %s\n", utils::packageVersion("simts"),
            utils::packageVersion("allanvar")))

freq <- 100
tau0 <- 1 / freq
scenarios <- list(
  "strong K" = c(N = 0.01, K = 1e-3, sigma = 0.02, tc = 2),
  "weak K" = c(N = 0.01, K = 2e-4, sigma = 0.02, tc = 2))
pn <- c("N", "K", "sigma", "tc")

# per-sample state-space variances of (N, K, sigma, tc)
ssm <- function(p) {
  phi <- exp(-tau0 / p[["tc"]])
  list(R = p[["N"]]^2 / tau0, qr = p[["K"]]^2 * tau0,
       qg = p[["sigma"]]^2 * (1 - phi^2), phi = phi)
}
loglik <- function(y, p) {
  s <- ssm(p)
  z <- kf_sums(y, s$R, s$qr, s$qg, s$phi)
  -0.5 * (z[[3]] * log(2 * pi) + z[[1]] + z[[2]])
}
# R profiled out (Durbin & Koopman 2012, sec. 7.2.3 "concentration"):
# th = (log qr/R, log s2/R, log tc)
prof <- function(y, th) {
  phi <- exp(-tau0 / exp(th[3]))
  z <- kf_sums(y, 1, exp(th[1]), exp(th[2]) * (1 - phi^2), phi)
  list(R = z[[2]] / z[[3]], ll = -0.5 * (z[[3]] * (log(2 * pi * z[[2]] / z[[3]]) + 1) + z[[1]]))
}
LOWK <- -80  # floor of log(qr / R): K = 0 for every purpose
fit_mle <- function(y, start) {
  s <- ssm(start)
  # avfit's estimate as the start; if its K is 0, the K whose AV equals
  # N's at a tenth of the record
  K0 <- max(start[["K"]], sqrt(3) * start[["N"]] / (length(y) * tau0 / 10))
  th0 <- c(log(K0^2 * tau0 / s$R), log(start[["sigma"]]^2 / s$R), log(start[["tc"]]))
  best <- NULL
  for (dk in log(c(1, 0.01, 100))) {
    o <- stats::optim(replace(th0, 1L, th0[1] + dk), function(t) -prof(y, t)$ll,
                      method = "L-BFGS-B", lower = c(LOWK, -30, log(tau0 / 10)),
                      upper = c(10, 30, log(length(y) * tau0)),
                      control = list(factr = 1e5))
    if (is.null(best) || o$value < best$value) best <- o
  }
  th <- best$par
  R <- prof(y, th)$R
  c(N = sqrt(R * tau0), K = if (th[1] <= LOWK + 1e-3) 0 else sqrt(exp(th[1]) * R / tau0),
    sigma = sqrt(exp(th[2]) * R), tc = exp(th[3]))
}
fit_allanvar <- function(x) {
  cf <- coef(avfit(allan(x, freq), terms = c("N", "K", "gm")))
  c(N = cf[["N"]], K = cf[["K"]], sigma = cf[["gm1.sigma"]], tc = cf[["gm1.tc"]])
}
fit_gmwm <- function(x) {  # as bench-gmwm.R
  g <- simts::gmwm(simts::AR1() + simts::WN() + simts::RW(), data = x)
  est <- g$estimate[, 1]
  nm <- rownames(g$estimate)
  phi <- est[[which(nm == "AR1")]]
  c(N = sqrt(est[[which(nm == "WN")]] * tau0), K = sqrt(est[[which(nm == "RW")]] / tau0),
    sigma = sqrt(est[[which(nm == "SIGMA2")]] / (1 - phi^2)), tc = -tau0 / log(phi))
}

# Whittle (1953) information of the n - 1 differences, Fourier frequencies
# k = 1..n-2 (k = 0 left out: the periodogram there is the end-point
# difference, dominated by the white and GM terms, not the PSD's S(0) = qr)
crb_whittle <- function(p, n) {
  m <- n - 1
  w <- 2 * pi * seq_len(m - 1) / m
  c1 <- 2 * (1 - cos(w))
  lS <- function(lp) {
    q <- exp(lp); phi <- exp(-tau0 / q[4])
    log(c1 * q[1]^2 / tau0 + q[2]^2 * tau0 +
        c1 * q[3]^2 * (1 - phi^2) / (1 - 2 * phi * cos(w) + phi^2))
  }
  G <- vapply(1:4, function(j) {
    e <- replace(numeric(4), j, 1e-5)
    (lS(log(p) + e) - lS(log(p) - e)) / 2e-5
  }, numeric(length(w)))
  100 * sqrt(diag(solve(0.5 * crossprod(G))))
}
# Exact expected information of the likelihood of y_2..y_n given y_1
# (Harvey 1989, sec. 3.4.6):
#   I_ij = sum_t [ dF_i dF_j / (2 F_t^2) + E(dv_i dv_j) / F_t ],
# F_t, v_t the innovation variance and innovation, d the derivative in the
# log parameters. F_t and the gain are deterministic (derivatives by central
# differences of the covariance recursion run at +-h); dv = -Z da, and the
# predicted state's derivatives da_t are linear in the noise, so E(dv dv')
# comes from the covariance of the stacked linear system
#   x_t = (filter error e_t (2), GM state g_t, da_t for 4 parameters (8)),
#   e_{t+1} = (T - G Z) e_t + eta_t - G eps_t,  g_{t+1} = phi g_t + eta_g,
#   da_{t+1} = dT (g_t - e_g,t) + (T - G Z) da_t + dG (Z e_t + eps_t),
# started after y_1 (da = 0, e = (-g_1 - eps_1, g_1) predicted one step).
# Once the filter and the stacked covariance are stationary the remaining
# steps add the same increment. Cov(e_t) = P_t is checked on the way.
crb_kalman <- function(p, n, h = 1e-5) {
  L <- matrix(log(p), 9L, 4L, byrow = TRUE)
  for (j in 1:4) L[2 * j, j] <- L[2 * j, j] + h; for (j in 1:4) L[2 * j + 1, j] <- L[2 * j + 1, j] - h
  P <- exp(L)  # row 1: p; rows 2j, 2j+1: parameter j at +-h
  R <- P[, 1]^2 / tau0; qr <- P[, 2]^2 * tau0; s2 <- P[, 3]^2
  phi <- exp(-tau0 / P[, 4]); qg <- s2 * (1 - phi^2); ph <- phi[1]
  Prr <- s2 + R + qr; Prg <- -phi * s2; Pgg <- s2  # predicted P_2
  dphi <- c(0, 0, 0, ph * tau0 / p[[4]])
  Sig <- matrix(0, 11, 11)
  Sig[1:3, 1:3] <- matrix(c(Prr[1], Prg[1], Prg[1], Prg[1], s2[1], s2[1], Prg[1], s2[1], s2[1]), 3)
  W <- diag(c(qr[1], qg[1], R[1]))
  rows <- lapply(1:4, function(j) 3 + 2 * j - 1:0)
  up <- 2 * (1:4); dn <- up + 1
  I <- matrix(0, 4, 4); inc_old <- NULL; dev <- 0
  for (t in 2:n) {
    kr <- Prr + Prg; kg <- Prg + Pgg
    F <- kr + kg + R
    Gr <- kr / F; Gg <- phi * kg / F
    dF <- (F[up] - F[dn]) / (2 * h)
    dGr <- (Gr[up] - Gr[dn]) / (2 * h); dGg <- (Gg[up] - Gg[dn]) / (2 * h)
    ZS <- matrix(0, 4, 4)
    for (i in 1:4) for (j in i:4) ZS[i, j] <- ZS[j, i] <- sum(Sig[rows[[i]], rows[[j]]])
    inc <- outer(dF, dF) / (2 * F[1]^2) + ZS / F[1]
    I <- I + inc
    if (t %% 1000 == 0) {
      dev <- max(dev, abs(Sig[1, 1] / Prr[1] - 1), abs(Sig[2, 2] / Pgg[1] - 1))
      if (!is.null(inc_old) && max(abs(inc - inc_old) / sqrt(outer(diag(inc), diag(inc)))) < 1e-10) {
        I <- I + inc * (n - t)
        break
      }
      inc_old <- inc
    }
    TGZ <- matrix(c(1 - Gr[1], -Gg[1], -Gr[1], ph - Gg[1]), 2)
    A <- matrix(0, 11, 11); B <- matrix(0, 11, 3)
    A[1:2, 1:2] <- TGZ; A[3, 3] <- ph
    B[1, 1] <- 1; B[2, 2] <- 1; B[3, 2] <- 1; B[1:2, 3] <- -c(Gr[1], Gg[1])
    for (j in 1:4) {
      r <- rows[[j]]
      A[r, 1:2] <- c(dGr[j], dGg[j])
      A[r[2], 3] <- dphi[j]; A[r[2], 2] <- A[r[2], 2] - dphi[j]
      A[r, r] <- TGZ
      B[r, 3] <- c(dGr[j], dGg[j])
    }
    Sig <- A %*% Sig %*% t(A) + B %*% W %*% t(B)
    fr <- Prr - kr^2 / F; fg <- Prg - kr * kg / F; fgg <- Pgg - kg^2 / F
    Prr <- fr + qr; Prg <- phi * fg; Pgg <- phi^2 * fgg + qg
  }
  stopifnot(dev < 1e-8)  # the stacked system reproduces the filter's P
  100 * sqrt(diag(solve(I)))
}

# Monte Carlo check of the exact bound: covariance of the score (central differences in log parameters)
crb_score <- function(p, n, S) {
  sc <- t(vapply(seq_len(S), function(s) {
    y <- composite_series(n, 500000L + s, p, tau0)
    vapply(1:4, function(j) {
      e <- replace(numeric(4), j, 1e-4)
      (loglik(y, setNames(exp(log(p) + e), pn)) - loglik(y, setNames(exp(log(p) - e), pn))) / 2e-4
    }, 0)
  }, numeric(4)))
  bound <- function(i) 100 * sqrt(diag(solve(crossprod(sc[i, , drop = FALSE]) / length(i))))
  set.seed(1)
  # a resample with fewer distinct seeds than parameters is singular
  bt <- replicate(500, tryCatch(bound(sample(S, replace = TRUE)),
                                error = function(e) rep(NA_real_, 4L)))
  rbind(est = bound(seq_len(S)), lo = apply(bt, 1, stats::quantile, 0.025, na.rm = TRUE),
        hi = apply(bt, 1, stats::quantile, 0.975, na.rm = TRUE))
}

crb <- list(); err <- list()
for (sc in names(scenarios)) {
  truth <- scenarios[[sc]]
  for (k in 1:2) {
    n <- c(1e5, 1e6)[k]
    w <- crb_whittle(truth, n)
    kb <- crb_kalman(truth, n)
    ex <- crb_score(truth, n, score_seeds[k])
    cell <- function(j) c(signif(w[j], 3), signif(kb[j], 3), signif(ex["est", j], 3),
                          sprintf("%.3g-%.3g", ex["lo", j], ex["hi", j]))
    crb[[length(crb) + 1L]] <- data.frame(
      scenario = sc, n = n,
      bound = c("whittle", "exact", sprintf("score MC (%d seeds)", score_seeds[k]), "score MC 95% range"),
      N = cell(1), K = cell(2), sigma = cell(3), tc = cell(4))
    E <- array(NA_real_, c(seeds[k], 4L, 3L), list(NULL, pn, c("allanvar", "mle", "gmwm")))
    tm <- matrix(NA_real_, seeds[k], 3L)
    for (s in seq_len(seeds[k])) {
      x <- composite_series(n, 1000L * k + s, truth, tau0)  # bench-gmwm.R's seeds
      tm[s, 1] <- system.time(E[s, , 1] <- fit_allanvar(x))[["elapsed"]]
      tm[s, 2] <- system.time(E[s, , 2] <- fit_mle(x, E[s, , 1]))[["elapsed"]]
      tm[s, 3] <- system.time(E[s, , 3] <- tryCatch(fit_gmwm(x),
        error = function(e) rep(NA_real_, 4L)))[["elapsed"]]
    }
    for (j in 1:3) {
      e <- matrix(E[, , j], ncol = 4L, dimnames = list(NULL, pn))
      e <- e[stats::complete.cases(e), , drop = FALSE]
      rel <- sweep(e, 2L, truth, "/") - 1
      err[[length(err) + 1L]] <- data.frame(
        scenario = sc, n = n, method = dimnames(E)[[3]][j], seeds = nrow(e),
        stat = c("rmse %", "median |err| %", "mean/truth"),
        rbind(100 * sqrt(colMeans(rel^2)), 100 * apply(abs(rel), 2L, stats::median),
              colMeans(rel + 1)),
        K_lt_1pct = sum(e[, "K"] < 0.01 * truth[["K"]]), median_s = stats::median(tm[, j]), check.names = FALSE)
    }
  }
}
for (sc in names(scenarios)) {
  tr <- scenarios[[sc]]
  cat(sprintf("%s: N = %g, K = %g, GM sigma = %g, tc = %g s; %g Hz\n", sc,
              tr[["N"]], tr[["K"]], tr[["sigma"]], tr[["tc"]], freq))
}
options(width = 200)
cat("\nCramer-Rao bound: relative SD of an unbiased estimator, percent\n")
print(do.call(rbind, crb), row.names = FALSE)
out <- do.call(rbind, err)
out[pn] <- lapply(out[pn], function(v) signif(v, 3))
out$median_s <- signif(out$median_s, 3)
out <- out[order(out$scenario, out$n, match(out$stat, unique(out$stat)),
                 match(out$method, c("allanvar", "mle", "gmwm"))), ]
cat("\nEstimates against truth (K_lt_1pct: fits with K below 1% of the truth, i.e. at 0)\n")
print(out, row.names = FALSE)
