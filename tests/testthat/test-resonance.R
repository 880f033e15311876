# The resonance (narrow-band) process. References: the Allan difference as
# a linear functional of the autocovariance (the covariance of two window
# means written out as a double sum), numerical integration of the PSD, and
# a real AR(2) generator written here.

# A band at fr Hz with decay time tc s: white noise through a real AR(2)
# (poles r exp(+-i w0)), scaled to unit standard deviation, at 100 Hz.
ar2_band <- function(n, fr, tc) {
  r <- exp(-0.01 / tc)
  w0 <- 2 * pi * fr / 100
  z <- as.numeric(stats::filter(rnorm(n), c(2 * r * cos(w0), -r^2), method = "recursive"))
  z / stats::sd(z)
}

av_double_sum <- function(m, g) {
  # AV = [Var(mean1) + Var(mean2) - 2 Cov(mean1, mean2)] / 2 with
  # mean1, mean2 adjacent windows of m samples
  vapply(m, function(mm) {
    i <- 0:(mm - 1)
    v <- sum(outer(i, i, function(a, b) g(abs(a - b)))) / mm^2
    c12 <- sum(outer(i, i + mm, function(a, b) g(abs(a - b)))) / mm^2
    (2 * v - 2 * c12) / 2
  }, 0)
}

test_that("the exact AV of a resonance matches the autocovariance double sum", {
  tau0 <- 0.01
  g <- function(h) resonance_acf(h, tau0, 0.7, 19, 0.05)
  m <- c(1, 2, 3, 5, 8, 13, 40)
  expect_equal(resonance_av(m, tau0, 0.7, 19, 0.05), av_double_sum(m, g),
               tolerance = 1e-10)
  # f_r = 0 is the Gauss-Markov process
  phi <- exp(-tau0 / 2)
  gm <- 0.3^2 * (m - 3 * phi - m * phi^2 + 4 * phi^(m + 1) - phi^(2 * m + 1)) /
    (m^2 * (1 - phi)^2)
  expect_equal(resonance_av(m, tau0, 0.3, 0, 2), gm, tolerance = 1e-10)
})

test_that("the resonance PSD integrates to its variance and peaks at f_r", {
  tau0 <- 0.01
  f <- seq(-50, 50, length.out = 200001)
  p <- resonance_psd(f, tau0, 0.7, 19, 0.05)
  expect_equal(sum(p) * diff(f[1:2]), 0.49, tolerance = 1e-4)
  pos <- f > 0
  expect_equal(f[pos][which.max(p[pos])], 19, tolerance = 0.01)
})

test_that("the resonance PSD equals its complex form, and keeps its digits at a long tc", {
  # the defining expression in R's complex arithmetic
  psd_r <- function(f, tau0, sigma, fr, tc) {
    r <- exp(-tau0 / tc)
    w <- 2 * pi * f * tau0
    w0 <- 2 * pi * fr * tau0
    one <- function(d) {
      q <- r * exp(1i * d)
      Re((1 + q) / (1 - q))
    }
    tau0 * sigma^2 * 0.5 * (one(w0 - w) + one(-w0 - w))
  }
  set.seed(32)
  for (k in 1:20) {
    freq <- c(100, 200, 1000, 97.65625)[(k - 1L) %% 4L + 1L]
    n <- sample(c(1L, 7L, 1000L, 50001L), 1L)
    f <- (seq_len(n) - 1) * freq / n
    f <- pmin(f, freq - f)
    if (k %% 3L == 0L) f <- stats::runif(n, -freq, freq)
    sigma <- 10^stats::runif(1, -6, 3)
    fr <- stats::runif(1, 0, freq / 2)
    tc <- 10^stats::runif(1, -3, 0)
    # the complex form's 1 - r cos(d) loses digits as r -> 1: at tc <= 1 s
    # and tau0 >= 1 ms, 1 - r >= 1e-3, so it keeps 12 of them
    expect_equal(resonance_psd(f, 1 / freq, sigma, fr, tc),
                 psd_r(f, 1 / freq, sigma, fr, tc), tolerance = 1e-11)
  }
  expect_identical(resonance_psd(numeric(), 0.01, 1, 5, 0.1), numeric())
  # tc = 1e4 s at 100 Hz: the peak is tau0 sigma^2 (1 + r) / (1 - r) / 2
  # (+ the mirror term); exact from r's own expm1
  tau0 <- 0.01
  a <- -expm1(-tau0 / 1e4)
  peak <- tau0 * 0.5 * ((2 - a) / a + (1 - (1 - a)^2) /
                          ((a^2) + 4 * (1 - a) * sin(2 * pi * 10 * tau0)^2))
  expect_equal(resonance_psd(10, tau0, 1, 10, 1e4), peak, tolerance = 1e-14)
})

