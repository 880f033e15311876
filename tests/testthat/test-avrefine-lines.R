# The loop on lines it was not tuned to: a line near Nyquist whose Allan
# signature sits at m = 1 only, and the harmonics of a square wave. Series
# built here with base R (rnorm, cumsum, sin, sign), not the package's
# simulator; references: the generating frequencies and the run without
# the effect.

gen_base <- function(n, freq) rnorm(n, sd = 0.01) + cumsum(rnorm(n, sd = 1e-4 / sqrt(freq)))
loop <- function(x, freq) {
  fit <- avfit(allan(x, freq), terms = c("N", "B", "K"))
  suppressMessages(avrefine(fit, data = x))
}
# the axis with a periodic wave (a line; `wave`: its shape) of `amp` x its
# white sd at f0 Hz added
with_wave <- function(ax, amp, f0, phase, wave = sin) {
  ax$b + amp * ax$s * wave(2 * pi * f0 * seq_along(ax$b) / ax$freq + phase)
}
# the sinusoids' fitted frequencies, named by coefficient
fitted_f0 <- function(r) {
  cf <- coef(r)
  cf[grepl("^sinusoid[0-9]+\\.f0$", names(cf))]
}
# the centre of each resonance or measured band, named by coefficient
band_centre <- function(r) {
  cf <- coef(r)
  cf[grepl("^resonance[0-9]+\\.fr$|^band[0-9]+\\.f_c$", names(cf))]
}
n_reading <- function(r) {
  cf <- coef(r)
  # N, or the white level a filter term of any form carries
  unname(cf[grepl("^N$|^filter[^.]*\\.Nf$", names(cf))][1L])
}

# own generator: white noise, a line at 1.7 Hz of amplitude 0.3 and one at
# 1.59 Hz five times weaker
two_close_lines <- function(freq) {
  set.seed(27)
  t <- seq_len(2e5) / freq
  rnorm(length(t)) + 0.3 * sin(2 * pi * 1.7 * t + 1) + 0.06 * sin(2 * pi * 1.59 * t + 2)
}

test_that("a line at 49.3 Hz (100 Hz sampling, amplitude the white sd) is named; no Q in its place", {
  set.seed(2711)
  freq <- 100
  n <- 3e5
  b <- gen_base(n, freq)
  x <- b + 0.01 * sin(2 * pi * 49.3 * seq_len(n) / freq + 0.7)
  r <- loop(x, freq)
  cf <- coef(r)
  f0 <- fitted_f0(r)
  expect_length(f0, 1L)
  expect_equal(unname(f0), 49.3, tolerance = 0.03 / 49.3)
  expect_equal(cf[[sub("f0", "amp", names(f0))]], 0.01, tolerance = 0.1)
  expect_false("Q" %in% r$terms)
  expect_false(any(r$steps$confirmed %in% FALSE))
  r0 <- loop(b, freq)
  expect_equal(n_reading(r), n_reading(r0), tolerance = 0.05)
  expect_lt(r$chi2, 2)
})

# Own generator: unit white noise through a two-tap filter (weights 1,
# 0.25: lag-1 ACF +0.235) and a 46.8 Hz line of amplitude 1 (the white
# sd), n samples at `freq`.
two_tap_with_line <- function(n, freq) {
  e <- rnorm(n + 1L)
  e[-1L] + 0.25 * e[-(n + 1L)] + sin(2 * pi * 46.8 * seq_len(n) / freq + 0.4)
}

test_that("quantization's lag-1 evidence is read without the periodogram's lines", {
  # own generator: white noise through a two-tap filter (lag-1 ACF +0.235)
  # and a 46.8 Hz line of the white sd: the raw lag-1 ACF is -0.17, the
  # filtered noise's own +0.235, which quantization cannot give
  set.seed(2713)
  freq <- 100
  n <- 2e5
  x <- two_tap_with_line(n, freq)
  d <- avdiagnose(x, freq)
  expect_lt(d$acf1, -0.1)
  q <- allanvar:::quantization_lag1(x, freq, d$lines)
  expect_equal(q$r1, 0.25 / 1.0625, tolerance = 0.03)
  dg <- allanvar:::refine_diagnostics(x, freq)
  ev <- allanvar:::raw_evidence("Q", list(Q = 0.001), dg, allanvar:::diag_series(dg), freq)
  expect_false(ev$support)
  expect_match(ev$text, "without its 1 periodogram line")
  # differenced uniform noise beside the same line: still quantization
  u <- diff(runif(n + 1L, -1, 1)) * sqrt(3) / 2
  y <- u + sin(2 * pi * 46.8 * seq_len(n) / freq + 0.4)
  dg <- allanvar:::refine_diagnostics(y, freq)
  expect_true(allanvar:::raw_evidence("Q", list(Q = 0.001), dg,
                                      allanvar:::diag_series(dg), freq)$support)
})

test_that("the raw short-lag autocovariance is compared with the model and the sharp lines it lacks", {
  # own generator: white noise through a two-tap filter (weights 1, 0.25)
  # and a 46.8 Hz line of the white sd. A model of the filtered noise alone
  # (a moving average of the same lag-1 excess) lacks the line; its
  # autocovariance steps at lags 1-3, with the line's A^2/2 cos(2 pi f k /
  # freq) added, are the raw series' to within a few se; without it they
  # are off by the line's swing.
  set.seed(2714)
  freq <- 100
  n <- 4e5
  x <- two_tap_with_line(n, freq)
  dg <- allanvar:::refine_diagnostics(x, freq)
  # the filtered noise as a moving average over L samples (lag-1
  # autocorrelation 1 - 1/L = 0.25 / 1.0625) at its white level 1.25 /
  # sqrt(freq); a free K keeps the fit's shape
  L <- 1 / (1 - 0.25 / 1.0625)
  fit <- avfit(allan(x, freq), terms = c("filter", "K"), start = c(K = 1e-9),
               fixed = c(filter.Nf = 1.25 / sqrt(freq), filter.L = L))
  k <- allanvar:::unheld_acov(dg, fit, 1:4, 1 / freq)
  expect_equal(k, cos(2 * pi * 46.8 * (1:4) / freq) / 2, tolerance = 0.02)
  raw <- allanvar:::diag_acov_steps(dg)
  md <- allanvar:::model_acov(fit$layout, coef(fit), 1:4, 1 / freq)
  z_with <- (raw$d + diff(md + k)) / raw$se
  z_without <- (raw$d + diff(md)) / raw$se
  expect_lt(max(abs(z_with)), 4)
  expect_gt(min(abs(z_without)), 50)
  # a model that holds the line: nothing is added
  g <- avfit(allan(x, freq), terms = c("filter", "sinusoid"), start = c(sinusoid1.amp = 1),
             fixed = c(filter.Nf = 1.25 / sqrt(freq), filter.L = L, sinusoid1.f0 = 46.8))
  expect_identical(allanvar:::unheld_acov(dg, g, 1:4, 1 / freq), numeric(4))
})

