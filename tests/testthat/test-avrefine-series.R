# The loop beside the series pass: a term is not accepted for what the
# series pass found and left in the data. Own generators (white + random
# walk + an exponential warm-up, a first-order Gauss-Markov by recursion).

series_case <- function(seed, n = 5e5, freq = 100, gm_tc = NA, wu_tc = 60, wu = 0.1) {
  set.seed(seed)
  t <- (seq_len(n) - 1) / freq
  x <- rnorm(n, sd = 0.01 * sqrt(freq)) + cumsum(rnorm(n, sd = 1e-4 / sqrt(freq))) +
    wu * exp(-t / wu_tc)
  if (is.finite(gm_tc)) {
    a <- exp(-1 / (freq * gm_tc))
    x <- x + as.numeric(stats::filter(rnorm(n, sd = 0.01 * sqrt(1 - a^2)), a,
                                      method = "recursive"))
  }
  x
}

test_that("a warm-up left in the data is not described again by a GM term", {
  skip_on_cran()
  for (s in 1:2) {
    x <- series_case(s)
    fit <- avfit(allan(x, 100), terms = c("N", "B", "K"))
    ref <- suppressMessages(avrefine(fit, data = x))
    wu <- ref$series$table[ref$series$table$kind == "warmup", , drop = FALSE]
    expect_equal(nrow(wu), 1L)
    expect_lt(abs(wu$tc / 60 - 1), 0.25)
    # without the rule a GM of tc 33-48 s took the warm-up's place
    expect_false("gm" %in% ref$steps$effect)
    d <- ref$refine$series_duplicates
    expect_true(all(d$series_kind == "warmup"))
    expect_true("gm" %in% d$effect)
    expect_gte(max(d$ratio[d$how == "share"]), 1)
    expect_output(print(ref), "would describe the warmup left in the series")
    # removed in the series, there is nothing left to describe again
    rem <- suppressMessages(avrefine(fit, data = x, remove = "warmup"))
    expect_equal(NROW(rem$refine$series_duplicates), 0L)
    expect_lt(abs(stats::coef(rem)[["N"]] / 0.01 - 1), 0.05)
  }
})

test_that("a GM that pays only for a warm-up's excess is not accepted (refit without it)", {
  skip_on_cran()
  # white + flicker + random walk, 1e6 samples at 100 Hz, and a 60 s
  # warm-up of 50 x ADEV(60 s): the warm-up adds only a quarter of the
  # GM's AV at its peak (the GM, tc 145 s, also takes part of the flicker
  # floor), so the share rule lets it through; with the warm-up's excess
  # taken out of the curve the GM no longer pays
  set.seed(201)
  n <- 1e6
  t <- seq_len(n) / 100
  m <- 2 * n
  k <- c(0:(m / 2), -((m / 2 - 1):1))
  h <- ifelse(k == 0, 0, 1 / sqrt(abs(k)))
  fl <- Re(stats::fft(stats::fft(rnorm(m)) * h, inverse = TRUE))[1:n]
  b <- rnorm(n, sd = 0.01) + 2e-4 * fl / stats::sd(fl) + cumsum(rnorm(n, sd = 2e-5))
  a <- allan(b, 100, taus = "octave")
  ad60 <- exp(stats::approx(log(a$tau), log(a$adev), log(60))$y)
  x <- b + 50 * ad60 * exp(-t / 60)
  ref <- suppressWarnings(suppressMessages(
    avrefine(avfit(allan(x, 100), c("N", "B", "K")), data = x)))
  expect_false("gm" %in% ref$steps$effect)
  d <- ref$refine$series_duplicates
  expect_true(any(d$effect == "gm" & d$series_kind == "warmup" & d$how == "refit"))
  expect_true(all(d$ratio[d$how == "refit"] < 1))
  expect_match(ref$refine$rejected$reason, "pays only for the warmup", all = FALSE)
})

