# Offline Monte Carlo behind TheoBR's limits (R/theobr-edf.R): TheoBR =
# kappa * Theo1(m), where kappa, the bias factor, is the mean over the
# ladder of AVAR(9 + 3i) / Theo1(12 + 4i) estimated from the same record:
# one random factor multiplying every row. Var(log TheoBR) = Var(log Theo1)
# + Var(log kappa) + 2 Cov. For each power-law noise type (own generators:
# tools/mc-coverage.R's mc_generators()), record length L = N + 1 phase
# points and ladder (N/6, N/30) this prints
#  * nu_kappa = 2 / Var(log kappa), the factor's EDF (a function of the
#    ladder alone: kappa does not depend on the row);
#  * rho(u), the correlation of log kappa with log Theo1(m) at u = m / N
#    (octave m), which the runs at several N show is a function of u.
# Prints the tables as R code for R/theobr-edf.R (TSV with MC_OUT=file).
#
#   Rscript tools/theobr-ratio-edf.R [reps] [N,N,...] [seed]
#   e.g. MC_INSTALLED=1 nice Rscript tools/theobr-ratio-edf.R 1000 64,256,1024,4096 29
args <- commandArgs(TRUE)
reps <- if (length(args) >= 1) as.integer(args[1]) else 1000L
Ns <- if (length(args) >= 2) as.integer(strsplit(args[2], ",")[[1]]) else
  c(64L, 256L, 1024L, 4096L)
seed <- if (length(args) >= 3) as.integer(args[3]) else 29L
if (file.exists("DESCRIPTION") && requireNamespace("pkgload", quietly = TRUE) &&
    !nzchar(Sys.getenv("MC_INSTALLED"))) {
  pkgload::load_all(".", quiet = TRUE)
} else {
  library(allanvar)
}
source("tools/mc-coverage.R")  # mc_generators() (its main block is skipped)
ns <- asNamespace("allanvar")
options(allanvar.threads = 1)
out <- list()
for (N in Ns) {
  set.seed(seed + N)
  gens <- mc_generators(N)
  for (g in names(gens)) {
    res <- replicate(reps, {
      y <- gens[[g]]()
      a <- allan(y, 1, type = "theo1", debias = FALSE, ci = FALSE)
      c(ns$theobr_factor(y, 1, TRUE, N + 1, 1L, "N/6"),
        ns$theobr_factor(y, 1, TRUE, N + 1, 1L, "N/30"), a$avar)
    })
    ms <- allan(gens[[g]](), 1, type = "theo1", ci = FALSE)$m
    lt <- log(res[-(1:2), , drop = FALSE])
    for (ld in 1:2) {
      lk <- log(res[ld, ])
      if (!all(is.finite(lk))) next  # no N/30 ladder on short records
      out[[length(out) + 1L]] <- data.frame(
        noise = g, N = N, ladder = c("N/6", "N/30")[ld], nu_kappa = 2 / var(lk),
        m = ms, u = ms / N, rho = apply(lt, 1, function(r) stats::cor(r, lk)))
    }
    message(g, " N = ", N, " done")
  }
}
d <- do.call(rbind, out)
if (nzchar(Sys.getenv("MC_OUT"))) {
  utils::write.table(d, Sys.getenv("MC_OUT"), sep = "\t", row.names = FALSE)
}
alphas <- c(wpm = 2L, fpm = 1L, wfm = 0L, ffm = -1L, rwfm = -2L)
k <- unique(d[, c("noise", "N", "ladder", "nu_kappa")])
cat("# nu_kappa by ladder, noise exponent (rows 2, 1, 0, -1, -2), N (columns)\n")
for (ld in c("N/6", "N/30")) {
  s <- k[k$ladder == ld, ]
  cat(sprintf('"%s": N = %s\n', ld, paste(sort(unique(s$N)), collapse = ", ")))
  for (g in names(alphas)) {
    r <- s[s$noise == g, ]
    cat(sprintf("  %2d: %s\n", alphas[[g]],
                paste(signif(r$nu_kappa[order(r$N)], 3), collapse = ", ")))
  }
}
cat("# rho by ladder, noise exponent, u = 2^-10 .. 2^0 (mean over N >= 256)\n")
for (ld in c("N/6", "N/30")) {
  cat(sprintf('"%s":\n', ld))
  for (g in names(alphas)) {
    r <- d[d$ladder == ld & d$noise == g & d$N >= 256, ]
    lu <- -10:0
    v <- vapply(lu, function(j) {
      x <- r$rho[abs(log2(r$u) - j) < 1e-9]
      if (length(x)) mean(x) else NA_real_
    }, 0)
    cat(sprintf("  %2d: %s\n", alphas[[g]], paste(sprintf("%.2f", v), collapse = ", ")))
  }
}
