# Bags of any size (issue 28): ROS1 .bag (none, lz4) and MCAP (none, zstd)
# with 640x480 mono8 images at 20 Hz beside sensor_msgs/Imu at 200 Hz,
# written chunk by chunk by this script's streaming writers (the formats as
# in tools/make-bag-fixtures.R), then read in a child process each:
# imu_topics() time, read_imu() time and peak resident memory
# (/usr/bin/time -v), bytes read (/proc/self/io rchar), the time of
# `cat file > /dev/null` just before, and a read of 10% of the time range.
# For compressed files, the decompressor's own speed on the file's chunks
# (the lz4/zstd tools on the first 200 chunks).
#
#   Rscript bench/bench-bigbag.R [GB] [dir]    (default 1 GB, /work/bigtmp)
# The files are deleted at the end. Needs the lz4 and zstd tools.
args <- commandArgs(TRUE)
gb <- if (length(args) >= 1L) as.numeric(args[1L]) else 1
dir <- if (length(args) >= 2L) args[2L] else "/work/bigtmp"
lib <- Sys.getenv("ALLANVAR_LIB", "")
dir.create(dir, showWarnings = FALSE, recursive = TRUE)
source(file.path("tools", "make-bag-fixtures.R"))

img_bytes <- 640L * 480L
img_rate <- 20
imu_rate <- 200
secs <- ceiling(gb * 1e9 / (img_bytes * img_rate))
set.seed(3)
# One image, 4 bits of entropy a pixel (compressible about 2x, as camera
# images roughly are); reused with new stamps.
img_px <- as.raw(sample(0:15, img_bytes, TRUE) * 16L + 8L)
img_msg <- function(sec, nsec) {
  c(u32(0), u32(sec), u32(nsec), str32("cam0"), u32(480), u32(640), str32("mono8"),
    u8(0), u32(640), u32(img_bytes), img_px)
}
imu_one <- function(n, sec, nsec) {
  rec <- list(sec = sec, nsec = nsec, gyro = matrix(rnorm(3 * n, sd = 0.01), n),
              accel = matrix(rnorm(3 * n, sd = 0.02) + c(0, 0, 9.81), n, byrow = FALSE))
  ros1_messages(rec)
}
cdr_img <- function(sec, nsec) {
  c(as.raw(c(0, 1, 0, 0)), u32(sec), u32(nsec), str32("cam0"), u32(480), u32(640),
    str32("mono8"), u8(0), as.raw(c(0, 0, 0)), u32(640), u32(img_bytes), img_px)
}

compress_batch <- function(raws, type, keep = NULL) {
  td <- tempfile("cb")
  dir.create(td)
  on.exit(unlink(td, recursive = TRUE))
  fs <- file.path(td, sprintf("c%05d", seq_along(raws)))
  for (i in seq_along(raws)) writeBin(raws[[i]], fs[i])
  if (type == "lz4") {
    system2("lz4", c("-q", "-f", "-m", "-1", fs))
    out <- paste0(fs, ".lz4")
  } else {
    system2("zstd", c("-q", "-f", "-1", fs))
    out <- paste0(fs, ".zst")
  }
  if (!is.null(keep)) file.copy(out, keep)
  lapply(out, function(f) readBin(f, "raw", file.size(f)))
}

# One second of messages: 200 IMU, 20 images, in time order; returns the
# records (as raw vectors) and their times.
second_of <- function(s, t0, fmt) {
  tn <- c(seq(0, 1e9 - 1, by = 1e9 / imu_rate), seq(0, 1e9 - 1, by = 1e9 / img_rate))
  kind <- c(rep(0L, imu_rate), rep(1L, img_rate))
  o <- order(tn, kind)
  sec <- t0 + s
  imu <- if (fmt == "ros1") imu_one(imu_rate, rep(sec, imu_rate), tn[kind == 0L])
         else cdr_messages(list(sec = rep(sec, imu_rate), nsec = tn[kind == 0L],
                                gyro = matrix(rnorm(3 * imu_rate, sd = 0.01), imu_rate),
                                accel = matrix(rnorm(3 * imu_rate, sd = 0.02), imu_rate)))
  list(tn = tn[o], kind = kind[o], imu = imu, sec = sec, imu_i = cumsum(kind[o] == 0L))
}

