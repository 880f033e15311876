# The loop's rules for a filtered sensor with a resonance, on series from generators written here (not avsim): white noise
# through a second-order Butterworth low-pass (bilinear transform), a
# damped resonance as a real AR(2) with poles r exp(+-iw), a random walk.

# Second-order Butterworth low-pass at cutoff fc, unit DC gain.
butter2 <- function(e, fc, freq) {
  wc <- tan(pi * fc / freq)
  d <- 1 + sqrt(2) * wc + wc^2
  b <- wc^2 / d * c(1, 2, 1)
  a <- c(2 * (wc^2 - 1), 1 - sqrt(2) * wc + wc^2) / d
  u <- stats::filter(e, b, sides = 1L)[-(1:2)]
  as.numeric(stats::filter(u, -a, method = "recursive"))
}

# The loop as analyze_imu() runs it on an axis: N, B, K, then the raw series.
loop_raw <- function(v, freq) {
  suppressMessages(avrefine(avfit(allan(v, freq), terms = c("N", "B", "K")), data = v))
}

# White noise, a random walk and a resonance (`res`: amplitude, fr, tc of
# an own AR(2)), and the same with a band (`band`, likewise) added: the
# loop on each, r0 without and r1 with the band.
loop_band_beside <- function(n, freq, res, band) {
  base <- stats::rnorm(n, sd = 0.01) + cumsum(stats::rnorm(n, sd = 1e-5)) +
    res[[1L]] * ar2_unit(n, res[[2L]], res[[3L]], freq)
  x <- base + band[[1L]] * ar2_unit(n, band[[2L]], band[[3L]], freq)
  list(r0 = loop_raw(base, freq), r1 = loop_raw(x, freq))
}

# AR(2) resonance at fr with damping time tc (innovation sd s).
ar2_resonance <- function(n, fr, tc, s, freq) {
  r <- exp(-1 / (freq * tc))
  w <- 2 * pi * fr / freq
  z <- stats::filter(stats::rnorm(n + 2000L, sd = s), c(2 * r * cos(w), -r^2),
                     method = "recursive")
  as.numeric(z[-(1:2000)])
}

test_that("remove_bands takes a resonance's excess out and keeps the white noise", {
  set.seed(11)
  n <- 2^17
  freq <- 100
  w <- stats::rnorm(n)
  x <- w + ar2_resonance(n, 15, 0.3, 0.3, freq)
  b <- find_bands(x, freq)
  expect_equal(nrow(b), 1L)
  y <- remove_bands(x, freq, b)
  expect_equal(nrow(find_bands(y, freq)), 0L)
  # what is left is (nearly) the white noise: its variance and a lag-1 ACF
  # near 0, where the resonance alone gives a strongly positive one
  r1 <- function(v) stats::acf(v, lag.max = 1, plot = FALSE)$acf[2]
  expect_gt(r1(x), 0.2)
  expect_lt(abs(r1(y)), 0.03)
  expect_equal(stats::var(y), stats::var(w), tolerance = 0.1)
  # no band: the series is returned unchanged
  expect_identical(remove_bands(w, freq, b[0, ]), w)
  # a record of prime length (2^17 - 1) is transformed zero-padded: the
  # same band comes out, the length is kept, and the last samples (beside
  # the pad) are as white as the rest
  p <- n - 1L
  yp <- remove_bands(x[seq_len(p)], freq, b)
  expect_length(yp, p)
  expect_equal(nrow(find_bands(yp, freq)), 0L)
  expect_lt(abs(r1(yp)), 0.03)
  expect_equal(stats::var(yp[(p - 999L):p]), stats::var(w[(p - 999L):p]), tolerance = 0.15)
  expect_equal(yp[1:1000], y[1:1000], tolerance = 0.02)
})

