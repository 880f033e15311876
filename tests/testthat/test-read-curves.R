# Other tools' results, read back under their own conventions. The numbers
# are typed from the tools' published files:
#   imu_utils (github.com/gaowenliang/imu_utils), data/BMI160_imu_param.yaml
#   and data/data_BMI160_sim_{gyr,acc}_{t,x}.txt (its fitted curves);
#   allan_variance_ros (github.com/ori-drs/allan_variance_ros), README.md:
#   the example terminal output and imu.yaml.

# imu_utils' own readings of a curve: gyr_n = sqrt(freq) * ADEV(1 s) (log-log
# interpolation between the neighbouring taus), gyr_w = min ADEV.
imu_utils_white <- function(cv, channel) {
  d <- cv[cv$channel == channel, ]
  f <- stats::approx(log(d$tau), log(d$adev), xout = 0)$y
  sqrt(attr(cv, "freq")) * exp(f)
}

write_imu_utils <- function(dir) {
  tau <- c(0.005091714049, 0.9063251007, 1.04380138, 30.01565432, 34.52691297,
           39.7204613, 45.68795016)
  gyr <- c(281.4451122, 21.97851658, 20.6048227, 7.723354005, 7.685867353,
           7.674680727, 7.689696198)                         # deg/h
  acc <- c(0.01995420249, 0.001440293468, 0.001343982573, 0.000378558378,
           0.0003786794681, 0.000382373209, 0.0003898598918) # m/s^2
  # (y and z repeat x: only the x axis is checked)
  for (s in c("gyr", "acc")) {
    v <- if (s == "gyr") gyr else acc
    writeLines(format(tau, digits = 10), file.path(dir, sprintf("data_BMI160_sim_%s_t.txt", s)))
    for (a in c("x", "y", "z")) {
      writeLines(format(v, digits = 10), file.path(dir, sprintf("data_BMI160_sim_%s_%s.txt", s, a)))
    }
  }
  writeLines(c("%YAML:1.0", "---", "type: IMU", "name: BMI160", "Gyr:",
               "   unit: \" rad/s\"", "   avg-axis:",
               "      gyr_n: 1.2138209013030823e-03", "      gyr_w: 2.6288838782975280e-05",
               "   x-axis:", "      gyr_n: 1.4274184891384049e-03",
               "      gyr_w: 3.7205161559693717e-05", "Acc:", "   unit: \" m/s^2\"",
               "   x-axis:", "      acc_n: 1.9234259821164789e-02",
               "      acc_w: 3.7855837800027711e-04"),
             file.path(dir, "BMI160_imu_param.yaml"))
}

test_that("imu_utils' fitted curve reads back to its yaml within 1%", {
  d <- tempfile()
  dir.create(d)
  on.exit(unlink(d, recursive = TRUE))
  write_imu_utils(d)
  cv <- read_imu_utils_curve(d, "BMI160", fitted = TRUE)
  expect_s3_class(cv, "tool_curve")
  expect_equal(attr(cv, "freq"), 1 / 0.005091714049)
  # deg/h back to rad/s with imu_utils' own 57.3
  expect_equal(cv$adev[cv$channel == "gyro_x"][1], 281.4451122 / (57.3 * 3600))
  y <- read_imu_utils_yaml(file.path(d, "BMI160_imu_param.yaml"), curve = cv)
  expect_true(attr(y, "scaled"))
  gx <- y[y$sensor == "gyro" & y$axis == "x", ]
  ax <- y[y$sensor == "accel" & y$axis == "x", ]
  # gyr_w is the floor of the fitted ADEV, gyr_n is sqrt(f) * ADEV(1 s)
  expect_equal(min(cv$adev[cv$channel == "gyro_x"]), gx$floor, tolerance = 0.01)
  expect_equal(imu_utils_white(cv, "gyro_x"), gx$white, tolerance = 0.01)
  expect_equal(min(cv$adev[cv$channel == "accel_x"]), ax$floor, tolerance = 0.01)
  expect_equal(imu_utils_white(cv, "accel_x"), ax$white, tolerance = 0.01)
  # in this package's conventions: N continuous, B = floor / 0.664
  expect_equal(gx$N, 1.4274184891384049e-03 / sqrt(1 / 0.005091714049))
  expect_equal(gx$B, 3.7205161559693717e-05 / 0.664)
  expect_identical(gx$unit_N, "rad/s/sqrt(Hz)")
  # the yaml alone: N unknown without the rate
  expect_true(all(is.na(read_imu_utils_yaml(file.path(d, "BMI160_imu_param.yaml"))$N)))
  expect_error(read_imu_utils_curve(d, "nope"), "no imu_utils curve",
               class = "allanvar_error_file")
})

