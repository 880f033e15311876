# write_report(): the page holds every axis, step and reading with its
# verdict, escapes text copied from the record, fetches nothing, and loads
# in a real browser (headless Chromium) without errors and with a layout
# that is not blank.

# A record with known effects, from this file's own generator (not avsim()):
# white noise, a 1.7 Hz sinusoid on every axis, a first-order Gauss-Markov
# process, a bias step on gyro_x at 60% of the record and two spikes on
# gyro_y.
report_sim_record <- function(n = 6e4, freq = 100, seed = 11) {
  set.seed(seed)
  t <- (seq_len(n) - 1) / freq
  axes <- c("gyro_x", "gyro_y", "accel_x")
  m <- vapply(seq_along(axes), function(k) {
    s <- if (k <= 2) 1e-3 else 5e-3
    phi <- exp(-1 / (freq * 5))
    gm <- stats::filter(rnorm(n, sd = 0.3 * s * sqrt(1 - phi^2)), phi,
                        method = "recursive")
    rnorm(n, sd = s) + as.numeric(gm) + 0.6 * s * sin(2 * pi * 1.7 * t)
  }, numeric(n))
  colnames(m) <- axes
  h <- floor(0.6 * n)
  m[h:n, 1] <- m[h:n, 1] + 5e-3
  m[c(1000, floor(n / 3)), 2] <- m[c(1000, floor(n / 3)), 2] + 0.05
  imu_record(m, freq = freq, units = c(gyro = "rad/s", accel = "m/s^2"))
}

report_fixture <- local({
  cache <- NULL
  function() {
    if (is.null(cache)) {
      rec <- report_sim_record()
      a <- suppressWarnings(analyze_imu(rec, progress = FALSE))
      cache <<- list(rec = rec, a = a)
    }
    cache
  }
})

# Parts of a page found by their markers (attributes written by
# write_report(); the values are escaped text).
page_attr <- function(html, tag_class, attr) {
  rx <- sprintf('<[a-z]+ [^>]*?class="%s"[^>]*? %s="([^"]*)"', tag_class, attr)
  m <- regmatches(html, gregexpr(rx, html, perl = TRUE))[[1L]]
  sub(rx, "\\1", m, perl = TRUE)
}

chromium_bin <- function() {
  b <- Sys.which(c("chromium", "chromium-browser", "google-chrome"))
  b <- b[nzchar(b)]
  if (length(b)) b[[1L]] else ""
}

# Runs headless Chromium on `file` with `what` ("--dump-dom" or
# "--screenshot=PATH") and returns its stdout.
run_chromium <- function(file, what, size = "1280,4000") {
  prof <- tempfile("chromium-profile-")
  dir.create(prof)
  on.exit(unlink(prof, recursive = TRUE), add = TRUE)
  args <- c("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
            "--no-first-run", "--disable-background-networking",
            "--disable-component-update", "--disable-sync",
            paste0("--user-data-dir=", prof), paste0("--window-size=", size),
            "--hide-scrollbars", what,
            paste0("file://", normalizePath(file)))
  cmd <- chromium_bin()
  if (nzchar(Sys.which("timeout"))) {
    args <- c("120", cmd, args)
    cmd <- Sys.which("timeout")
  }
  suppressWarnings(system2(cmd, args, stdout = TRUE, stderr = FALSE))
}

skip_without_chromium <- function() {
  if (!nzchar(chromium_bin())) {
    skip("headless Chromium is not installed (apt-get install chromium); the page is not opened in a browser")
  }
}