write_big_bag <- function(file, compression) {
  con <- file(file, "wb")
  on.exit(close(con))
  t0 <- 1700000000
  writeBin(charToRaw("#ROSBAG V2.0\n"), con)
  writeBin(raw(4096), con)  # bag header, rewritten at the end
  pos <- 13 + 4096
  conn_rec <- function(id, topic, type) {
    bag_record(bag_header_fields(op = u8(7), conn = u32(id), topic = topic),
               bag_header_fields(topic = topic, type = type, md5sum = "0",
                                 message_definition = "x"))
  }
  conns <- c(conn_rec(0, "/imu0", "sensor_msgs/Imu"), conn_rec(1, "/cam0/image_raw", "sensor_msgs/Image"))
  msg_rec <- function(conn, sec, nsec, data) {
    c(bag_record(c(u32(4), charToRaw("op="), u8(2), u32(9), charToRaw("conn="), u32(conn),
                   u32(13), charToRaw("time="), u32(sec), u32(nsec)), data))
  }
  infos <- list()
  pending <- list()
  flush <- function() {
    if (!length(pending)) return()
    raws <- lapply(pending, `[[`, "raw")
    comp <- if (compression == "none") raws else
      compress_batch(raws, compression, if (length(infos) == 0L) keepdir)
    for (i in seq_along(pending)) {
      ch <- bag_record(bag_header_fields(op = u8(5), compression = compression,
                                         size = u32(length(raws[[i]]))), comp[[i]])
      writeBin(ch, con)
      pk <- pending[[i]]
      infos[[length(infos) + 1L]] <<- bag_record(
        bag_header_fields(op = u8(6), ver = u32(1), chunk_pos = u64(pos),
                          start_time = c(u32(pk$t[1]), u32(pk$t[2])),
                          end_time = c(u32(pk$t[3]), u32(pk$t[4])), count = u32(2)),
        c(u32(0), u32(pk$n[1]), u32(1), u32(pk$n[2])))
      pos <<- pos + length(ch)
    }
    pending <<- list()
  }
  cur <- list(); cur_len <- 0; cur_t <- NULL; cur_n <- c(0, 0)
  for (s in seq_len(secs) - 1L) {
    sd <- second_of(s, t0, "ros1")
    for (j in seq_along(sd$tn)) {
      r <- if (sd$kind[j] == 0L) msg_rec(0, sd$sec, sd$tn[j], sd$imu[, sd$imu_i[j]])
           else msg_rec(1, sd$sec, sd$tn[j], img_msg(sd$sec, sd$tn[j]))
      if (!length(cur)) cur_t <- c(sd$sec, sd$tn[j])
      cur[[length(cur) + 1L]] <- r
      cur_len <- cur_len + length(r)
      cur_n[sd$kind[j] + 1L] <- cur_n[sd$kind[j] + 1L] + 1
      if (cur_len >= 768 * 1024) {
        pending[[length(pending) + 1L]] <- list(raw = c(conns, unlist(cur)),
                                                t = c(cur_t, sd$sec, sd$tn[j]), n = cur_n)
        cur <- list(); cur_len <- 0; cur_n <- c(0, 0)
        if (length(pending) >= 200L) flush()
      }
    }
  }
  flush()
  index_pos <- pos
  writeBin(c(conns, unlist(infos)), con)
  h <- bag_header_fields(op = u8(3), index_pos = u64(index_pos), conn_count = u32(2),
                         chunk_count = u32(length(infos)))
  seek(con, 13, rw = "write")
  writeBin(bag_record(h, charToRaw(strrep(" ", 4096 - (8 + length(h))))), con)
  invisible(file)
}