test_that("a line at 46.8 Hz on a measured accelerometer: no quantization term beside it", {
  # unit 2 accel_y carries the sensor's filter (positive short-lag ACF); a
  # 46.8 Hz line of the white sd made its raw lag-1 ACF negative, and a Q
  # term was taken as "confirmed" by it
  skip_if_no_shared()
  skip_on_cran()
  ax <- measured_axis(2, "accel_y")
  set.seed(2714)
  x <- with_wave(ax, 1, 46.8, runif(1, 0, 2 * pi))
  r <- loop(x, ax$freq)
  f0 <- fitted_f0(r)
  expect_true(any(abs(f0 / 46.8 - 1) <= 0.03))
  expect_false("Q" %in% r$terms)
  expect_false(any(r$steps$confirmed %in% FALSE))
  expect_equal(n_reading(r), n_reading(loop(ax$b, ax$freq)), tolerance = 0.05)
})

test_that("a 0.8 Hz square wave: its lines 0.8, 2.4 and 4.0 Hz are named, no band or resonance", {
  set.seed(2712)
  freq <- 100
  n <- 5e5
  x <- gen_base(n, freq) + 0.004 * sign(sin(2 * pi * 0.8 * seq_len(n) / freq + 0.3))
  r <- loop(x, freq)
  f0 <- fitted_f0(r)
  for (h in c(1, 3, 5)) expect_lte(min(abs(f0 / (0.8 * h) - 1)), 0.03)
  # only odd harmonics: the set's pattern
  expect_true(all(abs(f0 / 0.8 - round(f0 / 0.8)) < 0.01 & round(f0 / 0.8) %% 2 == 1))
  expect_false(any(grepl("^(band|resonance)", r$terms)))
  expect_false(any(r$steps$confirmed %in% FALSE))
})

test_that("a sinusoid sized for a strong line is not backed by a weak line beside it", {
  # own generator: white noise, a line at 1.7 Hz of amplitude 0.3 and one
  # at 1.59 Hz five times weaker (on a measured accelerometer the loop
  # once fitted the strong line's power at the weak line's frequency)
  freq <- 100
  x <- two_close_lines(freq)
  raw <- avdiagnose(x, freq)
  ev <- allanvar:::evidence_sinusoid
  expect_false(ev(list(amp = 0.3, f0 = 1.59), raw, x, freq)$support)
  expect_match(ev(list(amp = 0.3, f0 = 1.59), raw, x, freq)$text, "weaker than the fitted amp")
  expect_true(ev(list(amp = 0.3, f0 = 1.7), raw, x, freq)$support)
  expect_true(ev(list(amp = 0.06, f0 = 1.59), raw, x, freq)$support)
})

test_that("a further line of a sharp harmonic set is proposed at its measured amplitude", {
  # own generator: white noise, a square wave at 0.8 Hz (amplitude 0.25:
  # lines 4 a / (pi k) at the odd k, one frequency each) and a 0.5 Hz line
  # with its 3rd harmonic whose frequency wanders (a random walk of sd
  # 0.004 Hz over the record, as the measured accelerometers' own lines do)
  set.seed(2716)
  freq <- 100
  n <- 4e5
  t <- seq_len(n) / freq
  ph <- 2 * pi * cumsum(0.5 + 0.004 * cumsum(rnorm(n)) / sqrt(n)) / freq
  x <- rnorm(n) + 0.25 * sign(sin(2 * pi * 0.8 * t + 1)) + 0.4 * sin(ph) + 0.2 * sin(3 * ph + 1)
  # the least-squares sinusoid over the whole record holds all of a sharp
  # line's amplitude (the generator's), a fraction of a wandering one's
  fits <- allanvar:::record_line_fits(x, freq, c(0.8, 1.5))
  expect_equal(fits$amp[1], 4 * 0.25 / pi, tolerance = 0.02)
  expect_lt(fits$amp[2], 0.6 * 0.2)
  # the series less those sinusoids is remove_lines()'
  expect_identical(allanvar:::subtract_line_fits(x, freq, fits),
                   allanvar:::remove_lines(x, freq, c(0.8, 1.5)))
  raw <- allanvar:::refine_diagnostics(x, freq)
  l <- allanvar:::diag_part(raw, "lines")
  at <- function(f) which.min(abs(l$f0 - f))
  expect_gt(l$record_amp[at(2.4)] / l$amp[at(2.4)], 0.9)
  expect_lt(l$record_amp[at(1.5)] / l$amp[at(1.5)], 0.6)
  props <- allanvar:::effect_entry("sinusoid")$propose(raw, 2^(0:12) / freq, NULL)
  pinned <- function(f) {
    p <- props[[which.min(vapply(props, function(q) abs(q$init$f0 - f), 0))]]
    p$pin
  }
  # the square wave's 3rd and 5th harmonics: f0 and amp (the generator's)
  for (k in c(3, 5)) {
    pk <- pinned(0.8 * k)
    expect_equal(pk$f0, 0.8 * k, tolerance = 1e-3)
    expect_equal(pk$amp, 4 * 0.25 / (pi * k), tolerance = 0.1)
  }
  # a set's strongest line, and a wandering line's harmonic: f0 only
  expect_named(pinned(0.8), "f0")
  expect_named(pinned(1.5), "f0")
})

