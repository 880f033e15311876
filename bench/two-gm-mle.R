# The battery's "two Gauss-Markov terms an order apart" cases against the
# efficient estimator: the exact Gaussian likelihood of the raw series
# (avmle(), a Kalman filter over N, K and two GM states: the model the
# generator used), started from the loop's values. Reads the runs
# bench/battery-loop.R saved (BATTERY_RUNS=dir) and prints, per case, the
# realised tc of the added (slow) GM, the loop's two tcs and K, and the
# likelihood's.
#   R_LIBS=/tmp/lib Rscript bench/two-gm-mle.R /tmp/battery [more run dirs]
suppressPackageStartupMessages(library(allanvar))
options(allanvar.threads = 1L)
dirs <- commandArgs(TRUE)
files <- unlist(lapply(dirs, function(d) Sys.glob(file.path(d, "runs-*", "*_sim_GMs_*.rds"))))
slow_of <- function(cf) {
  tc <- cf[grepl("^gm[0-9]+\\.tc$", names(cf))]
  s <- names(tc)[which.max(tc)]
  c(fast = unname(min(tc)), slow = unname(max(tc)), K = unname(cf["K"] %||% 0))
}
`%||%` <- function(a, b) if (is.null(a) || is.na(a)) b else a
rows <- list()
for (f in files) {
  z <- readRDS(f)
  cf <- coef(z$r)
  if (sum(grepl("^gm[0-9]+\\.tc$", names(cf))) != 2L) next
  st <- cf[c("N", "K", "gm1.sigma", "gm1.tc", "gm2.sigma", "gm2.tc")]
  t0 <- proc.time()[["elapsed"]]
  m <- avmle(z$x, 100, c("N", "K", "gm", "gm"), start = st)
  sec <- proc.time()[["elapsed"]] - t0
  lo <- slow_of(cf)
  ml <- slow_of(coef(m))
  real <- z$expect[[1L]][[2L]]
  rows[[length(rows) + 1L]] <- data.frame(
    case = sub("\\.rds$", "", basename(f)), realised = signif(real, 3),
    loop_fast = signif(lo[["fast"]], 3), loop_slow = signif(lo[["slow"]], 3),
    loop_K = signif(lo[["K"]], 2),
    mle_fast = signif(ml[["fast"]], 3), mle_slow = signif(ml[["slow"]], 3),
    mle_K = signif(ml[["K"]], 2), sec = round(sec, 1))
}
out <- do.call(rbind, rows)
options(width = 200)
print(out, row.names = FALSE)
w <- function(v) sum(abs(v / out$realised - 1) <= 0.25)
cat(sprintf("slow tc within 25%% of the realised: loop %d / %d, likelihood %d / %d\n",
            w(out$loop_slow), nrow(out), w(out$mle_slow), nrow(out)))
cat(sprintf("likelihood's slow tc over the loop's: median %.2f, range %.2f-%.2f\n",
            stats::median(out$mle_slow / out$loop_slow), min(out$mle_slow / out$loop_slow),
            max(out$mle_slow / out$loop_slow)))
