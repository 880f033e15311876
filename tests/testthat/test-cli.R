adis_csv <- function(n = 2e5) {
  m <- readRDS(shared_file("adis16405_unit1.rds"))[seq_len(n), ]
  si <- cbind(m[, 1:3] * pi / 180, m[, 4:6] * 9.80665)
  write_kalibr_csv(si, tempfile(fileext = ".csv"), freq = 100)
}

# The 200,000-row CSV and its in-process run are shared by the first two
# tests (the analysis of six axes is the slow part).
cli_cache <- new.env()
withr_cleanup <- function() unlink(c(cli_cache$csv, cli_cache$out), recursive = TRUE)

# Overlapping Allan deviation at cluster size m, straight from the definition.
oadev <- function(y, m, freq) {
  th <- c(0, cumsum(y)) / freq
  k <- seq_len(length(th) - 2 * m)
  sqrt(mean((th[k + 2 * m] - 2 * th[k + m] + th[k])^2) / (2 * (m / freq)^2))
}

check_outputs <- function(dir) {
  files <- file.path(dir, c("allan_deviation.png", "datasheet.csv", "imu.yaml",
                            "filter_params.csv"))
  expect_true(all(file.exists(files)))
  png_magic <- readBin(files[1], "raw", 8)
  expect_identical(png_magic[2:4], charToRaw("PNG"))
  ds <- utils::read.csv(files[2])
  expect_setequal(unique(ds$axis), c("gyro_x", "gyro_y", "gyro_z",
                                     "accel_x", "accel_y", "accel_z"))
  expect_true(all(is.finite(ds$value)))
  y <- yaml::read_yaml(files[3])
  expect_true(all(c("gyroscope_noise_density", "gyroscope_random_walk",
                    "accelerometer_noise_density", "accelerometer_random_walk",
                    "update_rate") %in% names(y)))
  list(ds = ds, yaml = y, fp = utils::read.csv(files[4]))
}

test_that("a Kalibr CSV of a measured ADIS16405 gives plot, datasheet and imu.yaml in one R call", {
  skip_if_no_shared()
  skip_if_not_installed("yaml")
  csv <- cli_cache$csv <- adis_csv()
  out <- cli_cache$out <- tempfile("cli")
  expect_output(res <- allanvar_cli(c(csv, "--out", out, "--quiet", "--no-refine")),
                "Gyroscopes")
  o <- check_outputs(out)
  expect_equal(o$yaml$update_rate, 100)
  # the yaml holds the worst axis of the datasheet, in SI
  n_gyro <- o$ds$value[o$ds$sensor == "gyro" & o$ds$term == "N" &
                         o$ds$unit == "rad/s/sqrt(Hz)"]
  expect_equal(o$yaml$gyroscope_noise_density, max(n_gyro), tolerance = 1e-6)
  k_acc <- o$ds$value[o$ds$sensor == "accel" & o$ds$term == "K" &
                        o$ds$unit == "m/s^3/sqrt(Hz)"]
  expect_equal(o$yaml$accelerometer_random_walk, max(k_acc), tolerance = 1e-6)
  # independent check of N: the gyros are white-noise dominated at tau = 1 s,
  # where ADEV = N; computed here from the definition on the same samples.
  r <- read_imu(csv)
  hand <- vapply(1:3, function(j) oadev(r$data[, j], 100, 100), 0)
  expect_equal(max(n_gyro), max(hand), tolerance = 0.2)
  # the filter step of the yaml's rate: sigma_d = N / sqrt(0.01)
  sd <- o$fp$value[o$fp$parameter == "sigma_d" & o$fp$channel == "gyro_x"]
  expect_equal(sd, n_gyro[1] / sqrt(0.01), tolerance = 1e-6)
  expect_length(res$files, 5)  # with report.html
})