test_that("a square wave's harmonics beside a resonance keep their own amplitudes", {
  skip_on_cran()
  # own generator: white noise through a two-tap average, a resonance at
  # 9.8 Hz (an AR(2), 0.45e-3 rms), a slow random walk and a square wave
  # of amplitude 1.5e-3 at 0.7 Hz (lines 4 a / (pi k) at the odd k). Each
  # further harmonic free on the curve took the power of the harmonics not
  # yet in the model (seed 2: the 5th at 1.29 x its line, the 7th at 0.60
  # x). On seed 1 a GM of Tc 2.0 samples took the average's lag-1 ACF at
  # the first step, and neither the filter nor the resonance could follow.
  freq <- 100
  n <- 5e5
  t <- seq_len(n) / freq
  for (seed in 1:2) {
    set.seed(seed)
    r <- exp(-1 / (freq * 0.42))
    w <- 2 * pi * 9.8 / freq
    res <- as.numeric(stats::filter(rnorm(n), c(2 * r * cos(w), -r^2), method = "recursive"))
    res <- 4.5e-4 * res / sd(res)
    wn <- as.numeric(stats::filter(rnorm(n, sd = 4.8e-3), c(0.6, 0.4), sides = 1))
    wn[1] <- 0
    x <- wn + res + cumsum(rnorm(n, sd = 4e-5 / sqrt(freq))) +
      1.5e-3 * sign(sin(2 * pi * 0.7 * t + runif(1, 0, 2 * pi)))
    rl <- loop(x, freq)
    f0 <- fitted_f0(rl)
    k <- round(f0 / 0.7)
    expect_true(all(abs(f0 / (0.7 * k) - 1) < 0.01 & k %% 2 == 1))
    expect_true(all(c(1, 3, 5, 7) %in% k))
    amp <- coef(rl)[sub("f0$", "amp", names(f0))]
    expect_true(all(abs(amp / (4 * 1.5e-3 / (pi * k)) - 1) < 0.15))
    expect_true(any(grepl("^(resonance|band)", rl$terms)))
    expect_true(any(grepl("^filter", rl$terms)))
    expect_false("gm" %in% rl$terms)
  }
})

test_that("a sinusoid's f0 must lie within its periodogram line's own precision", {
  # own generator: white noise, a strong line at 0.61 Hz (2000 x its
  # background) and a weak one at 2.3 Hz. The curve took 0.6123 Hz for
  # such a line (0.77 Welch bins off) and its AV oscillation at long taus
  # went wrong; a weak line's frequency is read only to about a bin.
  set.seed(2715)
  freq <- 100
  t <- seq_len(5e5) / freq
  x <- rnorm(length(t)) + sin(2 * pi * 0.61 * t + 1) + 0.03 * sin(2 * pi * 2.3 * t + 2)
  raw <- avdiagnose(x, freq)
  l <- raw$lines
  res <- attr(l, "resolution")
  strong <- l[which.min(abs(l$f0 - 0.61)), ]
  weak <- l[which.min(abs(l$f0 - 2.3)), ]
  expect_gt(strong$ratio, 500)
  expect_lt(weak$ratio, 50)
  ev <- allanvar:::evidence_sinusoid
  expect_true(ev(list(amp = 1, f0 = strong$f0), raw, x, freq)$support)
  off <- ev(list(amp = 1, f0 = strong$f0 + 0.77 * res), raw, x, freq)
  expect_false(off$support)
  expect_match(off$text, "from the fitted f0")
  # the weak line: half a bin off is within what it can tell
  expect_true(ev(list(amp = 0.03, f0 = weak$f0 + 0.5 * res), raw, x, freq)$support)
  # a sinusoid the curve sizes far below the line is not the line the raw
  # data see (a harmonic fitted at amp 0 passed as confirmed): undecided
  expect_true(ev(list(amp = 0.4, f0 = strong$f0), raw, x, freq)$support)
  small <- ev(list(amp = 0.2, f0 = strong$f0), raw, x, freq)
  expect_identical(small$support, NA)
  expect_match(small$text, "5 x stronger than the fitted amp 0.2", fixed = TRUE)
  expect_match(ev(list(amp = 0, f0 = strong$f0), raw, x, freq)$text, "the fitted amp 0$")
})

test_that("a harmonic set's further lines do not spend the step budget", {
  # the square wave above with room for one effect only: its fundamental
  # spends the budget, 2.4 and 4.0 Hz follow as lines of the same source
  set.seed(2712)
  freq <- 100
  n <- 5e5
  t <- seq_len(n) / freq
  sq <- 0.004 * sign(sin(2 * pi * 0.8 * t + 0.3))
  b <- gen_base(n, freq)
  f0s <- function(x) {
    fit <- avfit(allan(x, freq), terms = c("N", "B", "K"))
    r <- suppressMessages(avrefine(fit, data = x, max_steps = 1))
    fitted_f0(r)
  }
  f0 <- f0s(b + sq)
  # (a further odd harmonic the periodogram finds may follow too: a set's
  # line need only lower the criterion)
  expect_gte(length(f0), 3L)
  for (h in c(1, 3, 5)) expect_lte(min(abs(f0 / (0.8 * h) - 1)), 0.03)
  expect_true(all(round(f0 / 0.8) %% 2 == 1 & abs(f0 / 0.8 - round(f0 / 0.8)) < 0.01))
  # an unrelated line (1.3 Hz, no harmonic of 0.8) is a new source: with
  # the budget spent it is not added, and only lines of the set are
  f0 <- f0s(b + sq + 0.002 * sin(2 * pi * 1.3 * t + 1))
  expect_false(any(abs(f0 / 1.3 - 1) < 0.03))
  expect_true(all(abs(f0 / 0.8 - round(f0 / 0.8)) < 0.01))
})

test_that("a line beside a measured axis's own is named, not taken as a GM of a few samples", {
  # unit 2 accel_y carries the sensor's filter, a 0.57 Hz line, a band near
  # 10 Hz and a slow GM; a 1.7 Hz line (0.3 x the white sd a sample) added
  # to it was first taken as a GM of tc 0.025 s, which then stayed until a
  # revisit took the periodogram's lines first. Such a GM keeps no
  # correlation at lag 2 in the raw data (a filter's), so it is refused:
  # the line is named, N stays where the run without it puts it, and the
  # model fits without a revisit.
  skip_if_no_shared()
  skip_on_cran()
  ax <- measured_axis(2, "accel_y")
  b <- ax$b
  freq <- ax$freq
  x <- with_wave(ax, 0.3, 1.7, 0.7)
  r <- loop(x, freq)
  f0 <- fitted_f0(r)
  expect_true(any(abs(f0 / 1.7 - 1) <= 0.03))
  expect_false(any(r$steps$confirmed %in% FALSE))
  expect_lt(r$chi2, 4)
  expect_false("gm" %in% r$terms[seq_len(2)])
  rj <- r$refine$rejected
  expect_true(any(rj$effect == "gm" & grepl("a filter's short correlation", rj$reason)))
  r0 <- loop(b, freq)
  expect_equal(n_reading(r), n_reading(r0), tolerance = 0.05)
})

