sim6 <- function(n, seed = 1) {
  set.seed(seed)
  m <- cbind(matrix(rnorm(3 * n, sd = 1e-3), n), matrix(rnorm(3 * n, sd = 1e-2), n))
  m[, 6] <- m[, 6] + 9.81
  m
}

test_that("the Kalibr layout is read without arguments, ns stamps exactly", {
  m <- sim6(1000)
  f <- write_kalibr_csv(m, tempfile(fileext = ".csv"), freq = 200)
  on.exit(unlink(f))
  expect_silent(r <- read_imu(f))
  expect_s3_class(r, "imu_record")
  expect_equal(r$freq, 200, tolerance = 1e-12)
  expect_identical(r$time_unit, "ns")
  expect_identical(r$layout, "kalibr")
  expect_identical(colnames(r$data), c("gyro_x", "gyro_y", "gyro_z",
                                       "accel_x", "accel_y", "accel_z"))
  expect_identical(unname(r$sensors), rep(c("gyro", "accel"), each = 3))
  expect_identical(unname(r$units), rep(c("rad/s", "m/s^2"), each = 3))
  expect_equal(unname(r$data), m, tolerance = 1e-15)
  expect_equal(r$time, (0:999) / 200, tolerance = 1e-12)
  expect_equal(nrow(r$problems), 0L)
  expect_equal(nrow(r$segments), 1L)
  expect_output(print(r), "1000 samples at 200 Hz")
  expect_output(print(r), "no timestamp problems")
})

test_that("the EuRoC header is recognized, units from its brackets", {
  m <- sim6(300)
  f <- write_kalibr_csv(m, tempfile(fileext = ".csv"), freq = 200, header = c(
    "#timestamp [ns]", "w_RS_S_x [rad s^-1]", "w_RS_S_y [rad s^-1]",
    "w_RS_S_z [rad s^-1]", "a_RS_S_x [m s^-2]", "a_RS_S_y [m s^-2]",
    "a_RS_S_z [m s^-2]"))
  on.exit(unlink(f))
  r <- read_imu(f)
  expect_identical(r$layout, "euroc")
  expect_identical(colnames(r$data)[c(1, 4)], c("gyro_x", "accel_x"))
  expect_equal(r$freq, 200, tolerance = 1e-12)
  expect_equal(unname(r$data), m, tolerance = 1e-15)
})

test_that("other layouts: columns, units and time unit by argument", {
  set.seed(2)
  n <- 500
  d <- data.frame(temp = 25, t_ms = 1000 + (0:(n - 1)) * 10,
                  gx = rnorm(n), gy = rnorm(n), ax = rnorm(n), az = rnorm(n))
  f <- tempfile(fileext = ".txt")
  on.exit(unlink(f))
  utils::write.table(d, f, sep = ";", row.names = FALSE, quote = FALSE)
  r <- read_imu(f, time = "t_ms", time_unit = "ms", sep = ";",
                columns = c(gyro_x = "gx", gyro_y = "gy", accel_x = "ax",
                            accel_z = "az"),
                units = c(gyro = "deg/s", accel = "mg"))
  expect_equal(r$freq, 100)
  expect_identical(colnames(r$data), c("gyro_x", "gyro_y", "accel_x", "accel_z"))
  expect_equal(unname(r$data[, "gyro_y"]), d$gy * pi / 180)
  expect_equal(unname(r$data[, "accel_z"]), d$az * 9.80665e-3)
  # ms picked automatically from the step (10) too
  # (rnorm(sd = 1) gyros read as rad/s: the plausibility warning is due)
  expect_warning(
    expect_message(r2 <- read_imu(f, time = 2, sep = ";", columns = 3:6,
                                  sensors = c("gyro", "gyro", "accel", "accel")),
                   "no units given"),
    class = "allanvar_warning_gyro_units")
  expect_identical(r2$time_unit, "ms")
  expect_equal(r2$freq, 100)
  # no time column: freq required
  expect_error(read_imu(f, time = FALSE, sep = ";", columns = 3:4,
                        sensors = c("gyro", "gyro")), "freq",
                        class = "allanvar_error_no_time")
  expect_warning(
    expect_message(r3 <- read_imu(f, time = FALSE, sep = ";", columns = 3:4,
                                  sensors = c("gyro", "gyro"), freq = 50),
                   "assuming rad/s"),
    class = "allanvar_warning_gyro_units")
  expect_equal(r3$freq, 50)
  expect_error(read_imu(f, time = 2, sep = ";", columns = "nope"), "not found",
    class = "allanvar_error_argument")
  expect_error(read_imu(f, time = 2, sep = ";", columns = "temp"), "sensor type",
    class = "allanvar_error_sensors")
  expect_error(read_imu(f, sep = ";"), "no timestamp column",
    class = "allanvar_error_no_time")
  expect_error(read_imu(tempfile()), "does not exist",
    class = "allanvar_error_file")
})

test_that("out-of-order stamps are sorted and reported", {
  m <- sim6(400)
  off <- (0:399) * 1e7
  o <- c(1:99, 101, 100, 102:250, 252, 251, 253:400)
  f <- write_kalibr_csv(m[o, ], tempfile(fileext = ".csv"), off_ns = off[o])
  on.exit(unlink(f))
  expect_warning(r <- read_imu(f), "out-of-order")
  p <- r$problems[r$problems$type == "out-of-order", ]
  expect_equal(p$count, 2L)
  expect_match(p$action, "sorted")
  expect_equal(unname(r$data), m, tolerance = 1e-15)
  expect_equal(r$freq, 100, tolerance = 1e-12)
})

