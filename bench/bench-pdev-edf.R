# What PDEV's limits cost (its exact EDF, src/edf.cpp terms_edf_cpp(), and
# the exact limits at N/m <= 16): allan(type = "pdev") without limits, with
# chi-square limits only (options(allanvar.ci_exact = 0)) and with the
# exact ones, each in a fresh callr process (first call: nothing cached)
# and again in it; then the EDF rule alone on a long curve's grid (every
# m <= 64 and 40 per decade up to N/2, the rows allan() evaluates) for the
# five noise types. Medians of `reps`.
#   Rscript bench/bench-pdev-edf.R [reps]   (ALLANVAR_LIB: installed tree)
args <- commandArgs(TRUE)
reps <- if (length(args)) as.integer(args[1]) else 3L
lib <- Sys.getenv("ALLANVAR_LIB", .libPaths()[1])
source("bench/common.R")
one <- function(N, taus, ci, exact) allan_fresh_times(N, "pdev", taus, exact, lib, ci = ci)
rows <- list()
for (N in c(1e4, 1e5, 1e6)) for (taus in c("octave", "decade")) {
  t0 <- replicate(reps, one(N, taus, FALSE, 0))
  t1 <- replicate(reps, one(N, taus, TRUE, 0))
  t2 <- replicate(reps, one(N, taus, TRUE, 16))
  rows[[length(rows) + 1L]] <- data.frame(
    N = N, taus = taus, no_limits = stats::median(t0["first", ]),
    chisq_first = stats::median(t1["first", ]),
    exact_first = stats::median(t2["first", ]),
    exact_again = stats::median(t2["again", ]))
}
rule <- function(N) {
  callr::r(function(N, lib) {
    library(allanvar, lib.loc = lib)
    ns <- asNamespace("allanvar")
    L <- N + 1
    top <- floor(N / 2)
    m <- sort(unique(c(1:64, round(10^seq(log10(64), log10(top),
                                            by = 1 / 40)))))
    system.time(for (a in 2:-2) {
      ns$extra_edf("pdev", m, L, rep(a, length(m)), L - 2 * m)
    })[["elapsed"]]
  }, list(N, lib))
}
edf_rows <- lapply(c(1e4, 1e6, 1e8), function(N) {
  data.frame(N = N, edf_rule_5_types = stats::median(replicate(reps, rule(N))))
})
cat(format(Sys.time(), "%Y-%m-%d %H:%M UTC", tz = "UTC"), "load",
    readLines("/proc/loadavg"), "\n")
print(do.call(rbind, rows), row.names = FALSE, digits = 3)
print(do.call(rbind, edf_rows), row.names = FALSE, digits = 3)
