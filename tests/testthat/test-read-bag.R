# ROS1 bags (format 2.0) read without ROS; fixtures from
# tools/make-bag-fixtures.R. The expected values are the recording's own,
# as the CSV holds them (17 significant digits).

csv_record <- function() read_imu(ros_fixture("imu.csv"))

# The value of `expr` and the warnings it gave.
with_warnings <- function(expr) {
  w <- list()
  val <- withCallingHandlers(expr, warning = function(c) {
    w[[length(w) + 1L]] <<- c
    invokeRestart("muffleWarning")
  })
  list(value = val, warnings = w)
}

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

test_that("a bag cut off mid-file gives the messages before the cut, with a warning naming the byte", {
  ref <- csv_record()
  f <- tempfile(fileext = ".bag")
  on.exit(unlink(f))
  b <- readBin(ros_fixture("imu_none.bag"), "raw", 1e6)
  s <- allanvar:::bag_scan(ros_fixture("imu_none.bag"))
  # Cut inside the third chunk: the index at the end is gone too.
  cut <- s$chunks$pos[3L] + 1000
  writeBin(b[seq_len(cut)], f)
  got <- with_warnings(read_imu(f, topic = "/imu0"))
  r <- got$value
  w <- got$warnings
  cls <- unlist(lapply(w, class))
  expect_true("allanvar_warning_unindexed" %in% cls)
  expect_true("allanvar_warning_damaged_file" %in% cls)
  msg <- vapply(w, conditionMessage, "")
  expect_true(any(grepl(paste0("damaged at byte ", format(s$chunks$pos[3L], scientific = FALSE)),
                        msg, fixed = TRUE)))
  # The messages of the two whole chunks, exactly the CSV's first rows.
  n <- nrow(r$data)
  expect_gt(n, 100L)
  expect_lt(n, 300L)
  expect_identical(unname(r$data), unname(ref$data[seq_len(n), ]))
  # Cut inside the bag header: nothing to trust.
  writeBin(b[1:100], f)
  expect_error(read_imu(f, topic = "/imu0"), "malformed", class = "allanvar_error_file_format")
})

test_that("an unindexed bag is read in one pass, with a warning", {
  ref <- csv_record()
  f <- tempfile(fileext = ".bag")
  on.exit(unlink(f))
  for (cmp in c("none", "lz4", "bz2")) {
    src <- ros_fixture(paste0("imu_", cmp, ".bag"))
    b <- readBin(src, "raw", file.size(src))
    s <- allanvar:::bag_scan(src)
    # Everything up to the index, with index_pos zeroed as rosbag leaves
    # a recording that was cut off.
    ip <- s$chunks$pos  # chunks stay where they were
    at <- grepRaw("index_pos=", b, fixed = TRUE) + 10L
    idx <- sum(as.numeric(b[at + 0:7]) * 256^(0:7))
    b2 <- b[seq_len(idx)]
    b2[at + 0:7] <- as.raw(0)
    writeBin(b2, f)
    s2 <- allanvar:::bag_scan(f)
    expect_false(s2$indexed)
    expect_identical(s2$chunks$pos, ip)
    if (cmp != "bz2") expect_identical(s2$topics$messages, c(300, 20, 5))
    expect_warning(r <- read_imu(f, topic = "/imu0"), "no index",
                   class = "allanvar_warning_unindexed")
    expect_identical(unname(r$data), unname(ref$data))
    expect_identical(r$time, ref$time)
  }
})

