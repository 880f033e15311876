# MCAP files read without ROS; fixtures from tools/make-bag-fixtures.R.

test_that("MCAP with uncompressed, lz4 and zstd chunks gives the CSV's record", {
  ref <- read_imu(ros_fixture("imu.csv"))
  for (cmp in c("none", "lz4", "zstd", "ros1")) {
    r <- read_imu(ros_fixture(paste0("imu_", cmp, ".mcap")), topic = "/imu0")
    expect_identical(r$layout, "mcap")
    expect_identical(unname(r$data), unname(ref$data))
    expect_identical(r$time, ref$time)
    expect_identical(r$freq, ref$freq)
    expect_equal(nrow(r$problems), 0L)
  }
})

test_that("MCAP topics come from the summary, with their message counts", {
  tp <- imu_topics(ros_fixture("imu_lz4.mcap"))
  expect_identical(tp$topic, c("/imu0", "/imu1", "/temperature"))
  expect_identical(tp$type[1], "sensor_msgs/msg/Imu")
  expect_identical(tp$messages, c(300, 20, 5))
  expect_identical(tp$encoding[1], "cdr")
  expect_error(read_imu(ros_fixture("imu_lz4.mcap")), "2 IMU topics",
               class = "allanvar_error_topic")
})

test_that("zstd decoding matches the reference zstd tool", {
  skip_if(!nzchar(Sys.which("zstd")), "the zstd command is not installed")
  set.seed(2)
  x <- c(as.raw(sample(0:255, 5e4, TRUE)), rep(charToRaw("imu"), 3e4))
  i <- tempfile(); o <- tempfile()
  on.exit(unlink(c(i, o)))
  writeBin(x, i)
  system2("zstd", c("-q", "-f", i, "-o", o))
  expect_identical(allanvar:::zstd_decompress_cpp(readBin(o, "raw", file.size(o)),
                                                  length(x)), x)
})

test_that("zstd is decoded by the vendored library, with no system libzstd", {
  expect_true(allanvar:::zstd_available_cpp())
  so <- system.file("libs", package = "allanvar")
  skip_if(!nzchar(Sys.which("ldd")) || !nzchar(so), "no ldd or installed library")
  deps <- system2("ldd", list.files(so, full.names = TRUE, pattern = "[.]so$"), stdout = TRUE)
  expect_false(any(grepl("libzstd", deps)))
})

test_that("an MCAP file cut off mid-file gives the messages before the cut, with a warning", {
  ref <- read_imu(ros_fixture("imu.csv"))
  for (cmp in c("none", "lz4")) {
    src <- ros_fixture(paste0("imu_", cmp, ".mcap"))
    b <- readBin(src, "raw", file.size(src))
    f <- tempfile(fileext = ".mcap")
    on.exit(unlink(f), add = TRUE)
    # Chunk records (op 0x06) start where the bytes say; cut inside the third.
    s <- allanvar:::mcap_scan(src)
    cut <- s$chunks$pos[3L] + 500
    writeBin(b[seq_len(cut)], f)
    expect_warning(r <- read_imu(f, topic = "/imu0"),
                   paste0("damaged at byte ", format(s$chunks$pos[3L], scientific = FALSE)),
                   class = "allanvar_warning_damaged_file")
    n <- nrow(r$data)
    # the /imu0 messages of the first two chunks (256 records of three topics)
    expect_gt(n, 200L)
    expect_lt(n, 256L)
    expect_identical(unname(r$data), unname(ref$data[seq_len(n), ]))
    # cut inside the first chunk: nothing to trust
    writeBin(b[seq_len(s$chunks$pos[1L] + 100)], f)
    expect_error(read_imu(f, topic = "/imu0"), "damaged", class = "allanvar_error_file_format")
  }
})

test_that("a damaged lz4 or zstd chunk is a classed condition naming the chunk's byte", {
  for (cmp in c("lz4", "zstd")) {
    src <- ros_fixture(paste0("imu_", cmp, ".mcap"))
    b <- readBin(src, "raw", file.size(src))
    s <- allanvar:::mcap_scan(src)
    f <- tempfile(fileext = ".mcap")
    on.exit(unlink(f), add = TRUE)
    # Bytes in the middle of the first chunk's compressed records.
    at <- s$chunks$pos[1L] + 200
    b[at + 0:40] <- as.raw(0xAB)
    writeBin(b, f)
    expect_error(read_imu(f, topic = "/imu0"),
                 paste0("damaged at byte ", format(s$chunks$pos[1L], scientific = FALSE)),
                 class = "allanvar_error_file_format")
  }
})