test_that("remove_bands takes out a wide band whose run reaches far (no background 3-6 run widths away)", {
  # at 100 Hz a 21 Hz band with tc = 0.1 s makes a run of about 11-29 Hz:
  # 3-6 run widths from its centre lie outside 0..50 Hz; the band was left
  # in the series (lag-1 ACF unchanged)
  set.seed(12)
  n <- 2^18
  freq <- 100
  w <- stats::rnorm(n)
  z <- ar2_resonance(n, 21, 0.1, 1, freq)
  x <- w + z / stats::sd(z)
  b <- find_bands(x, freq)
  expect_equal(nrow(b), 1L)
  expect_gt(b$f_to - b$f_from, 50 / 6)
  # the fitted AR(2) form recovers the band's variance and damping
  expect_equal(b$power, 1, tolerance = 0.1)
  expect_equal(b$tc, 0.1, tolerance = 0.15)
  y <- remove_bands(x, freq, b)
  r1 <- function(v) stats::acf(v, lag.max = 1, plot = FALSE)$acf[2]
  expect_gt(r1(x), 0.05)
  expect_lt(abs(r1(y)), 0.01)
  expect_equal(nrow(find_bands(y, freq)), 0L)
  expect_equal(stats::var(y), stats::var(w), tolerance = 0.05)
})

test_that("a filtered sensor with a resonance: the low-pass family, the band's centre, no slow sinusoid", {
  skip_on_cran()
  set.seed(3)
  n <- 2e5
  freq <- 100
  N <- 0.05
  e <- stats::rnorm(n + 2L, sd = N * sqrt(freq))
  x <- butter2(e, 20, freq) + ar2_resonance(n, 15, 0.3, 0.1, freq) +
    cumsum(stats::rnorm(n, sd = 1e-4))
  fit <- avfit(allan(x, freq, taus = 10, type = "overlapping"), terms = c("N", "B", "K"))
  ref <- suppressMessages(avrefine(fit, data = x, max_steps = 4))
  st <- ref$steps
  cf <- stats::coef(ref)
  # the filter term, as a low-pass family with its cutoff within 10%, and
  # the white level at DC within 10%
  expect_true(any(grepl("^filter", ref$terms)))
  expect_true("filter:lp2" %in% ref$terms)
  expect_equal(unname(cf[["filter_lp2.fc"]]), 20, tolerance = 0.1)
  expect_equal(unname(cf[["filter_lp2.Nf"]]), N, tolerance = 0.1)
  # the resonance, its centre pinned within the periodogram's resolution
  expect_true("resonance" %in% st$effect)
  expect_lt(abs(cf[["resonance1.fr"]] - 15), 0.2)
  # every step is confirmed by the raw data; no sinusoid stands in for the
  # random walk at the long-tau end
  expect_false(any(st$confirmed %in% FALSE))
  expect_false("sinusoid" %in% st$effect)
})

test_that("a sensor's two-pole recursive filter is the all-pole section, at another rate", {
  skip_on_cran()
  set.seed(21)
  n <- 2e5
  freq <- 200
  # white noise through y = w + 0.5 y[-1] - 0.15 y[-2] (complex poles: fn =
  # 0.2048 freq, zeta = 0.737; DC gain 1 / 0.65), and a random walk
  s <- 0.02
  x <- as.numeric(stats::filter(stats::rnorm(n + 100L, sd = s), c(0.5, -0.15),
                                method = "recursive"))[-(1:100)] +
    cumsum(stats::rnorm(n, sd = 1e-4 / sqrt(freq)))
  N <- s / sqrt(freq) / 0.65
  ref <- loop_raw(x, freq)
  cf <- stats::coef(ref)
  expect_true("filter:ar2" %in% ref$terms)
  expect_equal(unname(cf[["filter_ar2.fn"]]), 0.2048 * freq, tolerance = 0.1)
  expect_equal(unname(cf[["filter_ar2.zeta"]]), 0.737, tolerance = 0.15)
  expect_equal(unname(cf[["filter_ar2.Nf"]]), N, tolerance = 0.03)
  expect_lt(ref$chi2, 2)
  expect_false(any(ref$steps$confirmed %in% FALSE))
})

