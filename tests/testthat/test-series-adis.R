# detect_series_effects() on the measured ADIS16405 recordings (../shared/data;
# skipped without them). bench/adis16405/adis16405-study.md: the gyros y carry one
# sample 2.05 deg/s off (not an outlier of their own noise model); unit 1's
# accelerometers show transients (a knock, a tilt that returns) at 2154,
# 6817 and 7027 s on all three axes; no gyro has a bias step.

test_that("ADIS16405 unit 1 gyros: no bias step; the 2.05 deg/s sample is within the noise's own tail", {
  skip_if_no_shared()
  m <- readRDS(shared_file("adis16405_unit1.rds"))
  freq <- attr(m, "freq")
  for (axis in c("gyro_x", "gyro_y", "gyro_z")) {
    se <- detect_series_effects(m[, axis], freq)
    expect_false(any(se$table$kind %in% c("steps", "warmup")), label = axis)
  }
  # gyro_y's one sample 2.05 deg/s (41 LSB) above its running median is
  # 6.0 robust sd of that residual but an additive outlier of z 5.0 under
  # the axis's AR model (its noise is blue: lag-1 autocorrelation of the
  # differences -0.4), below the Bonferroni level over 1e6 samples (5.7),
  # and the record has a 5.4 elsewhere
  x <- m[, "gyro_y"]
  med <- stats::runmed(x, 7L, endrule = "median", algorithm = "Turlach")
  r <- x - med
  s <- robust_scale(r)
  at <- which.max(abs(r))
  expect_equal(r[at], 2.05, tolerance = 0.01)
  w <- seq_len(200000L)
  z <- spike_ao_z(x, med[w] + pmax(pmin(r[w], 4 * s), -4 * s))
  expect_lt(abs(z[at]), 5.73)
  expect_false(at %in% detect_spikes(x, freq)$index)
})

test_that("ADIS16405 unit 1 accel_z: the transient at 2154 s", {
  skip_if_no_shared()
  m <- readRDS(shared_file("adis16405_unit1.rds"))
  se <- detect_series_effects(m[, "accel_z"], attr(m, "freq"), remove = "spikes")
  tr <- se$table[se$table$kind == "transients", ]
  expect_gte(nrow(tr), 1L)
  expect_true(any(abs(tr$time - 2154) < 10))
  expect_true(all(abs(tr$size) > 0.001 & abs(tr$size) < 0.005))
  # its many outliers of 7-10 LSB (0.0033 g each) are the tail of the
  # axis's own heavy-tailed noise (a t body, spike_tail_level()): the
  # spikes are the few beyond it (two bursts in the first 7 s, 7-16 LSB),
  # none as large as a tenth of a g
  sp <- se$table[se$table$kind == "spikes", ]
  expect_gte(nrow(sp), 1L)
  expect_lte(nrow(sp), 8L)
  expect_true(all(abs(sp$size) > 6 * 0.00333 & abs(sp$size) < 0.1))
  expect_true(all(sp$removed))
  expect_false(any(se$table$kind %in% c("steps", "warmup")))
})

test_that("ADIS16405 unit 2 gyro_z: an added warm-up of tc 5% of the record is named within 25%", {
  skip_if_no_shared()
  skip_on_cran()
  m <- readRDS(shared_file("adis16405_unit2.rds"))
  freq <- attr(m, "freq")
  x <- m[, "gyro_z"]
  t <- (seq_along(x) - 1) / freq
  tc <- 0.05 * length(x) / freq
  amp <- 50 * allan(x, freq, taus = I(tc))$adev
  w <- detect_series_effects(x + amp * exp(-t / tc), freq, kinds = "warmup")$table
  expect_equal(nrow(w), 1L)
  expect_lt(abs(w$tc / tc - 1), 0.25)
})

test_that("ADIS16405 accelerometers: the spike count holds when white noise moves the scale 2%", {
  skip_if_no_shared()
  skip_on_cran()
  m <- readRDS(shared_file("adis16405_unit1.rds"))
  freq <- attr(m, "freq")
  set.seed(27)
  for (ax in c("accel_x", "accel_z")) {
    x <- m[, ax]
    sdw <- stats::sd(diff(x)) / sqrt(2)
    n0 <- nrow(detect_spikes(x, freq))
    n1 <- nrow(detect_spikes(x + rnorm(length(x), sd = sdw * sqrt(1.02^2 - 1)),
                             freq))
    # a level inside the heavy tail moved these counts 4-14% (tens of
    # samples on 20-80); beyond it they are a few and stay
    expect_lte(n0, 8L)
    expect_lte(abs(n1 - n0), 1L)
  }
})

