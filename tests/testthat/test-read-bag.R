# ROS1 bags (format 2.0) read without ROS; fixtures from
# tools/make-bag-fixtures.R. The expected values are the recording's own,
# as the CSV holds them (17 significant digits).

csv_record <- function() read_imu(ros_fixture("imu.csv"))

test_that("ROS1 bags with uncompressed, bz2 and lz4 chunks give the CSV's record", {
  ref <- csv_record()
  for (cmp in c("none", "bz2", "lz4")) {
    r <- read_imu(ros_fixture(paste0("imu_", cmp, ".bag")), topic = "/imu0")
    expect_identical(r$layout, "rosbag")
    expect_identical(r$topic, "/imu0")
    expect_identical(unname(r$data), unname(ref$data))
    expect_identical(colnames(r$data), colnames(ref$data))
    expect_identical(r$time, ref$time)
    expect_identical(r$freq, ref$freq)
    expect_identical(r$segments, ref$segments)
    expect_equal(nrow(r$problems), 0L)
  }
})

test_that("the header stamps are the timestamps, exactly", {
  r <- read_imu(ros_fixture("imu_none.bag"), topic = "/imu0")
  # 200 Hz: stamps every 5,000,000 ns from the first
  expect_identical(r$time, (0:299) * 5e6 / 1e9)
  expect_equal(r$freq, 200, tolerance = 1e-12)
})

test_that("topics are listed, and the IMU topic must be chosen among several", {
  f <- ros_fixture("imu_lz4.bag")
  tp <- imu_topics(f)
  expect_identical(tp$topic, c("/imu0", "/imu1", "/temperature"))
  expect_identical(tp$imu, c(TRUE, TRUE, FALSE))
  expect_identical(tp$messages, c(300, 20, 5))
  err <- expect_error(read_imu(f), class = "allanvar_error_topic")
  expect_match(conditionMessage(err), "/imu0 \\(sensor_msgs/Imu, 300 messages\\)")
  expect_match(conditionMessage(err), "/imu1")
  expect_match(conditionMessage(err), "topic = ")
  expect_error(read_imu(f, topic = "/temperature"), "not sensor_msgs/Imu",
               class = "allanvar_error_topic")
  expect_error(read_imu(f, topic = "/nope"), "is not in", class = "allanvar_error_topic")
  r1 <- read_imu(f, topic = "/imu1")
  expect_equal(nrow(r1$data), 20L)
  expect_equal(r1$freq, 10, tolerance = 1e-12)
})

test_that("a truncated bag is a classed error that names the file", {
  f <- tempfile(fileext = ".bag")
  on.exit(unlink(f))
  b <- readBin(ros_fixture("imu_none.bag"), "raw", 1e6)
  writeBin(b[1:6000], f)
  expect_error(read_imu(f, topic = "/imu0"), "malformed",
               class = "allanvar_error_file_format")
})

test_that("the LZ4 frame decoder inverts the reference lz4 tool", {
  skip_if(!nzchar(Sys.which("lz4")), "the lz4 command is not installed")
  set.seed(1)
  # long literal runs, long matches, overlapping matches, several blocks
  x <- c(as.raw(sample(0:255, 70000, TRUE)), as.raw(rep(7L, 300000)),
         rep(charToRaw("abcdefgh"), 40000), as.raw(sample(0:3, 1e5, TRUE)))
  i <- tempfile(); o <- tempfile()
  on.exit(unlink(c(i, o)))
  writeBin(x, i)
  for (opt in list(c("-B4"), c("-B4", "-BD"), c("-B7", "--content-size"), c("-BX", "-B5"))) {
    system2("lz4", c("-q", "-f", opt, i, o))
    z <- readBin(o, "raw", file.size(o))
    expect_identical(allanvar:::lz4_decompress_cpp(z, 0), x)
  }
  expect_error(allanvar:::lz4_decompress_cpp(as.raw(1:10), 0), "lz4",
    class = "Rcpp::exception")
})

test_that("long reads report progress through progressr, and only when asked", {
  f <- ros_fixture("imu_lz4.bag")
  steps <- character()
  record <- function(p) steps <<- c(steps, p$message)
  withr_opt <- options(progressr.enable = TRUE)
  on.exit(options(withr_opt))
  withCallingHandlers(
    progressr::with_progress(read_imu(f, topic = "/imu0"),
                             handlers = progressr::handler_void()),
    progression = record)
  expect_true(all(c("scanning the bag", "decoding chunks",
                    "checking stamps and units") %in% steps))
  # no handler: nothing printed
  expect_silent(read_imu(f, topic = "/imu0"))
})

test_that("bz2 chunks read through libbz2 and, without it, through memDecompress alike", {
  # The reference: base R's own bzip2 decoder on every chunk of the bag.
  f <- ros_fixture("imu_bz2.bag")
  s <- allanvar:::bag_scan(f)
  expect_true(all(s$chunks$compression == "bz2"))
  ref <- read_imu(ros_fixture("imu.csv"))
  got <- read_imu(f, topic = "/imu0")
  expect_identical(unname(got$data), unname(ref$data))
  # A chunk whose stated size is wrong is a classed error, not garbage.
  b <- readBin(f, "raw", file.size(f))
  k <- which(s$chunks$compression == "bz2")[1L]
  expect_identical(length(memDecompress(b[s$chunks$off[k] + seq_len(s$chunks$len[k])],
                                        type = "bzip2")), as.integer(s$chunks$size[k]))
  if (allanvar:::bz2_available_cpp()) {
    expect_error(allanvar:::rosbag_imu(b, s$chunks$off[k], s$chunks$len[k], 2L,
                                       s$chunks$size[k] + 1, 0L),
                 "stated size", class = "Rcpp::exception")
  }
  skip_if_not_installed("callr")
  skip_if_not(installed_allanvar(), "needs the installed package")
  res <- callr::r(function(f) {
    r <- allanvar::read_imu(f, topic = "/imu0")
    list(avail = allanvar:::bz2_available_cpp(), data = unname(r$data), time = r$time)
  }, args = list(f = normalizePath(f)),
  env = c(callr::rcmd_safe_env(), ALLANVAR_DISABLE_BZ2 = "1"), libpath = .libPaths())
  expect_false(res$avail)
  expect_identical(res$data, unname(ref$data))
  expect_identical(res$time, ref$time)
})