test_that("a greedy order far from the curve is revisited with the raw data's values first", {
  skip_on_cran()
  # own generator: white noise through a first-order low-pass (AR(1) 0.3),
  # a band at 15.5 Hz (an AR(2)), a 0.48 Hz line, a random walk and a 0.9
  # Hz square wave. The greedy order took a GM first and ended at chi2/dof
  # 6.7; taking the periodogram's lines and the band's spectrum first, the
  # run fits, and was the one kept (main 48ab052). Since a filter form the
  # raw data refuse at the curve's shape is tried at the raw data's, a
  # low-pass enters at step 2 in place of the GM and the greedy order
  # reaches that model itself; a revisit, if one is made, must keep it.
  set.seed(1)
  freq <- 100
  n <- 5e5
  t <- seq_len(n) / freq
  w <- as.numeric(stats::filter(rnorm(n, sd = 0.009), 0.3, method = "recursive"))
  r <- exp(-1 / (freq * 0.35))
  om <- 2 * pi * 15.5 / freq
  band <- as.numeric(stats::filter(rnorm(n), c(2 * r * cos(om), -r^2), method = "recursive"))
  band <- 0.008 * band / sd(band)
  b <- w + band + 0.009 * sin(2 * pi * 0.48 * t + runif(1, 0, 2 * pi)) +
    cumsum(rnorm(n, sd = 1.2e-4 / sqrt(freq)))
  x <- b + 0.004 * sign(sin(2 * pi * 0.9 * t + runif(1, 0, 2 * pi)))
  rl <- loop(x, freq)
  rv <- rl$refine$revisit
  if (!is.null(rv)) {
    expect_identical(rv$order, c("greedy", "raw-data values first"))
    expect_identical(rv$kept, c(FALSE, TRUE))
  }
  expect_lt(rl$chi2, 4)
  f0 <- fitted_f0(rl)
  for (f in c(0.48, 0.9, 2.7, 4.5)) expect_true(any(abs(f0 / f - 1) < 0.01))
  expect_true(any(grepl("^(resonance|band)", rl$terms)))
  expect_false("gm" %in% rl$terms)
})

test_that("late_pins(): steps that pinned raw-data values behind one that pinned nothing, still held", {
  st <- list(pins = list(numeric(0), c(a.f0 = 1.7), numeric(0), c(b.f0 = 0.566)),
             settings = list(fixed = c(x.f0 = 1.7, y.f0 = 0.566)))
  expect_identical(allanvar:::late_pins(st), c(2L, 4L))
  st$pins <- list(c(a.f0 = 1.7), numeric(0), c(b.f0 = 0.566))
  expect_identical(allanvar:::late_pins(st), 3L)
  st$settings$fixed <- c(x.f0 = 1.7)
  expect_identical(allanvar:::late_pins(st), integer(0))
  st$pins <- list(c(a.f0 = 1.7), c(b.f0 = 0.566))
  expect_identical(allanvar:::late_pins(st), integer(0))
  # a trial matches the seed whose values it pins
  seeds <- list(c(s.f0 = 1.7), c(b.s1 = 2, b.s2 = 3))
  expect_identical(allanvar:::seed_of(list(pin = list(list(f0 = 1.7))), seeds), 1L)
  expect_identical(allanvar:::seed_of(list(pin = list(list(s1 = 2, s2 = 3, u = 9))), seeds), 2L)
  expect_identical(allanvar:::seed_of(list(pin = list(list(f0 = 1.8))), seeds), 0L)
  expect_identical(allanvar:::seed_of(list(pin = list(NULL)), seeds), 0L)
})

test_that("fresh_pinned_trials(): lines the model holds leave, at most 5 others per entry stay, in order", {
  tr <- data.frame(effect = c(rep("sinusoid", 8), "gm"), stringsAsFactors = FALSE)
  tr$pin <- c(lapply(c(1.1, 3.3, 1.7, 5.5, 0.5, 7.7, 9.9, 12.1), function(f) list(f0 = f)),
              list(NULL))
  out <- fresh_pinned_trials(tr, c(sinusoid1.f0 = 1.1, sinusoid2.f0 = 3.3))
  got <- vapply(out$pin[out$effect == "sinusoid"], function(p) p$f0, 0)
  expect_equal(got, c(1.7, 5.5, 0.5, 7.7, 9.9))
  expect_true("gm" %in% out$effect)
  expect_identical(fresh_pinned_trials(tr[0, ], numeric(0)), tr[0, ])
})

test_that("a line on a measured accelerometer's band is named, and the band stays as it was", {
  # unit 3 accel_x carries a resonance at 9.86 Hz; a line at 9.3 Hz of 0.5
  # x the white sd sits on its flank. Read with the line in it, the band's
  # fit moved to 9.30 Hz, the band took the line's place in the model and
  # the line was never named.
  skip_if_no_shared()
  skip_on_cran()
  ax <- measured_axis(3, "accel_x")
  x <- with_wave(ax, 0.5, 9.3, 1)
  r0 <- loop(ax$b, ax$freq)
  r <- loop(x, ax$freq)
  expect_lte(min(abs(fitted_f0(r) / 9.3 - 1)), 0.03)
  expect_lte(abs(n_reading(r) / n_reading(r0) - 1), 0.05)
  expect_length(band_centre(r), 1L)
  expect_equal(unname(band_centre(r)), unname(band_centre(r0)), tolerance = 0.01)
})

test_that("a square wave added to a measured accelerometer: its 5th harmonic is named beside the axis's own lines", {
  # unit 2 accel_z carries a 0.57 Hz line and its 1.7 Hz third harmonic, the
  # sensor's filter and a band near 10 Hz; a 1.1 Hz square wave of 0.4 x the
  # white sd adds lines at 1.1, 3.3, 5.5 Hz, ... The 5th harmonic paid
  # less than min_gain on the curve, and the axis's own 1.7 Hz line ranked
  # below the square wave's harmonics and was never proposed.
  skip_if_no_shared()
  skip_on_cran()
  ax <- measured_axis(2, "accel_z")
  b <- ax$b
  freq <- ax$freq
  x <- with_wave(ax, 0.4, 1.1, 2.1, function(u) sign(sin(u)))
  r <- loop(x, freq)
  f0 <- fitted_f0(r)
  for (h in c(1, 3, 5)) expect_lte(min(abs(f0 / (1.1 * h) - 1)), 0.03)
  expect_lte(min(abs(f0 / 0.566 - 1)), 0.03)
  expect_false(any(r$steps$confirmed %in% FALSE))
})

