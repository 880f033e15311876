# plot.imu_analysis().

test_that("plot() draws both sensors with units and reading markers", {
  a <- suppressWarnings(analyze_imu(two_records()[[1]], progress = FALSE))
  f <- tempfile(fileext = ".png")
  on.exit(unlink(f))
  grDevices::png(f, width = 1000, height = 500)
  expect_invisible(plot(a))
  plot(a, sensor = "gyro", units = "datasheet")
  grDevices::dev.off()
  expect_gt(file.size(f), 1000)
  expect_error(plot(a, sensor = "mag"), "`sensor`",
    class = "allanvar_error_argument")
})

test_that("plot() errors are classed and worded", {
  a <- suppressWarnings(analyze_imu(two_records()[[1]], refine = FALSE,
                                    progress = FALSE))
  pdf(NULL)
  on.exit(dev.off())
  expect_snapshot(error = TRUE, {
    plot(a, units = "imperial")
    plot(a, sensor = "mag")
  })
})

test_that("markers sit where the readings are; the legend lists only what is drawn", {
  # white noise only: K is an upper bound, not drawn nor listed
  set.seed(31)
  r <- imu_record(cbind(gyro_x = rnorm(2e4) * 1e-3, gyro_y = rnorm(2e4) * 2e-3),
                  freq = 100, units = c("rad/s", "rad/s"))
  a <- suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE))
  rd <- a$channels$gyro_x$readings
  # B is drawn on the flat region, at sqrt(2 ln 2 / pi) B = 0.664 B
  expect_equal(rd$adev[rd$term == "B"], sqrt(2 * log(2) / pi) * rd$value[rd$term == "B"])
  # N on the -1/2 line at tau = 1 s: ADEV(1 s) = N
  expect_equal(rd$adev[rd$term == "N"], rd$value[rd$term == "N"])
  expect_true(rd$is_bound[rd$term == "K"])
  pdf(NULL)
  on.exit(dev.off())
  leg <- expect_no_warning(plot_sensor(a, "gyro", "SI"))
  expect_false(any(grepl("^K|\\+1/2", leg$legend)))
  expect_true(any(grepl("-1/2 line", leg$legend, fixed = TRUE)))
  expect_true(any(grepl("^B", leg$legend)))
  # with a resolved K (rate random walk simulated strongly) it is listed
  b <- suppressWarnings(analyze_imu(two_records()[[1]], refine = FALSE,
                                    progress = FALSE))
  if (!any(b$channels$gyro_x$readings$is_bound)) {
    leg2 <- plot_sensor(b, "gyro", "SI")
    expect_true(any(grepl("^K", leg2$legend)))
    expect_true(any(grepl("+1/2", leg2$legend, fixed = TRUE)))
  }
})

test_that("the legend goes to the corner with the fewest data points", {
  pdf(NULL)
  on.exit(dev.off())
  x <- 10^seq(0, 3, length.out = 30)
  # data along the top: the legend avoids the top corners
  plot(x, rep(c(100, 90), 15), log = "xy", ylim = c(1, 120))
  pos <- draw_legend(list(legend = c("a long label", "another")), x, rep(c(100, 90), 15))
  expect_true(pos %in% c("bottomleft", "bottomright"))
})

test_that("plot snapshots: IMU analysis and fits with units, envelopes, no warnings", {
  skip_if_not_installed("vdiffr")
  set.seed(32)
  r <- imu_record(cbind(gyro_x = rnorm(2e4) * 1e-3, gyro_y = rnorm(2e4) * 2e-3),
                  freq = 100, units = c("rad/s", "rad/s"), name = "white")
  a <- suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE))
  vdiffr::expect_doppelganger("imu white noise gyro", function() plot(a))
  # a fit of a curve in SI (its unit on the y axis and in print) with a
  # sinusoid: the sinusoid drawn as its envelope
  tau <- 10^seq(-1, 2.5, by = 0.05)
  f0 <- 0.2
  A <- 1e-3
  av <- 1e-8 / tau + A^2 * sin(pi * f0 * tau)^4 / (pi * f0 * tau)^2
  cv <- data.frame(tau = tau, avar = av, unit = "rad/s")
  fit <- suppressWarnings(avfit(cv, c("N", "sinusoid"), n = 1e6, freq = 100))
  expect_output(print(fit), "(rad/s)*sqrt(s)", fixed = TRUE)
  vdiffr::expect_doppelganger("avfit sinusoid with units", function() {
    expect_no_warning(plot(fit))
  })
})
