# The base series of the non-stationary tests (test-nonstationary.R,
# test-series.R), built with base R rather than avsim(): white noise plus a
# random walk (cumsum); each test adds its deterministic effect.
gen_white_walk <- function(n, white = 0.1, rw = 5e-5, seed) {
  set.seed(seed)
  rnorm(n, sd = white) + cumsum(rnorm(n, sd = rw))
}

# n samples of a two-pole resonance (white noise through stats::filter's
# AR(2) with poles exp(-1 / (freq tc) +- 2 pi i fr / freq), its first
# `burn` samples dropped), scaled to unit sd.
ar2_unit <- function(n, fr, tc, freq, burn = 2000L) {
  r <- exp(-1 / (freq * tc))
  z <- as.numeric(stats::filter(rnorm(n + burn), c(2 * r * cos(2 * pi * fr / freq), -r^2),
                                method = "recursive"))[-seq_len(burn)]
  z / stats::sd(z)
}

# A simulated sensor axis (own generator: stats::filter, sin, cumsum; not
# the package's simulator): white noise through a short moving average
# (weights 1, 0.25), a two-pole resonance at 9.85 Hz (tc 0.5 s), a 0.54 Hz
# line of amplitude 0.014 and a random walk. Its white level at DC is
# 1.25 x 0.01 x sqrt(1 / freq).
sim_sensor_axis <- function(n = 5e5, freq = 100) {
  w <- rnorm(n + 1L, sd = 0.01)
  r <- exp(-1 / (freq * 0.5))
  z <- as.numeric(stats::filter(rnorm(n + 2000), c(2 * r * cos(2 * pi * 9.85 / freq), -r^2),
                                method = "recursive"))[-(1:2000)]
  t <- seq_len(n) / freq
  (w[-1L] + 0.25 * w[-(n + 1L)]) + 0.012 * z / stats::sd(z) +
    0.014 * sin(2 * pi * 0.54 * t + runif(1, 0, 2 * pi)) + cumsum(rnorm(n, sd = 1.3e-4 / sqrt(freq)))
}