test_that("a square wave on a measured accelerometer: a low-pass taken for its harmonics' bumps gives way to the axis's filter and resonance", {
  # unit 3 accel_z carries a moving-average filter, a 0.54 Hz line and a
  # resonance near 9.85 Hz; a 0.66 Hz square wave of 0.4 x the white sd
  # adds lines at 0.66, 1.98, 3.3 Hz, ... A first-order low-pass, taken
  # early for the bumps of the harmonics not yet in, kept the resonance out
  # and no further harmonic paid beside it (on main 96019cc: N +5.4%
  # against the run without the wave, no resonance).
  skip_if_no_shared()
  skip_on_cran()
  ax <- measured_axis(3, "accel_z")
  x <- with_wave(ax, 0.4, 0.66, 0.4, function(u) sign(sin(u)))
  r0 <- loop(ax$b, ax$freq)
  r <- loop(x, ax$freq)
  f0 <- fitted_f0(r)
  for (h in c(1, 3)) expect_lte(min(abs(f0 / (0.66 * h) - 1)), 0.03)
  expect_lte(abs(n_reading(r) / n_reading(r0) - 1), 0.05)
  expect_true(any(split_term(r$terms)$kind %in% c("resonance", "band")))
  expect_false(any(r$steps$confirmed %in% FALSE))
})

test_that("a square wave beside a measured axis's resonance, at any phase: the filter's form chosen without the harmonics not yet in", {
  # unit 3 accel_z with a 0.6 Hz square wave of 0.4 x the white sd: its
  # harmonics up to 14 Hz are sharp lines. At phases 0.4, 1.3, 2.1, 3.0 and
  # 5.5 a first-order low-pass, taken at step 2, mimicked the bumps of the
  # harmonics not yet in; beside it each further harmonic at its
  # periodogram amplitude raised chi2/dof (9.3 -> 20), and the run ended
  # with three lines, no resonance. The form is now chosen again on the
  # curve without the sharp lines the model lacks. At phase 4.5 the moving
  # average came, but the axis's 9.9 Hz resonance, screened beside the
  # held filter, took 1.2% of the AV (2.7% free), below the 2% a term must
  # explain somewhere, and was never refitted free (chi2/dof 4.2).
  skip_if_no_shared()
  skip_on_cran()
  ax <- measured_axis(3, "accel_z")
  r0 <- loop(ax$b, ax$freq)
  for (phase in c(0.4, 2.1, 4.5)) {
    x <- with_wave(ax, 0.4, 0.6, phase, function(u) sign(sin(u)))
    r <- loop(x, ax$freq)
    f0 <- fitted_f0(r)
    for (h in c(1, 3, 5, 7)) expect_lte(min(abs(f0 / (0.6 * h) - 1)), 0.03)
    kinds <- split_term(r$terms)$kind
    expect_true(any(kinds %in% c("resonance", "band")))
    expect_identical(r$terms[kinds == "filter"], "filter")
    expect_lt(r$chi2, 3)
    expect_false(any(r$steps$confirmed %in% FALSE))
    expect_lte(abs(n_reading(r) / n_reading(r0) - 1), 0.05)
  }
})

test_that("an added line does not cost a measured axis its own Gauss-Markov term (a family chosen again is no effect)", {
  # unit 3 accel_y: filter, 0.54 Hz line, resonance and a slow GM; with a
  # 0.9 Hz line added, the filter, both lines and the resonance took four
  # steps of the old budget of five, and the step that only chose the
  # filter's form again spent the fifth: the GM was never reached
  skip_if_no_shared()
  skip_on_cran()
  ax <- measured_axis(3, "accel_y")
  b <- ax$b
  freq <- ax$freq
  x <- with_wave(ax, 0.3, 0.9, 0.4)
  r <- loop(x, freq)
  expect_true("gm" %in% split_term(r$terms)$kind)
  expect_lte(min(abs(fitted_f0(r) / 0.9 - 1)), 0.03)
  expect_lt(r$chi2, 4)
})

test_that("a line beside a measured axis's filter and resonance: the filter's form is chosen again beside the refused resonance", {
  # unit 3 accel_x: the sensor's filter (a moving average), a 0.54 Hz line
  # and a 9.8 Hz resonance. A 3.1 Hz line of 0.3 x the white sd bends the
  # short-tau end: the first step took a first-order low-pass, which then
  # carried part of the resonance, and the raw data refused the resonance
  # at the power the curve gave it (chi2/dof 38, N +11%).
  skip_if_no_shared()
  skip_on_cran()
  ax <- measured_axis(3, "accel_x")
  b <- ax$b
  freq <- ax$freq
  x <- with_wave(ax, 0.3, 3.1, 1.3)
  r0 <- loop(b, freq)
  r <- loop(x, freq)
  expect_lte(abs(n_reading(r) / n_reading(r0) - 1), 0.05)
  expect_lte(min(abs(fitted_f0(r) / 3.1 - 1)), 0.03)
  expect_lte(min(abs(band_centre(r) / 9.84 - 1)), 0.05)
  expect_true(any(grepl("chosen again (was filter:lp1) beside", r$steps$evidence, fixed = TRUE)))
  expect_false(any(r$steps$confirmed %in% FALSE))
  expect_lt(r$chi2, 4)
})

test_that("a strong line beside a measured band enters: the band's measured scale is held, not broken", {
  # a simulated sensor axis: white noise through a short moving average, a
  # two-pole resonance at 9.85 Hz, a 0.54 Hz line of 1.4 x the white sd and
  # a random walk. The first step took the band the raw spectrum measured;
  # the line's refit moved the band's scale beyond its measured power, so
  # the line was refused and the loop stopped at chi2/dof 6897 (N -54%).
  set.seed(14)
  freq <- 100
  n <- 5e5
  x <- sim_sensor_axis(n, freq)
  r <- loop(x, freq)
  expect_lte(min(abs(fitted_f0(r) / 0.54 - 1)), 0.03)
  expect_lt(r$chi2, 4)
  # the white level at DC: 1.25 x 0.01 x sqrt(1 / freq)
  expect_lte(abs(n_reading(r) / 1.25e-3 - 1), 0.15)
  expect_false(any(r$steps$confirmed %in% FALSE))
})

test_that("a filter form taken for a line's bump is chosen again once the line is in", {
  # a simulated sensor axis: white noise through a short moving average, a
  # two-pole resonance at 9.85 Hz, a 0.54 Hz line and a random walk, with
  # a 2.2 Hz line of 0.3 x the white sd added. Before the 2.2 Hz line
  # entered, a first-order low-pass paid best for the moving average's
  # bump and the line's together; it stayed once the line was in (on
  # main 2529cae: N +14% against the run without the line, which takes the
  # moving average).
  set.seed(6)
  freq <- 100
  n <- 5e5
  b <- sim_sensor_axis(n, freq)
  t <- seq_len(n) / freq
  x <- b + 0.003 * sin(2 * pi * 2.2 * t + runif(1, 0, 2 * pi))
  r0 <- loop(b, freq)
  r <- loop(x, freq)
  expect_lte(min(abs(fitted_f0(r) / 2.2 - 1)), 0.03)
  expect_lte(abs(n_reading(r) / n_reading(r0) - 1), 0.05)
  expect_identical(sort(r$terms[startsWith(r$terms, "filter")]),
                   sort(r0$terms[startsWith(r0$terms, "filter")]))
  expect_false(any(r$steps$confirmed %in% FALSE))
  expect_lt(r$chi2, 4)
})

