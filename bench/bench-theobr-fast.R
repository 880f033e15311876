# TheoBR's fast bias factor (R/theo-fast.R) against the exact one.
#  1. Error of the TheoBR deviation, sqrt(factor_fast / factor_exact) - 1
#     (the Theo1 values are exact on both paths), by noise type and N, at
#     averaging r = 4 and 16, the latter also without the correction;
#     mean and sd over `reps` records; the noise made here (Kasdin's filter
#     for flicker), not by avsim(); the type for the correction identified
#     as allan() does.
#  2. Time of allan(type = "theobr" / "theoh") at 1e5 and 1e6, white FM
#     rate input, octave taus, 2 threads: the fast path (the default above
#     1e5 phase points) and the exact one; one run each (exact at 1e6 takes
#     minutes), elapsed and user+system CPU.
#   Rscript bench/bench-theobr-fast.R [reps] [part: both, error, speed]
args <- commandArgs(TRUE)
reps <- if (length(args)) as.integer(args[1]) else 3L
part <- if (length(args) > 1L) args[2] else "both"
source("bench/common.R")
bench_install()
options(allanvar.threads = 2L)
ns <- asNamespace("allanvar")

flicker <- function(N) {
  h <- cumprod(c(1, (seq_len(N - 1) - 0.5) / seq_len(N - 1)))
  M <- 2^ceiling(log2(2 * N))
  z <- stats::fft(stats::fft(c(h, rep(0, M - N))) *
                    stats::fft(c(rnorm(N), rep(0, M - N))), inverse = TRUE)
  Re(z)[seq_len(N)] / M
}
gens <- list("white PM" = function(N) rnorm(N),
             "flicker PM" = function(N) flicker(N),
             "white FM" = function(N) cumsum(rnorm(N)),
             "flicker FM" = function(N) cumsum(flicker(N)),
             "random-walk FM" = function(N) cumsum(cumsum(rnorm(N))))

if (part %in% c("both", "error")) {
  rows <- list()
  set.seed(2029)
  for (N in c(1e4, 3e4, 1e5)) for (nm in names(gens)) {
    e <- vapply(seq_len(reps), function(i) {
      x <- gens[[nm]](N)
      ex <- ns$theobr_factor(x, 1, FALSE, N, 2L)
      al <- ns$theobr_ladder_alpha(x, 1, "integrated", N)
      f4 <- ns$theobr_factor_fast(x, FALSE, N, 4L, al, 2L)
      f16 <- ns$theobr_factor_fast(x, FALSE, N, 16L, al, 2L)
      u16 <- ns$theobr_factor_fast(x, FALSE, N, 16L, NA, 2L)
      100 * (sqrt(c(f4, f16, u16) / ex) - 1)
    }, numeric(3))
    ms <- function(j) sprintf("%+.3f (%.3f)", mean(e[j, ]), stats::sd(e[j, ]))
    rows[[length(rows) + 1L]] <- data.frame(
      N = format(N, scientific = TRUE), noise = nm, `r=4` = ms(1),
      `r=16` = ms(2), `r=16 uncorrected` = ms(3), check.names = FALSE)
    cat(".")
}
cat("\nTheoBR deviation, fast vs exact: error in % (mean (sd) of", reps,
    "records)\n")
print(do.call(rbind, rows), row.names = FALSE)
}
if (part %in% c("both", "speed")) {
  tm <- list()
  set.seed(1)
  for (N in c(1e5, 1e6)) {
    y <- rnorm(N)
    for (type in c("theobr", "theoh")) for (method in c("auto", "exact")) {
      gc(FALSE)
      t <- system.time(suppressMessages(
        allan(y, 1, type = type, theo = list(method = method))))
      tm[[length(tm) + 1L]] <- data.frame(
        N = format(N, scientific = TRUE), type = type,
        path = if (method == "auto") "fast (auto)" else "exact",
        elapsed_s = round(t[["elapsed"]], 2),
        cpu_s = round(t[["user.self"]] + t[["sys.self"]], 2))
      cat(".")
    }
}
cat("\nallan(type = \"theobr\" / \"theoh\"), white FM, octave taus, 2 threads\n")
print(do.call(rbind, tm), row.names = FALSE)
}