test_that("allan_variance_ros' imu.yaml (README) is the mean of its axes, in rad", {
  f <- tempfile(fileext = ".yaml")
  on.exit(unlink(f))
  writeLines(c("#Accelerometer", "accelerometer_noise_density: 0.006308226052016165 ",
               "accelerometer_random_walk: 0.00011673723527962174 ", "",
               "#Gyroscope", "gyroscope_noise_density: 0.00015198973532354657 ",
               "gyroscope_random_walk: 2.664506559330434e-06 ", "",
               "rostopic: '/sensors/imu' #Make sure this is correct",
               "update_rate: 400.0 #Make sure this is correct"), f)
  k <- read_kalibr_yaml(f)
  expect_identical(attr(k, "rostopic"), "/sensors/imu")
  expect_identical(attr(k, "update_rate"), 400)
  v <- function(s, t) k$value[k$sensor == s & k$term == t]
  # README terminal output, per axis: ARW in deg/sqrt(s), VRW in m/s/sqrt(s)
  arw <- c(0.00787, 0.00987, 0.00839)
  rrw <- c(0.00007, 0.00028, 0.00011)
  vrw <- c(0.00333, 0.01079, 0.00481)
  expect_equal(v("gyro", "N"), mean(arw) * pi / 180, tolerance = 0.01)
  expect_equal(v("accel", "N"), mean(vrw), tolerance = 0.01)
  expect_equal(v("gyro", "K"), mean(rrw) * pi / 180, tolerance = 0.02)  # 5-digit print
  expect_identical(k$unit[k$sensor == "gyro" & k$term == "N"], "rad/s/sqrt(Hz)")
  # and in a datasheet unit
  expect_equal(convert_units(v("gyro", "N"), "rad/s/sqrt(Hz)", "deg/sqrt(h)"),
               mean(arw) * 60, tolerance = 0.01)
})

test_that("allan_variance_ros' CSV curve: deg/s gyro columns back to rad/s, fit gives N", {
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  tau <- seq(0.1, 100, by = 0.1)
  N_g <- 0.008                      # deg/sqrt(s), as its analysis.py prints
  N_a <- 0.003                      # m/s/sqrt(s)
  utils::write.table(cbind(tau, N_a / sqrt(tau), N_a / sqrt(tau), N_a / sqrt(tau),
                           N_g / sqrt(tau), N_g / sqrt(tau), N_g / sqrt(tau)),
                     f, row.names = FALSE, col.names = FALSE)
  cv <- read_allan_variance_ros_curve(f)
  expect_identical(unique(cv$channel), c("accel_x", "accel_y", "accel_z",
                                         "gyro_x", "gyro_y", "gyro_z"))
  g <- cv[cv$channel == "gyro_x", ]
  expect_equal(g$adev[g$tau == 1], N_g * pi / 180)
  fit <- avfit(g, "N", n = 4e6, freq = 400)
  expect_equal(unname(coef(fit)["N"]), N_g * pi / 180, tolerance = 1e-3)
  bad <- tempfile()
  writeLines(c("1 2 3", "4 5 6"), bad)
  expect_error(read_allan_variance_ros_curve(bad), "7 numeric columns", class = "allanvar_error_file_format")
})

test_that("the published imu_utils files read back within 1% (optional)", {
  peer <- Sys.getenv("ALLANVAR_PEER_DATA")
  skip_if(!nzchar(peer), "ALLANVAR_PEER_DATA is not set")
  dir <- file.path(peer, "imu_utils", "data")
  skip_if_not(dir.exists(dir), "no imu_utils/data under ALLANVAR_PEER_DATA")
  yamls <- list.files(dir, "_imu_param\\.yaml$")
  expect_gt(length(yamls), 0L)
  for (yf in yamls) {
    name <- sub("_imu_param\\.yaml$", "", yf)
    if (!file.exists(file.path(dir, sprintf("data_%s_sim_gyr_t.txt", name)))) next
    cv <- read_imu_utils_curve(dir, name, fitted = TRUE)
    y <- read_imu_utils_yaml(file.path(dir, yf), curve = cv)
    # the old examples hold ADEV(1 s), BMI160 (May 2018) sqrt(f) * ADEV(1 s)
    expect_identical(attr(y, "scaled"), name == "BMI160", label = name)
    k <- if (attr(y, "scaled")) sqrt(attr(cv, "freq")) else 1
    for (a in c("x", "y", "z")) {
      for (s in c("gyro", "accel")) {
        row <- y[y$sensor == s & y$axis == a, ]
        ch <- paste0(s, "_", a)
        expect_equal(min(cv$adev[cv$channel == ch]), row$floor, tolerance = 0.01,
                     label = paste(name, ch, "floor"))
        expect_equal(imu_utils_white(cv, ch) / sqrt(attr(cv, "freq")) * k, row$white,
                     tolerance = 0.01, label = paste(name, ch, "white"))
      }
    }
    # this package's reading beside theirs: N from the measured curve at 1 s
    m <- read_imu_utils_curve(dir, name)
    ours <- stats::approx(log(m$tau[m$channel == "gyro_x"]),
                          log(m$adev[m$channel == "gyro_x"]), xout = 0)$y
    expect_equal(exp(ours), y$N[y$sensor == "gyro" & y$axis == "x"], tolerance = 0.3,
                 label = paste(name, "measured ADEV(1 s) vs gyr_n / sqrt(f)"))
  }
})

test_that("another tool's curve is fitted one channel at a time", {
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  tau <- 10^seq(-1, 2, by = 0.25)
  N <- c(0.002, 0.003, 0.004, 0.01, 0.02, 0.03)  # accel m/s^2, gyro deg/s
  write.table(cbind(tau, outer(1 / sqrt(tau), N)), f, row.names = FALSE,
              col.names = FALSE)
  cv <- read_allan_variance_ros_curve(f)
  expect_error(avfit(cv, "N", n = 1e6, freq = 100), "choose one with `channel`",
               class = "allanvar_error_argument")
  fit <- avfit(cv, "N", channel = "gyro_y", n = 1e6, freq = 100)
  # deg/s in the file, rad/s after reading: N = 0.02 deg/s*sqrt(s)
  expect_equal(unname(coef(fit)["N"]), 0.02 * pi / 180, tolerance = 0.02)
  expect_error(avfit(rbind(cv[cv$channel == "gyro_x", ], cv[cv$channel == "gyro_x", ]),
                     "N", n = 1e6, freq = 100), "repeats averaging times",
               class = "allanvar_error_curve")
})
