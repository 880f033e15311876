# analyze_imu(): per-axis orchestration over future.

test_that("every axis gets its own curve on one tau grid, fit and readings", {
  recs <- two_records()
  a <- suppressWarnings(analyze_imu(recs[[1]], progress = FALSE))
  expect_s3_class(a, "imu_analysis")
  expect_identical(names(a$channels), c("gyro_x", "accel_x"))
  expect_identical(a$channels$gyro_x$curve$tau, a$channels$accel_x$curve$tau)
  expect_identical(a$channels$gyro_x$unit, "rad/s")
  expect_identical(a$channels$accel_x$unit, "m/s^2")
  expect_identical(a$channels$gyro_x$readings$term, c("N", "B", "K"))
  expect_equal(a$n, 2e4)
  expect_output(print(a), "imu_analysis")
})

test_that("several recordings through future multisession equal the sequential run", {
  skip_on_cran()
  skip_if_not(installed_allanvar(), "needs the installed package on the workers")
  skip_if_not_installed("future")
  recs <- two_records()
  future::plan(future::sequential)
  seq_run <- suppressWarnings(analyze_imu(recs, progress = FALSE))
  old <- future::plan(future::multisession, workers = 2)
  on.exit(future::plan(future::sequential), add = TRUE)
  par_run <- suppressWarnings(analyze_imu(recs, progress = FALSE))
  future::plan(future::sequential)
  expect_s3_class(par_run, "imu_analysis_list")
  expect_identical(names(par_run), c("rec1", "rec2"))
  expect_identical(datasheet(par_run)$long, datasheet(seq_run)$long)
  for (i in 1:2) for (ch in c("gyro_x", "accel_x")) {
    expect_identical(par_run[[i]]$channels[[ch]]$curve, seq_run[[i]]$channels[[ch]]$curve)
    expect_identical(par_run[[i]]$channels[[ch]]$coef, seq_run[[i]]$channels[[ch]]$coef)
  }
})

test_that("forked workers give the run one after another; `workers` is checked", {
  skip_on_cran()
  skip_if_not(future::supportsMulticore(), "the platform cannot fork")
  recs <- two_records()
  threads <- getOption("allanvar.threads")
  one <- suppressWarnings(analyze_imu(recs, progress = FALSE, workers = 1))
  two <- suppressWarnings(analyze_imu(recs, progress = FALSE, workers = 2))
  expect_identical(datasheet(two)$long, datasheet(one)$long)
  for (i in 1:2) for (ch in c("gyro_x", "accel_x")) {
    expect_identical(two[[i]]$channels[[ch]]$coef, one[[i]]$channels[[ch]]$coef)
    expect_identical(two[[i]]$channels[[ch]]$readings, one[[i]]$channels[[ch]]$readings)
  }
  # the caller's plan is back, and the caller's thread option untouched
  expect_true(inherits(future::plan(), "sequential"))
  expect_identical(getOption("allanvar.threads"), threads)
  # the workers are one fork cluster started once (multicore would fork a
  # fresh process per axis), and the caller's plan comes back after it
  restore <- axis_plan(2L)
  expect_s3_class(future::plan(), "cluster")
  expect_identical(future::nbrOfWorkers(), 2L)
  restore()
  expect_true(inherits(future::plan(), "sequential"))
  # by default: forks only under the sequential plan, for a large record
  expect_identical(axis_workers(NULL, 6L, 6e6),
                   min(allanvar_threads(), as.integer(future::availableCores())))
  expect_identical(axis_workers(NULL, 2L, 4e4), 1L)
  expect_identical(axis_workers(NULL, 1L, 1e6), 1L)
  expect_identical(axis_workers(5, 3L, 10), 3L)
  expect_error(analyze_imu(recs, workers = 0), class = "allanvar_error_argument")
  expect_snapshot(analyze_imu(recs, workers = 1.5), error = TRUE)
})

