# Verdicts of the readings (R/verdicts.R), from simulated records of our own
# generator (white noise N and rate random walk K, in rad/s at f Hz: white
# sd N sqrt(f), walk increments K / sqrt(f); IEEE 952 coefficients).

white_walk <- function(n, f, N, K, seed) {
  set.seed(seed)
  N * sqrt(f) * rnorm(n) + cumsum(K / sqrt(f) * rnorm(n))
}

test_that("a bias step left in marks K with its effect; removed, K is within 20% of the truth", {
  skip_on_cran()
  f <- 100
  N <- 1e-3
  K <- 2e-5
  n <- 2e5
  x <- white_walk(n, f, N, K, seed = 5)
  x[(n / 2 + 1):n] <- x[(n / 2 + 1):n] + 0.01     # a step at 1000 s
  r <- imu_record(cbind(gyro_x = x), freq = f, units = "rad/s")
  a <- suppressWarnings(analyze_imu(r, progress = FALSE))
  k <- reading_of(a$channels$gyro_x$readings, "random_walk")
  # the step is named, its effect on K given, and K is not "measured"
  expect_match(k$biased_by, "steps")
  expect_gt(k$bias_change, 1)
  expect_false(k$verdict == "measured")
  expect_match(k$why, "remove = \"steps\"", fixed = TRUE)
  # every file says the same
  ds <- datasheet(a)$long
  expect_identical(unique(ds$verdict[ds$term == "K"]), k$verdict)
  f_yaml <- tempfile(fileext = ".yaml")
  on.exit(unlink(f_yaml))
  write_kalibr_yaml(a, f_yaml)
  y <- readLines(f_yaml)
  expect_match(y[startsWith(y, "gyroscope_random_walk:")],
               toupper(verdict_label(k$verdict)), fixed = TRUE)
  tp <- tool_params(a, "openvins")
  expect_identical(tp$verdict[tp$key == "gyroscope_random_walk"], k$verdict)
  # with the step removed: the corrected readings, within 20% of the truth
  b <- suppressWarnings(analyze_imu(r, progress = FALSE, remove = "steps"))
  kb <- reading_of(b$channels$gyro_x$readings, "random_walk")
  expect_equal(kb$value, K, tolerance = 0.2)
  expect_identical(kb$verdict, "measured")
  expect_identical(kb$removed, "steps")
  expect_identical(kb$biased_by, "")
})

test_that("without the loop, B is a bound when the flat minimum lies beyond the reliable taus", {
  f <- 100
  x <- white_walk(2e4, f, 1e-3, 0, seed = 2)
  r <- imu_record(cbind(gyro_x = x), freq = f, units = "rad/s")
  a <- suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE))
  rd <- a$channels$gyro_x$readings
  b <- reading_of(rd, "flicker")
  expect_identical(b$verdict, "upper_bound")
  expect_match(b$why, "flat minimum is not reached")
  # white noise alone: N measured, within 5% of the truth
  nn <- reading_of(rd, "white")
  expect_identical(nn$verdict, "measured")
  expect_equal(nn$value, 1e-3, tolerance = 0.05)
})

test_that("a true model is not rejected by chance: N and K measured on N + K records", {
  skip_on_cran()
  f <- 100
  verdicts <- vapply(1:4, function(seed) {
    x <- white_walk(2e5, f, 1e-3, 1e-4, seed = 100 + seed)
    r <- imu_record(cbind(gyro_x = x), freq = f, units = "rad/s")
    a <- suppressWarnings(analyze_imu(r, terms = c("N", "K"), refine = FALSE,
                                      progress = FALSE))
    rd <- a$channels$gyro_x$readings
    paste(rd$verdict[rd$term %in% c("N", "K")], collapse = ",")
  }, "")
  expect_identical(verdicts, rep("measured,measured", 4L))
})

