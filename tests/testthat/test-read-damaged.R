# Committed damaged fixtures (tools/make-bag-fixtures.R,
# make_damaged_fixtures()): one bit flipped inside the compressed data of the
# second chunk. Only the codecs' checksums can find such a fault; the reader
# must stop there with its damaged-file warning, keeping the chunk before.
expect_damaged_second_chunk <- function(file, pos, codec) {
  ref <- read_imu(ros_fixture("imu.csv"))
  w <- NULL
  r <- withCallingHandlers(read_imu(file, topic = "/imu0"), warning = function(c) {
    w <<- c
    invokeRestart("muffleWarning")
  })
  expect_s3_class(w, "allanvar_warning_damaged_file")
  msg <- conditionMessage(w)
  expect_match(msg, basename(file), fixed = TRUE)
  expect_match(msg, paste0("damaged at byte ", format(pos, scientific = FALSE), " ("),
               fixed = TRUE)
  expect_match(msg, paste0(codec, ": "), fixed = TRUE)
  expect_match(msg, "checksum")
  # the /imu0 messages of the first chunk, exactly, and nothing after it
  n <- nrow(r$data)
  expect_gt(n, 0L)
  expect_lt(n, nrow(ref$data))
  expect_identical(unname(r$data), unname(ref$data[seq_len(n), ]))
}

test_that("a bit flipped in an lz4 chunk of a ROS1 bag is caught by the frame's checksum", {
  f <- ros_fixture("imu_lz4_damaged.bag")
  pos <- allanvar:::bag_scan(ros_fixture("imu_lz4.bag"))$chunks$pos
  expect_damaged_second_chunk(f, pos[2L], "lz4")
  # the undamaged file reads whole
  expect_identical(nrow(read_imu(ros_fixture("imu_lz4.bag"), topic = "/imu0")$data),
                   nrow(read_imu(ros_fixture("imu.csv"))$data))
})

test_that("a bit flipped in a zstd chunk of an MCAP file is caught by the frame's checksum", {
  f <- ros_fixture("imu_zstd_damaged.mcap")
  pos <- allanvar:::mcap_scan(ros_fixture("imu_zstd.mcap"))$chunks$pos
  expect_damaged_second_chunk(f, pos[2L], "zstd")
})

test_that("a damaged first chunk leaves nothing to trust: a classed error", {
  for (src in c("imu_lz4.bag", "imu_zstd.mcap")) {
    f <- ros_fixture(src)
    b <- readBin(f, "raw", file.size(f))
    magic <- if (grepl("lz4", src)) as.raw(c(0x04, 0x22, 0x4D, 0x18)) else as.raw(c(0x28, 0xB5, 0x2F, 0xFD))
    at <- which(b == magic[1L])
    at <- at[vapply(at, function(i) identical(b[i + 0:3], magic), NA)][1L]
    b[at + 200L] <- xor(b[at + 200L], as.raw(1L))
    g <- tempfile(fileext = sub(".*([.][a-z]+)$", "\\1", src))
    on.exit(unlink(g), add = TRUE)
    writeBin(b, g)
    expect_error(read_imu(g, topic = "/imu0"), "checksum", class = "allanvar_error_file_format")
  }
})
