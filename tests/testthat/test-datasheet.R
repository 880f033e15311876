sim_analysis <- function() {
  n <- 4e4
  m <- cbind(gyro_x = avsim(n, 100, N = 1e-3, K = 1e-4, seed = 1),
             gyro_y = avsim(n, 100, N = 2e-3, K = 1e-4, seed = 2),
             accel_z = avsim(n, 100, N = 1e-2, K = 1e-3, seed = 3))
  suppressWarnings(analyze_imu(imu_record(m, freq = 100), progress = FALSE))
}

test_that("the datasheet has one row per axis, SI and datasheet units agree", {
  a <- sim_analysis()
  ds <- datasheet(a)
  expect_s3_class(ds, "imu_datasheet")
  g <- ds$gyro
  expect_identical(g$axis, c("gyro_x", "gyro_y"))
  expect_identical(ds$accel$axis, "accel_z")
  # hand-computed factors: deg/sqrt(h) = rad/sqrt(s) * (180/pi) * 60, ...
  expect_equal(g[["N [deg/sqrt(h)]"]], g[["N [rad/s/sqrt(Hz)]"]] * 180 / pi * 60)
  expect_equal(g[["B [deg/h]"]], g[["B [rad/s]"]] * 180 / pi * 3600)
  expect_equal(g[["K [deg/h/sqrt(h)]"]], g[["K [rad/s^2/sqrt(Hz)]"]] * 180 / pi * 3600 * 60)
  acc <- ds$accel
  expect_equal(acc[["N [m/s/sqrt(h)]"]], acc[["N [m/s^2/sqrt(Hz)]"]] * 60)
  expect_equal(acc[["N [ug/sqrt(Hz)]"]], acc[["N [m/s^2/sqrt(Hz)]"]] / 9.80665e-6)
  expect_equal(acc[["B [ug]"]], acc[["B [m/s^2]"]] / 9.80665e-6)
  expect_equal(acc[["B [mg]"]], acc[["B [m/s^2]"]] / 9.80665e-3)
  expect_equal(acc[["K [m/s/h^(3/2)]"]], acc[["K [m/s^3/sqrt(Hz)]"]] * 3600^1.5)
  # B is reported with the tau where it is read: the fitted curve's minimum
  fd <- a$channels$gyro_y$fit$data
  expect_equal(g[["tau_B [s]"]][2], fd$tau[which.min(fd$fitted)])
  # the values are the per-axis readings, never averaged
  expect_equal(g[["N [rad/s/sqrt(Hz)]"]],
               unname(vapply(a$channels[1:2], function(c) c$readings$value[1], 0)))
  expect_equal(g[["N [rad/s/sqrt(Hz)]"]], c(1e-3, 2e-3), tolerance = 0.15)
  expect_false(any(ds$long$axis == "mean of axes"))
  expect_output(print(ds), "Gyroscopes")
  expect_output(print(ds), "Accelerometers")
})

test_that("average = TRUE appends the mean of the axes, and only then", {
  a <- sim_analysis()
  ds <- datasheet(a, average = TRUE)
  g <- ds$gyro
  expect_identical(g$axis, c("gyro_x", "gyro_y", "mean of axes"))
  expect_equal(g[["N [deg/sqrt(h)]"]][3], mean(g[["N [deg/sqrt(h)]"]][1:2]))
  expect_error(datasheet(a, average = NA), "`average`",
    class = "allanvar_error_argument")
})

test_that("the effects the closed loop added are listed", {
  fit <- list(steps = data.frame(effect = c("Q", "gm", "sinusoid")),
              coefficients = c(N = 1, gm1.sigma = 2, gm1.tc = 12.34,
                               sinusoid1.amp = 1, sinusoid1.f0 = 0.25))
  expect_identical(allanvar:::added_effects(fit),
                   "Q, gm (Tc = 12.3 s), sinusoid (f0 = 0.25 Hz)")
  expect_identical(allanvar:::added_effects(NULL), "none")
})

