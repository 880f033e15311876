# The base series of the non-stationary tests (test-nonstationary.R,
# test-series.R), built with base R rather than avsim(): white noise plus a
# random walk (cumsum); each test adds its deterministic effect.
gen_white_walk <- function(n, white = 0.1, rw = 5e-5, seed) {
  set.seed(seed)
  rnorm(n, sd = white) + cumsum(rnorm(n, sd = rw))
}