test_that("a moving average over a sample and a bit is not read as a two-pole section", {
  skip_on_cran()
  set.seed(22)
  n <- 2e5
  freq <- 100
  # taps 0.55, 0.45 (lag-2 autocorrelation 0), a random walk and a line
  x <- as.numeric(stats::filter(stats::rnorm(n + 1L, sd = 0.01), c(0.55, 0.45),
                                sides = 1L))[-1L] +
    cumsum(stats::rnorm(n, sd = 1e-5)) + 0.004 * sin(2 * pi * 0.55 * seq_len(n) / freq)
  ref <- loop_raw(x, freq)
  fl <- ref$terms[startsWith(ref$terms, "filter")]
  expect_length(fl, 1L)
  expect_false(fl == "filter:ar2")
  expect_false(any(ref$steps$confirmed %in% FALSE))
})

test_that("with raw data, a sinusoid within 4 periodogram bins of DC is not taken", {
  set.seed(5)
  n <- 1e5
  freq <- 100
  x <- cumsum(stats::rnorm(n, sd = 0.01)) + stats::rnorm(n)
  raw <- avdiagnose(x, freq)
  res <- attr(raw$lines, "resolution")
  ev <- evidence_sinusoid(list(amp = 1, f0 = 2 * res), raw, x, freq)
  expect_false(ev$support)
  expect_match(ev$text, "within 4 bins")
  # a real line well above DC is still confirmed
  y <- x + 0.5 * sin(2 * pi * 3 * (seq_len(n) - 1) / freq)
  raw2 <- avdiagnose(y, freq)
  expect_true(evidence_sinusoid(list(amp = 0.5, f0 = 3), raw2, y, freq)$support)
})

test_that("a weak narrow band (below 2x its background): a resonance at the band's centre and width, not a tone", {
  skip_on_cran()
  # a 10 Hz band 0.6 Hz wide (tc = 0.5 s) carrying under 1% of the variance
  # over a 4-tap moving average: the case the old fixed 2x threshold missed
  # and a free damping time turned into a tone
  set.seed(21)
  n <- 4e5
  freq <- 100
  N <- 0.05
  e <- stats::rnorm(n + 3L, sd = N * sqrt(freq))
  z <- ar2_resonance(n, 10, 0.5, 1, freq)
  x <- stats::filter(e, rep(0.25, 4), sides = 1L)[-(1:3)] +
    0.08 * N * sqrt(freq) * z / stats::sd(z) + cumsum(stats::rnorm(n, sd = 1e-4))
  b <- find_bands(x, freq)
  expect_equal(nrow(b), 1L)
  expect_lt(b$peak_ratio, 2)
  fit <- avfit(allan(x, freq, taus = 10, type = "overlapping"), terms = c("N", "B", "K"))
  ref <- suppressMessages(avrefine(fit, data = x, max_steps = 4))
  cf <- stats::coef(ref)
  expect_true("resonance" %in% ref$steps$effect)
  expect_lt(abs(cf[["resonance1.fr"]] - 10), attr(b, "resolution"))
  # its width 1/(pi tc) within 3x of the band's, not a tone
  expect_lt(abs(log(cf[["resonance1.tc"]] / 0.5)), log(3))
  expect_false(any(ref$steps$confirmed %in% FALSE))
  expect_false(any(abs(cf[grepl("\\.f0$", names(cf))] - 10) < 1))
})