# The page in Chromium: loaded, no errors; every axis, step and reading in
# the DOM; a screenshot whose size is right and whose regions are not blank.
check_in_browser <- function(file, a) {
  dom <- paste(run_chromium(file, "--dump-dom"), collapse = "\n")
  expect_match(dom, 'data-report-loaded="1"', fixed = TRUE)
  errors <- regmatches(dom, regexpr('data-report-errors="[^"]*"', dom))
  expect_identical(errors, character())
  chans <- a$channels
  expect_setequal(page_attr(dom, "card axis", "data-axis"),
                  vapply(chans, function(ch) ch$channel, ""))
  n_steps <- sum(vapply(chans, function(ch) NROW(ch$fit$steps), 0L))
  expect_length(page_attr(dom, "step", "data-step"), n_steps)
  verdicts <- page_attr(dom, "reading", "data-verdict")
  expect_length(verdicts, sum(vapply(chans, function(ch) nrow(ch$readings), 0L)))
  expect_true(all(verdicts %in% c("measured", "upper_bound", "lower_bound",
                                   "not_determined")))
  png_file <- tempfile(fileext = ".png")
  on.exit(unlink(png_file), add = TRUE)
  run_chromium(file, paste0("--screenshot=", png_file), size = "1280,3200")
  expect_true(file.exists(png_file))
  skip_if_not_installed("png")
  img <- png::readPNG(png_file)
  expect_equal(dim(img)[1:2], c(3200L, 1280L))
  # ink: pixels darker than the page's background; every horizontal band of
  # the page (header, record, plots, tables) holds some, and the plots'
  # colours are there (not only grey text)
  grey <- (img[, , 1] + img[, , 2] + img[, , 3]) / 3
  ink <- grey < 0.8
  bands <- split(seq_len(nrow(ink)), cut(seq_len(nrow(ink)), 16))
  frac <- vapply(bands, function(r) mean(ink[r, ]), 0)
  expect_gt(min(frac), 0.002)
  expect_lt(max(frac), 0.6)
  chroma <- pmax(img[, , 1], img[, , 2], img[, , 3]) - pmin(img[, , 1], img[, , 2], img[, , 3])
  expect_gt(mean(chroma > 0.25), 0.001)
}

test_that("the report of an analysis holds every axis, step and reading with its verdict", {
  skip_on_cran()
  skip_if_not_installed("svglite")
  fx <- report_fixture()
  a <- fx$a
  f <- tempfile(fileext = ".html")
  on.exit(unlink(f))
  expect_identical(write_report(a, f, record = fx$rec), f)
  html <- paste(readLines(f, encoding = "UTF-8"), collapse = "\n")
  # every axis, every accepted step (the loop found the 1.7 Hz line), every
  # reading with its verdict
  expect_setequal(page_attr(html, "card axis", "data-axis"), names(a$channels))
  steps <- do.call(rbind, lapply(a$channels, function(ch) ch$fit$steps))
  expect_gt(nrow(steps), 0L)
  expect_true(any(grepl("sinusoid", steps$effect)))
  expect_identical(page_attr(html, "step", "data-effect"), steps$effect)
  rd <- do.call(rbind, lapply(a$channels, function(ch) ch$readings))
  expect_identical(page_attr(html, "reading", "data-term"), rd$term)
  expect_length(page_attr(html, "reading", "data-verdict"), nrow(rd))
  # the step on gyro_x is on the time axis and in the series table
  expect_match(html, "rate and series effects", fixed = TRUE)
  expect_match(html, ">steps<", fixed = TRUE)
  # the periodogram marks the line the step added
  expect_match(html, "Periodogram", fixed = TRUE)
  # self-contained: nothing is fetched
  expect_false(grepl("(src|href)=\"(https?:)?//", html))
  expect_false(grepl("url\\((https?:)?//", html))
  expect_false(grepl("<img", html, fixed = TRUE))
  # the other tools' parameters
  expect_match(html, "noise_density", fixed = TRUE)
  expect_lt(file.size(f), 3e6)
})

test_that("text from the record is escaped, never markup", {
  skip_on_cran()
  skip_if_not_installed("svglite")
  fx <- report_fixture()
  a <- fx$a
  evil <- "<script>alert(1)</script>"
  a$name <- evil
  a$record$file <- evil
  names(a$channels)[1] <- evil
  a$channels[[1]]$channel <- evil
  rec <- fx$rec
  rec$topic <- evil
  f <- tempfile(fileext = ".html")
  on.exit(unlink(f))
  write_report(a, f, record = rec)
  html <- paste(readLines(f, encoding = "UTF-8"), collapse = "\n")
  expect_false(grepl(evil, html, fixed = TRUE))
  expect_match(html, "&lt;script&gt;alert(1)&lt;/script&gt;", fixed = TRUE)
  # the page's own probe is its only script
  expect_identical(lengths(regmatches(html, gregexpr("<script", html, fixed = TRUE))), 1L)
  skip_without_chromium()
  dom <- paste(run_chromium(f, "--dump-dom"), collapse = "\n")
  expect_match(dom, 'data-report-loaded="1"', fixed = TRUE)
  expect_identical(regmatches(dom, regexpr('data-report-errors="[^"]*"', dom)),
                   character())
  expect_match(dom, "&lt;script&gt;alert(1)&lt;/script&gt;", fixed = TRUE)
})

test_that("the page loads in headless Chromium without errors and is laid out", {
  skip_on_cran()
  skip_if_not_installed("svglite")
  skip_without_chromium()
  fx <- report_fixture()
  f <- tempfile(fileext = ".html")
  on.exit(unlink(f))
  write_report(fx$a, f, record = fx$rec)
  check_in_browser(f, fx$a)
})