test_that("progress is reported per axis and can be silenced", {
  r <- two_records()[[1]]
  msg <- capture_messages(suppressWarnings(analyze_imu(r, progress = TRUE)))
  # one per axis, then one line pointing to the guidance (if any)
  g <- grepl("guidance note", msg)
  expect_lte(sum(g), 1L)
  msg <- msg[!g]
  expect_length(msg, 2)
  expect_match(msg[1], "analysing \\[1/2\\] rec1: gyro_x")
  expect_match(msg[2], "analysing \\[2/2\\] rec1: accel_x")
  expect_silent(suppressWarnings(analyze_imu(r, progress = FALSE)))
  expect_error(analyze_imu(r, progress = NA), "`progress`",
    class = "allanvar_error_argument")
})

test_that("segments: the longest by default, or each on its own", {
  set.seed(1)
  x <- cbind(gyro_x = rnorm(2900, sd = 1e-3))
  t <- c(0:999, 1100:2999) / 100
  expect_warning(r <- imu_record(x, time = t), "gap")
  a <- suppressWarnings(analyze_imu(r, progress = FALSE))
  expect_equal(a$n, 1900)
  al <- suppressWarnings(analyze_imu(r, segment = "each", progress = FALSE))
  expect_s3_class(al, "imu_analysis_list")
  expect_equal(vapply(al, function(z) z$n, 0), c(1000, 1900), ignore_attr = TRUE)
  expect_error(analyze_imu(r, segment = 5), "segment", class = "allanvar_error")
})

test_that("file paths are read and analysed; bad input is refused", {
  m <- cbind(matrix(rnorm(3 * 4000, sd = 1e-3), 4000), matrix(rnorm(3 * 4000), 4000))
  f <- write_kalibr_csv(m, tempfile(fileext = ".csv"))
  on.exit(unlink(f))
  a <- suppressWarnings(analyze_imu(f, progress = FALSE))
  expect_length(a$channels, 6)
  expect_error(analyze_imu(1), "imu_record", class = "allanvar_error_argument")
  expect_error(analyze_imu(two_records()[[1]], channels = "gyro_q"), "not in",
    class = "allanvar_error_argument")
})

test_that("effects the closed loop adds reach the datasheet", {
  x <- avsim(2e4, 100, N = 1e-3, K = 1e-3, gm = list(sigma = 0.02, tc = 2), seed = 1)
  r <- imu_record(cbind(gyro_x = as.numeric(x)), freq = 100)
  a <- suppressWarnings(analyze_imu(r, progress = FALSE))
  st <- a$channels$gyro_x$fit$steps
  expect_true("gm" %in% st$effect)
  expect_match(a$datasheet$gyro$effects, "gm \\(Tc = ")
  # the GM (Tc near 2 s, not white-like) goes to the filter as phi, q_d
  fp <- kalman_params(a)
  tc <- a$channels$gyro_x$coef[["gm1.tc"]]
  sig <- a$channels$gyro_x$coef[["gm1.sigma"]]
  expect_equal(fp$value[fp$term == "gm1" & fp$parameter == "phi"], exp(-0.01 / tc))
  expect_equal(fp$value[fp$term == "gm1" & fp$parameter == "q_d"],
               sig^2 * (1 - exp(-0.02 / tc)))
})

test_that("analyze_imu() errors are classed and worded", {
  r <- two_records()[[1]]
  expect_snapshot(error = TRUE, {
    analyze_imu()
    analyze_imu(1)
    analyze_imu(character())
    analyze_imu(r, refine = NA)
    analyze_imu(r, progress = "yes")
    analyze_imu(r, channels = "gyro_q")
    analyze_imu(r, refine_args = 1)
  })
  expect_error(analyze_imu(1), class = "allanvar_error_argument")
})