test_that("a genuine GM beside a slow warm-up stays (tc within 25%)", {
  skip_on_cran()
  x <- series_case(1, gm_tc = 2, wu_tc = 300, wu = 0.2)
  fit <- avfit(allan(x, 100), terms = c("N", "B", "K"))
  ref <- suppressMessages(avrefine(fit, data = x))
  expect_true("gm" %in% ref$steps$effect)
  expect_lt(abs(stats::coef(ref)[["gm1.tc"]] / 2 - 1), 0.25)
  expect_equal(NROW(ref$refine$series_duplicates), 0L)
})

test_that("series_duplicate() reads the series effect's AV against the term's", {
  # a term whose AV the series effect's excess matches is a duplicate; a
  # removed series effect, or none, never is
  tau <- 2^(0:6)
  fit <- list(data = list(tau = tau),
              components = cbind(N = 1 / tau, gm1 = c(0, 0.1, 1, 2, 1, 0.5, 0.2)))
  pass <- list(table = data.frame(kind = "warmup", removed = FALSE),
               adev_kinds = data.frame(kind = "warmup", tau = tau,
                                       before = sqrt(1 / tau + c(0, 0, 0.5, 1.5, 1, 0.4, 0.1)),
                                       after = sqrt(1 / tau)))
  d <- series_duplicate(pass, fit, "gm1", share = 0.7)
  expect_equal(d$series_kind, "warmup")
  expect_equal(d$tau, 8)
  expect_equal(d$ratio, 0.75)
  expect_null(series_duplicate(pass, fit, "gm1"))
  expect_equal(series_duplicate(pass, fit, "gm1", share = 0.5)$ratio, 0.75)
  pass$table$removed <- TRUE
  expect_null(series_duplicate(pass, fit, "gm1"))
  expect_null(series_duplicate(NULL, fit, "gm1"))
})

test_that("a long warm-up left in the data is not described again by a rate ramp", {
  skip_on_cran()
  # a warm-up of tc 10% of a 5000 s record: its tail reads as a linear
  # trend, and the fit lets R overshoot the last, sparse taus many times,
  # which hid its duplicate share before (R was added in every seed)
  for (s in 1:2) {
    set.seed(s)
    n <- 5e5
    t <- (seq_len(n) - 1) / 100
    x <- rnorm(n, sd = 0.01) + cumsum(rnorm(n, sd = 1e-5)) - 0.07 * exp(-t / 500)
    ref <- suppressMessages(avrefine(avfit(allan(x, 100), terms = c("N", "B", "K")), data = x))
    wu <- ref$series$table[ref$series$table$kind == "warmup", , drop = FALSE]
    expect_equal(nrow(wu), 1L)
    expect_lt(abs(wu$tc / 500 - 1), 0.25)
    expect_false("R" %in% ref$terms)
    # refused as the warm-up's duplicate, or (first) by the trend left
    # beside the warm-up, a fraction of the ramp the curve asks for
    rj <- ref$refine$rejected
    expect_true("R" %in% ref$refine$series_duplicates$effect ||
                  any(rj$effect == "R" & grepl("x below the fitted R", rj$reason)))
  }
})

test_that("a ramp must be backed by the trend left beside the series effects, at its size", {
  # white + random walk + a 900 s warm-up (18% of the record): the trend of
  # the block means is the warm-up's tail; fitted beside the warm-up's
  # shape it is a fraction of the ramp the curve asks for
  set.seed(2911)
  n <- 5e5
  t <- (seq_len(n) - 1) / 100
  b <- rnorm(n, sd = 0.01) + cumsum(rnorm(n, sd = 1e-4 / 10))
  x <- b - 0.08 * exp(-t / 900)
  pass <- detect_series_effects(x, 100)
  expect_true("warmup" %in% pass$table$kind)
  plain <- linear_trend(x, 100)
  beside <- linear_trend(x, 100, beside = series_shapes(pass, n, 100))
  expect_true(plain$significant)
  expect_lt(abs(beside$slope), abs(plain$slope) / 3)
  # a fitted R beyond 3x the raw slope is not backed; one within it is
  raw <- avdiagnose(x, 100)
  raw$trend <- beside
  ev_big <- evidence_trend(list(R = 5 * abs(beside$slope)), raw, x, 100)
  expect_false(ev_big$support)
  expect_match(ev_big$text, "x below the fitted R")
  # (the size rule alone: the trend taken as significant by both tests)
  raw$trend$significant <- TRUE
  raw$trend$z <- 10
  expect_true(evidence_trend(list(R = 2 * abs(beside$slope)), raw, x, 100)$support)
  # spikes move no block mean: they are not fitted beside the trend
  sp <- list(table = data.frame(kind = "spikes", index = 10L, time = 0.09, size = 1,
                                tc = NA, duration = NA, z = 9, removed = FALSE))
  expect_null(series_shapes(sp, n, 100)(n %/% 100))
  skip_on_cran()
  ref <- suppressMessages(avrefine(avfit(allan(x, 100), terms = c("N", "B", "K")), data = x))
  expect_false("R" %in% ref$terms)
})

