# The measured-band entry: its AV transfer function against exact forms,
# its measurement of a band from our own generator (a non-Lorentzian band
# made here by shaping white noise in the frequency domain, not with the
# package's simulator), its evidence rule, and the loop choosing it.

# A band with a skewed, non-Lorentzian shape: steep below fpk, a shoulder
# above; one-sided PSD `shape(f) * level` (u^2/Hz). Made by giving each
# Fourier frequency independent Gaussian cosine and sine amplitudes.
skewed_band <- function(n, freq, level = 1e-3, fpk = 20) {
  shape <- function(f) {
    ifelse(f < fpk - 3 | f > fpk + 6, 0,
           ifelse(f < fpk, ((f - fpk + 3) / 3)^3, 1 - 0.5 * (f - fpk) / 6))
  }
  k <- seq_len(n / 2 - 1)
  f <- k * freq / n
  sd <- sqrt(shape(f) * level * freq / n)
  z <- complex(n)
  z[k + 1] <- complex(real = rnorm(length(k), sd = sd), imaginary = rnorm(length(k), sd = sd))
  list(x = Re(fft(z, inverse = TRUE)),
       power = integrate(function(f) shape(f) * level, fpk - 3, fpk + 6,
                         subdivisions = 1000)$value)
}

test_that("the band's AV is the exact transfer function (white noise, a line)", {
  tau0 <- 0.01
  m <- c(1, 2, 3, 5, 8)
  # white noise of variance 1: S1 = 2 tau0 over [0, Nyquist] gives 1/m
  white <- allanvar:::band_av(m * tau0, tau0, 0, 50, rep(2 * tau0, 24))
  expect_equal(white * m, rep(1, 5), tolerance = 0.01)
  # a band 0.01 Hz wide of power A^2/2 is a sinusoid of amplitude A
  A <- 0.3; f0 <- 12.3
  s <- rep(A^2 / 2 / 0.01, 24)
  line <- allanvar:::band_av(m * tau0, tau0, f0 - 0.005, f0 + 0.005, s)
  exact <- A^2 * sin(pi * f0 * m * tau0)^4 / (m^2 * sin(pi * f0 * tau0)^2)
  expect_equal(line, exact, tolerance = 1e-3)
})

test_that("a skewed band is measured from the raw series and its AV matches", {
  set.seed(71)
  freq <- 100
  n <- 2^19
  b <- skewed_band(n, freq)
  x <- b$x + rnorm(n, sd = 0.02 * sqrt(freq))
  bands <- allanvar:::find_bands(x, freq)
  expect_gte(nrow(bands), 1)
  j <- which.max(bands$power)
  mb <- allanvar:::measure_band(x, freq, bands[j, ])
  # the measured power within 5% of the true one (and within 3 u)
  expect_equal(mb$power, b$power, tolerance = 0.05)
  expect_lt(abs(log(mb$power / b$power)), 3 * mb$u + 0.02)
  # the AV of the measured spectrum against the band alone, tau 0.02-1 s
  a <- allan(b$x, freq, taus = c(2, 3, 5, 10, 30, 100) / freq)
  th <- allanvar:::band_av(a$tau, 1 / freq, mb$f_lo, mb$f_hi, mb$s)
  expect_equal(th, a$avar, tolerance = 0.1)
  # the simulator has the same AV
  y <- allanvar:::sim_band(n, 1 / freq, 1, mb$f_lo, mb$f_hi, mb$s)
  expect_equal(allan(y, freq, taus = a$tau)$avar, th, tolerance = 0.1)
})

