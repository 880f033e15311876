# The resonance (narrow-band) process, a real AR(2). References: the Allan
# difference as a linear functional of the autocovariance (the covariance of
# two window means written out as a double sum), the AR(2)'s ACF from
# stats::ARMAacf(), its transfer function, numerical integration of the
# PSD, and a real AR(2) generator written here (stats::filter).

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

# The AR(2)'s autocovariance from stats::ARMAacf() (the Yule-Walker
# recursion), scaled to variance sigma^2.
ar2_acov <- function(h, tau0, sigma, fr, tc) {
  r <- exp(-tau0 / tc)
  w0 <- 2 * pi * fr * tau0
  rho <- stats::ARMAacf(ar = c(2 * r * cos(w0), -r^2), lag.max = max(abs(h)))
  sigma^2 * unname(rho[abs(h) + 1])
}

test_that("the resonance's ACF is the AR(2)'s (Yule-Walker), down to a double pole at f_r = 0", {
  h <- 0:60
  for (pp in list(c(0.01, 0.7, 19, 0.05), c(0.01, 1, 2, 0.3), c(0.001, 2, 0.3, 0.5),
                  c(0.01, 1, 49.9, 0.05))) {
    expect_equal(resonance_acf(h, pp[1], pp[2], pp[3], pp[4]),
                 ar2_acov(h, pp[1], pp[2], pp[3], pp[4]), tolerance = 1e-10)
  }
  expect_equal(resonance_acf(-h, 0.01, 0.7, 19, 0.05), resonance_acf(h, 0.01, 0.7, 19, 0.05))
  expect_equal(resonance_acf(h, 0.01, 1, 0, 0.2), ar2_acov(h, 0.01, 1, 0, 0.2), tolerance = 1e-10)
})

test_that("the exact AV of a resonance matches the AR(2) autocovariance summed directly", {
  m <- c(1, 2, 3, 5, 8, 13, 40, 100)
  for (pp in list(c(0.01, 0.7, 19, 0.05), c(0.01, 1, 7, 0.3), c(0.01, 1, 0.5, 0.2),
                  c(0.01, 0.3, 45, 0.02), c(0.001, 2, 3, 0.05))) {
    acv <- ar2_acov(0:250, pp[1], pp[2], pp[3], pp[4])
    expect_equal(resonance_av(m, pp[1], pp[2], pp[3], pp[4]),
                 av_double_sum(m, function(h) acv[h + 1]), tolerance = 1e-9)
  }
})

test_that("the resonance PSD integrates to its variance and peaks where the AR(2)'s does", {
  tau0 <- 0.01
  f <- seq(-50, 50, length.out = 200001)
  p <- resonance_psd(f, tau0, 0.7, 19, 0.05)
  expect_equal(sum(p) * diff(f[1:2]), 0.49, tolerance = 1e-4)
  # the AR(2)'s peak: cos(w) = (1 + r^2) cos(w0) / (2 r), a little below f_r
  r <- exp(-tau0 / 0.05)
  fpk <- acos((1 + r^2) * cos(2 * pi * 19 * tau0) / (2 * r)) / (2 * pi * tau0)
  pos <- f > 0
  expect_equal(f[pos][which.max(p[pos])], fpk, tolerance = 1e-3)
  expect_lt(fpk, 19)
  # the PSD is the ACF's transform: tau0 sum_h g(h) cos(w h)
  acv <- ar2_acov(0:2000, tau0, 0.7, 19, 0.05)
  fk <- c(0, 3, 10, 18.9, 30, 50)
  ft <- vapply(fk, function(q) tau0 * (acv[1] + 2 * sum(acv[-1] * cos(2 * pi * q * tau0 * (1:2000)))), 0)
  expect_equal(resonance_psd(fk, tau0, 0.7, 19, 0.05), ft, tolerance = 1e-9)
})