test_that("a GM the raw data do not confirm must pay twice min_gain without the warm-up's excess", {
  # unit 2 accel_z has its own slow wander (a 255 s GM gains 13 on the
  # curve, unconfirmed: its block means' ACF reads 88 s, and is refused);
  # a downward 60 s warm-up of 50 x ADEV(60 s) added to it raised that
  # GM's gain over 2 min_gain, and with the warm-up's excess taken out it
  # still paid min_gain: a 152 s GM, unconfirmed, was accepted beside the
  # warm-up the series pass had named (on b66a8d2). (An upward one brings
  # a 130 s GM that the ACF confirms at 103 s: the axis's own process.)
  skip_if_no_shared()
  skip_on_cran()
  ax <- measured_axis(2, "accel_z")
  freq <- ax$freq
  ad60 <- allan(ax$b, freq, taus = I(60))$adev
  x <- ax$b - 50 * ad60 * exp(-(seq_along(ax$b) - 1) / freq / 60)
  ref <- suppressWarnings(suppressMessages(
    avrefine(avfit(allan(x, freq), terms = c("N", "B", "K")), data = x)))
  wu <- ref$series$table[ref$series$table$kind == "warmup", , drop = FALSE]
  expect_equal(nrow(wu), 1L)
  expect_lt(abs(wu$tc / 60 - 1), 0.25)
  expect_false("gm" %in% ref$steps$effect)
  d <- ref$refine$series_duplicates
  expect_true(any(d$effect == "gm" & d$series_kind == "warmup" & d$how == "refit"))
  # the rule is the unconfirmed one's: an instance the raw data decided,
  # or a curve-only run, needs min_gain only
  raw <- structure(list(), class = "refine_diagnostics")
  expect_true(rests_on_curve("gm", list(support = NA), raw))
  expect_false(rests_on_curve("gm", list(support = TRUE), raw))
  expect_false(rests_on_curve("gm", list(support = NA), NULL))
  expect_false(rests_on_curve("gm", list(support = FALSE), raw))
})

test_that("a bias step left in a measured axis is no GM's raw support", {
  # unit 2 accel_z with a step of 10 x its ADEV(10 s) at 1571 s. The axis
  # alone reads an exponential ACF of 88 s for a 255 s GM (undecided), and
  # the curve gains too little for one the raw data leave undecided; with
  # the step left in, the block means read 139 s (confirmed), and a 241 s
  # GM entered (main 48ab052). Without the step the support is gone: the
  # GM must pay twice min_gain on the curve without the step's excess.
  skip_if_no_shared()
  skip_on_cran()
  a <- measured_axis(2, "accel_z")
  n <- length(a$b)
  loop <- function(v) {
    suppressWarnings(suppressMessages(avrefine(avfit(allan(v, a$freq), terms = c("N", "B", "K")),
                                               data = v)))
  }
  r0 <- loop(a$b)
  expect_false("gm" %in% r0$terms)
  size <- 10 * allan(a$b, a$freq, taus = I(10))$adev
  r <- loop(a$b + size * ((seq_len(n) - 1) / a$freq >= 1571))
  st <- r$series$table[r$series$table$kind == "steps", , drop = FALSE]
  expect_lte(min(abs(st$time - 1571)), 2)
  expect_false("gm" %in% r$terms)
  d <- r$refine$series_duplicates
  expect_true(any(d$effect == "gm" & d$series_kind == "steps"))
})

