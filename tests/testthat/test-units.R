# Conversion factors against values computed by hand from the definitions
# 1 deg = pi/180 rad, 1 h = 3600 s, g = 9.80665 m/s^2.

test_that("rate units convert to SI with hand-computed factors", {
  expect_equal(convert_units(1, "deg/s", "rad/s"), 0.017453292519943295)
  expect_equal(convert_units(1, "deg/h", "rad/s"), 4.84813681109536e-06)
  expect_equal(convert_units(1, "rad/h", "rad/s"), 1 / 3600)
  expect_equal(convert_units(60, "rpm", "rad/s"), 2 * pi)
  expect_equal(convert_units(1, "g", "m/s^2"), 9.80665)
  expect_equal(convert_units(1, "mg", "m/s^2"), 0.00980665)
  expect_equal(convert_units(1000, "ug", "mg"), 1)
  expect_equal(convert_units(9.80665, "m/s^2", "g"), 1)
  # 15 deg/h, Earth-rate order, in deg/s
  expect_equal(convert_units(15, "deg/h", "deg/s"), 15 / 3600)
})

test_that("noise-coefficient units convert with hand-computed factors", {
  # ARW: 1 deg/sqrt(h) = (pi/180) rad / 60 sqrt(s)
  expect_equal(convert_units(1, "deg/sqrt(h)", "rad/s/sqrt(Hz)"),
               2.908882086657216e-04)
  # ADIS16405 datasheet ARW 2 deg/sqrt(h)
  expect_equal(convert_units(2, "deg/sqrt(h)", "rad/sqrt(s)"), 5.817764173314432e-04)
  # rad/s/sqrt(Hz) and rad/sqrt(s) are the same unit
  expect_equal(convert_units(3, "rad/s/sqrt(Hz)", "rad/sqrt(s)"), 3)
  # RRW: 1 deg/h/sqrt(h) = (pi/180) / 3600 / 60 rad/s^2/sqrt(Hz)
  expect_equal(convert_units(1, "deg/h/sqrt(h)", "rad/s^2/sqrt(Hz)"),
               8.080228018492267e-08)
  expect_equal(convert_units(1, "deg/h^(3/2)", "deg/h/sqrt(h)"), 1)
  # VRW: 1 m/s/sqrt(h) = 1/60 m/s^2/sqrt(Hz); 100 ug/sqrt(Hz) = 9.80665e-4
  expect_equal(convert_units(1, "m/s/sqrt(h)", "m/s^2/sqrt(Hz)"), 1 / 60)
  expect_equal(convert_units(100, "ug/sqrt(Hz)", "m/s^2/sqrt(Hz)"), 9.80665e-4)
  # accel K: 1 m/s/h^(3/2) = 1 / 3600^1.5 = 1/216000 m/s^3/sqrt(Hz)
  expect_equal(convert_units(216000, "m/s/h^(3/2)", "m/s^3/sqrt(Hz)"), 1)
  expect_equal(convert_units(1, "ug/sqrt(s)", "m/s^3/sqrt(Hz)"), 9.80665e-6)
  # B in deg/h and ug
  expect_equal(convert_units(1e-4, "rad/s", "deg/h"), 1e-4 * 180 / pi * 3600)
  expect_equal(convert_units(9.80665e-5, "m/s^2", "ug"), 10)
  # Q and R
  expect_equal(convert_units(1, "arcsec", "rad"), pi / 180 / 3600)
  expect_equal(convert_units(1, "deg/h^2", "rad/s^2"), pi / 180 / 3600^2)
})

test_that("spellings are normalised and conversions round-trip", {
  expect_equal(convert_units(1, "m/s2", "m/s^2"), 1)
  expect_equal(convert_units(1, "\u00b5g", "ug"), 1)
  expect_equal(convert_units(1, "deg / s", "rad/s"), pi / 180)
  x <- c(0.1, 2, 30)
  for (u in av_units("gyro", "N")$unit) {
    expect_equal(convert_units(convert_units(x, "deg/sqrt(h)", u), u,
                               "deg/sqrt(h)"), x)
  }
})

test_that("bad units and mismatched kinds stop with a clear message", {
  expect_error(convert_units(1, "deg/s", "m/s^2"), "same quantity",
    class = "allanvar_error_units")
  expect_error(convert_units(1, "deg/sqrt(h)", "deg/h"), "same quantity",
    class = "allanvar_error_units")
  expect_error(convert_units(1, "furlong", "rad/s"), "`from`.*not a known",
    class = "allanvar_error_units")
  expect_error(convert_units("1", "g", "mg"), "`x` must be numeric",
    class = "allanvar_error_argument")
  expect_error(av_units("magnetometer"), "`sensor`",
    class = "allanvar_error_argument")
})

test_that("av_units() lists every unit with its SI unit", {
  tab <- av_units()
  expect_true(all(c("unit", "sensor", "kind", "to_si", "si") %in% names(tab)))
  expect_false(anyDuplicated(paste(tab$unit, tab$sensor)) > 0)
  expect_true(all(tab$to_si[tab$unit == tab$si] == 1))
  expect_setequal(av_units("accel", "K")$si, "m/s^3/sqrt(Hz)")
})