write_big_mcap <- function(file, compression) {
  con <- file(file, "wb")
  on.exit(close(con))
  t0 <- 1700000000
  schema <- c(mcap_rec(3, c(u16(1), str32("sensor_msgs/msg/Imu"), str32("ros2msg"), str32("x"))),
              mcap_rec(3, c(u16(2), str32("sensor_msgs/msg/Image"), str32("ros2msg"), str32("x"))))
  chans <- c(mcap_rec(4, c(u16(1), u16(1), str32("/imu0"), str32("cdr"), u32(0))),
             mcap_rec(4, c(u16(2), u16(2), str32("/cam0/image_raw"), str32("cdr"), u32(0))))
  head <- c(as.raw(c(0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a)),
            mcap_rec(1, c(str32("ros2"), str32("allanvar bench"))), schema, chans)
  writeBin(head, con)
  pos <- length(head)
  idx <- list()
  pending <- list()
  counts <- c(0, 0)
  comp_name <- if (compression == "none") "" else compression
  flush <- function() {
    if (!length(pending)) return()
    raws <- lapply(pending, `[[`, "raw")
    comp <- if (compression == "none") raws else
      compress_batch(raws, compression, if (length(idx) == 0L) keepdir)
    for (i in seq_along(pending)) {
      pk <- pending[[i]]
      rec <- mcap_rec(6, c(u64(pk$t[1]), u64(pk$t[2]), u64(length(raws[[i]])), u32(0),
                           str32(comp_name), u64(length(comp[[i]])), comp[[i]]))
      writeBin(rec, con)
      idx[[length(idx) + 1L]] <<- mcap_rec(8, c(u64(pk$t[1]), u64(pk$t[2]), u64(pos),
                                               u64(length(rec)), u32(0), u64(0),
                                               str32(comp_name), u64(length(comp[[i]])),
                                               u64(length(raws[[i]]))))
      pos <<- pos + length(rec)
    }
    pending <<- list()
  }
  msg <- function(ch, t, data) {
    c(u8(5), u64(22 + length(data)), u16(ch), u32(0), u64(t), u64(t), data)
  }
  cur <- list(); cur_len <- 0; cur_t <- NULL
  for (s in seq_len(secs) - 1L) {
    sd <- second_of(s, t0, "cdr")
    for (j in seq_along(sd$tn)) {
      t <- (t0 + s) * 1e9 + sd$tn[j]
      r <- if (sd$kind[j] == 0L) msg(1, t, sd$imu[, sd$imu_i[j]])
           else msg(2, t, cdr_img(sd$sec, sd$tn[j]))
      counts[sd$kind[j] + 1L] <- counts[sd$kind[j] + 1L] + 1
      if (!length(cur)) cur_t <- t
      cur[[length(cur) + 1L]] <- r
      cur_len <- cur_len + length(r)
      if (cur_len >= 1024 * 1024) {
        pending[[length(pending) + 1L]] <- list(raw = unlist(cur), t = c(cur_t, t))
        cur <- list(); cur_len <- 0
        if (length(pending) >= 200L) flush()
      }
    }
  }
  flush()
  de <- mcap_rec(0x0F, u32(0))
  writeBin(de, con)
  summary_start <- pos + length(de)
  stats <- mcap_rec(0x0B, c(u64(sum(counts)), u16(2), u32(2), u32(0), u32(0), u32(length(idx)),
                            u64(t0 * 1e9), u64((t0 + secs) * 1e9), u32(20),
                            u16(1), u64(counts[1]), u16(2), u64(counts[2])))
  writeBin(c(schema, chans, stats, unlist(idx)), con)
  writeBin(c(mcap_rec(2, c(u64(summary_start), u64(0), u32(0))),
             as.raw(c(0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a))), con)
  invisible(file)
}

