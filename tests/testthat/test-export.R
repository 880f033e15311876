test_that("kalman_params() follows the stated discrete-time conventions", {
  dt <- 0.01
  fp <- kalman_params(c(N = 0.01, K = 1e-4, B = 0.002, gm1.sigma = 0.5,
                        gm1.tc = 10), dt = dt, tau_B = 50)
  get <- function(term, par) fp$value[fp$term == term & fp$parameter == par]
  expect_equal(get("N", "sigma_d"), 0.1)               # 0.01 / sqrt(0.01)
  expect_equal(get("K", "sigma_bd"), 1e-5)             # 1e-4 * sqrt(0.01)
  expect_equal(get("gm1", "phi"), exp(-0.001))         # exp(-0.01 / 10)
  expect_equal(get("gm1", "q_d"), 0.25 * (1 - exp(-0.002)))
  # bias instability as a GM whose ADEV peak sits on the flat minimum
  expect_equal(get("B", "phi"), exp(-0.01 / (50 / 1.893)))
  expect_equal(get("B", "q_d"), (0.664 * 0.002 / 0.6174)^2 *
                 (1 - exp(-0.02 / (50 / 1.893))))
  expect_match(fp$convention[fp$parameter == "sigma_d"], "N / sqrt(dt)", fixed = TRUE)
  expect_match(fp$convention[fp$parameter == "sigma_bd"], "K * sqrt(dt)", fixed = TRUE)
  expect_match(fp$convention[fp$term == "gm1" & fp$parameter == "q_d"],
               "sigma^2 * (1 - phi^2)", fixed = TRUE)
  expect_true(all(fp$dt == dt))
  expect_equal(fp$continuous[fp$parameter == "sigma_d"], 0.01)
  fp2 <- kalman_params(c(N = 0.01, B = 0.002), dt = dt, bias_instability = "omit")
  expect_identical(fp2$parameter, "sigma_d")
  expect_error(kalman_params(c(N = 1)), "`dt`",
    class = "allanvar_error_missing_argument")
  expect_error(kalman_params(c(N = 1), dt = -1), "`dt`",
    class = "allanvar_error_argument")
})

test_that("simulating the discrete parameters gives back the continuous model", {
  # Independent check of the conventions: white noise of std sigma_d and a
  # random walk with steps sigma_bd have AV = N^2/tau + K^2 tau/3 (+ the
  # discrete K^2 dt^2/(6 tau)); the AR(1) has stationary variance sigma^2.
  dt <- 0.01
  N <- 2e-3
  K <- 5e-4
  fp <- kalman_params(c(N = N, K = K, gm1.sigma = 0.3, gm1.tc = 0.5), dt = dt)
  get <- function(term, par) fp$value[fp$term == term & fp$parameter == par]
  set.seed(11)
  n <- 4e5
  y <- get("N", "sigma_d") * rnorm(n) + cumsum(get("K", "sigma_bd") * rnorm(n))
  av <- avar(y, 1 / dt)
  sel <- av$time >= 0.1 & av$time <= 50
  expect_av <- N^2 / av$time + K^2 * av$time / 3 + K^2 * dt^2 / (6 * av$time)
  expect_lt(max(abs(av$av[sel] / expect_av[sel] - 1)), 0.25)
  expect_lt(abs(mean(av$av[sel] / expect_av[sel]) - 1), 0.06)
  phi <- get("gm1", "phi")
  w <- rnorm(n, sd = sqrt(get("gm1", "q_d")))
  x <- stats::filter(w, phi, method = "recursive")
  expect_equal(var(x[-(1:1000)]), 0.3^2, tolerance = 0.05)
})