test_that("duplicated stamps are dropped and reported", {
  m <- sim6(400)
  off <- (0:399) * 1e7
  i <- c(1:50, 50, 51:300, 300, 300, 301:400)
  f <- write_kalibr_csv(m[i, ], tempfile(fileext = ".csv"), off_ns = off[i])
  on.exit(unlink(f))
  expect_warning(r <- read_imu(f), "duplicate")
  expect_equal(r$problems$count[r$problems$type == "duplicate"], 3L)
  expect_equal(nrow(r$data), 400L)
  expect_equal(unname(r$data), m, tolerance = 1e-15)
})

test_that("gaps split the record, stop it, or are ignored, always reported", {
  m <- sim6(1000)
  keep <- c(1:300, 351:1000)          # 50 samples (0.5 s) missing after row 300
  off <- ((0:999) * 1e7)[keep]
  f <- write_kalibr_csv(m[keep, ], tempfile(fileext = ".csv"), off_ns = off)
  on.exit(unlink(f))
  expect_warning(r <- read_imu(f), "gap")
  expect_equal(r$segments$n, c(300L, 650L))
  expect_equal(r$segments$t_start, c(0, 3.5), tolerance = 1e-12)
  g <- r$problems[r$problems$type == "gap", ]
  expect_equal(g$count, 1L)
  expect_match(g$detail, "longest 0.51 s at t = 2.99 s")
  expect_match(g$action, "split into 2 segments")
  expect_equal(r$sampling$gaps$length, 0.51, tolerance = 1e-12)
  expect_error(read_imu(f, gap = "error"), "gap = \"segments\"",
    class = "allanvar_error_gap")
  expect_warning(r2 <- read_imu(f, gap = "ignore"), "ignored")
  expect_equal(nrow(r2$segments), 1L)
  expect_equal(nrow(r2$data), 950L)
  # the longest segment is what the analysis uses
  expect_equal(allanvar:::record_segment(r), r$data[301:950, ])
})

test_that("jitter is measured (RMS) and reported above 1% of the step", {
  m <- sim6(2000)
  set.seed(3)
  a <- 1e6                           # stamps moved by U(-a, a) ns, step 1e7 ns
  off <- round((0:1999) * 1e7 + runif(2000, -a, a))
  f <- write_kalibr_csv(m, tempfile(fileext = ".csv"), off_ns = off)
  on.exit(unlink(f))
  expect_warning(r <- read_imu(f), "jitter")
  # step = dt + e[k+1] - e[k]: RMS deviation sqrt(2/3) a (about 8.2% of dt)
  expect_equal(r$sampling$jitter_rms, sqrt(2 / 3) * a * 1e-9, tolerance = 0.05)
  expect_equal(r$sampling$jitter_rel, sqrt(2 / 3) * 0.1, tolerance = 0.05)
  expect_equal(nrow(r$segments), 1L)
  expect_match(r$problems$detail[r$problems$type == "jitter"], "RMS step deviation")
  # a clean record reports its (tiny) jitter without a problem
  f2 <- write_kalibr_csv(m, tempfile(fileext = ".csv"))
  on.exit(unlink(f2), add = TRUE)
  expect_silent(r2 <- read_imu(f2))
  expect_lt(r2$sampling$jitter_rel, 1e-9)
})

test_that("imu_record() builds records from memory with unit conversion", {
  m <- cbind(gyro_x = c(1, 2, 3), accel_x = c(1, 0, -1))
  r <- imu_record(m, freq = 10, units = c(gyro = "deg/h", accel = "g"))
  expect_equal(unname(r$data[, 1]), c(1, 2, 3) * pi / 180 / 3600)
  expect_equal(unname(r$data[, 2]), c(1, 0, -1) * 9.80665)
  expect_error(imu_record(m), "freq", class = "allanvar_error_no_time")
  expect_error(imu_record(cbind(foo = 1:3), freq = 1), "sensor type",
    class = "allanvar_error_sensors")
  r2 <- imu_record(cbind(foo = c(1, 2, 3)), freq = 1, sensors = "gyro")
  expect_identical(unname(r2$sensors), "gyro")
})

test_that("a 200,000-row Kalibr CSV of a measured ADIS16405 round-trips", {
  skip_if_no_shared()
  m <- readRDS(shared_file("adis16405_unit1.rds"))[1:2e5, ]
  si <- cbind(m[, 1:3] * pi / 180, m[, 4:6] * 9.80665)
  f <- write_kalibr_csv(si, tempfile(fileext = ".csv"), freq = 100)
  on.exit(unlink(f))
  r <- read_imu(f)
  expect_equal(r$freq, 100, tolerance = 1e-12)
  expect_equal(nrow(r$data), 2e5)
  # back to the recording's own units: deg/s and g
  expect_equal(unname(convert_units(r$data[, 1:3], "rad/s", "deg/s")),
               unname(m[, 1:3]), tolerance = 1e-14)
  expect_equal(unname(convert_units(r$data[, 4:6], "m/s^2", "g")),
               unname(m[, 4:6]), tolerance = 1e-14)
})