test_that("write_datasheet() writes the long and wide CSV", {
  a <- sim_analysis()
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  write_datasheet(a, f)
  d <- utils::read.csv(f)
  expect_identical(names(d), c("record", "sensor", "axis", "term", "value",
                               "unit", "tau", "method", "effects", "verdict",
                               "why", "tau_lo", "tau_hi", "biased_by",
                               "bias_change", "removed", "warning"))
  expect_equal(d$value, datasheet(a)$long$value)
  write_datasheet(datasheet(a), f, format = "wide")
  expect_true(any(grepl("N \\[deg/sqrt\\(h\\)\\]", readLines(f))))
  expect_error(write_datasheet(1, f), "imu_datasheet",
    class = "allanvar_error_argument")
})

test_that("datasheet() and write_datasheet() errors are classed and worded", {
  a <- sim_analysis()
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  expect_snapshot(error = TRUE, {
    datasheet(a, average = NA)
    write_datasheet(1, f)
    write_datasheet(a, f, format = "tall")
  })
})

test_that("a fit of a curve alone gets a datasheet, guidance and filter parameters in units", {
  # allan_variance_ros' curve: deg/s gyro columns with N, B, K by hand
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  tau <- 10^seq(-1, 3, by = 0.05)
  N <- 0.008                       # deg/sqrt(s)
  B <- 2e-3                        # deg/s
  K <- 1e-4                        # deg/s/sqrt(s)
  ad <- sqrt(N^2 / tau + (2 * log(2) / pi) * B^2 + K^2 * tau / 3)
  Na <- 0.003
  utils::write.table(cbind(tau, Na / sqrt(tau), Na / sqrt(tau), Na / sqrt(tau),
                           ad, ad, ad), f, row.names = FALSE, col.names = FALSE)
  cv <- read_allan_variance_ros_curve(f)
  fit <- avfit(cv[cv$channel == "gyro_x", ], n = 4e6, freq = 400)
  ds <- datasheet(fit)
  expect_s3_class(ds, "imu_datasheet")
  g <- ds$gyro
  expect_identical(nrow(g), 1L)
  expect_identical(g$axis, "gyro_x")
  # deg/sqrt(s) * 60 = deg/sqrt(h); deg/s * 3600 = deg/h;
  # deg/s/sqrt(s) * 3600 * 60 = deg/h/sqrt(h)
  expect_equal(g[["N [deg/sqrt(h)]"]], N * 60, tolerance = 1e-3)
  expect_equal(g[["N [rad/s/sqrt(Hz)]"]], N * pi / 180, tolerance = 1e-3)
  expect_equal(g[["B [deg/h]"]], B * 3600, tolerance = 0.01)
  # (the fit's flicker term is not exactly flat at large tau: K within 5%)
  expect_equal(g[["K [deg/h/sqrt(h)]"]], K * 3600 * 60, tolerance = 0.05)
  # filter parameters in rad/s: sigma_d = N / sqrt(dt), dt = 1 / freq
  fp <- kalman_params(fit)
  sd <- fp[fp$parameter == "sigma_d", ]
  expect_identical(sd$unit, "rad/s")
  expect_identical(sd$continuous_unit, "rad/s/sqrt(Hz)")
  expect_equal(sd$value, N * pi / 180 * sqrt(400), tolerance = 1e-3)
  gd <- imu_guidance(fit)
  expect_named(gd, c("record", "channel", "message"))
  expect_true(all(grepl("rad/s|h|s", gd$message)))
  # an allan() curve of unknown unit: values in u, or in the unit given
  set.seed(4)
  a <- allan(rnorm(2e4) * 0.1, 100)
  fa <- avfit(a, "N")
  du <- datasheet(fa)
  expect_null(du$gyro)
  expect_identical(du$long$unit[du$long$term == "N"], "u*sqrt(s)")
  expect_equal(du$long$value[du$long$term == "N"], unname(coef(fa)["N"]))
  dg <- datasheet(fa, unit = "deg/s")
  expect_equal(dg$gyro[["N [deg/sqrt(h)]"]], unname(coef(fa)["N"]) * 60)
  fu <- kalman_params(fa)
  expect_identical(fu$unit[fu$parameter == "sigma_d"], "u")
  expect_identical(fu$continuous_unit[fu$parameter == "sigma_d"], "u*sqrt(s)")
  expect_error(datasheet(fa, unit = "furlong"), class = "allanvar_error_units")
  expect_error(datasheet(1), "`x` must be an imu_analysis",
               class = "allanvar_error_argument")
})