test_that("write_kalibr_yaml() writes Kalibr's keys with units in comments", {
  f <- tempfile(fileext = ".yaml")
  on.exit(unlink(f))
  vals <- list(gyroscope_noise_density = 1.7e-4, gyroscope_random_walk = 2e-5,
               accelerometer_noise_density = 2e-3,
               accelerometer_random_walk = 3e-3, update_rate = 200)
  out <- write_kalibr_yaml(vals, f)
  txt <- readLines(f)
  expect_true(any(grepl("^gyroscope_noise_density: +1.700000e-04 +# \\[rad/s/sqrt\\(Hz\\)\\]", txt)))
  expect_true(any(grepl("^gyroscope_random_walk: .*\\[rad/s\\^2/sqrt\\(Hz\\)\\]", txt)))
  expect_true(any(grepl("^accelerometer_noise_density: .*\\[m/s\\^2/sqrt\\(Hz\\)\\]", txt)))
  expect_true(any(grepl("^accelerometer_random_walk: .*\\[m/s\\^3/sqrt\\(Hz\\)\\]", txt)))
  expect_true(any(grepl("continuous time", txt)))
  skip_if_not_installed("yaml")
  y <- yaml::read_yaml(f)
  expect_equal(y$gyroscope_noise_density, 1.7e-4)
  expect_equal(y$accelerometer_random_walk, 3e-3)
  expect_equal(y$update_rate, 200)
  expect_identical(y$rostopic, "/imu0")
  write_kalibr_yaml(vals, f, inflate = 2)
  y2 <- yaml::read_yaml(f)
  expect_equal(y2$gyroscope_random_walk, 4e-5)
  expect_equal(y2$update_rate, 200)
  expect_error(write_kalibr_yaml(vals[-1], f), "lacks gyroscope_noise_density",
    class = "allanvar_error_argument")
  expect_error(write_kalibr_yaml(vals, f, inflate = 0.5), "`inflate`",
    class = "allanvar_error_argument")
})

test_that("write_kalibr_yaml() takes the worst axis of an analysis and says so", {
  skip_if_not_installed("yaml")
  n <- 4e4
  m <- cbind(gyro_x = avsim(n, 100, N = 1e-3, K = 1e-4, seed = 1),
             gyro_y = avsim(n, 100, N = 3e-3, K = 1e-4, seed = 2),
             accel_x = avsim(n, 100, N = 2e-2, K = 1e-3, seed = 3),
             accel_y = avsim(n, 100, N = 1e-2, K = 4e-3, seed = 4))
  a <- suppressWarnings(analyze_imu(imu_record(m, freq = 100), progress = FALSE))
  f <- tempfile(fileext = ".yaml")
  on.exit(unlink(f))
  write_kalibr_yaml(a, f)
  y <- yaml::read_yaml(f)
  val <- function(ch, term) {
    r <- a$channels[[ch]]$readings
    r$value[r$term == term]
  }
  expect_equal(y$gyroscope_noise_density, max(val("gyro_x", "N"), val("gyro_y", "N")),
               tolerance = 1e-6)
  expect_equal(y$accelerometer_random_walk,
               max(val("accel_x", "K"), val("accel_y", "K")), tolerance = 1e-6)
  expect_equal(y$update_rate, 100)
  txt <- readLines(f)
  expect_true(any(grepl("gyroscope_noise_density.*worst axis \\(gyro_y\\)", txt)))
  expect_true(any(grepl("accelerometer_random_walk.*worst axis \\(accel_y\\)", txt)))
  # the white-noise level is recovered to within 15%
  expect_equal(y$gyroscope_noise_density, 3e-3, tolerance = 0.15)
  write_kalibr_yaml(a, f, axis = "mean")
  y2 <- yaml::read_yaml(f)
  expect_equal(y2$gyroscope_noise_density, mean(c(val("gyro_x", "N"), val("gyro_y", "N"))),
               tolerance = 1e-6)
  # filter parameters of the same analysis: sigma_d = N / sqrt(dt) per axis
  fp <- kalman_params(a)
  expect_equal(fp$value[fp$channel == "gyro_y" & fp$parameter == "sigma_d"],
               val("gyro_y", "N") / sqrt(0.01))
  expect_identical(unique(fp$unit[fp$sensor == "accel" & fp$parameter == "sigma_d"]),
                   "m/s^2")
})

test_that("write_kalibr_yaml() and kalman_params() errors are classed and worded", {
  f <- tempfile(fileext = ".yaml")
  on.exit(unlink(f))
  vals <- list(gyroscope_noise_density = 1.7e-4, gyroscope_random_walk = 2e-5,
               accelerometer_noise_density = 2e-3,
               accelerometer_random_walk = 3e-3, update_rate = 200)
  expect_snapshot(error = TRUE, {
    write_kalibr_yaml()
    write_kalibr_yaml(vals[-1], f)
    write_kalibr_yaml(vals, f, inflate = 0.5)
    write_kalibr_yaml(vals, f, axis = "min")
    write_kalibr_yaml("x", f)
    kalman_params()
    kalman_params(c(N = 1))
    kalman_params(c(N = 1), dt = -1)
    kalman_params("x", dt = 1)
    kalman_params(c(N = 1), dt = 1, bias_instability = "none")
  })
  expect_error(kalman_params(c(N = 1)), class = "allanvar_error_missing_argument")
})

