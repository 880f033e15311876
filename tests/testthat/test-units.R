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
  expect_error(convert_units(1, "deg/s", "m/s^2"), "same quantity")
  expect_error(convert_units(1, "deg/sqrt(h)", "deg/h"), "same quantity")
  expect_error(convert_units(1, "furlong", "rad/s"), "`from`.*not a known")
  expect_error(convert_units("1", "g", "mg"), "`x` must be numeric")
  expect_error(av_units("magnetometer"), "`sensor`")
})

test_that("av_units() lists every unit with its SI unit", {
  tab <- av_units()
  expect_true(all(c("unit", "sensor", "kind", "to_si", "si") %in% names(tab)))
  expect_false(anyDuplicated(paste(tab$unit, tab$sensor)) > 0)
  expect_true(all(tab$to_si[tab$unit == tab$si] == 1))
  expect_setequal(av_units("accel", "K")$si, "m/s^3/sqrt(Hz)")
})