test_that("a measured band's centre is its half-power centroid, not the middle of its skirted edges", {
  # two-pole resonators (AR(2), stats::filter) at 7 and 18 Hz beside each
  # other and white noise: each one's skirt widens the other's band edges
  # unevenly, so the edges' midpoint and the whole band's centroid drift
  set.seed(72)
  freq <- 100
  n <- 2^19
  ar2 <- function(fr, tc) {
    r <- exp(-1 / (freq * tc))
    z <- as.numeric(stats::filter(rnorm(n + 2000), c(2 * r * cos(2 * pi * fr / freq), -r^2),
                                  method = "recursive"))[-(1:2000)]
    z / stats::sd(z)
  }
  x <- 0.5 * ar2(7, 0.3) + ar2(18, 0.1) + rnorm(n, sd = 0.3)
  bands <- allanvar:::find_bands(x, freq)
  centre <- vapply(seq_len(nrow(bands)), function(j) {
    allanvar:::measure_band(x, freq, bands[j, ], others = bands[-j, ])$f_c
  }, 0)
  for (fr in c(7, 18)) expect_lte(min(abs(centre / fr - 1)), 0.03)
})

test_that("the curve's scale must be the measured one", {
  e <- allanvar:::effect_entry("band")
  par <- list(amp = 1, f_lo = 17, f_hi = 26, u = 0.03)
  expect_true(e$evidence(par, NULL, NULL, 100)$support)
  par$amp <- sqrt(1.05)
  expect_true(e$evidence(par, NULL, NULL, 100)$support)
  par$amp <- sqrt(1.2)
  ev <- e$evidence(par, NULL, NULL, 100)
  expect_false(ev$support)
  expect_match(ev$text, "1.200 x its power")
})

test_that("the loop takes the measured band where the Lorentzian cannot describe it", {
  skip_on_cran()
  set.seed(72)
  freq <- 100
  n <- 2^19
  b <- skewed_band(n, freq, level = 2e-3)
  x <- b$x + rnorm(n, sd = 0.02 * sqrt(freq)) + cumsum(rnorm(n, sd = 2e-4 / sqrt(freq)))
  fit0 <- avfit(allan(x, freq), terms = c("N", "B", "K"))
  ref <- suppressMessages(avrefine(fit0, data = x, max_steps = 4))
  expect_true("band" %in% ref$terms)
  expect_false("resonance" %in% ref$terms)
  st <- ref$steps[ref$steps$effect == "band", ]
  expect_true(isTRUE(st$confirmed))
  expect_lt(ref$chi2, 2)
  expect_equal(coef(ref)[["N"]], 0.02, tolerance = 0.1)
  # the hidden spectrum stays out of the step summary and the printed tables
  expect_false(grepl("s1=", st$params))
  hid <- summary(ref)$coefficients$hidden
  expect_gt(sum(hid), 20)
  shown <- capture.output(print(ref))
  expect_false(any(grepl("s1", shown, fixed = TRUE)))
  expect_true(any(grepl(paste(sum(hid), "measured value"), shown, fixed = TRUE)))
  expect_false(any(grepl("s1", capture.output(print(summary(ref))), fixed = TRUE)))
  expect_true(all(grepl("^s[0-9]+$|band", names(coef(ref))[hid])))
})

test_that("without a band in the raw data the band is never tried", {
  skip_on_cran()
  set.seed(73)
  freq <- 100
  n <- 2^18
  x <- rnorm(n, sd = 0.02 * sqrt(freq)) + cumsum(rnorm(n, sd = 2e-4 / sqrt(freq)))
  ref <- suppressMessages(avrefine(avfit(allan(x, freq), terms = c("N", "B", "K")),
                                   data = x, max_steps = 3))
  expect_false("band" %in% ref$terms)
  expect_false("band" %in% ref$refine$rejected$effect)
  expect_false("band" %in% ref$refine$failures$effect)
  expect_true(isTRUE(allanvar:::effect_entry("band")$proposed_only))
})

test_that("a band is not searched on a curve: its measured values come with it", {
  set.seed(5)
  x <- rnorm(2^14, sd = 0.1) + cumsum(rnorm(2^14, sd = 1e-3))
  av <- allan(x, 100)
  expect_snapshot(error = TRUE, avfit(av, terms = c("N", "K", "band")))
  expect_error(avfit(av, terms = c("N", "band")),
               class = "allanvar_error_argument")
})