test_that("the resonance PSD equals the AR(2)'s transfer form, and keeps its digits at a long tc", {
  # tau0 s_e^2 / |1 - phi1 z - phi2 z^2|^2, z = exp(-i w), with the
  # innovation variance s_e^2 = gamma0 (1 + phi2) ((1 - phi2)^2 - phi1^2) / (1 - phi2)
  psd_r <- function(f, tau0, sigma, fr, tc) {
    r <- exp(-tau0 / tc)
    phi1 <- 2 * r * cos(2 * pi * fr * tau0)
    phi2 <- -r^2
    se2 <- sigma^2 * (1 + phi2) * ((1 - phi2)^2 - phi1^2) / (1 - phi2)
    z <- exp(-1i * 2 * pi * f * tau0)
    tau0 * se2 / Mod(1 - phi1 * z - phi2 * z^2)^2
  }
  set.seed(32)
  for (k in 1:20) {
    freq <- c(100, 200, 1000, 97.65625)[(k - 1L) %% 4L + 1L]
    n <- sample(c(1L, 7L, 1000L, 50001L), 1L)
    f <- (seq_len(n) - 1) * freq / n
    f <- pmin(f, freq - f)
    if (k %% 3L == 0L) f <- stats::runif(n, -freq, freq)
    sigma <- 10^stats::runif(1, -6, 3)
    fr <- stats::runif(1, 0.01, 0.49) * freq
    tc <- 10^stats::runif(1, -3, 0)
    # the polynomial form loses digits as r -> 1 (1 - r >= 1e-3 here)
    expect_equal(resonance_psd(f, 1 / freq, sigma, fr, tc),
                 psd_r(f, 1 / freq, sigma, fr, tc), tolerance = 1e-9)
  }
  expect_identical(resonance_psd(numeric(), 0.01, 1, 5, 0.1), numeric())
  # tc = 1e4 s at 100 Hz: at its pole the PSD is tau0 s_e^2 / ((1 - r)^2 D(2 w0)),
  # D(d) = (1 - r)^2 + 4 r sin(d / 2)^2, about tau0 / (1 - r); exact from
  # r's own expm1 (the polynomial form keeps none of its digits)
  tau0 <- 0.01
  a <- -expm1(-tau0 / 1e4)
  r <- 1 - a
  s0 <- sin(2 * pi * 10 * tau0)
  q <- a * (2 - a)
  peak <- tau0 * q * (q^2 + 4 * r^2 * s0^2) / (1 + r^2) / (a^2 * (a^2 + 4 * r * s0^2))
  expect_equal(resonance_psd(10, tau0, 1, 10, 1e4), peak, tolerance = 1e-13)
  expect_equal(peak, tau0 / a, tolerance = 1e-5)
})

test_that("resonance_av() in C++ is the R expression to the bit", {
  ns_r <- function(m, tau0, sigma, fr, tc) {
    p <- exp(-tau0 / tc) * exp(1i * 2 * pi * fr * tau0)
    r <- exp(-tau0 / tc)
    cc <- (1 - r^2) / (1 + r^2) / tan(2 * pi * fr * tau0)
    Re(geometric_av(m, complex(real = sigma^2, imaginary = -(sigma^2 * cc)), p))
  }
  set.seed(27)
  for (i in 1:200) {
    freq <- sample(c(100, 819.2, 1000), 1)
    tau0 <- 1 / freq
    # whole cluster sizes below and above 65536 (R's repeated products and
    # cpow), fractional ones
    m <- switch(i %% 3 + 1, 2^(0:20), unique(round(exp(runif(30, 0, log(3e5))))),
                runif(25, 1, 1e6))
    fr <- exp(runif(1, log(1e-3), log(0.499 * freq)))
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
  expect_equal(r, ar2_acov(1:3, 0.01, 1, 19, 0.05), tolerance = 0.03)
  # started in the stationary law: the first samples have variance sigma^2
  x12 <- replicate(4000, sim_resonance(2, 0.01, 0.7, 7, 0.3))
  expect_equal(apply(x12, 1, stats::var), c(0.49, 0.49), tolerance = 0.1)
  expect_equal(stats::cor(x12[1, ], x12[2, ]), ar2_acov(1, 0.01, 1, 7, 0.3), tolerance = 0.05)
})

test_that("the AV of an AR(2) from stats::filter is the resonance's exact AV", {
  set.seed(34)
  z <- ar2_band(4e5, 7, 0.3)
  a <- allan(z, 100, taus = I(c(0.01, 0.03, 0.1, 0.5, 2)))
  expect_equal(a$avar, resonance_av(a$tau * 100, 0.01, 1, 7, 0.3), tolerance = 0.05)
})

test_that("band start values recover the resonance from an independent generator", {
  set.seed(32)
  n <- 2e5
  x <- rnorm(n) + 0.8 * ar2_band(n, 20, 0.08)
  b <- find_bands(x, 100)
  s <- resonance_start(b[1, ])
  expect_equal(s$fr, 20, tolerance = 0.05)
  expect_equal(s$sigma, 0.8, tolerance = 0.1)
  expect_equal(s$tc, 0.08, tolerance = 0.3)
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
  # a resonance far narrower than the Welch bin is a tone, not this band
  expect_false(resonance_raw_support(0.8, 20, 100, b)$support)
  # the curve's power against the band's measured one: within a factor 2
  # it is the band; at 2.5x either way it stands for something else
  p <- b$power[1]
  for (k in c(0.6, 1.6)) expect_true(resonance_raw_support(sqrt(k * p), 20, 0.08, b)$support)
  for (k in c(0.4, 2.5)) {
    ev <- resonance_raw_support(sqrt(k * p), 20, 0.08, b)
    expect_false(ev$support)
    expect_match(ev$text, sprintf("power %.2g x", 1 / k), fixed = TRUE)
  }
  # the width: up to 3 x narrower (the curve hardly tells a band from a
  # tone), but at most 2 x wider than the band, whose flanks the raw data
  # do not show
  w <- b$width[1]
  for (k in c(0.4, 1.6)) {
    expect_true(resonance_raw_support(sqrt(p), 20, 1 / (pi * w * k), b)$support)
  }
  expect_false(resonance_raw_support(sqrt(p), 20, 1 / (pi * w * 2.5), b)$support)
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