test_that("the same outputs come from one shell command", {
  skip_if_no_shared()
  skip_if_not_installed("yaml")
  skip_if_not(installed_allanvar(), "needs the installed package")
  bin <- system.file("bin", "allanvar", package = "allanvar")
  skip_if_not(nzchar(bin))
  skip_if(is.null(cli_cache$out), "the in-process run did not happen")
  csv <- cli_cache$csv
  out1 <- cli_cache$out
  out2 <- tempfile("sh")
  on.exit(unlink(out2, recursive = TRUE))
  on.exit(withr_cleanup(), add = TRUE)
  rscript <- file.path(R.home("bin"), "Rscript")
  log <- suppressWarnings(system2(rscript, c(shQuote(bin), shQuote(csv), "--no-refine", "--out",
                                             shQuote(out2), "--quiet"),
                                  stdout = TRUE, stderr = TRUE))
  expect_null(attr(log, "status"))
  expect_true(any(grepl("Written:", log)))
  o2 <- check_outputs(out2)
  o1 <- check_outputs(out1)
  expect_equal(o2$yaml, o1$yaml)
  expect_equal(o2$ds, o1$ds)
  # and through Rscript -e with --args, as in the README (a shorter file)
  out3 <- tempfile("e")
  csv3 <- adis_csv(2e4)
  on.exit(unlink(c(out3, csv3), recursive = TRUE), add = TRUE)
  log3 <- suppressWarnings(system2(rscript, c("-e", shQuote("allanvar::allanvar_cli()"),
                                              "--args", shQuote(csv3), "--out",
                                              shQuote(out3), "--quiet", "--no-refine"),
                                   stdout = TRUE, stderr = TRUE))
  expect_null(attr(log3, "status"))
  expect_true(file.exists(file.path(out3, "imu.yaml")))
  # a failing command exits with status 1 and says why
  bad <- suppressWarnings(system2(rscript, c(shQuote(bin), "--bogus"),
                                  stdout = TRUE, stderr = TRUE))
  expect_identical(attr(bad, "status"), 1L)
  expect_true(any(grepl("unknown option --bogus", bad)))
})

test_that("options describe other layouts; bad options are refused", {
  set.seed(3)
  n <- 6000
  d <- data.frame(time = (0:(n - 1)) / 50, gx = rnorm(n, sd = 0.05),
                  gy = rnorm(n, sd = 0.05), ax = rnorm(n, sd = 2))
  f <- tempfile(fileext = ".csv")
  out <- tempfile("cli")
  on.exit(unlink(c(f, out), recursive = TRUE))
  utils::write.csv(d, f, row.names = FALSE)
  capture.output(res <- suppressWarnings(allanvar_cli(c(
    f, "--out", out, "--gyro-cols", "gx,gy", "--accel-cols", "ax",
    "--gyro-units", "deg/s", "--accel-units=mg", "--time-unit", "s",
    "--no-refine", "--quiet", "--average"))))
  a <- res$analyses[[1]]
  expect_equal(a$freq, 50)
  expect_equal(unname(a$channels$gyro_y$unit), "rad/s")
  r <- read_imu(f, time_unit = "s", columns = c("gx", "gy", "ax"),
                sensors = c("gyro", "gyro", "accel"),
                units = c(gyro = "deg/s", accel = "mg"))
  b <- suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE))
  expect_equal(a$channels$gyro_x$readings, b$channels$gyro_x$readings)
  ds <- utils::read.csv(file.path(out, "datasheet.csv"))
  expect_true("mean of axes" %in% ds$axis)
  expect_error(allanvar:::cli_run("--bogus"), "unknown option --bogus",
    class = "allanvar_error_cli")
  expect_error(allanvar:::cli_run(c(f, "--rate")), "needs a value",
    class = "allanvar_error_cli")
  expect_error(allanvar:::cli_run(c(f, "--rate", "fast")), "--rate must be a number",
    class = "allanvar_error_cli")
  expect_error(allanvar:::cli_run(character()), "no input file",
    class = "allanvar_error_cli")
  expect_output(allanvar_cli("--help"), "Usage: allanvar")
})

