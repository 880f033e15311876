# The battery's generators, written with base R (rnorm, filter, sin, cumsum),
# never the package's simulator; `freq` (Hz) must be set before sourcing.
# Sourced from the repository root by bench/battery-loop.R and
# bench/band-shapes.R.
stopifnot(exists("freq"))
g_white <- function(n, sd) rnorm(n, sd = sd)
g_rw <- function(n, K) cumsum(rnorm(n, sd = K / sqrt(freq)))
g_gm <- function(n, sigma, tc) {
  phi <- exp(-1 / (freq * tc))
  w <- rnorm(n, sd = sigma * sqrt(1 - phi^2))
  w[1] <- rnorm(1, sd = sigma)
  as.numeric(stats::filter(w, phi, method = "recursive"))
}
g_line <- function(n, amp, f0) amp * sin(2 * pi * f0 * seq_len(n) / freq + runif(1, 0, 2 * pi))
g_square <- function(n, amp, f0) amp * sign(sin(2 * pi * f0 * seq_len(n) / freq + runif(1, 0, 2 * pi)))
# a sawtooth: every harmonic k f0 at amplitude 1/k of the first
g_saw <- function(n, amp, f0) {
  ph <- (f0 * seq_len(n) / freq + runif(1)) %% 1
  amp * (2 * ph - 1)
}
# a narrow band: white noise through a two-pole resonator (AR(2)) at f_r
# with damping time tc (FWHM 1/(pi tc)), scaled to sd `sigma`
g_band <- function(n, sigma, fr, tc) {
  r <- exp(-1 / (freq * tc))
  w0 <- 2 * pi * fr / freq
  z <- as.numeric(stats::filter(rnorm(n + 2000), c(2 * r * cos(w0), -r^2),
                                method = "recursive"))[-(1:2000)]
  sigma * z / stats::sd(z)
}
g_flicker <- function(n, B) {               # flicker by summed AR(1)s, 1/f over 4 decades
  out <- numeric(n)
  for (tc in 10^seq(-1, 3, by = 0.5)) out <- out + g_gm(n, B * 0.6, tc)
  out
}
# an exponential warm-up of time constant tc, amplitude 50 x ADEV(tc) of
# the series it is added to, random sign
g_warmup <- function(b, tc) {
  n <- length(b)
  a <- 50 * allan(b, freq, taus = I(min(tc, n / freq / 4)))$adev * sample(c(-1, 1), 1)
  a * exp(-(seq_len(n) - 1) / freq / tc)
}
# a bias step of 10 x ADEV(10 s) of the series, at time t0 (s)
g_step_size <- function(b) 10 * allan(b, freq, taus = I(10))$adev * sample(c(-1, 1), 1)
g_step <- function(n, t0, size) size * ((seq_len(n) - 1) / freq >= t0)
# realised time constant of an injected GM alone: its AR(1) coefficient by
# least squares (the maximum-likelihood estimate given the first sample)
realised_tc <- function(g) {
  n <- length(g)
  phi <- sum(g[-1L] * g[-n]) / sum(g[-n]^2)
  -1 / (freq * log(phi))
}