test_that("a line near Nyquist and the filter it hides enter together", {
  # white noise through a moving average (0.35), a resonance at 13.3 Hz, a
  # 0.73 Hz line and a random walk, with a line near Nyquist of 0.8 x the
  # white sd added. The line's AV sits at tau0, where the moving average's
  # dip is: the line alone did not pay, and the filter alone was refused
  # (fitted without the line it predicted too little lag-1
  # autocorrelation). On main 96019cc the line was not named, N -2.5%.
  set.seed(1)
  freq <- 100
  n <- 5e5
  t <- seq_len(n) / freq
  w <- rnorm(n + 1L, sd = 0.01)
  z <- ar2_unit(n, 13.3, 0.6, freq)
  b <- (w[-1L] + 0.35 * w[-(n + 1L)]) + 0.009 * z +
    0.01 * sin(2 * pi * 0.73 * t + 1) + cumsum(rnorm(n, sd = 1e-4 / sqrt(freq)))
  f0 <- runif(1, 44, 48.5)
  x <- b + 0.008 * sin(2 * pi * f0 * t + runif(1, 0, 2 * pi))
  r0 <- loop(b, freq)
  r <- loop(x, freq)
  expect_lte(min(abs(fitted_f0(r) / f0 - 1)), 0.03)
  expect_identical(sum(startsWith(r$terms, "filter")), 1L)
  expect_lte(abs(n_reading(r) / n_reading(r0) - 1), 0.05)
  expect_false(any(r$steps$confirmed %in% FALSE))
  expect_lt(r$chi2, 4)
})

test_that("a square wave beside a first-order low-pass sensor: no low-pass sized for the resonance and the harmonics", {
  # white noise through a first-order low-pass (AR(1) 0.3), a resonance at
  # 15.5 Hz, a 0.48 Hz line and a random walk, with a square wave near 1 Hz
  # added. The first step took a low-pass that carried the resonance's and
  # the harmonics' bumps and predicted 2.9 x the raw lag-1 autocorrelation
  # (undecided, not contradicted): the resonance was refused beside it and
  # the third harmonic never paid (on main 96019cc: N +8.5%).
  set.seed(3)
  freq <- 100
  n <- 5e5
  t <- seq_len(n) / freq
  z <- ar2_unit(n, 15.5, 0.35, freq)
  b <- as.numeric(stats::filter(rnorm(n, sd = 0.009), 0.3, method = "recursive")) +
    0.008 * z + 0.009 * sin(2 * pi * 0.48 * t + 2) +
    cumsum(rnorm(n, sd = 1.2e-4 / sqrt(freq)))
  f0 <- runif(1, 0.7, 1.2)
  x <- b + 0.004 * sign(sin(2 * pi * f0 * t + runif(1, 0, 2 * pi)))
  r0 <- loop(b, freq)
  r <- loop(x, freq)
  f <- fitted_f0(r)
  for (h in c(1, 3)) expect_lte(min(abs(f / (f0 * h) - 1)), 0.03)
  expect_lte(abs(n_reading(r) / n_reading(r0) - 1), 0.05)
  expect_true(any(split_term(r$terms)$kind %in% c("resonance", "band")))
  expect_false(any(r$steps$confirmed %in% FALSE))
})

test_that("a filter form taken first beside a line added to a measured axis gives way to the moving average", {
  # unit 3 accel_x (a moving-average filter, a 0.54 Hz line, a 9.8 Hz
  # resonance) with a 4.3 Hz line of 0.35 x the white sd: the first step
  # took a first-order low-pass (on main 2529cae it was kept: N +8.2%,
  # chi2/dof 3.77). On the final model the moving average was within the
  # criterion's min_gain of it and the raw steps c(h) - c(h + 1) chose it
  # (acov_choice()); since d33bf3a the form is chosen again once the
  # 0.54 Hz line is in, while its harmonics are still trials, and the curve
  # chooses it there and at the end
  skip_if_no_shared()
  skip_on_cran()
  ax <- measured_axis(3, "accel_x")
  x <- with_wave(ax, 0.35, 4.3, 1.3)
  r0 <- loop(ax$b, ax$freq)
  r <- loop(x, ax$freq)
  expect_lte(abs(n_reading(r) / n_reading(r0) - 1), 0.05)
  expect_true(any(grepl("filter family chosen again", r$steps$evidence, fixed = TRUE)))
  expect_identical(sort(r$terms[startsWith(r$terms, "filter")]),
                   sort(r0$terms[startsWith(r0$terms, "filter")]))
  expect_false(any(r$steps$confirmed %in% FALSE))
  expect_lt(r$chi2, 4)
})

test_that("a measured axis's own 3rd harmonic is named with and without a line added", {
  # unit 1 accel_y carries a 0.564 Hz line and its 3rd harmonic at 1.691 Hz
  # (periodogram amp 1.3e-4, p = 2e-38). Held to no gain of its own, the
  # harmonic cost the curve 2.9 alone and gained 1.7 beside an added 2.7
  # Hz line: it was named only when the line was added (on b66a8d2). Its
  # confirmation by the raw data now counts as min_gain, as for any effect.
  skip_if_no_shared()
  skip_on_cran()
  ax <- measured_axis(1, "accel_y")
  harmonic <- function(r) {
    f <- fitted_f0(r)
    any(abs(f / (3 * f[which.min(abs(f - 0.564))]) - 1) < 1e-3)
  }
  r0 <- loop(ax$b, ax$freq)
  expect_true(harmonic(r0))
  set.seed(3)
  r1 <- loop(with_wave(ax, 0.3, 2.7, stats::runif(1, 0, 2 * pi)), ax$freq)
  expect_true(any(abs(fitted_f0(r1) / 2.7 - 1) < 0.03))
  expect_true(harmonic(r1))
  expect_equal(n_reading(r1), n_reading(r0), tolerance = 0.05)
})