test_that("YAML output quotes what it copies from the user", {
  f <- tempfile(fileext = ".yaml")
  on.exit(unlink(f))
  vals <- list(gyroscope_noise_density = 1.7e-4, gyroscope_random_walk = 2e-5,
               accelerometer_noise_density = 2e-3,
               accelerometer_random_walk = 3e-3, update_rate = 200)
  evil <- c("a\nb: evil", "x\" # y", "back\\slash", "tab\there: 1", "'single'",
            "- item", "{a: 1}", "\u00b5s")
  for (topic in evil) {
    write_kalibr_yaml(vals, f, rostopic = topic)
    y <- yaml::read_yaml(f)
    # the topic comes back as it was given, and no key was added
    expect_identical(y$rostopic, topic)
    expect_setequal(names(y), c("accelerometer_noise_density",
                                "accelerometer_random_walk",
                                "gyroscope_noise_density",
                                "gyroscope_random_walk", "rostopic",
                                "update_rate"))
  }
  # a record name with a line break stays inside its comment line
  set.seed(2)
  m <- cbind(gyro_x = rnorm(3000) * 1e-3, accel_x = rnorm(3000) * 1e-2)
  r <- imu_record(m, freq = 100, units = c("rad/s", "m/s^2"),
                  name = "rec\nbad_key: 1")
  a <- suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE))
  write_kalibr_yaml(a, f)
  y <- yaml::read_yaml(f)
  expect_null(y$bad_key)
  expect_length(grep("^bad_key", readLines(f)), 0)
})

test_that("writers refuse bad output paths and leave no half file", {
  vals <- list(gyroscope_noise_density = 1.7e-4, gyroscope_random_walk = 2e-5,
               accelerometer_noise_density = 2e-3,
               accelerometer_random_walk = 3e-3, update_rate = 200)
  d <- tempfile("outdir")
  dir.create(d)
  on.exit(unlink(d, recursive = TRUE))
  for (bad in list(d, "", "   ", file.path(d, "no", "such", "x.yaml"), NA_character_,
                   c("a", "b"), 1)) {
    expect_error(write_kalibr_yaml(vals, bad),
                 class = "allanvar_error_output_path")
  }
  expect_snapshot(error = TRUE, {
    write_kalibr_yaml(vals, "")
    write_kalibr_yaml(vals, 1)
  })
  # a failure while writing leaves the old file as it was and no temporary
  f <- file.path(d, "imu.yaml")
  writeLines("old", f)
  expect_error(write_atomic(f, function(path) {
    writeLines("half", path)
    stop("disk full")
  }), "disk full", class = "simpleError")
  expect_identical(readLines(f), "old")
  expect_identical(list.files(d, all.files = TRUE, no.. = TRUE), "imu.yaml")
  # a success replaces it whole
  write_kalibr_yaml(vals, f)
  expect_identical(yaml::read_yaml(f)$update_rate, 200)
  expect_identical(list.files(d, all.files = TRUE, no.. = TRUE), "imu.yaml")
})

test_that("kalman_params() refuses garbage instead of returning it", {
  # tau_B = -1 gave q_d < 0 and phi > 1; "a" silently dropped the B row
  cf <- c(N = 1e-3, B = 1e-4, K = 1e-5)
  for (tb in list(-1, 0, "a", NA_real_, Inf, c(1, 2))) {
    expect_error(kalman_params(cf, dt = 0.01, tau_B = tb),
                 "`tau_B`", class = "allanvar_error_argument")
  }
  for (x in list(c(N = -1e-3), c(N = NaN), c(N = Inf), c(N = 1e-3, K = -1),
                 c(N = 1e-3, N = 2e-3),
                 stats::setNames(1e-3, ""), c(1e-3))) {
    expect_error(kalman_params(x, dt = 0.01), class = "allanvar_error_argument")
  }
  expect_error(kalman_params(cf, dt = 0), "`dt`", class = "allanvar_error_argument")
  expect_error(kalman_params(cf, dt = 0.01, unit = "furlong"),
               class = "allanvar_error_units")
  # a valid tau_B: phi = exp(-dt / Tc) with Tc = tau_B / 1.893, in (0, 1),
  # and q_d = sigma^2 (1 - phi^2) > 0 with sigma = 0.664 B / 0.6174
  fp <- kalman_params(cf, dt = 0.01, tau_B = 20)
  phi <- fp$value[fp$parameter == "phi"]
  expect_equal(phi, exp(-0.01 / (20 / 1.893)))
  expect_equal(fp$value[fp$parameter == "q_d"],
               (0.664 * 1e-4 / 0.6174)^2 * (1 - phi^2), tolerance = 2e-3)
  expect_true(all(fp$value > 0))
})