test_that("analyze_imu reports one progressr step per axis, also from future workers", {
  set.seed(3)
  r <- imu_record(cbind(gyro_x = rnorm(4000, sd = 1e-3), accel_x = rnorm(4000, sd = 1e-2)),
                  freq = 100)
  old_opt <- options(progressr.enable = TRUE)   # progressr is off when not interactive
  on.exit(options(old_opt), add = TRUE)
  got <- function(...) {
    steps <- character()
    withCallingHandlers(
      progressr::with_progress(
        suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE, ...)),
        handlers = progressr::handler_void()),
      progression = function(p) if (identical(p$type, "update")) steps <<- c(steps, p$message))
    steps
  }
  expect_setequal(got(), c("[1/2] in memory: gyro_x", "[2/2] in memory: accel_x"))
  if (future::supportsMulticore()) {
    # from the fork cluster's workers
    expect_setequal(got(workers = 2), c("[1/2] in memory: gyro_x", "[2/2] in memory: accel_x"))
  }
  skip_if_not_installed("future")
  skip_if_not(installed_allanvar(), "workers need the installed package")
  skip_on_cran()
  old <- future::plan(future::multisession, workers = 2L)
  on.exit(future::plan(old), add = TRUE)
  expect_setequal(got(), c("[1/2] in memory: gyro_x", "[2/2] in memory: accel_x"))
  # No handler: nothing is printed.
  expect_silent(suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE)))
})

test_that("a dead (constant) axis is reported and the others analysed", {
  set.seed(11)
  m <- cbind(gyro_x = rnorm(4000) * 1e-3, gyro_y = rep(0.01, 4000),
             gyro_z = rnorm(4000) * 2e-3)
  r <- imu_record(m, freq = 100, units = rep("rad/s", 3))
  expect_warning(
    a <- suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE),
                          classes = "allanvar_guidance"),
    "gyro_y is a dead axis", class = "allanvar_warning_dead_axis")
  expect_identical(a$channels$gyro_y$dead,
                   "dead axis: constant signal (Allan variance 0 at every tau), not analysed")
  expect_null(a$channels$gyro_y$fit)
  # the live axes: white noise N = sigma / sqrt(f), read to within 10%
  ds <- datasheet(a)$gyro
  n_col <- "N [rad/s/sqrt(Hz)]"
  expect_equal(ds[[n_col]][ds$axis == "gyro_x"], 1e-3 / 10, tolerance = 0.1)
  expect_equal(ds[[n_col]][ds$axis == "gyro_z"], 2e-3 / 10, tolerance = 0.1)
  expect_true(is.na(ds[[n_col]][ds$axis == "gyro_y"]))
  expect_match(ds$method[ds$axis == "gyro_y"], "dead axis")
  g <- imu_guidance(a)
  expect_match(g$message[g$channel == "gyro_y"], "dead axis")
  fp <- kalman_params(a)
  expect_false("gyro_y" %in% fp$channel)
  expect_true(all(is.finite(fp$value)))
  # Kalibr: the worst live axis, the dead one listed in the comment
  f <- tempfile(fileext = ".yaml")
  on.exit(unlink(f))
  for (ax in c("max", "mean")) {
    write_kalibr_yaml(a, f, axis = ax)
    y <- yaml::read_yaml(f)
    expect_true(is.numeric(y$gyroscope_noise_density) &&
                  is.finite(y$gyroscope_noise_density))
    expect_match(readLines(f), "gyro_y = NA (dead axis)", fixed = TRUE, all = FALSE)
  }
  expect_equal(y$gyroscope_noise_density, mean(ds[[n_col]][c(1, 3)]),
               tolerance = 1e-6)
})

test_that("each analysed axis signals one progressr step, silently by default", {
  r <- two_records()[[1]]
  steps <- character()
  # progressr signals outside interactive sessions only when enabled
  old <- options(progressr.enable = TRUE)
  on.exit(options(old))
  withCallingHandlers(
    expect_silent(suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE))),
    progression = function(p) {
      if (identical(p$type, "update")) steps <<- c(steps, p$message)
    })
  expect_identical(steps, c("[1/2] rec1: gyro_x", "[2/2] rec1: accel_x"))
})