test_that("a line the curve sizes far off its periodogram line is held at the line's amplitude", {
  # own generator: white noise, a line at 1.7 Hz of amplitude 0.3 and one
  # at 1.59 Hz five times weaker: on the curve the two look alike
  freq <- 100
  x <- two_close_lines(freq)
  raw <- avdiagnose(x, freq)
  hold <- allanvar:::hold_sinusoid
  h <- hold(list(amp = 0, f0 = 1.59), raw)
  expect_equal(h$values[["amp"]], 0.06, tolerance = 0.25)
  expect_match(h$note, "held at the periodogram line's 0.0[56][0-9]* \\(the curve put it at 0\\)")
  expect_equal(hold(list(amp = 0.01, f0 = 1.59), raw)$values, h$values)
  # sized 5 x its line (the curve giving it its neighbour's power): held too
  expect_equal(hold(list(amp = 0.3, f0 = 1.59), raw)$values, h$values)
  # sized within a factor 3 of the line, or away from any line: nothing
  # to hold
  expect_null(hold(list(amp = 0.05, f0 = 1.59), raw))
  expect_null(hold(list(amp = 0.15, f0 = 1.59), raw))
  expect_null(hold(list(amp = 0, f0 = 3.3), raw))
  skip_if_no_shared()
  skip_on_cran()
  # unit 2 accel_x: the loop adds the axis's 1.596 Hz line, then its 1.697
  # Hz neighbour takes their power on the curve (the final model held the
  # first at amplitude 0, and left it out, on 38dc352)
  ax <- measured_axis(2, "accel_x")
  r <- loop(ax$b, ax$freq)
  line <- avdiagnose(ax$b, ax$freq)$lines
  raw_line <- line[which.min(abs(line$f0 - 1.596)), ]
  f0 <- fitted_f0(r)
  j <- which.min(abs(f0 - raw_line$f0))
  expect_lt(abs(f0[[j]] - raw_line$f0), 0.001)
  amp <- coef(r)[[sub("f0$", "amp", names(f0)[j])]]
  expect_equal(amp, raw_line$amp, tolerance = 1e-6)
  expect_true(r$layout$fixed[r$layout$name == sub("f0$", "amp", names(f0)[j])])
  expect_match(r$steps$evidence[r$steps$label == sub("[.]f0$", "", names(f0)[j])],
               "at the end, amp held at the periodogram line's")
  expect_false(any(r$steps$confirmed %in% FALSE))
})

test_that("an instance the final model holds at amplitude 0 leaves it, and the steps say so", {
  lm <- asNamespace("allanvar")$label_map
  expect_identical(lm(c("B", "gm", "sinusoid", "sinusoid", "sinusoid"), c(FALSE, FALSE, FALSE, TRUE, FALSE)),
                   c(B = "B", gm1 = "gm1", sinusoid1 = "sinusoid1", sinusoid3 = "sinusoid2"))
  # The stage on a state built here: white noise and a 1 Hz line (own
  # generator), the model N + a 7.3 Hz sinusoid held at amplitude 0 + the
  # 1 Hz one, each taken at a step of its own. (The loop's own case, unit
  # 3 accel_z with a 0.7 Hz square wave whose 3.5 and 4.9 Hz harmonics the
  # final curve held at 0, no longer arises: the axis's resonance now
  # enters and the harmonics keep their amplitudes.)
  ns <- asNamespace("allanvar")
  set.seed(5)
  freq <- 100
  t <- seq_len(2e5) / freq
  x <- rnorm(length(t), sd = 0.01) + 0.004 * sin(2 * pi * t + 0.3)
  held <- c(sinusoid1.f0 = 7.3, sinusoid1.amp = 0, sinusoid2.f0 = 1)
  fit <- avfit(allan(x, freq), terms = c("N", "sinusoid", "sinusoid"), fixed = held)
  st <- list(current = fit,
             steps = list(list(label = "sinusoid2", evidence = "a line at 1 Hz"),
                          list(label = "sinusoid1", evidence = "a line at 7.3 Hz")),
             settings = list(fixed = held), rejected = ns$new_rejected(),
             failures = ns$new_failures(),
             args = list(criterion = "BIC", min_gain = 10, freq = freq))
  out <- ns$stage_prune(st)
  expect_identical(out$current$terms, c("N", "sinusoid"))
  expect_equal(unname(coef(out$current)["sinusoid1.amp"]), 0.004, tolerance = 0.05)
  expect_identical(out$settings$fixed, c(sinusoid1.f0 = 1))
  expect_identical(vapply(out$steps, function(s) s$label, ""), c("sinusoid1", "left:sinusoid1"))
  expect_match(out$steps[[2]]$evidence, "left out at the end: amplitude 0 in the final model")
  expect_identical(nrow(out$rejected), 1L)
  expect_match(out$rejected$reason, "at amplitude 0 in the final model")
  expect_match(out$rejected$params, "f0=7.3 Hz")
  # nothing at 0: nothing leaves
  st$steps <- st$steps[1]
  expect_identical(ns$stage_prune(st), st)
})

test_that("a line near Nyquist on a measured gyro: the filter refused at the curve's shape enters at the raw data's", {
  # unit 2 gyro_z (a moving average, a 20 Hz resonance) with a 44.56 Hz
  # line of the white sd added. At m = 1 the line's amplitude and the
  # filter's dip trade on the curve alone: the moving average came out at
  # L 2.39 (resonance held) and 1.47 (free), each contradicted by the raw
  # lag-1 excess, and the loop ended without a filter at chi2/dof 106, N
  # -7% (main 48ab052). At the raw data's L (1.14) it fits at chi2/dof 1.5.
  skip_if_no_shared()
  skip_on_cran()
  a <- measured_axis(2, "gyro_z")
  r0 <- loop(a$b, a$freq)
  set.seed(1)
  r <- loop(with_wave(a, 1, 44.56, runif(1, 0, 2 * pi)), a$freq)
  expect_lte(min(abs(fitted_f0(r) / 44.56 - 1)), 0.03)
  expect_identical(r$terms[startsWith(r$terms, "filter")], "filter")
  expect_lte(abs(n_reading(r) / n_reading(r0) - 1), 0.05)
  expect_lt(r$chi2, 4)
  expect_false(any(r$steps$confirmed %in% FALSE))
})