test_that("from/to read only the chunks of the range, and the messages in it", {
  ref <- csv_record()
  for (f in ros_fixture(c("imu_none.bag", "imu_lz4.bag", "imu_bz2.bag", "imu_lz4.mcap",
                          "imu_none.mcap", "imu.db3"))) {
    r <- read_imu(f, topic = "/imu0", from = 0.5, to = 1)
    # 200 Hz stamps from 0: messages 100..200 (0-based) lie in [0.5, 1].
    expect_identical(unname(r$data), unname(ref$data[101:201, ]))
    r2 <- read_imu(f, topic = "/imu0", from = 1.2)
    expect_identical(unname(r2$data), unname(ref$data[241:300, ]))
  }
  expect_error(read_imu(ros_fixture("imu.csv"), from = 1), class = "allanvar_error_argument")
  expect_error(read_imu(ros_fixture("imu_none.bag"), topic = "/imu0", from = 2, to = 1),
               "after", class = "allanvar_error_argument")
  expect_error(read_imu(ros_fixture("imu_none.bag"), topic = "/imu0", from = -1),
               "non-negative", class = "allanvar_error_argument")
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
  # Checksums verified: a flipped byte in a block is caught (block checksum
  # with -BX, content checksum by default), as is one in the frame header.
  for (opt in list(c("-B4", "-BX"), c("-B4"))) {
    system2("lz4", c("-q", "-f", opt, i, o))
    z <- readBin(o, "raw", file.size(o))
    expect_identical(allanvar:::lz4_decompress_cpp(z, 0), x)
    z2 <- z
    k <- 70000L  # inside the literals of the first block
    z2[k] <- xor(z2[k], as.raw(1))
    expect_error(allanvar:::lz4_decompress_cpp(z2, 0), "checksum mismatch",
      class = "Rcpp::exception")
    z3 <- z
    z3[6L] <- xor(z3[6L], as.raw(0x40))  # the block-maximum-size byte
    expect_error(allanvar:::lz4_decompress_cpp(z3, 0), "lz4",
      class = "Rcpp::exception")
  }
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

test_that("bz2 chunks are decompressed by R's own bzip2, and a bad one is reported", {
  ref <- read_imu(ros_fixture("imu.csv"))
  f <- ros_fixture("imu_bz2.bag")
  got <- read_imu(f, topic = "/imu0")
  expect_identical(unname(got$data), unname(ref$data))
  # A chunk whose bytes are damaged: the chunks before it are kept.
  s <- allanvar:::bag_scan(f)
  b <- readBin(f, "raw", file.size(f))
  g <- tempfile(fileext = ".bag")
  on.exit(unlink(g))
  at <- s$chunks$pos[2L] + 200
  b[at + 0:20] <- as.raw(0)
  writeBin(b, g)
  expect_warning(r <- read_imu(g, topic = "/imu0"), "damaged at byte",
                 class = "allanvar_warning_damaged_file")
  expect_identical(unname(r$data), unname(ref$data[seq_len(nrow(r$data)), ]))
  expect_lt(nrow(r$data), 300L)
})

test_that("a bag larger than the memory allowed is read, a chunk at a time", {
  skip_on_cran()
  skip_if_not(.Platform$OS.type == "unix" && nzchar(Sys.which("sh")), "needs ulimit")
  skip_if_not_installed("callr")
  skip_if_not(installed_allanvar(), "needs the installed package")
  # A 600 MB bag, written here: per chunk 50 sensor_msgs/Imu messages
  # (ROS1 serialization, written out field by field) and one 4 MB blob
  # of another topic; the index at the end.
  f <- tempfile(fileext = ".bag")
  on.exit(unlink(f))
  u32 <- function(x) writeBin(as.integer(x), raw(), size = 4L, endian = "little")
  u64 <- function(x) c(u32(x %% 2^32), u32(x %/% 2^32))
  f64 <- function(x) writeBin(as.double(x), raw(), size = 8L, endian = "little")
  fld <- function(k, v) { v <- if (is.raw(v)) v else charToRaw(v); c(u32(nchar(k) + 1L + length(v)), charToRaw(paste0(k, "=")), v) }
  rec <- function(h, d) c(u32(length(h)), h, u32(length(d)), d)
  conn <- function(id, topic, type) rec(c(fld("op", as.raw(7)), fld("conn", u32(id)), fld("topic", topic)),
                                        c(fld("topic", topic), fld("type", type)))
  conns <- c(conn(0, "/imu0", "sensor_msgs/Imu"), conn(1, "/blob", "std_msgs/ByteMultiArray"))
  t0 <- 1700000000
  imu_msg <- function(i) {
    s <- t0 + i %/% 100; ns <- (i %% 100) * 1e7
    c(u32(i), u32(s), u32(ns), u32(0), f64(c(0, 0, 0, 1)), f64(rep(0, 9)),
      f64(c(i, -i, 2 * i)), f64(rep(0, 9)), f64(c(1, 2, 3) + i), f64(rep(0, 9)))
  }
  msg <- function(id, i, d) rec(c(fld("op", as.raw(2)), fld("conn", u32(id)),
                                  fld("time", c(u32(t0 + i %/% 100), u32((i %% 100) * 1e7)))), d)
  blob <- msg(1, 0, as.raw(rep(1:255, length.out = 4e6)))
  con <- file(f, "wb")
  writeBin(charToRaw("#ROSBAG V2.0\n"), con)
  writeBin(raw(4096), con)
  pos <- 13 + 4096
  infos <- list()
  n_chunk <- 150L
  for (k in seq_len(n_chunk) - 1L) {
    ii <- k * 50L + 0:49
    body <- c(conns, unlist(lapply(ii, function(i) msg(0, i, imu_msg(i)))), blob)
    ch <- rec(c(fld("op", as.raw(5)), fld("compression", "none"), fld("size", u32(length(body)))), body)
    writeBin(ch, con)
    infos[[k + 1L]] <- rec(c(fld("op", as.raw(6)), fld("ver", u32(1)), fld("chunk_pos", u64(pos)),
                             fld("start_time", c(u32(t0 + ii[1] %/% 100), u32(0))),
                             fld("end_time", c(u32(t0 + ii[50] %/% 100 + 1), u32(0))),
                             fld("count", u32(2))), c(u32(0), u32(50), u32(1), u32(1)))
    pos <- pos + length(ch)
  }
  writeBin(c(conns, unlist(infos)), con)
  h <- c(fld("op", as.raw(3)), fld("index_pos", u64(pos)), fld("conn_count", u32(2)),
         fld("chunk_count", u32(n_chunk)))
  seek(con, 13, rw = "write")
  writeBin(rec(h, charToRaw(strrep(" ", 4096 - 8 - length(h)))), con)
  close(con)
  expect_gt(file.size(f), 6e8)
  # In a child whose address space is limited to 450 MB (R itself takes
  # about 130 MB): the file could not be held in memory.
  out <- tempfile(fileext = ".rds")
  on.exit(unlink(out), add = TRUE)
  code <- sprintf(paste0("r <- allanvar::read_imu(%s, topic = '/imu0'); ",
                         "saveRDS(list(n = nrow(r$data), gx = r$data[, 1L], ",
                         "ax = r$data[, 4L], time = r$time), %s)"),
                  deparse(f), deparse(out))
  limited <- function(code) {
    suppressWarnings(system2("sh", c("-c", shQuote(paste("ulimit -v 450000;",
      shQuote(file.path(R.home("bin"), "Rscript")), "-e", shQuote(code)))),
      env = paste0("R_LIBS=", paste(.libPaths(), collapse = ":")), stdout = TRUE, stderr = TRUE))
  }
  # The limit bites: the whole file cannot be read into memory there.
  whole <- tempfile(fileext = ".rds")
  limited(sprintf("x <- readBin(%s, 'raw', file.size(%s)); saveRDS(length(x), %s)",
                  deparse(f), deparse(f), deparse(whole)))
  expect_false(file.exists(whole))
  st <- limited(code)
  expect_true(file.exists(out), info = paste(st, collapse = "\n"))
  res <- readRDS(out)
  expect_identical(res$n, 7500L)
  expect_identical(res$gx, as.numeric(0:7499))
  expect_identical(res$ax, as.numeric(0:7499) + 1)
  expect_identical(res$time, (0:7499) / 100)
})