test_that("the same recording as CSV, ROS1 bag, ROS2 db3 and MCAP gives identical datasheets", {
  # fixtures: tools/make-bag-fixtures.R (one recording in every format)
  files <- c(csv = "imu.csv", bag = "imu_lz4.bag", db3 = "imu.db3",
             mcap = "imu_lz4.mcap", mcap_ros1 = "imu_ros1.mcap")
  sheets <- lapply(names(files), function(k) {
    args <- if (k == "csv") list() else list(topic = "/imu0")
    r <- do.call(read_imu, c(list(ros_fixture(files[[k]])), args))
    a <- suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE))
    ds <- datasheet(a)
    # the record's name is its file name; everything else must agree
    ds$long$record <- NULL
    ds$gyro$record <- ds$accel$record <- NULL
    ds
  })
  names(sheets) <- names(files)
  expect_setequal(unique(sheets$csv$long$axis),
                  c("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"))
  expect_true(all(is.finite(sheets$csv$long$value)))
  for (k in names(files)[-1]) {
    expect_identical(sheets[[k]]$long, sheets$csv$long, label = k)
    expect_identical(sheets[[k]]$gyro, sheets$csv$gyro, label = k)
    expect_identical(sheets[[k]]$accel, sheets$csv$accel, label = k)
  }
})

test_that("write_datasheet() quotes names copied from the user and writes whole files", {
  set.seed(41)
  m <- cbind(gyro_x = rnorm(4000) * 1e-3)
  nm <- "rec, \"quoted\"\nnext line"
  a <- suppressWarnings(analyze_imu(imu_record(m, freq = 100, units = "rad/s",
                                               name = nm),
                                    refine = FALSE, progress = FALSE))
  d <- tempfile("ds")
  dir.create(d)
  on.exit(unlink(d, recursive = TRUE))
  f <- file.path(d, "datasheet.csv")
  for (fmt in c("long", "wide")) {
    write_datasheet(a, f, format = fmt)
    back <- utils::read.csv(f, stringsAsFactors = FALSE)
    expect_identical(unique(back$record), nm)
    expect_identical(list.files(d, all.files = TRUE, no.. = TRUE), "datasheet.csv")
  }
  expect_equal(back[["N..rad.s.sqrt.Hz.."]], datasheet(a)$gyro[["N [rad/s/sqrt(Hz)]"]],
               tolerance = 1e-12)
  expect_error(write_datasheet(a, d), class = "allanvar_error_output_path")
  expect_error(write_datasheet(a, file.path(d, "no", "x.csv")),
               class = "allanvar_error_output_path")
})

test_that("an added term the record does not determine says so in the datasheet's effects", {
  # own generator: white noise and a Gauss-Markov process of tc 60 s, in a
  # 600 s record (about 10 time constants: its tc's 95% interval spans more
  # than a factor 2 either way) and in a 6000 s one with tc 6 s (it does not)
  gm_series <- function(n, tc, seed) {
    set.seed(seed)
    phi <- exp(-1 / (100 * tc))
    rnorm(n, sd = 0.01) +
      as.numeric(stats::filter(rnorm(n, sd = 0.01 * sqrt(1 - phi^2)), phi, method = "recursive"))
  }
  effects_of <- function(x) {
    f <- avfit(allan(x, 100), terms = c("N", "gm"))
    ci <- confint(f)["gm1.tc", ]
    list(text = unique(datasheet(allanvar:::fit_analysis(f, unit = "rad/s"))$long$effects),
         ratio = max(coef(f)[["gm1.tc"]] / ci[[1]], ci[[2]] / coef(f)[["gm1.tc"]]), ci = ci)
  }
  short <- effects_of(gm_series(6e4, 60, 5))
  expect_gt(short$ratio, 2)
  expect_match(short$text, "^gm1 not determined: tc's 95% interval ")
  expect_match(short$text, format_num(short$ci[[2]], 3), fixed = TRUE)
  long <- effects_of(gm_series(6e5, 6, 5))
  expect_lt(long$ratio, 2)
  expect_identical(long$text, "none")
})
