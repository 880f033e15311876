# Cost of allan()'s exact limits at few averages (R/ci-exact.R): a curve
# with chi-square limits only (options(allanvar.ci_exact = 0)), with the
# exact ones in a fresh session (every problem computed), and again (the
# session's cache). Each in its own callr process; medians of `reps`.
#   [BENCH_TYPES=total,mtotdev] Rscript bench/bench-ci-exact.R [reps]
args <- commandArgs(TRUE)
reps <- if (length(args)) as.integer(args[1]) else 3L
lib <- Sys.getenv("ALLANVAR_LIB", .libPaths()[1])
source("bench/common.R")
one <- function(N, type, taus, exact) allan_fresh_times(N, type, taus, exact, lib)
types <- if (nzchar(Sys.getenv("BENCH_TYPES"))) {
  strsplit(Sys.getenv("BENCH_TYPES"), ",")[[1]]
} else {
  c("standard", "overlapping", "modified", "hadamard", "ohadamard")
}
rows <- list()
for (N in c(1e4, 1e6)) for (type in types) {
  for (taus in c("octave", "decade")) {
    t0 <- replicate(reps, one(N, type, taus, 0))
    t1 <- replicate(reps, one(N, type, taus, 16))
    rows[[length(rows) + 1L]] <- data.frame(
      N = N, type = type, taus = taus,
      chisq = stats::median(t0["first", ]),
      exact_first = stats::median(t1["first", ]),
      exact_again = stats::median(t1["again", ]))
  }
}
cat(format(Sys.time(), "%Y-%m-%d %H:%M UTC", tz = "UTC"), "load",
    readLines("/proc/loadavg"), "\n")
print(do.call(rbind, rows), row.names = FALSE, digits = 3)