# A child R reading `expr` under /usr/bin/time -v: seconds, peak RSS (MB),
# bytes read (rchar) and what the expression printed.
child <- function(file, expr) {
  code <- sprintf(paste(
    "suppressMessages(library(allanvar)); f <- %s;",
    "io <- function() as.numeric(sub('rchar: ', '', readLines('/proc/self/io')[1]));",
    "b0 <- io(); t <- system.time(r <- %s)[['elapsed']];",
    "cat('RESULT', t, io() - b0, if (is.list(r) && !is.data.frame(r)) nrow(r$data) else nrow(r), '\\n')"),
    deparse(file), expr)
  env <- if (nzchar(lib)) paste0("R_LIBS=", lib) else character()
  out <- system2("/usr/bin/time", c("-v", file.path(R.home("bin"), "Rscript"), "-e", shQuote(code)),
                 stdout = TRUE, stderr = TRUE, env = env)
  res <- strsplit(grep("^RESULT", out, value = TRUE), " ")[[1]]
  rss <- as.numeric(sub(".*: ", "", grep("Maximum resident", out, value = TRUE))) / 1024
  data.frame(s = as.numeric(res[2]), MB_read = as.numeric(res[3]) / 1e6,
             rows = as.numeric(res[4]), peak_rss_MB = rss)
}

cat_time <- function(f) system.time(system2("sh", c("-c", shQuote(paste("cat", shQuote(f), "> /dev/null")))))[["elapsed"]]

specs <- list(c("bag", "none"), c("bag", "lz4"), c("mcap", "none"), c("mcap", "zstd"))
only <- Sys.getenv("ALLANVAR_BENCH_ONLY", "")  # e.g. "bag:none,mcap:none"
if (nzchar(only)) {
  specs <- Filter(function(x) paste(x, collapse = ":") %in% strsplit(only, ",")[[1]], specs)
}
rows <- list()
for (spec in specs) {
  f <- file.path(dir, paste0("big_", spec[2], ".", spec[1]))
  keepdir <- tempfile("keep")
  dir.create(keepdir)
  # ALLANVAR_BENCH_REUSE=1: measure a file left by an earlier run.
  reuse <- Sys.getenv("ALLANVAR_BENCH_REUSE") == "1" && file.exists(f) && spec[2] == "none"
  tw <- if (reuse) NA_real_ else
    system.time(if (spec[1] == "bag") write_big_bag(f, spec[2]) else write_big_mcap(f, spec[2]))[["elapsed"]]
  if (reuse) secs <- round(file.size(f) / (img_bytes * img_rate + 200 * 400))
  size <- file.size(f)
  tc <- cat_time(f)
  tp <- child(f, "imu_topics(f)")
  full <- child(f, "read_imu(f, topic = '/imu0')")
  part <- child(f, sprintf("read_imu(f, topic = '/imu0', from = %f, to = %f)", 0.45 * secs, 0.55 * secs))
  dec <- NA_real_
  if (spec[2] != "none") {
    ks <- list.files(keepdir, full.names = TRUE)
    kb <- sum(file.size(ks))
    cmd <- if (spec[2] == "lz4") "lz4 -dc" else "zstd -dc"
    td <- system.time(system2("sh", c("-c", shQuote(paste("cat", paste(shQuote(ks), collapse = " "), "|", cmd, "> /dev/null")))))[["elapsed"]]
    dec <- td * size / kb  # the decompressor's time for the whole file
  }
  unlink(keepdir, recursive = TRUE)
  rows[[length(rows) + 1L]] <- data.frame(
    file = basename(f), GB = round(size / 1e9, 2), write_s = round(tw, 1),
    cat_s = round(tc, 2), decomp_s = round(dec, 2), topics_s = round(tp$s, 3),
    read_s = round(full$s, 2), read_MB = round(full$MB_read), rss_MB = round(full$peak_rss_MB),
    imu_rows = full$rows, imu_MB = round(full$rows * 10 * 8 / 1e6, 1),
    range10_s = round(part$s, 2), range10_read_pct = round(100 * part$MB_read * 1e6 / size, 1),
    range10_rows = part$rows)
  print(rows[[length(rows)]])
  if (Sys.getenv("ALLANVAR_BENCH_KEEP") != "1") unlink(f)
}
cat("\n", format(Sys.time(), "%Y-%m-%d %H:%M UTC", tz = "UTC"), " git ",
    system("git rev-parse --short HEAD", intern = TRUE), ", ", gb, " GB target\n", sep = "")
print(do.call(rbind, rows), row.names = FALSE)
