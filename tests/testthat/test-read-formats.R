# One recording in every format read_imu() knows (Kalibr CSV; ROS1 bag with
# uncompressed, bz2 and lz4 chunks; MCAP with uncompressed, lz4 and zstd
# chunks, CDR and ROS1 messages; rosbag2 db3), written by the repository's
# generator (tools/make-bag-fixtures.R, from the formats' specifications):
# the records, and so the analyses and datasheets, must be identical. The
# reference is the CSV, whose 17-digit values and integer ns stamps are the
# recording exactly.

format_files <- c(csv = "imu.csv", bag_none = "imu_none.bag",
                  bag_bz2 = "imu_bz2.bag", bag_lz4 = "imu_lz4.bag",
                  mcap_none = "imu_none.mcap", mcap_lz4 = "imu_lz4.mcap",
                  mcap_zstd = "imu_zstd.mcap", mcap_ros1 = "imu_ros1.mcap",
                  db3 = "imu.db3")

read_format <- function(path) {
  if (grepl("\\.csv$", path)) read_imu(path) else read_imu(path, topic = "/imu0")
}

# The datasheet without the column naming the source file (which differs).
datasheet_content <- function(rec) {
  d <- datasheet(suppressWarnings(analyze_imu(rec, refine = FALSE, progress = FALSE)))
  for (k in names(d)) if (is.data.frame(d[[k]])) d[[k]]$record <- NULL
  d
}

expect_same_record <- function(r, ref, label) {
  for (k in c("data", "time", "freq", "dt", "sensors", "units", "si_units",
              "segments", "sampling", "unit_checks")) {
    expect_identical(r[[k]], ref[[k]], label = paste(label, k))
  }
}

formats_available <- function(names) {
  ok <- rep(TRUE, length(names))
  ok[grepl("zstd", names)] <- allanvar:::zstd_available_cpp()
  names[ok]
}

test_that("the committed fixtures give one record and one datasheet in every format", {
  use <- formats_available(names(format_files))
  recs <- lapply(format_files[use], function(f) read_format(ros_fixture(f)))
  ref <- recs$csv
  expect_identical(dim(ref$data), c(300L, 6L))
  ds_ref <- datasheet_content(ref)
  # Not vacuous: the reference datasheet holds the six axes' white noise.
  expect_identical(nrow(ds_ref$gyro), 3L)
  expect_true(all(is.finite(ds_ref$gyro[["N [rad/s/sqrt(Hz)]"]])))
  for (k in setdiff(use, "csv")) {
    expect_same_record(recs[[k]], ref, k)
    expect_identical(datasheet_content(recs[[k]]), ds_ref, label = k)
  }
})

test_that("a longer recording written now by the generator reads back identically in every format", {
  gen_file <- test_path("..", "..", "tools", "make-bag-fixtures.R")
  skip_if_not(file.exists(gen_file), "tools/make-bag-fixtures.R is not in this tree")
  gen <- new.env()
  sys.source(gen_file, gen)
  tools_ok <- nzchar(Sys.which(c("lz4", "zstd")))
  dir <- tempfile("formats")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE), add = TRUE)
  # 30 s at 200 Hz, gyro and accel white noise with biases, gravity on z.
  rec <- gen$fixture_recording(6000L, freq = 200, seed = 11L)
  t1 <- gen$fixture_topics(rec, "ros1")
  t2 <- gen$fixture_topics(rec, "cdr")
  path <- function(k) file.path(dir, format_files[[k]])
  gen$write_imu_csv(rec, path("csv"))
  write <- list(
    bag_none = function() gen$write_ros1_bag(path("bag_none"), t1, "none"),
    bag_bz2 = function() gen$write_ros1_bag(path("bag_bz2"), t1, "bz2"),
    bag_lz4 = function() gen$write_ros1_bag(path("bag_lz4"), t1, "lz4"),
    mcap_none = function() gen$write_mcap(path("mcap_none"), t2, ""),
    mcap_lz4 = function() gen$write_mcap(path("mcap_lz4"), t2, "lz4"),
    mcap_zstd = function() gen$write_mcap(path("mcap_zstd"), t2, "zstd"),
    mcap_ros1 = function() gen$write_mcap(path("mcap_ros1"), t1, "lz4", "ros1"),
    db3 = function() gen$write_db3(path("db3"), t2))
  use <- formats_available(names(write))
  if (!tools_ok[1L]) use <- use[!grepl("lz4|mcap_ros1", use)]
  if (!tools_ok[2L]) use <- use[!grepl("zstd", use)]
  for (k in use) write[[k]]()
  ref <- read_format(path("csv"))
  expect_identical(nrow(ref$data), 6000L)
  expect_identical(ref$time, (0:5999) * 5e6 / 1e9)
  ds_ref <- datasheet_content(ref)
  for (k in use) {
    r <- read_format(path(k))
    expect_same_record(r, ref, k)
    expect_identical(datasheet_content(r), ds_ref, label = k)
  }
  # Every writer ran (lz4 and zstd are in tools/setup.sh); say so when not.
  if (length(use) < length(write)) {
    skip(paste("not written here:", paste(setdiff(names(write), use), collapse = ", ")))
  }
})