test_that("a band proposes its resonance pinned, released from its values only", {
  set.seed(12)
  n <- 2^17
  freq <- 100
  x <- stats::rnorm(n) + ar2_resonance(n, 15, 0.3, 0.3, freq)
  fit <- avfit(allan(x, freq), terms = c("N", "K"))
  raw <- refine_diagnostics(x, freq)
  b <- diag_part(raw, "bands")
  expect_equal(nrow(b), 1L)
  p <- effect_entry("resonance")$propose(raw, fit$data$tau, NULL)
  expect_length(p, 1L)
  expect_identical(p[[1]]$pin, list(fr = b$f_center, tc = b$tc))
  expect_true(isTRUE(p[[1]]$release))
  # the release is one search from the pinned values; without `local` the
  # search over the whole range runs first
  log <- new.env()
  log$stages <- character()
  suppressMessages(trace("try_refit", where = asNamespace("allanvar"), print = FALSE,
                         tracer = bquote(assign("stages", c(get("stages", envir = .(log)), stage), envir = .(log)))))
  on.exit(suppressMessages(untrace("try_refit", where = asNamespace("allanvar"))),
          add = TRUE)
  settings <- refit_settings(fit, list())
  loc <- refit_with(fit, c(fit$terms, "resonance"), "resonance", p[[1]]$pin,
                    settings, local = TRUE)
  expect_identical(log$stages, "screen from the traced start")
  log$stages <- character()
  both <- refit_with(fit, c(fit$terms, "resonance"), "resonance", p[[1]]$pin, settings)
  expect_identical(log$stages[1], "screen")
  # from the band's values the search finds the band
  expect_lt(abs(stats::coef(loc$fit)[["resonance1.fr"]] - 15), 0.3)
  expect_lte(both$fit$objective, loc$fit$objective * (1 + 1e-8))
})

test_that("a band beside a resonance: no filter term, N within 5% of the run without the band", {
  # white + a 18 Hz resonance (AR(2)), then a 7 Hz band (AR(2)) added: the
  # resonance's skirt, left by a Lorentzian description, was taken for a
  # sensor filter that carried the white noise (N +12-14% on seeds 1-3)
  skip_on_cran()
  set.seed(1)
  runs <- loop_band_beside(2e5, 100, res = c(0.01, 18, 0.1), band = c(0.006, 7, 0.3))
  r0 <- runs$r0
  r1 <- runs$r1
  expect_false(any(grepl("^filter", r1$terms)))
  expect_true("N" %in% r0$terms && "N" %in% r1$terms)
  expect_equal(unname(coef(r1)[["N"]]), unname(coef(r0)[["N"]]), tolerance = 0.05)
  # the added band is named (a resonance within 5% of 7 Hz)
  fr <- coef(r1)[grepl("^resonance[0-9]*\\.fr$", names(coef(r1)))]
  expect_true(any(abs(fr / 7 - 1) < 0.05))
})

test_that("a sensor's resonance taken first as a measured band is described again as a resonance; the filter's form beside it", {
  # a simulated sensor axis: white noise through a short moving average
  # (weights 1, 0.25), a two-pole resonance at 9.85 Hz, a 0.54 Hz line and
  # a random walk. The first step took the band the raw spectrum measured
  # (its run 2.6-13.8 Hz), which leaves the resonance's skirt to the
  # background; a first-order low-pass then fitted that skirt and stayed
  # (on main 2529cae: N +16% against the generating 1.25e-3)
  set.seed(1)
  freq <- 100
  n <- 5e5
  x <- sim_sensor_axis(n, freq)
  fit <- avfit(allan(x, freq), terms = c("N", "B", "K"))
  res <- suppressMessages(avrefine(fit, data = x))
  cf <- coef(res)
  # the white level at DC: 1.25 x 0.01 x sqrt(1 / freq)
  nf <- cf[grepl("^filter[^.]*\\.Nf$", names(cf))]
  expect_length(nf, 1L)
  expect_lte(abs(nf / 1.25e-3 - 1), 0.05)
  expect_true("resonance" %in% res$terms)
  expect_lte(abs(cf[["resonance1.fr"]] / 9.85 - 1), 0.02)
  expect_false(any(res$steps$confirmed %in% FALSE))
  expect_lt(res$chi2, 4)
})

