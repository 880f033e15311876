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
  expect_error(plot(a, sensor = "mag"), "`sensor`")
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
