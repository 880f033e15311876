# A warm-up and the steps beside it (the trade between the two): on the 18
# measured ADIS16405 axes with an added warm-up (tc drawn from 50-1000 s,
# amplitude 50 x ADEV(tc), random sign; own generator) the series pass
# should name the warm-up (tc within 25%) and no step the axis without it
# does not have; on simulated white noise + random walk with a warm-up and
# a genuine step within 3 time constants (size 10-15 x ADEV(10 s)), the
# step should stay (time within 2 s, size within 25%).
#
#   R_LIBS=/tmp/lib Rscript bench/warmup-step-trade.R [data dir] [seed]
suppressPackageStartupMessages(library(allanvar))
args <- commandArgs(TRUE)
dir <- if (length(args) >= 1L && nzchar(args[1L])) args[1L] else "../shared/data"
seed <- if (length(args) >= 2L) as.integer(args[2L]) else 7100L
freq <- 100
tab <- function(x) detect_series_effects(x, freq)$table
new_steps <- function(t1, t0) {
  s1 <- t1$time[t1$kind == "steps"]
  s0 <- t0$time[t0$kind == "steps"]
  sum(vapply(s1, function(s) !any(abs(s0 - s) <= 2), NA))
}
# the warm-ups a table names, and whether one is within 25% of tc
warmup_read <- function(t1, tc) {
  w <- t1[t1$kind == "warmup", ]
  list(warmup_tc = if (nrow(w)) paste(signif(w$tc, 3), collapse = ",") else "-",
       tc_ok = nrow(w) >= 1L && any(abs(w$tc / tc - 1) <= 0.25))
}
rows <- list()
set.seed(seed)
for (u in 1:3) {
  m <- readRDS(file.path(dir, sprintf("adis16405_unit%d.rds", u)))
  for (ax in colnames(m)) {
    b <- as.numeric(m[, ax])
    t <- (seq_along(b) - 1) / freq
    tc <- round(exp(runif(1, log(50), log(1000))), 1)
    a <- 50 * allan(b, freq, taus = I(tc))$adev * sample(c(-1, 1), 1)
    t0 <- proc.time()[["elapsed"]]
    t1 <- tab(b + a * exp(-t / tc))
    sec <- proc.time()[["elapsed"]] - t0
    rows[[length(rows) + 1L]] <- data.frame(
      case = sprintf("unit %d %s + warm-up %s s", u, ax, tc), warmup_read(t1, tc),
      new_steps = new_steps(t1, tab(b)), step_ok = NA, seconds = round(sec, 1))
  }
}
n <- 1e6
t <- (seq_len(n) - 1) / freq
for (k in 1:12) {
  b <- rnorm(n, sd = 0.01) + cumsum(rnorm(n, sd = runif(1, 3e-5, 2e-4) / sqrt(freq)))
  a10 <- allan(b, freq, taus = I(10))$adev
  tc <- round(exp(runif(1, log(50), log(1000))), 1)
  ts <- round(runif(1, 0.2, 3) * tc)
  sz <- runif(1, 10, 15) * a10 * sample(c(-1, 1), 1)
  x <- b + 50 * allan(b, freq, taus = I(tc))$adev * exp(-t / tc) + sz * (t >= ts)
  t0 <- proc.time()[["elapsed"]]
  t1 <- tab(x)
  sec <- proc.time()[["elapsed"]] - t0
  st <- t1[t1$kind == "steps", ]
  rows[[length(rows) + 1L]] <- data.frame(
    case = sprintf("sim: warm-up %s s, step at %s s", tc, ts), warmup_read(t1, tc),
    new_steps = sum(abs(st$time - ts) > 2),
    step_ok = any(abs(st$time - ts) <= 2 & abs(st$size / sz - 1) <= 0.25),
    seconds = round(sec, 1))
}
out <- do.call(rbind, rows)
print(out, row.names = FALSE, right = FALSE)
real <- is.na(out$step_ok)
cat(sprintf(paste0("\nmeasured axes: warm-up tc within 25%% %d/%d, axes with a step the axis ",
                   "alone lacks %d\nsimulated: step kept %d/%d, warm-up tc within 25%% %d/%d, ",
                   "other steps %d\nseconds per pass: median %.1f, max %.1f\n"),
            sum(out$tc_ok[real]), sum(real), sum(out$new_steps[real] > 0),
            sum(out$step_ok[!real]), sum(!real), sum(out$tc_ok[!real]), sum(!real),
            sum(out$new_steps[!real]), stats::median(out$seconds), max(out$seconds)))
