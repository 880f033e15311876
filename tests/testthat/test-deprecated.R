test_that("the deprecated names warn and give what the new names give", {
  p <- c(N = 1e-3, K = 1e-5)
  expect_warning(old <- filter_params(p, dt = 0.01), "kalman_params",
                 class = "deprecatedWarning")
  expect_identical(old, kalman_params(p, dt = 0.01))
  set.seed(1)
  x <- rnorm(5000)
  expect_warning(old <- series_effects(x, 100), "detect_series_effects",
                 class = "deprecatedWarning")
  expect_identical(old, detect_series_effects(x, 100))
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  expect_warning(expect_error(read_avr_curve(f),
                              class = "allanvar_error"),
                 "read_allan_variance_ros_curve", class = "deprecatedWarning")
})
