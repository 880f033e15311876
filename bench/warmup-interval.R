# Coverage of the warm-up time constant's 95% interval (profile likelihood,
# warmup_tc_interval()) on an own generator: white noise (sd 0.01), a random
# walk (1e-4 / sqrt(Hz)) and a warm-up of `amp` x ADEV(10 s) decaying over
# tc, 4e5 samples at 100 Hz (4000 s); `seeds` seeds per time constant.
#   R_LIBS=/tmp/lib Rscript bench/warmup-interval.R [seeds]
suppressPackageStartupMessages(library(allanvar))
args <- commandArgs(TRUE)
seeds <- if (length(args)) as.integer(args[1]) else 40L
freq <- 100
n <- 4e5
t <- (seq_len(n) - 1) / freq
rows <- list()
for (tc in c(40, 100, 400)) {
  for (amp in c(20, 40)) {
    got <- t(vapply(seq_len(seeds), function(s) {
      set.seed(7000 + s)
      b <- rnorm(n, sd = 0.01) + cumsum(rnorm(n, sd = 1e-4 / sqrt(freq)))
      a10 <- allan(b, freq, taus = I(10))$adev
      x <- b + amp * a10 * exp(-t / tc)
      w <- asNamespace("allanvar")$detect_warmup(x, freq)$all
      if (!nrow(w)) return(c(found = 0, est = NA, lo = NA, hi = NA))
      c(found = 1, est = w$tc[1], lo = w$tc_lower[1], hi = w$tc_upper[1])
    }, numeric(4)))
    f <- got[, "found"] == 1
    cover <- f & got[, "lo"] <= tc & got[, "hi"] >= tc
    rows[[length(rows) + 1L]] <- data.frame(
      tc = tc, amp_x_adev10 = amp, seeds = seeds, found = sum(f),
      within_25pct = sum(f & abs(got[, "est"] / tc - 1) <= 0.25, na.rm = TRUE),
      covered = sum(cover, na.rm = TRUE),
      coverage = round(sum(cover, na.rm = TRUE) / max(1, sum(f)), 3),
      median_width = round(stats::median(got[f, "hi"] / got[f, "lo"], na.rm = TRUE), 2),
      undetermined = sum(f & is.na(got[, "lo"])))
  }
}
print(do.call(rbind, rows), row.names = FALSE)