cli_csv <- function(n = 3000, freq = 100, seed = 4) {
  set.seed(seed)
  f <- tempfile(fileext = ".csv")
  d <- data.frame(time = (0:(n - 1)) / freq, p = rnorm(n, sd = 0.02),
                  q = rnorm(n, sd = 0.02), r = rnorm(n, sd = 0.02))
  utils::write.csv(d, f, row.names = FALSE)
  f
}

test_that("the CLI's errors and warnings name its flags, not R arguments", {
  f <- cli_csv()
  out <- tempfile("cli")
  on.exit(unlink(c(f, out), recursive = TRUE))
  # no recognizable gyro columns -> the flags to choose them
  expect_error(allanvar:::cli_run(c(f, "--out", out, "--quiet")),
               "--gyro-cols / --accel-cols", class = "allanvar_error_no_columns")
  # no time column -> --time-col / --rate
  f2 <- tempfile(fileext = ".csv")
  on.exit(unlink(f2), add = TRUE)
  writeLines(c("a,gyro_x", "1,0.1", "2,0.2"), f2)
  err <- expect_error(allanvar:::cli_run(c(f2, "--out", out, "--quiet")),
                      class = "allanvar_error_no_time")
  expect_match(conditionMessage(err), "--time-col")
  expect_match(conditionMessage(err), "--rate")
  expect_no_match(conditionMessage(err), "`")
  # seconds declared as ns -> --time-unit s
  err <- expect_error(allanvar:::cli_run(c(f, "--out", out, "--quiet", "--gyro-cols",
                                           "p,q,r", "--time-unit", "ns")),
                      class = "allanvar_error_time_unit")
  expect_match(conditionMessage(err), "--time-unit s")
  expect_false(dir.exists(out))
  # deg/s data taken as rad/s -> a loud warning naming --gyro-units
  g <- tempfile(fileext = ".csv")
  on.exit(unlink(g), add = TRUE)
  n <- 6000
  set.seed(5)
  utils::write.csv(data.frame(time = (0:(n - 1)) / 100, gx = rnorm(n, sd = 0.3),
                              gy = rnorm(n, sd = 0.3)), g, row.names = FALSE)
  msgs <- character()
  capture.output(withCallingHandlers(
    allanvar:::cli_run(c(g, "--out", out, "--gyro-cols", "gx,gy", "--no-refine",
                         "--quiet")),
    message = function(m) {
      msgs <<- c(msgs, conditionMessage(m))
      invokeRestart("muffleMessage")
    }))
  w <- grep("gyroscope units look wrong", msgs, value = TRUE)
  expect_length(w, 1L)
  expect_match(w, "--gyro-units deg/s")
  expect_no_match(w, "units = c")
  expect_true(any(grepl("assuming rad/s.*--gyro-units / --accel-units", msgs)))
})

test_that("--terms, --axis, --gap and units are validated, naming the flag", {
  f <- cli_csv()
  on.exit(unlink(f))
  expect_error(allanvar:::cli_run(c(f, "--terms", "N,X")),
               "--terms: unknown term\\(s\\) X", class = "allanvar_error_cli")
  expect_error(allanvar:::cli_run(c(f, "--axis", "worst")), "--axis must be one of",
    class = "allanvar_error_cli")
  expect_error(allanvar:::cli_run(c(f, "--gap", "skip")), "--gap must be one of",
    class = "allanvar_error_cli")
  expect_error(allanvar:::cli_run(c(f, "--gyro-units", "furlong/s")),
               "--gyro-units \"furlong/s\" is not a known gyro unit",
               class = "allanvar_error_cli")
  expect_error(allanvar:::cli_run(c(f, "--width", "-3")), "--width must be",
    class = "allanvar_error_cli")
  expect_identical(allanvar:::cli_terms("n,b,K,gm"), c("N", "B", "K", "gm"))
})