test_that("a band beside another: the neighbour is not read as background", {
  # white noise + two AR(2) resonances (12 Hz and 21 Hz, 100 Hz sampling);
  # reference: the exact AR(2) spectrum of the 21 Hz one over the measured
  # edges. With the 12 Hz band in its lower flank the background under the
  # 21 Hz band rose and its power came out at 0.63 of the truth.
  set.seed(27)
  freq <- 100
  n <- 3e5
  ar2 <- function(sd, fr, tc) {
    r <- exp(-1 / (freq * tc))
    a <- c(2 * r * cos(2 * pi * fr / freq), -r^2)
    z <- as.numeric(stats::filter(rnorm(n + 2000), a, method = "recursive"))[-(1:2000)]
    list(x = sd * z / sd(z), a = a, scale = sd / sd(z))
  }
  psd <- function(f, a, scale) {
    w <- 2 * pi * f / freq
    scale^2 * 2 / freq / Mod(1 - a[1] * exp(-1i * w) - a[2] * exp(-2i * w))^2
  }
  b21 <- ar2(0.01, 21, 0.1)
  b12 <- ar2(0.006, 12, 0.3)
  x <- rnorm(n, sd = 0.01) + b21$x + b12$x
  bands <- allanvar:::find_bands(x, freq)
  expect_equal(nrow(bands), 2L)
  j <- which.min(abs((bands$f_from + bands$f_to) / 2 - 21))
  alone <- allanvar:::measure_band(x, freq, bands[j, ])
  m <- allanvar:::measure_band(x, freq, bands[j, ], others = bands[-j, ])
  truth <- integrate(function(f) psd(f, b21$a, b21$scale), m$f_lo, m$f_hi)$value
  expect_equal(m$power / truth, 1, tolerance = 0.15)
  expect_lt(alone$power / truth, 0.8)
})

test_that("a line on top of a band is the line's, not the band's", {
  # white noise + an AR(2) resonance at 9.8 Hz (tc 0.4 s) + a sinusoid
  # carrying a fifth of the band's power. Reference:
  # the exact AR(2) spectrum. Read with a line at 8.97 Hz, the band came out
  # 1.5 x as wide (tc 0.26 s), centred at 9.69 Hz, its power 14% high.
  set.seed(29)
  freq <- 100
  n <- 3e5
  r <- exp(-1 / (freq * 0.4))
  a <- c(2 * r * cos(2 * pi * 9.8 / freq), -r^2)
  z <- as.numeric(stats::filter(rnorm(n + 2000), a, method = "recursive"))[-(1:2000)]
  scale <- 0.01 / sd(z)
  psd <- function(f) {
    w <- 2 * pi * f / freq
    scale^2 * 2 / freq / Mod(1 - a[1] * exp(-1i * w) - a[2] * exp(-2i * w))^2
  }
  # on the band's flank, and in its background (where the band read
  # without it grows over it: measured with it, the power came out 19% low)
  white <- rnorm(n, sd = 0.01)
  for (f0 in c(8.97, 7.6)) {
    x <- white + scale * z + 0.006 * sin(2 * pi * f0 * seq_len(n) / freq + 1)
    dg <- allanvar:::refine_diagnostics(x, freq)
    bands <- allanvar:::diag_part(dg, "bands")
    expect_equal(nrow(bands), 1L)
    expect_equal(bands$f_center, 9.8, tolerance = 0.005)
    expect_equal(bands$tc, 0.4, tolerance = 0.15)
    # the line is still proposed as one
    lines <- allanvar:::diag_part(dg, "lines")
    expect_true(any(abs(lines$f0 - f0) < 0.01))
    mb <- allanvar:::diag_part(dg, "band_spectra")[[1L]]
    expect_equal(mb$f_c, 9.8, tolerance = 0.01)
    expect_equal(mb$power / integrate(psd, mb$f_lo, mb$f_hi)$value, 1, tolerance = 0.1)
  }
})