test_that("resonance_av() in C++ is the R expression to the bit", {
  ns_r <- function(m, tau0, sigma, fr, tc) {
    p <- exp(-tau0 / tc) * exp(1i * 2 * pi * fr * tau0)
    Re(geometric_av(m, sigma^2, p))
  }
  set.seed(27)
  for (i in 1:200) {
    freq <- sample(c(100, 819.2, 1000), 1)
    tau0 <- 1 / freq
    # whole cluster sizes below and above 65536 (R's repeated products and
    # cpow), fractional ones
    m <- switch(i %% 3 + 1, 2^(0:20), unique(round(exp(runif(30, 0, log(3e5))))),
                runif(25, 1, 1e6))
    fr <- exp(runif(1, log(1e-3), log(0.5 * freq)))
    tc <- exp(runif(1, log(tau0 / 4), log(1e5)))
    sg <- exp(rnorm(1))
    expect_identical(resonance_av(m, tau0, sg, fr, tc), ns_r(m, tau0, sg, fr, tc))
  }
  # anything but plain numbers takes the R expression
  m <- c(a = 1, b = 2, c = 4)
  expect_identical(resonance_av(m, 0.01, 1, 3, 2), ns_r(m, 0.01, 1, 3, 2))
})

test_that("simulated resonance has the stated variance and autocorrelation", {
  set.seed(31)
  x <- sim_resonance(2e5, 0.01, 0.7, 19, 0.05)
  expect_equal(stats::var(x), 0.49, tolerance = 0.03)
  r <- stats::acf(x, lag.max = 3, plot = FALSE)$acf[2:4]
  expect_equal(r, resonance_acf(1:3, 0.01, 1, 19, 0.05), tolerance = 0.03)
})

test_that("band start values recover the resonance from an independent generator", {
  set.seed(32)
  n <- 2e5
  r <- exp(-0.01 / 0.08)
  w0 <- 2 * pi * 20 / 100
  # Re of a complex AR(1) is the AR(2) below with an MA(1) input
  e1 <- rnorm(n)
  e2 <- rnorm(n)
  u <- e1 - r * cos(w0) * c(0, e1[-n]) - r * sin(w0) * c(0, e2[-n])
  z <- as.numeric(stats::filter(u, c(2 * r * cos(w0), -r^2), method = "recursive"))
  z <- z / sqrt(1 / (1 - r^2))        # unit variance
  x <- rnorm(n) + 0.8 * z
  b <- find_bands(x, 100)
  s <- resonance_start(b[1, ])
  expect_equal(s$fr, 20, tolerance = 0.05)
  expect_equal(s$sigma, 0.8, tolerance = 0.3)
  expect_equal(s$tc, 0.08, tolerance = 0.5)
})

test_that("the raw data support a resonance where a band is, and contradict one elsewhere", {
  set.seed(33)
  n <- 2e5
  z <- ar2_band(n, 20, 0.08)
  x <- rnorm(n) + 0.8 * z
  b <- find_bands(x, 100)
  expect_true(resonance_raw_support(0.8, 20, 0.08, b)$support)
  expect_false(resonance_raw_support(0.8, 7, 0.08, b)$support)
  expect_false(resonance_raw_support(0.8, 20, 0.08, find_bands(rnorm(n), 100))$support)
  # the curve's power against the band's measured one: within a factor 2
  # it is the band; at 2.5x either way it stands for something else
  p <- b$power[1]
  for (k in c(0.6, 1.6)) expect_true(resonance_raw_support(sqrt(k * p), 20, 0.08, b)$support)
  for (k in c(0.4, 2.5)) {
    ev <- resonance_raw_support(sqrt(k * p), 20, 0.08, b)
    expect_false(ev$support)
    expect_match(ev$text, sprintf("power %.2g x", 1 / k), fixed = TRUE)
  }
})

test_that("find_bands invents no band on smooth spectra (own generators, 10 seeds each)", {
  # white, a 4-tap moving average, a first-order low-pass, white + random
  # walk and white + a slow Gauss-Markov: monotone spectra with no band;
  # the threshold is the Welch chi-square's alone (no fixed power ratio)
  n <- 2e5
  gens <- list(
    white = function() rnorm(n),
    ma4 = function() as.numeric(stats::filter(rnorm(n + 3), rep(0.25, 4), sides = 1))[-(1:3)],
    lp1 = function() as.numeric(stats::filter(rnorm(n), 0.7, method = "recursive")),
    rw = function() rnorm(n) + cumsum(rnorm(n, sd = 0.05)),
    gm = function() rnorm(n) + 3 * as.numeric(stats::filter(
      rnorm(n, sd = sqrt(1 - 0.999^2)), 0.999, method = "recursive")))
  for (nm in names(gens)) {
    found <- vapply(1:10, function(s) {
      set.seed(700 + s)
      nrow(find_bands(gens[[nm]](), 100))
    }, 0L)
    expect_equal(sum(found), 0L, label = nm)
  }
})

test_that("find_bands finds a weak band (peak about 1.5x the background) at 1e6 samples", {
  # a band far below the old fixed 2x threshold, significant by the EDF
  set.seed(41)
  n <- 1e6
  z <- ar2_band(n, 10, 0.5)
  x <- as.numeric(stats::filter(rnorm(n + 3), rep(0.25, 4), sides = 1))[-(1:3)] +
    0.1 * z
  b <- find_bands(x, 100)
  expect_equal(nrow(b), 1L)
  expect_equal(b$f_center, 10, tolerance = 0.02)
  expect_lt(b$peak_ratio, 2)
})