test_that("--out is validated and a failed run writes nothing", {
  f <- cli_csv()
  on.exit(unlink(f))
  expect_error(allanvar:::cli_run(c(f, "--out=")), "--out must name a directory",
               class = "allanvar_error_cli")
  expect_error(allanvar:::cli_run(c(f, "--out", f)), "is a file",
               class = "allanvar_error_cli")
  expect_error(allanvar:::cli_run(c(f, "--out", "/")), "root",
               class = "allanvar_error_cli")
  # a 2-row file fails in the analysis: no output at all, not 2 of 4
  two <- tempfile(fileext = ".csv")
  writeLines(c("time,gyro_x", "0,0.001", "0.01,0.002"), two)
  out <- tempfile("cli")
  on.exit(unlink(c(two, out), recursive = TRUE), add = TRUE)
  expect_error(suppressMessages(capture.output(
    allanvar:::cli_run(c(two, "--out", out, "--quiet", "--no-refine")))),
    class = "allanvar_error_record_too_short")
  expect_false(dir.exists(out) && length(list.files(out)) > 0)
  # with a good file first and the bad one second: still nothing written
  expect_error(suppressMessages(capture.output(suppressWarnings(
    allanvar:::cli_run(c(f, two, "--out", out, "--quiet", "--no-refine",
                         "--gyro-cols", "p,q,r"))))),
                         class = "allanvar_error_argument")
  expect_length(list.files(out), 0L)
})

test_that("--width/--height size the PNG; --topic reads a bag", {
  f <- ros_fixture("imu_lz4.bag")
  out <- tempfile("cli")
  on.exit(unlink(out, recursive = TRUE))
  err <- expect_error(allanvar:::cli_run(c(f, "--out", out, "--quiet")),
                      class = "allanvar_error_topic")
  expect_match(conditionMessage(err), "choose one with --topic")
  capture.output(res <- suppressMessages(suppressWarnings(allanvar:::cli_run(c(
    f, "--topic", "/imu0", "--out", out, "--quiet", "--no-refine",
    "--width", "900", "--height", "450")))))
  png <- readBin(file.path(out, "allan_deviation.png"), "raw", 24)
  # PNG IHDR: width and height as big-endian 32-bit integers at bytes 17-24
  be32 <- function(r) sum(as.numeric(r) * 256^(3:0))
  expect_identical(c(be32(png[17:20]), be32(png[21:24])), c(900, 450))
  expect_length(res$files, 5L)  # with report.html
  expect_equal(res$analyses[[1]]$freq, 200, tolerance = 1e-9)
})

test_that("a gyro-only CSV gives a valid imu.yaml holding only the gyro", {
  skip_if_not_installed("yaml")
  set.seed(5)
  m <- matrix(rnorm(3e4) * 1e-3, ncol = 3)
  csv <- write_kalibr_csv(m, tempfile(fileext = ".csv"),
                          header = c("timestamp", "omega_x", "omega_y", "omega_z"))
  out <- tempfile("cli")
  on.exit(unlink(c(csv, out), recursive = TRUE))
  expect_output(allanvar_cli(c(csv, "--out", out, "--quiet", "--no-refine")),
                "Gyroscopes")
  txt <- readLines(file.path(out, "imu.yaml"))
  expect_false(any(grepl("nan", txt, ignore.case = TRUE)))
  expect_match(txt, "no accelerometer channel in the record", fixed = TRUE, all = FALSE)
  y <- yaml::read_yaml(file.path(out, "imu.yaml"))
  expect_setequal(names(y), c("gyroscope_noise_density", "gyroscope_random_walk",
                              "rostopic", "update_rate"))
  # sigma = 1e-3 rad/s at 100 Hz: N = 1e-4 rad/s/sqrt(Hz)
  expect_equal(y$gyroscope_noise_density, 1e-4, tolerance = 0.1)
})
