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
