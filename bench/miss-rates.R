# How often the battery's failing classes miss by chance: each class of
# bench/battery-loop.R whose rows fail on one seed, drawn again with other
# seeds (the battery's own generators, never the package's simulator), and
# the series pass run on every draw. A class whose estimator is unbiased
# and whose 95% interval covers the truth misses the battery's tolerance
# at the rate its spread implies; one that misses on most draws is a
# defect. Prints one table; not run by the tests.
#   Rscript bench/miss-rates.R [reps] [--data DIR]
suppressPackageStartupMessages(library(allanvar))
ns <- asNamespace("allanvar")
args <- commandArgs(TRUE)
reps <- if (length(args) && !startsWith(args[1L], "--")) as.integer(args[1L]) else 20L
data_dir <- if ("--data" %in% args) args[match("--data", args) + 1L] else
  Sys.getenv("ALLANVAR_SHARED_DATA", "../shared/data")
freq <- 100
source("bench/battery-generators.R")

# a warm-up class: `base(seed)` the series without it (at `fs` Hz), the
# warm-up of time constant `tc` added as the battery adds it; the series
# pass's warm-up and detect_warmup()'s 95% interval of its tc
warmup_class <- function(label, fs, tc, base) {
  rows <- lapply(seq_len(reps), function(s) {
    freq <<- fs
    set.seed(5000 + s)
    b <- base()
    x <- b + g_warmup(b, tc)
    se <- detect_series_effects(x, fs, kinds = "warmup")
    w <- se$table[se$table$kind == "warmup", , drop = FALSE]
    d <- ns$detect_warmup(ns$without_sharp_lines(x, fs), fs)
    hit <- if (nrow(w)) w$tc[which.min(abs(log(w$tc / tc)))] else NA_real_
    lo <- d$all$tc_lower[1L] %||% NA_real_
    hi <- d$all$tc_upper[1L] %||% NA_real_
    c(named = nrow(w) > 0L, ratio = hit / tc, covered = isTRUE(lo <= tc && hi >= tc))
  })
  r <- do.call(rbind, rows)
  ok <- r[, "named"] == 1
  data.frame(class = label, draws = reps, named = sum(ok),
             within = sum(ok & abs(r[, "ratio"] - 1) <= 0.25),
             median_ratio = round(stats::median(r[ok, "ratio"]), 3),
             sd_ratio = round(stats::sd(r[ok, "ratio"]), 3),
             covered_95 = sum(r[, "covered"]), stringsAsFactors = FALSE)
}
`%||%` <- function(a, b) if (is.null(a) || !length(a)) b else a

out <- list()
# set h's "sim: warm-up tc 57.6 s" (N + K at 100 Hz, 5e5 samples)
out[[1]] <- warmup_class("N + K, 100 Hz, warm-up 57.6 s", 100, 57.6, function() {
  g_white(5e5, 0.0091) + g_rw(5e5, 6.5e-5)
})
# set e's "sim sensor: warm-up tc 200 s" (a two-tap average, a 11.2 Hz
# band, a 0.61 Hz line and a walk)
out[[2]] <- warmup_class("sensor (set e), 100 Hz, warm-up 200 s", 100, 200, function() {
  n <- 5e5
  w <- rnorm(n + 1L, sd = 0.012)
  (w[-1L] + 0.35 * w[-(n + 1L)]) + g_band(n, 0.01, 11.2, 0.4) + g_line(n, 0.011, 0.61) +
    g_rw(n, 1e-4)
})
# set j's "warm-up tc 299 s" at 1000 Hz (1e6 samples, 1000 s)
out[[3]] <- warmup_class("N + K, 1000 Hz, warm-up 299 s (30%)", 1000, 299, function() {
  g_white(1e6, 0.015 * sqrt(10)) + g_rw(1e6, 6.6e-5)
})
tab <- do.call(rbind, out)
cat("Warm-ups (named: the series pass names one; within: tc within 25%;",
    "covered_95: detect_warmup()'s 95% interval holds the true tc)\n")
print(tab, row.names = FALSE)

