# File faults of delimited text: each is reported with its line (the file's
# own numbering, header = line 1) and column, and handled by its rule.

kalibr_lines <- function(n = 400, freq = 100, seed = 1) {
  set.seed(seed)
  k <- 0:(n - 1)
  step <- round(1e9 / freq)
  stamp <- sprintf("%d%09d", 1403636579L + (k * step) %/% 1e9, (k * step) %% 1e9)
  v <- cbind(matrix(rnorm(3 * n, sd = 1e-3), n), matrix(rnorm(3 * n, sd = 1e-2), n))
  v[, 6] <- v[, 6] + 9.81
  c("timestamp,omega_x,omega_y,omega_z,alpha_x,alpha_y,alpha_z",
    do.call(paste, c(list(stamp), lapply(1:6, function(j) format(v[, j], digits = 8)),
                     sep = ",")))
}

write_lines <- function(lines, ext = ".csv") {
  f <- tempfile(fileext = ext)
  writeLines(lines, f)
  f
}

problem <- function(r, type) r$problems[r$problems$type == type, , drop = FALSE]

test_that("a cell that is not a number: its row dropped, line and column named", {
  l <- kalibr_lines()
  l[151] <- sub(",[^,]*,", ",abc,", l[151])     # omega_x of data row 150
  f <- write_lines(l)
  on.exit(unlink(f))
  expect_warning(r <- read_imu(f), "not a number")
  p <- problem(r, "not a number")
  expect_equal(p$count, 1L)
  expect_match(p$detail, "line 151, column 2 omega_x: \"abc\"", fixed = TRUE)
  expect_identical(p$action, "rows dropped")
  expect_equal(nrow(r$data), 399L)
  # the gap left by the row is reported too (never silent)
  expect_equal(nrow(problem(r, "gap")), 1L)
})

test_that("rows with the wrong number of fields are dropped and reported", {
  l <- kalibr_lines()
  l[201] <- paste0(l[201], ",7")                  # one extra field
  l[301] <- sub(",[^,]*$", "", l[301])            # one field missing
  f <- write_lines(l)
  on.exit(unlink(f))
  expect_warning(r <- read_imu(f, gap = "ignore"), "fields")
  p <- problem(r, "fields")
  expect_equal(p$count, 2L)
  expect_match(p$detail, "first at line 201, which has 8; the extra field begins at column 8",
               fixed = TRUE)
  expect_equal(nrow(r$data), 398L)
  # the extra field was not silently dropped: the row is gone, not truncated
  expect_false(any(abs(r$data[, "gyro_x"] * 1e3 - 7e3) < 1e-9))
})

test_that("a row with too many fields early in the file (fread's sample) too", {
  l <- kalibr_lines()
  l[6] <- paste0(l[6], ",7")
  f <- write_lines(l)
  on.exit(unlink(f))
  expect_warning(r <- read_imu(f, gap = "ignore"), "fields")
  expect_match(problem(r, "fields")$detail, "line 6, which has 8")
})

test_that("Inf and missing cells: rows dropped, line and column named", {
  l <- kalibr_lines()
  l[11] <- sub(",[^,]*$", ",Inf", l[11])          # alpha_z of line 11
  l[21] <- sub("^([^,]*,[^,]*,)[^,]*", "\\1NA", l[21])  # omega_y of line 21
  f <- write_lines(l)
  on.exit(unlink(f))
  expect_warning(r <- read_imu(f, gap = "ignore"), "infinite")
  expect_match(problem(r, "infinite")$detail, "first at line 11, column accel_z: Inf",
               fixed = TRUE)
  expect_match(problem(r, "missing")$detail, "first at line 21, column gyro_y",
               fixed = TRUE)
  expect_true(all(is.finite(r$data)))
  expect_equal(nrow(r$data), 398L)
})

test_that("decimal commas in a comma-separated file stop the reading, saying why", {
  l <- kalibr_lines(50)
  l[-1] <- gsub(".", ",", l[-1], fixed = TRUE)
  f <- write_lines(l)
  on.exit(unlink(f))
  err <- expect_error(read_imu(f), class = "allanvar_error_file_fields")
  expect_match(conditionMessage(err), "first at line 2, which has 13")
  expect_match(conditionMessage(err), "decimal commas")
  expect_match(conditionMessage(err), "dec = \",\"")
})

test_that("decimal commas with ';' are read with dec = ',' and explained without", {
  l <- kalibr_lines(200)
  l2 <- gsub(",", ";", l, fixed = TRUE)
  l2[-1] <- gsub(".", ",", l2[-1], fixed = TRUE)
  f <- write_lines(l2)
  on.exit(unlink(f))
  err <- expect_error(read_imu(f, sep = ";"), class = "allanvar_error_file_values")
  expect_match(conditionMessage(err), "column 2 \\(omega_x\\).*line 2")
  expect_match(conditionMessage(err), "dec = \",\"")
  r <- read_imu(f, sep = ";", dec = ",")
  ref <- read_imu(write_lines(l))
  expect_equal(r$data, ref$data)
})