# A Gauss-Markov series (own generator: an AR(1) by stats::filter) that
# raises the ADEV of `b` by about 45% at tau = tc (as bench/battery-loop.R
# sizes a GM on the measured axes; its AV at tau = tc is about 0.42 sigma^2).
gm_raising_adev <- function(b, freq, tc) {
  a <- allan(b, freq, taus = "octave")
  sigma <- sqrt(exp(stats::approx(log(a$tau), log(a$avar), log(tc))$y) * (1.45^2 - 1) / 0.42)
  phi <- exp(-1 / (freq * tc))
  w <- rnorm(length(b), sd = sigma * sqrt(1 - phi^2))
  w[1L] <- rnorm(1L, sd = sigma)
  as.numeric(stats::filter(w, phi, method = "recursive"))
}

test_that("ADIS16405 unit 1 accel_z: its transient at 2151 s stays a transient when a Gauss-Markov of tc 12 s is added", {
  skip_if_no_shared()
  m <- readRDS(shared_file("adis16405_unit1.rds"))
  freq <- attr(m, "freq")
  b <- as.numeric(m[, "accel_z"])
  kept <- 0L
  for (seed in 1:6) {
    set.seed(seed)
    x <- b + gm_raising_adev(b, freq, 12)
    tab <- detect_series_effects(x, freq)$table
    near <- abs(tab$time - 2152) < 10
    kept <- kept + (any(near & tab$kind == "transients") && !any(near & tab$kind == "steps"))
  }
  # the GM lengthened the window the onset was read over past the 120 s a
  # return is looked for in: the return went unseen and the pulse became a
  # lone step (a transient in 2 seeds of 6). Where the GM moves the level
  # across the pulse by half its size, it is a step (1 seed in 6).
  expect_gte(kept, 5L)
})

test_that("ADIS16405 unit 3 accel_x: its pulse at 1844 s stays a transient when a Gauss-Markov term leaves its two steps' sizes unlike", {
  skip_if_no_shared()
  m <- readRDS(shared_file("adis16405_unit3.rds"))
  freq <- attr(m, "freq")
  b <- as.numeric(m[, "accel_x"])
  # one of 162 runs of lines, square waves and GMs added to the 18 axes
  # (a GM of tc 12.3 s raising ADEV there by about 45%): both steps of the
  # pulse pass the record-wide threshold, the least-noisy window between
  # them is 4 s and their sizes read there are 0.0031 and 0.0010 (ratio
  # 0.31); the level comes back, so they are a transient, not two steps
  set.seed(3432)
  x <- b + gm_raising_adev(b, freq, exp(stats::runif(1, log(8), log(60))))
  tab <- detect_series_effects(x, freq)$table
  near <- abs(tab$time - 1850) < 25
  expect_true(any(near & tab$kind == "transients"))
  expect_false(any(near & tab$kind == "steps"))
})

test_that("ADIS16405 unit 1 accel_z: a slow Gauss-Markov term added leaves its spike count as it was", {
  skip_if_no_shared()
  m <- readRDS(shared_file("adis16405_unit1.rds"))
  freq <- attr(m, "freq")
  b <- as.numeric(m[, "accel_z"])
  n0 <- nrow(detect_spikes(b, freq))
  counts <- integer()
  for (seed in 1:3) {
    # slow against the 10 s the statistic's slow part is read over (a GM
    # of 1-5 s is local noise to it, and moves the level as noise does)
    for (tc in c(12, 60)) {
      set.seed(seed)
      counts <- c(counts, nrow(detect_spikes(b + gm_raising_adev(b, freq, tc), freq)))
    }
  }
  # judged with the slow part in, the GM lightened the statistic's tail
  # and the count went from 3 to 5 in 4 of these 6 runs
  expect_true(all(counts == n0))
})

test_that("ADIS16405 unit 2 accel_x: an added warm-up is named without a step at the axis's own level drop", {
  skip_if_no_shared()
  skip_on_cran()
  # the axis's level drops about 0.0035 at 272 s (z 5.8 to the step
  # detector, below its threshold). With a warm-up of tc 100-130 s added, its
  # misfit took the drop over the threshold, and the warm-up read again
  # with the "step" out bent to 81-137 s; the step judged beside the
  # warm-up by the warm-up's likelihood is not there
  m <- readRDS(shared_file("adis16405_unit2.rds"))
  freq <- attr(m, "freq")
  x <- m[, "accel_x"]
  t <- (seq_along(x) - 1) / freq
  expect_false(any(detect_series_effects(x, freq)$table$kind == "steps"))
  for (case in list(c(tc = 100, sign = 1), c(tc = 130, sign = -1))) {
    amp <- case[["sign"]] * 50 * allan(x, freq, taus = I(case[["tc"]]))$adev
    tb <- detect_series_effects(x + amp * exp(-t / case[["tc"]]), freq)$table
    expect_false(any(tb$kind == "steps"))
    w <- tb[tb$kind == "warmup", ]
    expect_equal(nrow(w), 1L)
    expect_lt(abs(w$tc / case[["tc"]] - 1), 0.15)
  }
})