# Unit checks on the data. A static IMU of our own making: white gyro noise
# N (deg/sqrt(h)) and a bias, accelerometers holding gravity on z.
static_imu <- function(n = 6000, freq = 100, N_dph = 2, bias_dps = 0.2,
                       tilt = c(0.01, -0.02), seed = 1) {
  set.seed(seed)
  sd_dps <- N_dph / 60 * sqrt(freq)            # white: sd = N sqrt(f)
  g <- matrix(rnorm(3 * n, bias_dps, sd_dps), n)
  a <- cbind(tilt[1] + rnorm(n, sd = 0.003), tilt[2] + rnorm(n, sd = 0.003),
             sqrt(1 - sum(tilt^2)) + rnorm(n, sd = 0.003))
  colnames(g) <- c("gyro_x", "gyro_y", "gyro_z")
  colnames(a) <- c("accel_x", "accel_y", "accel_z")
  list(gyro_dps = g, accel_g = a, freq = freq)
}

test_that("accelerometer units are read from gravity: g and m/s^2 inputs", {
  s <- static_imu()
  # in g, no units given: detected, said, recorded, converted
  expect_message(r <- imu_record(cbind(s$gyro_dps * pi / 180, s$accel_g), freq = 100),
                 "accelerometers read as g")
  expect_identical(unname(r$units[4:6]), rep("g", 3))
  expect_identical(unique(r$unit_checks$source[4:6]), "gravity")
  expect_equal(sqrt(sum(colMeans(r$data[, 4:6])^2)), 9.80665, tolerance = 1e-3)
  # in m/s^2: confirmed, no change
  m <- cbind(s$gyro_dps * pi / 180, s$accel_g * 9.80665)
  r2 <- imu_record(m, freq = 100)
  expect_identical(unname(r2$units[4:6]), rep("m/s^2", 3))
  expect_identical(unique(r2$unit_checks$source[4:6]), "gravity")
  expect_equal(r2$data, r$data, tolerance = 1e-12)
  # in mg
  expect_message(r3 <- imu_record(cbind(s$gyro_dps * pi / 180, s$accel_g * 1000),
                                  freq = 100), "read as mg")
  expect_equal(r3$data[, 4:6], r$data[, 4:6], tolerance = 1e-12)
  # given units that gravity contradicts: a classed warning, units kept
  expect_warning(r4 <- imu_record(cbind(s$gyro_dps * pi / 180, s$accel_g), freq = 100,
                                  units = c(accel = "m/s^2")),
                 "look like g", class = "allanvar_warning_accel_units")
  expect_identical(unname(r4$units[4]), "m/s^2")
  # read_imu says it in its message too
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  utils::write.csv(data.frame(time = (0:5999) / 100, s$gyro_dps * pi / 180, s$accel_g), f,
                   row.names = FALSE)
  expect_message(r5 <- read_imu(f), "no units given.*accelerometers read as g")
  expect_identical(unname(r5$units[4:6]), rep("g", 3))
})

test_that("gyro units are checked against real gyros: deg/s and rad/s inputs", {
  s <- static_imu()
  acc <- s$accel_g * 9.80665
  # deg/s samples (N = 2 deg/sqrt(h)) taken as rad/s: N looks 57 times too large
  w <- expect_warning(imu_record(cbind(s$gyro_dps, acc), freq = 100),
                      class = "allanvar_warning_gyro_units")
  expect_match(conditionMessage(w), "gyro_x: white noise N ~ 1[0-9]{2} deg/sqrt\\(h\\)")
  expect_match(conditionMessage(w), "units = c\\(gyro = \"deg/s\"\\)")
  # the same samples declared deg/s, or converted to rad/s: no warning, N ~ 2
  expect_silent(r <- imu_record(cbind(s$gyro_dps, acc), freq = 100,
                                units = c(gyro = "deg/s", accel = "m/s^2")))
  expect_match(r$unit_checks$evidence[1], "N ~ 2")
  expect_silent(imu_record(cbind(s$gyro_dps * pi / 180, acc), freq = 100))
  # a large bias in deg/s taken as rad/s (white noise alone plausible)
  s2 <- static_imu(N_dph = 0.3, bias_dps = 2)
  expect_warning(imu_record(cbind(s2$gyro_dps, acc), freq = 100),
                 "mean rate", class = "allanvar_warning_gyro_units")
})

test_that("the measured ADIS16405 (deg/s, g) is recognized", {
  skip_if_no_shared()
  m <- readRDS(shared_file("adis16405_unit1.rds"))[1:60000, ]
  colnames(m) <- c("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")
  w <- NULL
  r <- withCallingHandlers(
    suppressMessages(imu_record(m, freq = 100)),
    allanvar_warning_gyro_units = function(c) {
      w <<- conditionMessage(c)
      invokeRestart("muffleWarning")
    })
  expect_match(w, "as deg/s it would be")
  expect_identical(unname(r$units[4:6]), rep("g", 3))
})