test_that("a term the final model moves to where it stands in for the steps left in leaves", {
  # unit 3 accel_x with a 3.7 Hz line of 0.3 x its white noise's sd. The
  # axis alone refuses a 35 s GM as paying only for the steps the series
  # pass found (and left in). Beside the line a GM entered at 13 s (its
  # block means read 19 s), and the refits after it moved it to 35 s,
  # where that rule would have refused it: it stayed in the final model
  # (main d7dd14c). Its removal sized the measured 8.3-11.8 Hz band at
  # 1.05 x its power, beyond twice its 2.2% uncertainty: the band is held
  # at its measured power.
  skip_if_no_shared()
  skip_on_cran()
  a <- measured_axis(3, "accel_x")
  x <- a$b + 0.3 * a$s * sin(2 * pi * 3.7 * seq_along(a$b) / a$freq + 1)
  ref <- suppressWarnings(suppressMessages(
    avrefine(avfit(allan(x, a$freq), terms = c("N", "B", "K")), data = x)))
  expect_false("gm" %in% ref$terms)
  cf <- stats::coef(ref)
  f0 <- cf[grepl("^sinusoid[0-9]+\\.f0$", names(cf))]
  expect_lt(min(abs(f0 / 3.7 - 1)), 0.01)
  left <- ref$steps[startsWith(ref$steps$label, "left:"), , drop = FALSE]
  expect_equal(left$effect, "gm")
  expect_match(left$evidence, "left out at the end: pays only for the steps")
  d <- ref$refine$series_duplicates
  expect_true(any(d$effect == "gm" & d$series_kind == "steps" & d$how == "refit"))
  expect_false(any(ref$steps$confirmed %in% FALSE))
  # the band keeps the scale its raw-data check asks for
  expect_true("band1.amp" %in% names(cf))
  expect_lte(abs(log(cf[["band1.amp"]]^2)), 2 * cf[["band1.u"]])
})

test_that("a measured band sized off its power is held at it", {
  hold <- effect_entry("band")$raw_hold
  expect_null(hold(list(amp = sqrt(1.04), u = 0.022), NULL))
  h <- hold(list(amp = sqrt(1.053), u = 0.022), NULL)
  expect_equal(h$values, c(amp = 1))
  expect_match(h$note, "held at the measured band's power \\(the curve asked for 1.053 x it\\)")
  expect_false(is.null(hold(list(amp = sqrt(0.9), u = 0.022), NULL)))
})

test_that("values_moved() reads an instance's nonlinear values only", {
  expect_true(values_moved("gm", c(sigma = 4e-4, tc = 13.1), c(sigma = 3.6e-4, tc = 35.4)))
  expect_false(values_moved("gm", c(sigma = 4e-4, tc = 90.8), c(sigma = 4e-4, tc = 104)))
  # an amplitude is no value the instance moved to
  expect_false(values_moved("gm", c(sigma = 1e-4, tc = 84), c(sigma = 9e-4, tc = 84)))
  expect_true(values_moved("gm", NULL, c(sigma = 1e-4, tc = 84)))
  expect_false(values_moved("N", c(N = 1), c(N = 3)))
})

test_that("the steps table carries no row's record of its values", {
  row <- step_row("gm", "gm1", list(tau_from = 1, tau_to = 2), c(sigma = 1, tc = 2), "e", TRUE,
                  list(chi2 = 2, rms = 0.1), list(chi2 = 1, rms = 0.1), 10, 0)
  expect_equal(attr(row, "values"), c(sigma = 1, tc = 2))
  tab <- bind_steps(new_steps(), row)
  expect_null(attr(tab, "values"))
  expect_equal(tab$params, "sigma=1, tc=2 s")
})