# two GMs an order apart (set h's "sim: GMs 3.3 s and 56.6 s": white,
# walk, the fast GM in the base, the slow one added), the whole loop as
# the battery runs it; the slow GM named when a GM of the final model
# lies within 25% of its realised tc
freq <- 100
t0 <- proc.time()[[3]]
gp <- t(vapply(seq_len(reps), function(s) {
  set.seed(8000 + s)
  n <- 1e6
  g <- g_gm(n, 0.00273, 56.6)
  x <- g_white(n, 0.0091) + g_rw(n, 7.4e-5) + g_gm(n, 0.00355, 3.3) + g
  rc <- realised_tc(g)
  f <- avfit(allan(x, freq), terms = c("N", "B", "K"))
  r <- suppressWarnings(suppressMessages(avrefine(f, data = x)))
  cf <- coef(r)
  tc <- cf[grepl("^gm[0-9]*\\.tc$", names(cf)) &
             cf[sub("tc$", "sigma", names(cf))] > 0]
  near <- if (length(tc)) tc[which.min(abs(log(tc / rc)))] / rc else NA_real_
  c(gms = length(tc), ratio = unname(near))
}, c(0, 0)))
cat(sprintf(paste("\nTwo GMs, 3.3 s and 56.6 s, white and walk (set h's class), %d draws:",
                  "two GMs or more %d, the slow one within 25%% %d, its ratio median %.3f",
                  "(%.0f s)\n"),
            reps, sum(gp[, "gms"] >= 2), sum(abs(gp[, "ratio"] - 1) <= 0.25, na.rm = TRUE),
            stats::median(gp[, "ratio"], na.rm = TRUE), proc.time()[[3]] - t0))

# false steps: set j's 200 Hz sensor (white through 1/(1 - 0.5 z^-1 +
# 0.15 z^-2), a 22 Hz band and a walk; its 0.5 Hz line left out, as the
# series pass takes sharp lines out first), nothing added
fs <- 200
freq <- fs
ns_reps <- 10L * reps
t0 <- proc.time()[[3]]
fa <- vapply(seq_len(ns_reps), function(s) {
  set.seed(6000 + s)
  sd0 <- 0.015 * sqrt(fs / 100)
  x <- as.numeric(stats::filter(rnorm(1e6, sd = sd0), c(0.5, -0.15), method = "recursive")) +
    g_band(1e6, 0.8 * sd0, 22, 0.4) + g_rw(1e6, 6.6e-5)
  st <- ns$detect_steps(x, fs)
  c(steps = nrow(st), transients = nrow(attr(st, "pulses")))
}, c(0, 0))
cat(sprintf(paste("\nFalse steps: the 200 Hz sensor of set j as it is (1e6 samples), %d draws:",
                  "%d with a step, %d with a transient (%.0f s)\n"),
            ns_reps, sum(fa[1L, ] > 0), sum(fa[2L, ] > 0), proc.time()[[3]] - t0))

# a step's size on a measured gyro: unit 1 gyro_z (set b's "step at 2500
# s") with the battery's step, 10 x ADEV(10 s), at other times
f <- file.path(data_dir, "adis16405_unit1.rds")
if (file.exists(f)) {
  freq <- 100
  m <- readRDS(f)
  rec <- imu_record(m, freq = attr(m, "freq"), name = "unit1",
                    units = c(gyro = "deg/s", accel = "g"))
  b <- rec$data[, "gyro_z"]
  set.seed(7000)
  sz <- g_step_size(b)
  times <- seq(1000, 9000, length.out = reps)
  r <- t(vapply(times, function(t0) {
    x <- b + g_step(length(b), t0, sz)
    s <- detect_series_effects(x, freq, kinds = "steps")$table
    s <- s[s$kind == "steps", , drop = FALSE]
    j <- if (nrow(s)) which.min(abs(s$time - t0)) else NA_integer_
    ok <- !is.na(j) && abs(s$time[j] - t0) <= 2
    c(named = ok, ratio = if (ok) s$size[j] / sz else NA_real_)
  }, c(0, 0)))
  cat(sprintf(paste("\nA step of 10 x ADEV(10 s) (%s) on unit 1 gyro_z at %d times",
                    "from 1000 to 9000 s: named at the time %d, size within 25%% %d,",
                    "size ratio median %.3f, range %.3f-%.3f\n"),
              format(signif(sz, 3)), reps, sum(r[, "named"]),
              sum(abs(r[, "ratio"] - 1) <= 0.25, na.rm = TRUE),
              stats::median(r[, "ratio"], na.rm = TRUE),
              min(r[, "ratio"], na.rm = TRUE), max(r[, "ratio"], na.rm = TRUE)))
}
