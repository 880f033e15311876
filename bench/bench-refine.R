# Scaling of the closed loop's raw-data work with the record length
# (issue 9, item 6): each raw-data diagnostic and the whole
# avrefine(fit, data = x), at 1e5, 1e6, 4e6 and 1e7 samples, with R's
# sum(x) on the same data as the yardstick. Measures the installed package:
#   R CMD INSTALL --preclean . && Rscript bench/bench-refine.R [max_n] [reps]
# (--preclean: objects pkgload::load_all() left in src/ are built with -O0
# and a plain install would reuse them; allan() ran 30x slower that way.)
# Prints one row per (case, n): the median elapsed seconds over `reps`
# runs and the ratio to sum(x); then the growth exponent between sizes
# (1 = linear). The series: white + random walk + a 1.3 Hz line + a
# Gauss-Markov term at 100 Hz, generated here with base R.
library(allanvar)
options(allanvar.threads = 2L)
args <- commandArgs(TRUE)
max_n <- if (length(args) >= 1L) as.numeric(args[1L]) else 1e7
reps <- if (length(args) >= 2L) as.integer(args[2L]) else 3L
ns <- c(1e5, 1e6, 4e6, 1e7)
ns <- ns[ns <= max_n]
freq <- 100
ns_fun <- function(name) get(name, envir = asNamespace("allanvar"))
gen <- function(n) {
  set.seed(1)
  t <- seq_len(n) / freq
  phi <- exp(-1 / (freq * 20))
  gm <- as.numeric(stats::filter(rnorm(n, sd = 0.004 * sqrt(1 - phi^2)), phi,
                                 method = "recursive"))
  rnorm(n, sd = 0.1) + cumsum(rnorm(n, sd = 1e-5)) +
    0.01 * sin(2 * pi * 1.3 * t) + gm
}
time_med <- function(f, r) {
  median(vapply(seq_len(r), function(i) system.time(f())[["elapsed"]], 0))
}
cases <- list(
  "sum(x) (yardstick)" = function(x) sum(x),
  "allan(x) octave" = function(x) allan(x, freq),
  "find_bands" = function(x) ns_fun("find_bands")(x, freq),
  "filter_evidence" = function(x) ns_fun("filter_evidence")(x, freq),
  "detect_spikes" = function(x) ns_fun("detect_spikes")(x, freq),
  "detect_steps" = function(x) ns_fun("detect_steps")(x, freq),
  "detect_warmup" = function(x) ns_fun("detect_warmup")(x, freq),
  "spectral_lines (avdiagnose's lines)" = function(x) ns_fun("spectral_lines")(x, freq),
  "remove_lines (one line)" = function(x) ns_fun("remove_lines")(x, freq, 1.3),
  "acf_exponential (Tc = 0.05 s)" = function(x) ns_fun("acf_exponential")(x, freq, 0.05),
  "quantization_grid (radix sort)" = function(x) ns_fun("quantization_grid")(x),
  "welch_psd (seg 512)" = function(x) ns_fun("welch_psd")(x, freq, 512L, detrend = FALSE),
  "series_effects" = function(x) detect_series_effects(x, freq),
  "avdiagnose (today)" = function(x) avdiagnose(x, freq),
  "avrefine(fit, data = x) (today's loop)" = function(x) {
    fit <- avfit(allan(x, freq), terms = c("N", "B", "K"))
    avrefine(fit, data = x, max_steps = 2)
  }
)
rows <- list()
for (n in ns) {
  x <- gen(n)
  r <- if (n >= 4e6) 1L else reps
  # sum(x) is too quick for one timing: enough in a row for about 2e8
  # additions (system.time() resolves 1 ms), divided
  k <- max(20L, ceiling(2e8 / n))
  base <- time_med(function() for (i in seq_len(k)) sum(x), 3L) / k
  for (nm in names(cases)) {
    f <- cases[[nm]]
    sec <- time_med(function() f(x), r)
    rows[[length(rows) + 1L]] <- data.frame(case = nm, n = n, seconds = signif(sec, 3),
                                            ratio_to_sum = signif(sec / base, 3))
    # progress, so that a long run that is stopped still leaves its rows
    message(sprintf("%s, n = %g: %.3g s", nm, n, sec))
  }
  cat(sprintf("done n = %g\n", n))
}
tab <- do.call(rbind, rows)
print(tab, row.names = FALSE)
# growth exponent: log(time ratio) / log(n ratio) between successive sizes
cat("\nGrowth exponent between sizes (1 = linear):\n")
ex <- do.call(rbind, lapply(split(tab, tab$case), function(d) {
  d <- d[order(d$n), ]
  if (nrow(d) < 2L) return(NULL)
  e <- diff(log(d$seconds)) / diff(log(d$n))
  data.frame(case = d$case[1L], t(setNames(signif(e, 2),
                                           sprintf("%g->%g", d$n[-nrow(d)], d$n[-1L]))),
             check.names = FALSE)
}))
print(ex[match(names(cases), ex$case), ], row.names = FALSE)