test_that("a band added beside a sensor's resonance in one run: two resonances, the axis's kept where the raw data measure it", {
  # white noise, a random walk and a 9.86 Hz resonance (AR(2), tc 0.47 s);
  # an 8.1 Hz band (tc 0.3 s) added makes one run of the spectrum with
  # both. Released at once, the first resonance in spread over the second
  # (one resonance at 8.25 Hz, the axis's own lost; on main 2e5d30c).
  skip_on_cran()
  set.seed(1)
  runs <- loop_band_beside(5e5, 100, res = c(0.002, 9.86, 0.47), band = c(0.005, 8.1, 0.3))
  r0 <- runs$r0
  r1 <- runs$r1
  fr <- coef(r1)[grepl("^resonance[0-9]*\\.fr$", names(coef(r1)))]
  expect_length(fr, 2L)
  expect_equal(sort(unname(fr)), c(8.1, 9.86), tolerance = 0.03)
  expect_equal(unname(coef(r1)[["N"]]), unname(coef(r0)[["N"]]), tolerance = 0.05)
  expect_false(any(r1$steps$confirmed %in% FALSE))
  expect_lt(r1$chi2, 2)
})

test_that("a band added beside a measured accelerometer's own resonance: both named, the filter's form and N kept", {
  # unit 3 accel_x carries a moving-average filter, a 0.54 Hz line and a
  # 9.86 Hz resonance; an 8.1 Hz band (own AR(2), 0.5 x the white sd)
  # makes one run of 3-12 Hz with it. One resonance fitted to the run sat
  # at 8.14 Hz and the loop ended at chi2/dof 25.7, its own resonance and
  # its 1.52 Hz line lost (on main 2e5d30c)
  skip_if_no_shared()
  skip_on_cran()
  m <- readRDS(shared_file("adis16405_unit3.rds"))
  b <- as.numeric(m[, "accel_x"])
  freq <- attr(m, "freq")
  set.seed(5)
  n <- length(b)
  x <- b + 0.5 * stats::sd(diff(b)) / sqrt(2) * ar2_unit(n, 8.1, 0.3, freq)
  r0 <- loop_raw(b, freq)
  r1 <- loop_raw(x, freq)
  fr <- coef(r1)[grepl("^resonance[0-9]*\\.fr$", names(coef(r1)))]
  expect_true(any(abs(fr / 8.1 - 1) < 0.05))
  expect_true(any(abs(fr / 9.86 - 1) < 0.05))
  nf <- function(r) unname(coef(r)[grepl("^filter[^.]*\\.Nf$", names(coef(r)))])
  expect_equal(nf(r1), nf(r0), tolerance = 0.05)
  expect_identical(r1$terms[startsWith(r1$terms, "filter")], r0$terms[startsWith(r0$terms, "filter")])
  expect_false(any(r1$steps$confirmed %in% FALSE))
  expect_lt(r1$chi2, 4)
})

test_that("a band added to a measured accelerometer: the filter's form chosen again before the band's measure takes the resonance's place", {
  # unit 3 accel_z carries a moving-average filter, a 0.54 Hz line with a
  # weak third harmonic and a 9.84 Hz resonance (1% of its variance); a
  # 7.9 Hz band (own AR(2), 0.5 x the white sd) is added. Beside the band's
  # resonance held at its step-1 values a first-order low-pass beats the
  # moving average; the form was to be chosen again once the 0.54 Hz line
  # was in, but waited while the line's harmonic was a trial of the step,
  # and the harmonic never paid: the measured band of 4-10 Hz took the
  # resonance's place first, beside which the low-pass won (N +7.4-7.6% in
  # 4 of seeds 1-6, the harmonic lost; on main 8eb3ca2)
  skip_if_no_shared()
  skip_on_cran()
  a <- measured_axis(3, "accel_z")
  n <- length(a$b)
  nf <- function(r) unname(coef(r)[grepl("^filter[^.]*\\.Nf$", names(coef(r)))])
  r0 <- loop_raw(a$b, a$freq)
  for (seed in c(2L, 4L)) {
    set.seed(seed)
    r1 <- loop_raw(a$b + 0.5 * a$s * ar2_unit(n, 7.9, 0.3, a$freq), a$freq)
    expect_identical(r1$terms[startsWith(r1$terms, "filter")], r0$terms[startsWith(r0$terms, "filter")])
    expect_equal(nf(r1), nf(r0), tolerance = 0.05)
    fr <- coef(r1)[grepl("^resonance[0-9]*\\.fr$", names(coef(r1)))]
    expect_true(any(abs(fr / 7.9 - 1) < 0.05))
    f0 <- coef(r1)[grepl("^sinusoid[0-9]*\\.f0$", names(coef(r1)))]
    expect_true(any(abs(f0 - 1.618) < 0.01))
  }
})

