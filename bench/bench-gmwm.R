# allanvar's Allan-variance fit against GMWM (Guerrier et al. 2013, JASA;
# CRAN simts) on composite simulations: white noise + rate random walk +
# Gauss-Markov. Relative RMSE of every parameter over seeds, at 1e5 and
# 1e6 samples. The series come from the generator written below (not
# avsim()), so neither method is scored on its own simulator.
#
#   R CMD INSTALL --preclean . && Rscript bench/bench-gmwm.R [seeds_1e5] [seeds_1e6]
# (--preclean: objects pkgload::load_all() left in src/ are built with -O0
# and a plain install would reuse them; allan() ran 30x slower that way.)
#
# simts is installed into a temporary library (or into
# $ALLANVAR_BENCH_LIB when set, to keep it between runs); the time the
# install takes is printed. Debian's prebuilt r-cran-rcpparmadillo saves
# most of the compile time: apt-get install -y r-cran-rcpparmadillo
# r-cran-scales r-cran-broom r-cran-dplyr r-cran-tidyr first.
library(allanvar)
source("bench/common.R")
args <- as.integer(commandArgs(TRUE))
seeds <- c(if (length(args) >= 1L) args[1L] else 20L,
           if (length(args) >= 2L) args[2L] else 10L)

lib <- Sys.getenv("ALLANVAR_BENCH_LIB", tempfile("simts-lib"))
dir.create(lib, showWarnings = FALSE, recursive = TRUE)
.libPaths(c(lib, .libPaths()))
if (!requireNamespace("simts", quietly = TRUE)) {
  t_inst <- system.time(
    utils::install.packages("simts", lib = lib, repos = "https://cloud.r-project.org",
                            Ncpus = 2L, quiet = TRUE))[["elapsed"]]
  cat(sprintf("simts installed into %s in %.0f s\n", lib, t_inst))
}
stopifnot(requireNamespace("simts", quietly = TRUE))
cat(sprintf("simts %s\n", utils::packageVersion("simts")))

freq <- 100
tau0 <- 1 / freq
# Two composites: K clearly above the GM at long tau ("strong K"), and K
# level with the GM's tail at the longest tau of a 1e5 record ("weak K").
scenarios <- list(
  "strong K" = c(N = 0.01, K = 1e-3, sigma = 0.02, tc = 2),
  "weak K" = c(N = 0.01, K = 2e-4, sigma = 0.02, tc = 2))
truth <- scenarios[[1L]]

# Our own generator (bench/common.R), the current scenario's truth.
gen <- function(n, seed) composite_series(n, seed, truth, tau0)

fit_allanvar <- function(x) {
  f <- avfit(allan(x, freq), terms = c("N", "K", "gm"))
  cf <- coef(f)
  c(N = cf[["N"]], K = cf[["K"]], sigma = cf[["gm1.sigma"]], tc = cf[["gm1.tc"]])
}
# the exact likelihood of the raw series (avmle(); its Cramer-Rao bounds in
# bench/gmwm-mle.R)
fit_mle <- function(x) {
  cf <- coef(avmle(x, freq, terms = c("N", "K", "gm")))
  c(N = cf[["N"]], K = cf[["K"]], sigma = cf[["gm1.sigma"]], tc = cf[["gm1.tc"]])
}

# simts works per sample: WN sigma2 = N^2 / tau0; RW gamma2 = K^2 tau0;
# AR1 (phi, innovation variance s2): sigma^2 = s2 / (1 - phi^2),
# tc = -tau0 / log(phi).
fit_gmwm <- function(x) {
  g <- simts::gmwm(simts::AR1() + simts::WN() + simts::RW(), data = x)
  est <- g$estimate[, 1]
  nm <- rownames(g$estimate)
  phi <- est[[which(nm == "AR1")]]
  s2 <- est[[which(nm == "SIGMA2")]]
  c(N = sqrt(est[[which(nm == "WN")]] * tau0),
    K = sqrt(est[[which(nm == "RW")]] / tau0),
    sigma = sqrt(s2 / (1 - phi^2)),
    tc = -tau0 / log(phi))
}

