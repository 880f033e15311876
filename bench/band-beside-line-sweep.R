# A weak band beside a strong line, own generator (stats::filter, sin,
# cumsum; not the package's simulator): white noise (sd 0.01) through a
# moving average (weights 1, 0.25), a 9.9 Hz two-pole band (tc 0.3 s) of
# 0.12-0.25 x the white sd and a line of half the white sd 0.7-1.3 Hz
# beside it; six configurations x 12 seeds, 5e5 samples at 100 Hz.
# find_bands() on each: the band found (centre within 3%), alone or with
# another. Where it is lost or has company, the loop runs with and without
# the line (a random walk added) and prints its terms, N against the run
# without the line and the band's centre.
#   R_LIBS=/tmp/lib Rscript bench/band-beside-line-sweep.R
# (from the repository root: it sources bench/band-line-helpers.R)
source("bench/band-line-helpers.R")
configs <- list(c(0.0012, 10.8), c(0.0016, 10.8), c(0.002, 9.0), c(0.0016, 9.1),
                c(0.0025, 11.2), c(0.0014, 10.6))
count <- c(alone = 0, with_another = 0, lost = 0)
for (seed in 1:12) for (cfg in configs) {
  set.seed(seed)
  w <- rnorm(n + 1L, sd = 0.01)
  base <- w[-1L] + 0.25 * w[-(n + 1L)] + cfg[1] * ar2_unit(9.9, 0.3)
  line <- 0.005 * sin(2 * pi * cfg[2] * t + 1)
  b <- allanvar:::find_bands(base + line, freq)
  has <- any(abs(b$f_center / 9.9 - 1) < 0.03)
  k <- if (!has) "lost" else if (nrow(b) > 1L) "with_another" else "alone"
  count[k] <- count[k] + 1
  if (k == "alone") next
  rw <- cumsum(rnorm(n, sd = 2e-5))
  r0 <- run(base + rw)
  r1 <- run(base + rw + line)
  cat(sprintf("seed %d band sd %.4f line %.1f Hz: find_bands %s | loop %s -> %s | N %+.2f%% | band %s -> %s\n",
              seed, cfg[1], cfg[2], paste(sprintf("%.2f", b$f_center), collapse = ","),
              r0$terms, r1$terms, 100 * (r1$N / r0$N - 1),
              paste(signif(r0$band, 4), collapse = ","), paste(signif(r1$band, 4), collapse = ",")))
}
cat("find_bands over", sum(count), "cases: the band alone", count[["alone"]],
    " with another", count[["with_another"]], " lost", count[["lost"]], "\n")