test_that("a resonance the curve makes far narrower than its raw band is held at the band's centre and width", {
  # hold_resonance() on a band of own data (an AR(2) at 13 Hz, tc 0.3 s):
  # sized within a factor 2 of the band's width, nothing to hold; twice as
  # narrow or as wide, held at the band's fr and tc
  set.seed(2)
  freq <- 100
  n <- 2e5
  x <- stats::rnorm(n, sd = 0.01) + 0.006 * ar2_unit(n, 13, 0.3, freq)
  raw <- allanvar:::refine_diagnostics(x, freq)
  hold <- allanvar:::hold_resonance
  expect_null(hold(c(sigma = 0.006, fr = 13, tc = 0.3), raw))
  expect_null(hold(c(sigma = 0.006, fr = 13, tc = 0.45), raw))
  h <- hold(c(sigma = 0.006, fr = 13.3, tc = 0.7), raw)
  expect_equal(h$values[["fr"]], 13, tolerance = 0.01)
  expect_equal(h$values[["tc"]], 0.3, tolerance = 0.2)
  expect_match(h$note, "fr and tc held at the spectral band's 1[23][.][0-9]+ Hz and 0[.][0-9]+ s \\(the curve put tc at 0.7 s\\)")
  expect_identical(names(hold(c(sigma = 0.006, fr = 13, tc = 0.1), raw)$values), c("fr", "tc"))
  # far from any band: nothing
  expect_null(hold(c(sigma = 0.006, fr = 40, tc = 0.7), raw))
  skip_on_cran()
  # the loop: white, a walk and a 27 Hz resonance, a 13 Hz band added.
  # Beside the 27 Hz one the curve ran the 13 Hz resonance's tc to 0.61 s
  # at 13.3 Hz (seed 4), twice as narrow as its band
  set.seed(4)
  runs <- loop_band_beside(5e5, 100, res = c(0.01, 27, 0.1), band = c(0.006, 13, 0.3))
  cf <- coef(runs$r1)
  fr <- cf[grepl("^resonance[0-9]*\\.fr$", names(cf))]
  j <- which.min(abs(fr - 13))
  expect_equal(unname(fr[j]), 13, tolerance = 0.01)
  expect_equal(unname(cf[[sub("fr$", "tc", names(fr)[j])]]), 0.3, tolerance = 0.25)
  expect_equal(unname(cf[["N"]]), unname(coef(runs$r0)[["N"]]), tolerance = 0.05)
})

test_that("a band beside a resonance the model lacks both: the two enter together at their raw values", {
  # white, a walk, a 26 Hz resonance (tc 0.15 s, the white sd) and a 7.9 Hz
  # band (tc 0.3 s, 0.6 x). Alone, the 26 Hz one was fitted at half its
  # measured power (the curve's short end carries both) and the 7.9 Hz one
  # raised chi2: the loop took nothing and ended at N, B, K, chi2/dof
  # 1360-1410, N +58% (main 48ab052, seeds 1-4)
  skip_on_cran()
  set.seed(2)
  runs <- loop_band_beside(5e5, 100, res = c(0.01, 26, 0.15), band = c(0.006, 7.9, 0.3))
  cf <- coef(runs$r1)
  fr <- cf[grepl("^resonance[0-9]*\\.fr$", names(cf))]
  expect_lte(min(abs(fr / 7.9 - 1)), 0.05)
  expect_lte(min(abs(fr / 26 - 1)), 0.05)
  expect_equal(unname(cf[["N"]]), unname(coef(runs$r0)[["N"]]), tolerance = 0.05)
  expect_lt(runs$r1$chi2, 4)
  expect_match(runs$r1$steps$evidence, "taken together \\(neither paid alone\\)", all = FALSE)
})