test_that("a gyro-only record writes a valid imu.yaml holding only the gyro", {
  set.seed(5)
  m <- cbind(gyro_x = rnorm(1e4) * 1e-3, gyro_y = rnorm(1e4) * 2e-3)
  r <- imu_record(m, freq = 100, units = c("rad/s", "rad/s"))
  a <- suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE))
  f <- tempfile(fileext = ".yaml")
  on.exit(unlink(f))
  write_kalibr_yaml(a, f)
  txt <- readLines(f)
  expect_false(any(grepl("nan", txt, ignore.case = TRUE)))
  expect_match(txt, "# (no accelerometer channel in the record", fixed = TRUE,
               all = FALSE)
  y <- yaml::read_yaml(f)
  expect_setequal(names(y), c("gyroscope_noise_density", "gyroscope_random_walk",
                              "rostopic", "update_rate"))
  # N of the worst axis: sigma / sqrt(freq) = 2e-3 / 10
  expect_equal(y$gyroscope_noise_density, 2e-4, tolerance = 0.1)
})

test_that("write_kalibr_yaml() writes a fit of another tool's curve", {
  tau <- 10^seq(-1, 2, 0.1)
  cv <- data.frame(tau = tau, avar = 1e-8 / tau + 1e-12 * tau / 3, unit = "rad/s")
  fit <- avfit(cv, c("N", "K"), n = 1e6, freq = 200)
  f <- tempfile(fileext = ".yaml")
  on.exit(unlink(f))
  write_kalibr_yaml(fit, f)
  y <- yaml::read_yaml(f)
  expect_equal(y$gyroscope_noise_density, 1e-4, tolerance = 1e-3)
  expect_equal(y$gyroscope_random_walk, 1e-6, tolerance = 1e-2)
  expect_null(y$accelerometer_noise_density)
  expect_equal(y$update_rate, 200)
  un <- avfit(cv[c("tau", "avar")], "N", n = 1e6, freq = 200)
  expect_error(write_kalibr_yaml(un, f), "unit", class = "allanvar_error_argument")
})

test_that("write_kalibr_yaml() refuses a sensor with a value it could not read", {
  # 3 samples: no -1/2 region, so N is not read; K would be a bound
  r <- imu_record(cbind(gyro_x = c(0.001, 0.002, 0.0015)), freq = 100,
                  units = "rad/s")
  a <- suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE))
  f <- tempfile(fileext = ".yaml")
  expect_error(write_kalibr_yaml(a, f), "gyroscope_noise_density could not be read",
               class = "allanvar_error_argument")
  expect_false(file.exists(f))
})