test_that("a line on a resonance's flank is named, and the resonance stays where its band is", {
  skip_on_cran()
  # own generator: white noise, an AR(2) resonance at 9.8 Hz (tc 0.4 s,
  # sd 0.01) and a line at 8.97 Hz of amplitude 0.006. Fitted before the
  # line entered, the resonance took its power (9.65 Hz, tc 0.48 s) and the
  # line, screened beside it held there, was refused; the raw data read the
  # band without the line at 9.80 Hz.
  set.seed(29)
  freq <- 100
  n <- 3e5
  r <- exp(-1 / (freq * 0.4))
  z <- as.numeric(stats::filter(rnorm(n + 2000), c(2 * r * cos(2 * pi * 9.8 / freq), -r^2),
                                method = "recursive"))[-(1:2000)]
  b <- rnorm(n, sd = 0.01) + 0.01 * z / sd(z)
  x <- b + 0.006 * sin(2 * pi * 8.97 * seq_len(n) / freq + 1)
  rb <- loop(b, freq)
  rx <- loop(x, freq)
  f0 <- fitted_f0(rx)
  expect_true(any(abs(f0 / 8.97 - 1) < 0.01))
  expect_equal(unname(band_centre(rx)), 9.8, tolerance = 0.01)
  expect_equal(unname(coef(rx)["resonance1.tc"]), 0.4, tolerance = 0.1)
  expect_equal(n_reading(rx), n_reading(rb), tolerance = 0.01)
  # the step says how it entered, and the line is held at the raw data's
  # values (the curve does not judge it again)
  s <- rx$steps[rx$steps$effect == "sinusoid", ]
  expect_equal(nrow(s), 1L)
  expect_match(s$evidence, "in the reach of the resonance at 9[.][78]")
  expect_true(s$confirmed)
  # it carries at most a seventh of the model AV at any tau: placed where
  # its share is largest, not said to carry a quarter over the whole curve
  expect_match(s$evidence, "carries at most 1[0-9]% of the model AV, at tau = 0.04 s")
  expect_equal(s$tau_from, s$tau_to)
  # nothing else: the run without the line has the resonance alone
  expect_setequal(rx$terms, c(rb$terms, "sinusoid"))
})

test_that("a strong line beside a weak band enters at its measured amplitude, and the band stays", {
  skip_on_cran()
  # own generator: an MA(1) sensor filter, a weak 9.9 Hz two-pole band
  # (sd 0.002, tc 0.27 s), a random walk, and a line at 10.7 Hz of half
  # the white sd. Sized free on the curve the line took 11% more than its
  # amplitude and with it the band's power, and the band was lost (on
  # main 28eac03: N + K + filter + sinusoid, amp 0.00554)
  set.seed(2)
  freq <- 100
  n <- 5e5
  w <- rnorm(n + 1L, sd = 0.01)
  b <- w[-1L] + 0.25 * w[-(n + 1L)] + 0.002 * ar2_unit(n, 9.9, 0.27, freq) +
    cumsum(rnorm(n, sd = 2e-5))
  x <- b + 0.005 * sin(2 * pi * 10.7 * seq_len(n) / freq + 1)
  rb <- loop(b, freq)
  rx <- loop(x, freq)
  expect_true(any(abs(fitted_f0(rx) / 10.7 - 1) < 0.01))
  cf <- coef(rx)
  expect_equal(unname(cf[grepl("^sinusoid[0-9]+\\.amp$", names(cf))]), 0.005, tolerance = 0.03)
  expect_setequal(rx$terms, c(rb$terms, "sinusoid"))
  expect_equal(unname(band_centre(rx)), 9.9, tolerance = 0.02)
  expect_equal(unname(band_centre(rx)), unname(band_centre(rb)), tolerance = 0.01)
  expect_equal(n_reading(rx), n_reading(rb), tolerance = 0.01)
})

# a line of `amp` x the white sd at f0 Hz added to a measured axis beside
# its own band: the line named, the terms those of the run without it and
# the line, the band where it was and N within 1%; the run with the line
line_beside_axis_band <- function(unit, axis, amp, f0, phase) {
  ax <- measured_axis(unit, axis)
  r0 <- loop(ax$b, ax$freq)
  r <- loop(with_wave(ax, amp, f0, phase), ax$freq)
  expect_lte(min(abs(fitted_f0(r) / f0 - 1)), 0.01)
  expect_setequal(r$terms, c(r0$terms, "sinusoid"))
  expect_equal(unname(band_centre(r)), unname(band_centre(r0)), tolerance = 0.01)
  expect_lte(abs(n_reading(r) / n_reading(r0) - 1), 0.01)
  invisible(r)
}

test_that("a line beside a measured accelerometer's weak resonance: the resonance stays beside the line held at its amplitude", {
  # unit 3 accel_z carries a 9.84 Hz resonance of 1% of its variance; a
  # 9.13 Hz line of 0.42 x the white sd is added. With the line pinned at
  # its record amplitude the resonance lowered the criterion by 16 and
  # chi2 by a third, but carried 1.8% of the model AV (the line's AV in
  # the denominator) and was dropped as a refit artefact (on main 6bd0c80)
  skip_if_no_shared()
  skip_on_cran()
  line_beside_axis_band(3, "accel_z", 0.42, 9.13, 6.12)
})

test_that("a sawtooth beside a measured accelerometer's weak band: the resonance taken before the harmonics leaves when they are in", {
  # unit 3 accel_y carries a weak 8.17 Hz band beside its 9.85 Hz
  # resonance; the run without the wave leaves the weak one out. With a
  # 0.78 Hz sawtooth of 0.5 x the white sd added, a resonance pinned at
  # the weak band was taken before the harmonics at 7.8 and 8.58 Hz, took
  # their power on the curve, and, its values measured, was never judged
  # again (on main b296202: two resonances, N -0.3%)
  skip_if_no_shared()
  skip_on_cran()
  ax <- measured_axis(3, "accel_y")
  saw <- function(th) 2 * ((th / (2 * pi)) %% 1) - 1
  r0 <- loop(ax$b, ax$freq)
  r <- loop(with_wave(ax, 0.5, 0.78, 2, wave = saw), ax$freq)
  f0 <- fitted_f0(r)
  expect_true(all(c(0.78, 1.56, 2.34) %in% round(f0, 2)))
  expect_equal(sum(r$terms == "resonance"), sum(r0$terms == "resonance"))
  expect_setequal(r$terms, c(r0$terms, "sinusoid"))
  expect_lte(abs(n_reading(r) / n_reading(r0) - 1), 0.01)
})

test_that("a line a measured accelerometer's resonance took at step 2 is taken first on a revisit", {
  # unit 1 accel_y with an 8.46 Hz line of 0.32 x the white sd, 15% below
  # its 10 Hz resonance: the resonance, fitted at step 2, took the line's
  # power; the line at its periodogram values, the axis's own GM and
  # lines were refused beside it, and the loop ended at chi2/dof 211 with
  # N +5% (on main 9b7b4be). The revisit takes the line first.
  skip_if_no_shared()
  skip_on_cran()
  r <- line_beside_axis_band(1, "accel_y", 0.32, 8.46, 3.72)
  expect_true(isTRUE(r$refine$revisit$kept[2L]))
  expect_match(r$steps$evidence[1L], "taken first on a revisit")
  expect_lt(r$chi2 / r$df.residual, 4)
})