test_that("a report of a fit and of an allan() curve alone", {
  skip_on_cran()
  skip_if_not_installed("svglite")
  fx <- report_fixture()
  fit <- fx$a$channels$gyro_x$fit
  f <- tempfile(fileext = ".html")
  on.exit(unlink(f))
  write_report(fit, f)
  html <- paste(readLines(f), collapse = "\n")
  expect_length(page_attr(html, "card axis", "data-axis"), 1L)
  expect_length(page_attr(html, "step", "data-step"), NROW(fit$steps))
  expect_length(page_attr(html, "reading", "data-verdict"), 3L)
  cv <- fx$a$channels$gyro_x$curve
  write_report(cv, f, title = "gyro x")
  html <- paste(readLines(f), collapse = "\n")
  expect_match(html, "<title>gyro x</title>", fixed = TRUE)
  expect_match(html, "<svg", fixed = TRUE)
  # every tau of the curve is in its table
  expect_equal(lengths(regmatches(html, gregexpr("<tr>", html, fixed = TRUE))),
               nrow(cv) + 1L)
})

test_that("write_report() checks its arguments", {
  fx <- list(a = structure(list(), class = "not_an_analysis"))
  f <- tempfile(fileext = ".html")
  expect_error(write_report(1:3, f), class = "allanvar_error_argument")
  expect_error(write_report(), class = "allanvar_error_missing_argument")
  expect_error(write_report(allan(rnorm(1000), 10), file.path(tempdir(), "no", "such", "x.html")),
               class = "allanvar_error_output_path")
  expect_error(write_report(allan(rnorm(1000), 10), tempdir()),
               class = "allanvar_error_output_path")
  skip_on_cran()
  a <- report_fixture()$a
  expect_error(write_report(a, f, record = "x"), class = "allanvar_error_argument")
  expect_false(file.exists(f))
})

test_that("the CLI writes report.html beside its outputs, and not with --no-report", {
  skip_on_cran()
  skip_if_not_installed("svglite")
  set.seed(3)
  n <- 3e4
  d <- data.frame(timestamp = sprintf("%.3f", (0:(n - 1)) / 100),
                  gyro_x = rnorm(n, sd = 1e-3), gyro_y = rnorm(n, sd = 1e-3))
  csv <- tempfile(fileext = ".csv")
  utils::write.csv(d, csv, row.names = FALSE, quote = FALSE)
  out <- tempfile("cli-report-")
  on.exit(unlink(c(csv, out), recursive = TRUE))
  capture.output(suppressMessages(allanvar_cli(c(csv, "--out", out, "--quiet",
                                                 "--gyro-cols", "gyro_x,gyro_y"))))
  expect_true(file.exists(file.path(out, "report.html")))
  html <- paste(readLines(file.path(out, "report.html")), collapse = "\n")
  expect_setequal(page_attr(html, "card axis", "data-axis"), c("gyro_x", "gyro_y"))
  out2 <- tempfile("cli-noreport-")
  on.exit(unlink(out2, recursive = TRUE), add = TRUE)
  capture.output(suppressMessages(allanvar_cli(c(csv, "--out", out2, "--quiet",
                                                 "--gyro-cols", "gyro_x,gyro_y",
                                                 "--no-report"))))
  expect_true(file.exists(file.path(out2, "imu.yaml")))
  expect_false(file.exists(file.path(out2, "report.html")))
})

test_that("the report of a measured ADIS16405 unit loads in the browser", {
  skip_on_cran()
  skip_if_not_installed("svglite")
  skip_if_no_shared()
  path <- shared_file("adis16405_unit1.rds")
  skip_if_not(file.exists(path), "the measured ADIS16405 recordings are not in ../shared/data")
  m <- readRDS(path)
  # the first 2e5 samples (33 min) of every axis: the loop's effects (the
  # quantization, the oscillations, the filter) are there already
  rec <- imu_record(m[seq_len(2e5), ], freq = attr(m, "freq"),
                    units = c(gyro = "deg/s", accel = "g"))
  a <- suppressWarnings(suppressMessages(analyze_imu(rec, progress = FALSE)))
  f <- tempfile(fileext = ".html")
  on.exit(unlink(f))
  write_report(a, f, record = rec)
  html <- paste(readLines(f), collapse = "\n")
  expect_setequal(page_attr(html, "card axis", "data-axis"), colnames(m))
  expect_false(grepl("plot-failed", html, fixed = TRUE))
  skip_without_chromium()
  check_in_browser(f, a)
})
