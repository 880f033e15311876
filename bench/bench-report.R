# write_report(): time and size of the HTML report of a 6-axis record of
# 1e6 samples per axis (100 Hz, 2.8 h), beyond the analysis itself.
# The record comes from this script's own generator: white noise, a
# first-order Gauss-Markov process, a 1.7 Hz sinusoid and rate random walk
# on every axis, a bias step on gyro_x and two spikes on gyro_y.
# Run from the repository root: Rscript bench/bench-report.R
# (ALLANVAR_BENCH_LIB=path uses an installed library instead of installing).
source("bench/common.R")
lib <- Sys.getenv("ALLANVAR_BENCH_LIB")
if (nzchar(lib)) library(allanvar, lib.loc = lib) else bench_install()
options(allanvar.threads = 2)

sim_record <- function(n = 1e6, freq = 100, seed = 1) {
  set.seed(seed)
  axes <- c("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")
  t <- (seq_len(n) - 1) / freq
  m <- vapply(seq_along(axes), function(k) {
    s <- if (k <= 3) 1e-3 else 5e-3
    phi <- exp(-1 / (freq * 5))
    gm <- stats::filter(rnorm(n, sd = 0.3 * s * sqrt(1 - phi^2)), phi,
                        method = "recursive")
    rnorm(n, sd = s) + as.numeric(gm) + 0.4 * s * sin(2 * pi * 1.7 * t) +
      cumsum(rnorm(n, sd = s * 2e-3))
  }, numeric(n))
  colnames(m) <- axes
  h <- floor(0.6 * n)
  m[h:n, 1] <- m[h:n, 1] + 5e-3
  m[c(1000, floor(n / 3)), 2] <- m[c(1000, floor(n / 3)), 2] + 0.05
  imu_record(m, freq = freq, units = c(gyro = "rad/s", accel = "m/s^2"))
}

rec <- sim_record()
t_an <- system.time(a <- suppressWarnings(analyze_imu(rec, progress = FALSE)))[["elapsed"]]
f <- tempfile(fileext = ".html")
with_rec <- timed(write_report(a, f, record = rec), reps = 5)
size_rec <- file.size(f)
without <- timed(write_report(a, f), reps = 5)
size_without <- file.size(f)
steps <- sum(vapply(a$channels, function(ch) NROW(ch$fit$steps), 0L))
out <- data.frame(
  case = c("analysis (analyze_imu)", "write_report(a, f, record = rec)",
           "write_report(a, f)"),
  seconds = c(t_an, with_rec, without),
  MB = c(NA, size_rec, size_without) / 1e6)
cat(sprintf("6 axes x 1e6 samples, %d loop steps in all; medians of 5 runs after a warm-up\n",
            steps))
print(out, row.names = FALSE, digits = 3)
unlink(f)
