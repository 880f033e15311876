# A strong line beside a weak band, own generator (stats::filter, sin,
# cumsum; not the package's simulator): white noise through a moving
# average (weights 1, 0.25), a 9.9 Hz two-pole band (tc 0.27 s, sd 0.002
# or 0.003 against the white sd 0.01), a random walk, and a line 0.75-0.8
# Hz above the band at half the white sd; seeds 1-4, 5e5 samples at 100
# Hz. Each case runs the loop with and without the line and prints the
# terms, N against the run without it, the band's centre and the line's
# fitted f0 and amplitude (true 0.005).
#   R_LIBS=/tmp/lib Rscript bench/line-beside-sim-band.R
# (from the repository root: it sources bench/band-line-helpers.R)
source("bench/band-line-helpers.R")
kept <- 0; near <- 0; nok <- 0; k <- 0
for (seed in 1:4) for (cfg in list(c(0.003, 10.65), c(0.002, 10.7))) {
  set.seed(seed)
  w <- rnorm(n + 1L, sd = 0.01)
  b <- w[-1L] + 0.25 * w[-(n + 1L)] + cfg[1] * ar2_unit(9.9, 0.27) + cumsum(rnorm(n, sd = 2e-5))
  x <- b + 0.005 * sin(2 * pi * cfg[2] * t + 1)
  r0 <- run(b)
  r1 <- run(x)
  dn <- 100 * (r1$N / r0$N - 1)
  k <- k + 1
  kept <- kept + (length(r1$band) == length(r0$band))
  near <- near + (length(r1$band) == 1L && length(r0$band) == 1L && abs(r1$band / r0$band - 1) < 0.01)
  nok <- nok + (abs(dn) <= 1)
  cat(sprintf("seed %d band sd %.3f line %.2f Hz: %s -> %s | N %+.2f%% | band %s -> %s | f0 %s amp %s\n",
              seed, cfg[1], cfg[2], r0$terms, r1$terms, dn,
              paste(signif(r0$band, 4), collapse = ","), paste(signif(r1$band, 4), collapse = ","),
              paste(signif(r1$f0, 4), collapse = ","), paste(signif(r1$amp, 3), collapse = ",")))
}
cat("band kept", kept, "/", k, " its centre within 1% of the run without the line", near,
    " N within 1%", nok, "\n")