test_that("a band added to a measured accelerometer: the pair of bands enters beside the filter's form chosen again", {
  # unit 2 accel_x (a moving average, a 9.95 Hz resonance) with a 28.2 Hz
  # band (own AR(2), tc 0.3 s, 0.5 x the white sd). A second-order
  # low-pass at 45 Hz took both bands' power before either was in; then
  # each resonance alone, and each beside the moving average, was refused:
  # the loop ended at chi2/dof 75, N +6.7% (main 48ab052)
  skip_if_no_shared()
  skip_on_cran()
  a <- measured_axis(2, "accel_x")
  nf <- function(r) unname(coef(r)[grepl("^filter[^.]*\\.Nf$", names(coef(r)))])
  r0 <- loop_raw(a$b, a$freq)
  set.seed(1)
  r1 <- loop_raw(a$b + 0.5 * a$s * ar2_unit(length(a$b), 28.2, 0.3, a$freq), a$freq)
  # (the axis alone takes the two-pole section at 35 Hz; beside the added
  # band the moving average, chosen again beside the two resonances, ends
  # at the same white level)
  expect_false("filter:lp2" %in% r1$terms)
  expect_equal(nf(r1), nf(r0), tolerance = 0.05)
  fr <- coef(r1)[grepl("^resonance[0-9]*\\.fr$", names(coef(r1)))]
  expect_true(any(abs(fr / 28.2 - 1) < 0.05))
  expect_lt(r1$chi2, 4)
})

test_that("a line near Nyquist added to a two-pole sensor with a resonance: N within 5% of the run without it", {
  # white noise through y = w + 0.5 y[-1] - 0.15 y[-2], a 9.8 Hz resonance
  # (own AR(2), tc 0.4 s), a 0.52 Hz line and a random walk, then a 44.16
  # Hz line at 0.7 x the white sd. The line, not yet in the model at step
  # 1, let a measured band take the resonance's place and a moving average
  # the filter's; the raw short-lag autocovariance steps were off at
  # chi-square 139 and N read 7.1% high (main 9148074; 4 of 4 seeds above
  # 5%). The resonance is described again where those steps say so.
  skip_on_cran()
  set.seed(1)
  freq <- 100
  n <- 5e5
  s <- 0.0131
  w <- as.numeric(stats::filter(stats::rnorm(n + 100, sd = s), c(0.5, -0.15),
                                method = "recursive"))[-(1:100)]
  b <- w + 0.8 * s * ar2_unit(n, 9.8, 0.4, freq) +
    0.9 * s * sin(2 * pi * 0.52 * seq_len(n) / freq + stats::runif(1, 0, 2 * pi)) +
    cumsum(stats::rnorm(n, sd = 6e-5 / sqrt(freq)))
  x <- b + 0.7 * s * sin(2 * pi * 44.16 * seq_len(n) / freq + stats::runif(1, 0, 2 * pi))
  nf <- function(r) unname(coef(r)[grepl("^filter[^.]*\\.Nf$", names(coef(r)))])
  r0 <- loop_raw(b, freq)
  r1 <- loop_raw(x, freq)
  expect_equal(nf(r1), nf(r0), tolerance = 0.05)
  f0 <- coef(r1)[grepl("^sinusoid[0-9]*\\.f0$", names(coef(r1)))]
  expect_true(any(abs(f0 / 44.16 - 1) < 0.01))
  expect_true("resonance" %in% r1$terms)
  expect_lt(r1$chi2, 2)
})