test_that("judge_span(): the model outside the joint limits makes a bound, with the side", {
  tau <- 2^(0:9)
  edf <- rep(50, 10)
  cv <- data.frame(tau = tau, adev = 1 / sqrt(tau), edf = edf)
  cv$lower <- cv$adev * sqrt(edf / stats::qchisq(0.8415, edf))
  cv$upper <- cv$adev * sqrt(edf / stats::qchisq(0.1585, edf))
  ctx <- list(curve = cv, ok = rep(TRUE, 10), rel = rep(TRUE, 10), limits = TRUE)
  e <- reading_entry("white")
  r <- data.frame(term = "N", value = 1)
  span <- rep(TRUE, 10)
  expect_identical(judge_span(r, e, span, cv$adev, ctx)$verdict, "measured")
  # 1.5x above at one point of 50 EDF: far outside its limits
  m <- cv$adev
  m[8] <- 1.5 * m[8]
  v <- judge_span(r, e, span, m, ctx)
  expect_identical(v$verdict, "upper_bound")
  expect_match(v$why, "up to 1.5x")
  m[3] <- 0.5 * m[3]
  expect_identical(judge_span(r, e, span, m, ctx)$verdict, "not_determined")
  expect_identical(judge_span(r, e, span, cv$adev * 0.6, ctx)$verdict, "lower_bound")
  # limits at 68% point by point would reject a model 1.2 sd off at one of
  # ten points; the joint 95% limits do not
  m <- cv$adev
  m[5] <- cv$upper[5] * 1.05
  expect_identical(judge_span(r, e, span, m, ctx)$verdict, "measured")
})

# A curve of white noise N and rate random walk K by hand (IEEE 952:
# N^2/tau + K^2 tau/3; they cross at sqrt(3) N/K = 17 s), overlapping-AV
# EDF falling to 3 at the longest tau, 68% limits from it; `raise` scales
# the ADEV of the points in [from, to].
nk_curve <- function(N = 1e-3, K = 1e-4, raise = 1, from = Inf, to = Inf) {
  tau <- 0.01 * 2^(0:16)
  edf <- 2e5 * 0.01 / tau
  adev <- sqrt(N^2 / tau + K^2 * tau / 3)
  inr <- tau >= from & tau <= to
  adev[inr] <- adev[inr] * raise
  data.frame(tau = tau, m = tau / 0.01, avar = adev^2, adev = adev,
             lower = adev * sqrt(edf / stats::qchisq(0.8415, edf)),
             upper = adev * sqrt(edf / stats::qchisq(0.1585, edf)), edf = edf)
}
runs <- function(from, to, kind = "long_end") {
  data.frame(kind = kind, tau_from = from, tau_to = to, strength = 4.2,
             size = 15, description = "run", stringsAsFactors = FALSE)
}