test_that("a Kalibr header holding seconds is read as seconds and reported", {
  n <- 300
  l <- kalibr_lines(n)
  st <- sprintf("%.3f", 1403636579 + (0:(n - 1)) / 100)
  l[-1] <- paste0(st, sub("^[^,]*", "", l[-1]))
  f <- write_lines(l)
  on.exit(unlink(f))
  expect_warning(r <- read_imu(f), "time unit")
  expect_equal(r$freq, 100, tolerance = 1e-6)
  expect_identical(r$time_unit, "s")
  expect_match(problem(r, "time unit")$detail, "column 1 timestamp holds 1403636579 at line 2")
  # declared ns: an implausible rate stops, naming the column and the fix
  err <- expect_error(read_imu(f, time_unit = "ns"), class = "allanvar_error_time_unit")
  expect_match(conditionMessage(err), "column 1 timestamp, read as ns")
  expect_match(conditionMessage(err), "1e\\+11 Hz")
  expect_match(conditionMessage(err), "time_unit = \"s\"")
})

test_that("a directory, an empty file, a missing file: clear errors", {
  d <- tempfile()
  dir.create(d)
  on.exit(unlink(d, recursive = TRUE))
  expect_error(read_imu(d), "is a directory", class = "allanvar_error_file")
  e <- file.path(d, "empty.csv")
  file.create(e)
  expect_error(read_imu(e), "is empty", class = "allanvar_error_file")
  expect_error(read_imu(file.path(d, "nope.csv")), "does not exist",
               class = "allanvar_error_file")
  expect_error(read_imu(c("a", "b")), "single file path", class = "allanvar_error_argument")
})

test_that("a non-UTF-8 byte in the header is shown and reported with its column", {
  l <- kalibr_lines(200)
  l[1] <- paste0(l[1], ",temp\xe9rature")
  l[-1] <- paste0(l[-1], ",25")
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  writeLines(l, f, useBytes = TRUE)
  expect_warning(r <- read_imu(f), "encoding")
  expect_match(problem(r, "encoding")$detail, "line 1, column 8 (\"temp<e9>rature\")",
               fixed = TRUE)
  expect_equal(ncol(r$data), 6L)
  # and when that column is the time column, the error shows the name
  l[1] <- sub("^timestamp", "t\xefme", l[1], useBytes = TRUE)
  writeLines(l, f, useBytes = TRUE)
  expect_error(suppressWarnings(read_imu(f)), "t<ef>me", class = "allanvar_error_no_time")
})

test_that("blank lines are skipped and reported", {
  l <- kalibr_lines(200)
  l <- c(l[1:50], "", l[51:201])
  f <- write_lines(l)
  on.exit(unlink(f))
  expect_warning(r <- read_imu(f), "blank")
  expect_match(problem(r, "blank")$detail, "first at line 51")
  expect_equal(nrow(r$data), 200L)
})

test_that("integer nanosecond stamps stay exact through bit64", {
  l <- kalibr_lines(1000, freq = 1000)
  f <- write_lines(l)
  on.exit(unlink(f))
  r <- read_imu(f)
  # 1 ms steps from an epoch near 1.4e18 ns: exact, not rounded to 256 ns
  expect_identical(r$time, (0:999) / 1000)
})

test_that("imu_record() refuses dates and arrays, and reports rows of bad values", {
  expect_error(imu_record(Sys.Date() + 0:9, freq = 1), "dates",
               class = "allanvar_error_argument")
  expect_error(imu_record(array(0, c(5, 2, 2)), freq = 1), "3 dimensions",
               class = "allanvar_error_argument")
  expect_error(imu_record(data.frame(gyro_x = letters), freq = 1), "text",
               class = "allanvar_error_argument")
  m <- cbind(gyro_x = c(1, 2, Inf, 4, 5) * 1e-3, accel_x = c(0, NA, 0, 0, 0))
  expect_warning(r <- imu_record(m, freq = 10), "infinite")
  expect_match(r$problems$detail[r$problems$type == "missing"], "row 2, column accel_x")
  expect_match(r$problems$detail[r$problems$type == "infinite"], "row 3, column gyro_x")
  expect_equal(nrow(r$data), 3L)
  # exact integer64 stamps
  t <- bit64::as.integer64("1403636579000000000") + bit64::as.integer64(0:4) * 10000000L
  r2 <- imu_record(cbind(gyro_x = 1:5 * 1e-3), time = t, time_unit = "ns")
  expect_identical(r2$time, (0:4) / 100)
})
