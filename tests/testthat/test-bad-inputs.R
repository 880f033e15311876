# Inputs that cannot be right stop the run with a classed error naming the
# argument (or, for units, mark every output and end the CLI run with its
# own status); the wording is snapshot-tested.

scrub <- function(x) gsub("[^ \"]*(file|Rtmp)[[:alnum:]_]+(\\.csv)?", "<file>", x)

imu_csv <- function(time, cols, file = tempfile(fileext = ".csv")) {
  set.seed(3)
  n <- length(time)
  d <- data.frame(t = time)
  for (nm in cols) d[[nm]] <- rnorm(n) * 1e-3
  if ("az1" %in% cols) d$az1 <- d$az1 + 9.8
  utils::write.csv(d, file, row.names = FALSE)
  file
}

test_that("a time unit or rate no IMU has is an error naming time_unit / freq", {
  x <- cbind(gyro_x = rnorm(1000))
  # stamps in ms read as s: 0.1 Hz
  expect_error(imu_record(x, time = (0:999) * 10, time_unit = "s"),
               class = "allanvar_error_time_unit")
  # a given freq 10x what the stamps say
  expect_error(imu_record(x, time = (0:999) / 100, freq = 1000),
               class = "allanvar_error_rate_mismatch")
  # within 1% it is accepted
  expect_s3_class(suppressWarnings(imu_record(x, time = (0:999) / 100, freq = 100.5)),
                  "imu_record")
  expect_error(imu_record(x, freq = 0.01), class = "allanvar_error_argument")
  expect_snapshot(error = TRUE, {
    imu_record(x, time = (0:999) * 10, time_unit = "s")
    imu_record(x, time = (0:999) / 100, freq = 1000)
    imu_record(x, freq = 0.01)
  })
})

test_that("columns the reader cannot place are an error listing them, never dropped", {
  f <- imu_csv((0:999) / 100, c("wx", "wy", "wz", "ax1", "ay1", "az1"))
  on.exit(unlink(f))
  expect_error(read_imu(f), class = "allanvar_error_unplaced_columns")
  expect_snapshot(error = TRUE, read_imu(f), transform = scrub)
  # with the mapping given, all six are read
  r <- suppressWarnings(suppressMessages(read_imu(f, columns = c("wx", "wy", "wz", "ax1", "ay1", "az1"),
                                                  sensors = rep(c("gyro", "accel"), each = 3))))
  expect_identical(unname(r$sensors), rep(c("gyro", "accel"), each = 3))
  # columns whose names say they are something else are left out, said so
  g <- imu_csv((0:999) / 100, c("gyro_x", "temperature"))
  on.exit(unlink(g), add = TRUE)
  expect_message(read_imu(g, units = "rad/s"), "temperature left out")
})

test_that("bad arguments get classed errors in the package's words", {
  expect_error(imu_record(x = function(x) x, freq = 100), class = "allanvar_error_argument")
  av <- allan(rnorm(1e4), 100)
  expect_error(avfit(av, c("N", "gm"), start = c(gm1.tc = -1)),
               class = "allanvar_error_argument")
  broken <- structure(list(channels = list(1)), class = "imu_analysis")
  expect_error(datasheet(broken), class = "allanvar_error_argument")
  expect_error(write_datasheet(broken, tempfile()), class = "allanvar_error_argument")
  expect_snapshot(error = TRUE, {
    imu_record(x = function(x) x, freq = 100)
    avfit(av, c("N", "gm"), start = c(gm1.tc = -1))
    datasheet(broken)
  })
})

test_that("avfit() leaves out points with EDF below 1, and says so", {
  tau <- 2^(0:7)
  cv <- data.frame(tau = tau, avar = 1e-6 / tau + 1e-9 * tau, edf = c(rep(50, 6), 0.01, 0.02))
  expect_warning(fit <- avfit(cv, c("N", "K")), class = "allanvar_warning_points_dropped")
  expect_identical(fit$nobs, 6L)
  expect_true(all(is.finite(coef(fit))) && all(is.finite(fit$se)))
  expect_equal(unname(coef(fit)["N"]), 1e-3, tolerance = 0.05)
})

test_that("the CLI: units that fail their checks mark every file and end the run in error", {
  skip_on_cran()
  set.seed(4)
  n <- 20000
  # gyros in deg/s, accelerometers in g, no units stated
  f <- tempfile(fileext = ".csv")
  d <- data.frame(time = (0:(n - 1)) / 100,
                  gyro_x = rnorm(n) * 0.4, gyro_y = rnorm(n) * 0.4, gyro_z = rnorm(n) * 0.4,
                  accel_x = rnorm(n) * 1e-3, accel_y = rnorm(n) * 1e-3,
                  accel_z = 1 + rnorm(n) * 1e-3)
  utils::write.csv(d, f, row.names = FALSE)
  out <- tempfile("cli")
  on.exit(unlink(c(f, out), recursive = TRUE))
  expect_error(suppressMessages(capture.output(
    allanvar_cli(c(f, "--out", out, "--quiet", "--no-refine", "--no-report",
                   "--accel-units", "m/s^2")))),
    class = "allanvar_error_units_unchecked")
  # the files were written, and each says so
  y <- readLines(file.path(out, "imu.yaml"))
  expect_true(any(grepl("^# WARNING: the units failed their checks", y)))
  ds <- utils::read.csv(file.path(out, "datasheet.csv"))
  expect_true(all(grepl("units suspect", ds$warning[ds$sensor == "gyro"])))
  fp <- utils::read.csv(file.path(out, "filter_params.csv"))
  expect_true(all(grepl("units suspect", fp$warning[fp$sensor == "gyro"])))
  # the user says the units are right: no error
  expect_no_error(suppressMessages(capture.output(
    allanvar_cli(c(f, "--out", out, "--quiet", "--no-refine", "--no-report",
                   "--accel-units", "m/s^2", "--units-checked")))))
  # the launcher's exit status is 3
  bin <- system.file("bin", "allanvar", package = "allanvar")
  skip_if(!nzchar(bin) || !installed_allanvar(), "the launcher needs the installed package")
  res <- suppressWarnings(system2(file.path(R.home("bin"), "Rscript"),
                                  c(bin, f, "--out", out, "--quiet", "--no-refine",
                                    "--no-report", "--accel-units", "m/s^2"),
                                  stdout = TRUE, stderr = TRUE))
  expect_identical(attr(res, "status"), 3L)
  # and a wrong time unit is an error in the CLI's words (status 1)
  expect_snapshot(error = TRUE, allanvar_cli(c(f, "--time-unit", "ms", "--out", out,
                                               "--quiet", "--no-refine")),
                  transform = scrub)
})