rel_rmse <- function(est) {
  rel <- sweep(est, 2L, truth[colnames(est)], "/") - 1
  100 * sqrt(colMeans(rel^2))
}
# median absolute relative error: the typical error, which a few wild
# estimates do not dominate
rel_mdae <- function(est) {
  rel <- sweep(est, 2L, truth[colnames(est)], "/") - 1
  100 * apply(abs(rel), 2L, stats::median)
}

# mean estimate over truth: the bias, which the RMSE mixes with the spread
# (an estimator shrunk towards 0 trades one for the other)
rel_mean <- function(est) {
  colMeans(sweep(est, 2L, truth[colnames(est)], "/"))
}

rows <- list()
mdae <- list()
bias <- list()
for (sc in names(scenarios)) {
truth <- scenarios[[sc]]
for (k in 1:2) {
  n <- c(1e5, 1e6)[k]
  ea <- eg <- em <- matrix(NA_real_, seeds[k], 4L, dimnames = list(NULL, names(truth)))
  ta <- tg <- tm <- numeric(seeds[k])
  for (s in seq_len(seeds[k])) {
    x <- gen(n, 1000L * k + s)
    ta[s] <- system.time(ea[s, ] <- fit_allanvar(x))[["elapsed"]]
    tm[s] <- system.time(em[s, ] <- fit_mle(x))[["elapsed"]]
    tg[s] <- system.time(eg[s, ] <- tryCatch(fit_gmwm(x),
                                             error = function(e) rep(NA_real_, 4L)))[["elapsed"]]
  }
  ok <- stats::complete.cases(eg)
  rows[[length(rows) + 1L]] <- data.frame(
    scenario = sc, n = n, method = c("allanvar", "allanvar mle", "gmwm"),
    seeds = c(seeds[k], seeds[k], sum(ok)),
    rbind(rel_rmse(ea), rel_rmse(em), rel_rmse(eg[ok, , drop = FALSE])),
    median_s = c(median(ta), median(tm), median(tg)), check.names = FALSE)
  mdae[[length(mdae) + 1L]] <- data.frame(
    scenario = sc, n = n, method = c("allanvar", "allanvar mle", "gmwm"),
    rbind(rel_mdae(ea), rel_mdae(em), rel_mdae(eg[ok, , drop = FALSE])), check.names = FALSE)
  bias[[length(bias) + 1L]] <- data.frame(
    scenario = sc, n = n, method = c("allanvar", "allanvar mle", "gmwm"),
    rbind(rel_mean(ea), rel_mean(em), rel_mean(eg[ok, , drop = FALSE])), check.names = FALSE)
}
}
out <- do.call(rbind, rows)
for (sc in names(scenarios)) {
  tr <- scenarios[[sc]]
  cat(sprintf("%s: N = %g, K = %g, GM sigma = %g, tc = %g s; %g Hz\n", sc,
              tr[["N"]], tr[["K"]], tr[["sigma"]], tr[["tc"]], freq))
}
cat("Relative RMSE of each parameter, percent (lower is better):\n")
num <- c("N", "K", "sigma", "tc")
out[num] <- lapply(out[num], function(v) signif(v, 3))
out$median_s <- signif(out$median_s, 3)
print(out, row.names = FALSE)
md <- do.call(rbind, mdae)
md[num] <- lapply(md[num], function(v) signif(v, 3))
cat("\nMedian absolute relative error, percent:\n")
print(md, row.names = FALSE)
bi <- do.call(rbind, bias)
bi[num] <- lapply(bi[num], function(v) signif(v, 3))
cat("\nMean estimate / truth (1 = unbiased):\n")
print(bi, row.names = FALSE)
