# Files written by the formats' own libraries, not by this package's
# writers: ROS1 bags by Debian's python3-rosbag (tools/make-rosbag-python.py)
# and MCAP by the official @mcap/core writer with
# @foxglove/rosmsg2-serialization (tools/make-mcap-official.js). Each holds
# /imu0 at 200 Hz beside a camera topic; the CSV beside it holds the
# values the writer was given (17 significant digits), the stamps in ns.

foreign_csv <- function(name) {
  x <- utils::read.csv(ros_fixture(name), colClasses = c("character", rep("numeric", 6)))
  stamp <- x$timestamp
  list(values = unname(as.matrix(x[, -1L])),
       time = (as.numeric(substr(stamp, 1L, 10L)) - as.numeric(substr(stamp[1L], 1L, 10L))) +
         as.numeric(substr(stamp, 11L, 19L)) / 1e9 - as.numeric(substr(stamp[1L], 11L, 19L)) / 1e9)
}

test_that("bags written by the ROS1 library give the values written, exactly", {
  ref <- foreign_csv("rosbag_imu.csv")
  for (cmp in c("none", "lz4")) {
    f <- ros_fixture(paste0("rosbag_", cmp, ".bag"))
    tp <- imu_topics(f)
    expect_identical(sort(tp$topic), c("/cam0/image_raw", "/imu0"))
    expect_identical(tp$messages[tp$topic == "/imu0"], 200)
    expect_identical(tp$messages[tp$topic == "/cam0/image_raw"], 10)
    expect_identical(tp$type[tp$topic == "/imu0"], "sensor_msgs/Imu")
    r <- read_imu(f, topic = "/imu0")
    expect_identical(nrow(r$data), 200L)
    expect_identical(unname(r$data[, 1:6]), ref$values)
    # The header stamps (1 ms before the receive times), every 5 ms.
    expect_identical(r$time, ref$time)
    expect_identical(r$time, (0:199) * 5e6 / 1e9)
    expect_equal(nrow(r$problems), 0L)
    # A 10% time range: the messages of [0.45, 0.55] s of the stamps.
    r2 <- read_imu(f, topic = "/imu0", from = 0.45, to = 0.55)
    expect_identical(unname(r2$data[, 1:6]), ref$values[91:111, ])
  }
})

test_that("a bag the ROS1 library left unclosed is read up to its cut, with warnings", {
  ref <- foreign_csv("rosbag_imu.csv")
  # Copied while rosbag was writing, after the first 151 messages (143 of
  # /imu0): no index, and the chunk being written has lengths 0 (rosbag
  # writes them when it closes the chunk), its records following it.
  f <- ros_fixture("rosbag_unindexed.bag")
  expect_warning(r <- read_imu(f, topic = "/imu0"), "no index", class = "allanvar_warning_unindexed")
  expect_identical(nrow(r$data), 143L)
  expect_identical(unname(r$data[, 1:6]), ref$values[1:143, ])
  expect_identical(imu_topics(f)$messages, c(143, 8))
  # Cut inside its last record: the messages before it, and a warning
  # naming the byte of the open chunk.
  g <- tempfile(fileext = ".bag")
  on.exit(unlink(g))
  b <- readBin(f, "raw", file.size(f))
  writeBin(b[seq_len(length(b) - 100L)], g)
  w <- list()
  r2 <- withCallingHandlers(read_imu(g, topic = "/imu0"), warning = function(c) {
    w[[length(w) + 1L]] <<- c
    invokeRestart("muffleWarning")
  })
  cls <- unlist(lapply(w, class))
  expect_true(all(c("allanvar_warning_unindexed", "allanvar_warning_damaged_file") %in% cls))
  expect_identical(nrow(r2$data), 142L)
  expect_identical(unname(r2$data[, 1:6]), ref$values[1:142, ])
})

test_that("MCAP files of the official writer give the values written, exactly", {
  ref <- foreign_csv("mcap_official_imu.csv")
  for (f in ros_fixture(c("mcap_official.mcap", "mcap_official_zstd.mcap"))) {
    tp <- imu_topics(f)
    expect_identical(sort(tp$topic), c("/cam0/image_raw", "/imu0"))
    expect_identical(tp$messages[tp$topic == "/imu0"], 200)
    expect_identical(tp$type[tp$topic == "/imu0"], "sensor_msgs/msg/Imu")
    r <- read_imu(f, topic = "/imu0")
    expect_identical(nrow(r$data), 200L)
    expect_identical(unname(r$data[, 1:6]), ref$values)
    expect_identical(r$time, ref$time)
    expect_equal(nrow(r$problems), 0L)
    r2 <- read_imu(f, topic = "/imu0", from = 0.45, to = 0.55)
    expect_identical(unname(r2$data[, 1:6]), ref$values[91:111, ])
  }
})

test_that("the streaming readers give the records of the previous whole-file readers", {
  # previous-reader.rds: read_imu() of allanvar before the streaming
  # readers (2b1db2b, which read the whole file into memory), on every
  # committed bag, MCAP and db3 fixture (tools/make-previous-reader-ref.R).
  ref <- readRDS(ros_fixture("previous-reader.rds"))
  files <- setdiff(names(ref), ".version")
  expect_gte(length(files), 12L)
  for (f in files) {
    r <- read_imu(ros_fixture(f), topic = "/imu0")
    expect_identical(unname(r$data), ref[[f]]$data, info = f)
    expect_identical(r$time, ref[[f]]$time, info = f)
    expect_identical(r$freq, ref[[f]]$freq, info = f)
    expect_identical(r$segments, ref[[f]]$segments, info = f)
  }
})