test_that("a Gauss-Markov term's rows say how well the record determines it", {
  # own generator: white + walk + an AR(1) of tc 10 s over 4000 s; the
  # exact Fisher information of that model puts log tc's SD at 0.096
  # (av_information()), so a factor-2 95% interval is within reach
  set.seed(11)
  n <- 4e5
  phi <- exp(-1 / (100 * 10))
  g <- as.numeric(stats::filter(rnorm(n, sd = 0.003 * sqrt(1 - phi^2)), phi, "recursive"))
  x <- rnorm(n, sd = 0.01) + cumsum(rnorm(n, sd = 1e-5)) + g
  bound <- av_information(c(N = 1e-3, K = 1e-4, gm1.sigma = 0.003, gm1.tc = 10),
                          n = n, freq = 100)$bound
  expect_lt(bound$rel_se[bound$parameter == "gm1.tc"], log(2) / 1.96 / 2)
  a <- suppressWarnings(analyze_imu(imu_record(cbind(gyro_x = x), freq = 100, unit = "rad/s")))
  kp <- kalman_params(a)
  gm <- kp[grepl("^gm", kp$term), , drop = FALSE]
  expect_identical(nrow(gm), 2L)
  expect_identical(unique(gm$verdict), "measured")
  tc <- -0.01 / log(gm$value[gm$parameter == "phi"])
  expect_lt(abs(log(tc / 10)), 1.96 * 0.096 + 0.05)

  # the rule itself, on a fit's layout: 1.96 standard errors of the log
  # within log 2 is measured; wider, or a value held, is not
  lay <- data.frame(name = c("gm1.sigma", "gm1.tc"), label = "gm1", kind = "gm",
                    variant = "", param = c("sigma", "tc"), role = c("amp", "nonlinear"),
                    unit = c("u", "s"), hidden = FALSE, fixed = FALSE)
  fit <- function(se_tc, fixed = c(FALSE, FALSE)) {
    lay$fixed <- fixed
    list(layout = lay, coefficients = c(gm1.sigma = 0.002, gm1.tc = 50),
         se = c(gm1.sigma = 1e-4, gm1.tc = se_tc))
  }
  ns <- asNamespace("allanvar")
  v <- ns$term_verdict(fit(50 * 0.3), "gm1")
  expect_identical(v$verdict, "measured")
  expect_equal(c(v$lo, v$hi), 50 * exp(c(-1, 1) * 1.96 * 0.3), tolerance = 1e-3)
  v <- ns$term_verdict(fit(50 * 0.4), "gm1")
  expect_identical(v$verdict, "not_determined")
  expect_match(v$why, "tc's 95% interval 22.8-110 s is wider than a factor 2", fixed = TRUE)
  v <- ns$term_verdict(fit(0, fixed = c(FALSE, TRUE)), "gm1")
  expect_identical(v$verdict, "not_determined")
  expect_match(v$why, "tc held in the final fit", fixed = TRUE)
  # the guidance's reading judges the estimated values only
  expect_identical(ns$term_verdict(fit(50 * 0.3, fixed = c(FALSE, TRUE)), "gm1",
                                   free_only = TRUE)$verdict, "measured")
  expect_null(ns$term_verdict(fit(0, fixed = c(TRUE, TRUE)), "gm1", free_only = TRUE))
})

test_that("a term's verdict follows it when a fast GM before it is folded into N", {
  # gm1 (tc 0.05 s) folds into the white noise; kalman_params() and the
  # guidance then call the 50 s GM "gm1", and its verdict is its own (on
  # b66a8d2 the row took the folded GM's: held, not determined)
  lay <- data.frame(name = c("N", "gm1.sigma", "gm1.tc", "gm2.sigma", "gm2.tc"),
                    label = c("N", "gm1", "gm1", "gm2", "gm2"), kind = c("N", "gm", "gm", "gm", "gm"),
                    variant = "", param = c("N", "sigma", "tc", "sigma", "tc"),
                    role = c("amp", "amp", "nonlinear", "amp", "nonlinear"),
                    unit = c("u", "u", "s", "u", "s"), hidden = FALSE,
                    fixed = c(FALSE, FALSE, TRUE, FALSE, FALSE))
  cf <- c(N = 1e-3, gm1.sigma = 0.01, gm1.tc = 0.05, gm2.sigma = 0.002, gm2.tc = 50)
  fit <- list(layout = lay, coefficients = cf,
              se = c(N = 1e-5, gm1.sigma = 1e-3, gm1.tc = NA, gm2.sigma = 1e-4, gm2.tc = 5))
  rd <- data.frame(term = "N", folded = "gm1", stringsAsFactors = FALSE)
  tv <- asNamespace("allanvar")$own_term_verdicts(fit, cf, rd)
  expect_named(tv, "gm1")
  expect_identical(tv$gm1$verdict, "measured")
  expect_equal(c(tv$gm1$lo, tv$gm1$hi), 50 * exp(c(-1, 1) * 1.96 * 0.1), tolerance = 1e-3)
  # not folded, both are their own terms, under their own names
  rd$folded <- ""
  tv <- asNamespace("allanvar")$own_term_verdicts(fit, cf, rd)
  expect_named(tv, c("gm1", "gm2"))
  expect_identical(tv$gm1$verdict, "not_determined")
})