test_that("a measured reading with an unexplained run in its range is a bound or not determined, and says which run", {
  cf <- c(N = 1e-3, K = 1e-4)
  # the curve 15% above the model over the long end (163.84-655.36 s): within
  # the joint limits point by point (EDF 12 down to 3), so K is measured
  # without the run
  cv <- nk_curve(raise = 1.15, from = 150, to = 700)
  rd <- allanvar:::channel_readings(cv, cf, "gyro")
  k <- reading_of(rd, "random_walk")
  expect_identical(k$verdict, "measured")
  expect_lt(k$tau_lo, 163.84)
  u <- runs(163.84, 655.36)
  rd_u <- allanvar:::channel_readings(cv, cf, "gyro", unexplained = u)
  k_u <- reading_of(rd_u, "random_walk")
  # there K makes the model and the data show more: K is at least this
  expect_identical(k_u$verdict, "lower_bound")
  expect_true(k_u$is_bound)
  expect_match(k_u$why, "an unexplained run at tau 164-655 s lies in its range (see $unexplained)",
               fixed = TRUE)
  expect_match(k_u$why, "K is at least this", fixed = TRUE)
  expect_identical(k_u$value, k$value)
  # N rests on the short taus: the run changes nothing there
  expect_identical(reading_of(rd_u, "white"), reading_of(rd, "white"))
  # the curve below the model where K makes it: K is at most this
  cv_low <- nk_curve(raise = 1 / 1.15, from = 150, to = 700)
  k_low <- reading_of(allanvar:::channel_readings(cv_low, cf, "gyro", unexplained = u),
                      "random_walk")
  expect_identical(k_low$verdict, "upper_bound")
  expect_match(k_low$why, "below the model there, where K makes most of it")
  # B read at a flat minimum that N and K make (B^2 2 ln2/pi is an eighth of
  # the minimum): a run there says nothing of B's value
  cf3 <- c(N = 1e-3, B = 2e-4, K = 1e-4)
  cv3 <- nk_curve()
  cv3$avar <- cv3$avar + 2 * log(2) / pi * 2e-4^2
  cv3$adev <- sqrt(cv3$avar)
  b <- reading_of(allanvar:::channel_readings(cv3, cf3, "gyro"), "flicker")
  bump <- function(raise) {
    cv <- cv3
    inr <- cv$tau >= b$tau_lo & cv$tau <= b$tau_hi
    cv$adev[inr] <- raise * cv$adev[inr]
    cv
  }
  u_b <- runs(b$tau_lo, b$tau_hi, "bump")
  expect_identical(reading_of(allanvar:::channel_readings(bump(1.05), cf3, "gyro"),
                              "flicker")$verdict, "measured")
  b_u <- reading_of(allanvar:::channel_readings(bump(1.05), cf3, "gyro", unexplained = u_b),
                    "flicker")
  expect_identical(b_u$verdict, "not_determined")
  expect_match(b_u$why, "lies in its range (see $unexplained): other terms make most of the model there",
               fixed = TRUE)
  # a run within 2% of the model (the verdicts' tolerance) does not count
  b_small <- reading_of(allanvar:::channel_readings(bump(1.01), cf3, "gyro", unexplained = u_b),
                        "flicker")
  expect_identical(b_small$verdict, "measured")
})

test_that("an unexplained run outside a reading's range changes no reading", {
  cf <- c(N = 1e-3, K = 1e-4)
  cv <- nk_curve()
  rd <- allanvar:::channel_readings(cv, cf, "gyro")
  expect_identical(rd$verdict[rd$term %in% c("N", "K")], c("measured", "measured"))
  # beyond every reading's range (the curve ends at 655 s) and none at all
  rd_far <- allanvar:::channel_readings(cv, cf, "gyro", unexplained = runs(1e4, 2e4))
  expect_identical(rd_far, rd)
  rd_none <- allanvar:::channel_readings(cv, cf, "gyro", unexplained = runs(1, 1)[0, ])
  expect_identical(rd_none, rd)
})

test_that("a fit's unexplained run reaches every file's verdict (datasheet, Kalibr YAML, filter parameters)", {
  cv <- nk_curve(raise = 1.15, from = 150, to = 700)
  cv$unit <- "rad/s"
  fit <- avfit(cv[c("tau", "avar", "edf", "unit")], terms = c("N", "K"), freq = 100,
               n = 2e5)
  expect_identical(reading_of(datasheet(fit)$long, "random_walk")$verdict[1L], "measured")
  fit$unexplained <- runs(163.84, 655.36)
  k <- reading_of(datasheet(fit)$long, "random_walk")[1L, ]   # the axis, then the mean
  expect_false(k$verdict == "measured")
  expect_match(k$why, "unexplained run at tau 164-655 s", fixed = TRUE)
  f_yaml <- tempfile(fileext = ".yaml")
  on.exit(unlink(f_yaml))
  write_kalibr_yaml(fit, f_yaml)
  y <- readLines(f_yaml)
  rw <- y[startsWith(y, "gyroscope_random_walk:")]
  expect_match(rw, toupper(verdict_label(k$verdict)), fixed = TRUE)
  expect_match(rw, "unexplained run at tau 164-655 s", fixed = TRUE)
  kp <- kalman_params(fit)
  expect_identical(unique(kp$verdict[kp$term == "K"]), k$verdict)
  expect_match(unique(kp$why[kp$term == "K"]), "164-655 s", fixed = TRUE)
})
