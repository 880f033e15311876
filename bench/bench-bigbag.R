# Bags of any size (issue 28): ROS1 .bag (none, lz4) and MCAP (none, zstd)
# with 640x480 mono8 images at 20 Hz beside sensor_msgs/Imu at 200 Hz,
# written chunk by chunk by this script's streaming writers (the formats as
# in tools/make-bag-fixtures.R; 8 chunk templates of 0.1 s, cycled with
# their times rewritten), then read in a child process each:
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
if (nzchar(lib)) .libPaths(c(lib, .libPaths()))
dir.create(dir, showWarnings = FALSE, recursive = TRUE)
source(file.path("tools", "make-bag-fixtures.R"))

# Full definitions and md5 sums of the ROS1 messages (as Debian's
# python3-sensor-msgs gives them), so that rosbag can deserialize the bags.
ros1_defs <- list(
  imu = list(md5 = "6a62c6daae103f4ff57a132d6f95cec2", def = "# This is a message to hold data from an IMU (Inertial Measurement Unit)\n#\n# Accelerations should be in m/s^2 (not in g's), and rotational velocity should be in rad/sec\n#\n# If the covariance of the measurement is known, it should be filled in (if all you know is the \n# variance of each measurement, e.g. from the datasheet, just put those along the diagonal)\n# A covariance matrix of all zeros will be interpreted as \"covariance unknown\", and to use the\n# data a covariance will have to be assumed or gotten from some other source\n#\n# If you have no estimate for one of the data elements (e.g. your IMU doesn't produce an orientation \n# estimate), please set element 0 of the associated covariance matrix to -1\n# If you are interpreting this message, please check for a value of -1 in the first element of each \n# covariance matrix, and disregard the associated estimate.\n\nHeader header\n\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance # Row major about x, y, z axes\n\ngeometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance # Row major about x, y, z axes\n\ngeometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance # Row major x, y z \n\n================================================================================\nMSG: std_msgs/Header\n# Standard metadata for higher-level stamped data types.\n# This is generally used to communicate timestamped data \n# in a particular coordinate frame.\n# \n# sequence ID: consecutively increasing ID \nuint32 seq\n#Two-integer timestamp that is expressed as:\n# * stamp.sec: seconds (stamp_secs) since epoch (in Python the variable is called 'secs')\n# * stamp.nsec: nanoseconds since stamp_secs (in Python the variable is called 'nsecs')\n# time-handling sugar is provided by the client library\ntime stamp\n#Frame this data is associated with\nstring frame_id\n\n================================================================================\nMSG: geometry_msgs/Quaternion\n# This represents an orientation in free space in quaternion form.\n\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n\n================================================================================\nMSG: geometry_msgs/Vector3\n# This represents a vector in free space. \n# It is only meant to represent a direction. Therefore, it does not\n# make sense to apply a translation to it (e.g., when applying a \n# generic rigid transformation to a Vector3, tf2 will only apply the\n# rotation). If you want your data to be translatable too, use the\n# geometry_msgs/Point message instead.\n\nfloat64 x\nfloat64 y\nfloat64 z"),
  image = list(md5 = "060021388200f6f0f447d0fcd9c64743", def = "# This message contains an uncompressed image\n# (0, 0) is at top-left corner of image\n#\n\nHeader header        # Header timestamp should be acquisition time of image\n                     # Header frame_id should be optical frame of camera\n                     # origin of frame should be optical center of camera\n                     # +x should point to the right in the image\n                     # +y should point down in the image\n                     # +z should point into to plane of the image\n                     # If the frame_id here and the frame_id of the CameraInfo\n                     # message associated with the image conflict\n                     # the behavior is undefined\n\nuint32 height         # image height, that is, number of rows\nuint32 width          # image width, that is, number of columns\n\n# The legal values for encoding are in file src/image_encodings.cpp\n# If you want to standardize a new string format, join\n# ros-users@lists.sourceforge.net and send an email proposing a new encoding.\n\nstring encoding       # Encoding of pixels -- channel meaning, ordering, size\n                      # taken from the list of strings in include/sensor_msgs/image_encodings.h\n\nuint8 is_bigendian    # is this data bigendian?\nuint32 step           # Full row length in bytes\nuint8[] data          # actual matrix data, size is (step * rows)\n\n================================================================================\nMSG: std_msgs/Header\n# Standard metadata for higher-level stamped data types.\n# This is generally used to communicate timestamped data \n# in a particular coordinate frame.\n# \n# sequence ID: consecutively increasing ID \nuint32 seq\n#Two-integer timestamp that is expressed as:\n# * stamp.sec: seconds (stamp_secs) since epoch (in Python the variable is called 'secs')\n# * stamp.nsec: nanoseconds since stamp_secs (in Python the variable is called 'nsecs')\n# time-handling sugar is provided by the client library\ntime stamp\n#Frame this data is associated with\nstring frame_id\n"))

img_bytes <- 640L * 480L
img_rate <- 20
imu_rate <- 200
# One chunk holds 0.1 s: 20 IMU messages and 2 images (about 0.62 MB, near
# rosbag's default chunk threshold of 768 kB).
chunk_ns <- 1e8
n_chunks <- ceiling(gb * 1e9 / ((img_bytes + 100) * img_rate * chunk_ns / 1e9 + 20 * 400))
secs <- n_chunks * chunk_ns / 1e9
t0 <- 1700000000
set.seed(3)
# One image, 4 bits of entropy a pixel (zstd -1 shrinks it about 7x, lz4 -1
# not at all); reused with new stamps.
img_px <- as.raw(sample(0:15, img_bytes, TRUE) * 16L + 8L)
img_msg <- function(sec, nsec) {
  c(u32(0), u32(sec), u32(nsec), str32("cam0"), u32(480), u32(640), str32("mono8"),
    u8(0), u32(640), u32(img_bytes), img_px)
}
cdr_img <- function(sec, nsec) {
  c(as.raw(c(0, 1, 0, 0)), u32(sec), u32(nsec), str32("cam0"), u32(480), u32(640),
    str32("mono8"), u8(0), as.raw(c(0, 0, 0)), u32(640), u32(img_bytes), img_px)
}
# Times in ns within a chunk, in order: IMU every 5 ms, images at 2.5 and
# 52.5 ms; kind 0 IMU, 1 image.
chunk_off <- c(seq(0, chunk_ns - 1, by = 1e9 / imu_rate), seq(2.5e6, chunk_ns - 1, by = 1e9 / img_rate))
chunk_kind <- c(rep(0L, length(chunk_off) - 2L), 1L, 1L)
o <- order(chunk_off)
chunk_off <- chunk_off[o]
chunk_kind <- chunk_kind[o]
n_imu <- sum(chunk_kind == 0L)

# u64 of sec * 1e9 + nsec, exact (the sum exceeds 2^53).
u64_sn <- function(sec, nsec) {
  sh <- sec %/% 65536
  x <- sh * 1e9
  y <- (sec %% 65536) * 1e9 + nsec
  lo <- (x %% 65536) * 65536 + y
  as.vector(rbind(matrix(u32(lo %% 2^32), 4L), matrix(u32(x %/% 65536 + lo %/% 2^32), 4L)))
}

# Chunk templates: the record bytes of one chunk at time 0 and the byte
# positions (0-based) of its time fields, `pair` (u32 sec, u32 nsec) and
# `u64` (ns); 8 templates with different IMU noise, cycled. A chunk k is
# its template with every time shifted by k * chunk_ns.
make_templates <- function(fmt, head = raw()) {
  lapply(1:8, function(v) {
    rec <- list(sec = rep(0, n_imu), nsec = chunk_off[chunk_kind == 0L],
                gyro = matrix(rnorm(3 * n_imu, sd = 0.01), n_imu),
                accel = matrix(rnorm(3 * n_imu, sd = 0.02), n_imu) + rep(c(0, 0, 9.81), each = n_imu))
    imu <- if (fmt == "ros1") ros1_messages(rec) else cdr_messages(rec)
    parts <- list(head)
    at <- length(head)
    pair <- u64p <- pair_off <- u64_off <- rec_at <- numeric()
    ii <- 0L
    for (j in seq_along(chunk_off)) {
      if (chunk_kind[j] == 0L) {
        ii <- ii + 1L
        d <- imu[, ii]
      } else {
        d <- if (fmt == "ros1") img_msg(0, chunk_off[j]) else cdr_img(0, chunk_off[j])
      }
      if (fmt == "ros1") {
        conn <- chunk_kind[j]
        r <- bag_record(c(u32(4), charToRaw("op="), u8(2), u32(9), charToRaw("conn="), u32(conn),
                          u32(13), charToRaw("time="), u32(0), u32(chunk_off[j])), d)
        # receive time in the record header (at 34), header stamp in the message (at 46 + 4)
        pair <- c(pair, at + 34, at + 50)
        pair_off <- c(pair_off, chunk_off[j], chunk_off[j])
      } else {
        r <- c(u8(5), u64(22 + length(d)), u16(chunk_kind[j] + 1L), u32(0), u64(chunk_off[j]),
               u64(chunk_off[j]), d)
        u64p <- c(u64p, at + 15, at + 23)
        u64_off <- c(u64_off, chunk_off[j], chunk_off[j])
        pair <- c(pair, at + 35)  # the CDR header stamp, after the encapsulation
        pair_off <- c(pair_off, chunk_off[j])
      }
      parts[[length(parts) + 1L]] <- r
      rec_at <- c(rec_at, at)
      at <- at + length(r)
    }
    bytes <- unlist(parts)
    stopifnot(length(bytes) == at,
              all(readBin(bytes[rep(pair, each = 4) + 5:8], "integer", length(pair), 4L) == pair_off))
    list(bytes = bytes, pair = as.vector(outer(1:8, pair, "+")), pair_off = pair_off,
         u64 = as.vector(outer(1:8, u64p, "+")), u64_off = u64_off, rec_at = rec_at)
  })
}

# Chunk k (0-based): its bytes, first and last time (ns).
chunk_bytes <- function(tmpls, k) {
  tp <- tmpls[[k %% length(tmpls) + 1L]]
  b <- tp$bytes
  base <- k * chunk_ns  # exact: below 2^53
  abs_s <- function(off) t0 + (base + off) %/% 1e9
  abs_n <- function(off) (base + off) %% 1e9
  b[tp$pair] <- u32(rbind(abs_s(tp$pair_off), abs_n(tp$pair_off)))
  if (length(tp$u64)) b[tp$u64] <- u64_sn(abs_s(tp$u64_off), abs_n(tp$u64_off))
  list(bytes = b, sec = abs_s(chunk_off), nsec = abs_n(chunk_off), rec_at = tp$rec_at,
       first = c(abs_s(chunk_off[1]), abs_n(chunk_off[1])),
       last = c(abs_s(chunk_off[length(chunk_off)]), abs_n(chunk_off[length(chunk_off)])))
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
  if (!is.null(keep)) {
    file.copy(out, keep)
    writeLines(format(lengths(raws), scientific = FALSE), file.path(keep, "sizes.txt"))
  }
  lapply(out, function(f) readBin(f, "raw", file.size(f)))
}

write_big_bag <- function(file, compression) {
  con <- file(file, "wb")
  on.exit(close(con))
  writeBin(charToRaw("#ROSBAG V2.0\n"), con)
  writeBin(raw(4096), con)  # bag header, rewritten at the end
  pos <- 13 + 4096
  conn_rec <- function(id, topic, type, def) {
    bag_record(bag_header_fields(op = u8(7), conn = u32(id), topic = topic),
               bag_header_fields(topic = topic, type = type, md5sum = def$md5,
                                 message_definition = def$def))
  }
  conns <- c(conn_rec(0, "/imu0", "sensor_msgs/Imu", ros1_defs$imu),
             conn_rec(1, "/cam0/image_raw", "sensor_msgs/Image", ros1_defs$image))
  # The index data records after a chunk: per connection, each message's
  # receive time and offset in the chunk's data (rosbag needs them).
  index_data <- function(ch) {
    unlist(lapply(0:1, function(conn) {
      w <- which(chunk_kind == conn)
      bag_record(bag_header_fields(op = u8(4), ver = u32(1), conn = u32(conn), count = u32(length(w))),
                 u32(rbind(ch$sec[w], ch$nsec[w], ch$rec_at[w])))
    }))
  }
  tmpls <- make_templates("ros1", conns)
  infos <- vector("list", n_chunks)
  for (k0 in seq(0, n_chunks - 1, by = 200)) {
    ks <- k0:min(n_chunks - 1, k0 + 199)
    chs <- lapply(ks, function(k) chunk_bytes(tmpls, k))
    raws <- lapply(chs, `[[`, "bytes")
    comp <- if (compression == "none") raws else
      compress_batch(raws, compression, if (k0 == 0) keepdir)
    for (i in seq_along(ks)) {
      ch <- c(bag_record(bag_header_fields(op = u8(5), compression = compression,
                                           size = u32(length(raws[[i]]))), comp[[i]]),
              index_data(chs[[i]]))
      writeBin(ch, con)
      infos[[ks[i] + 1L]] <- bag_record(
        bag_header_fields(op = u8(6), ver = u32(1), chunk_pos = u64(pos),
                          start_time = u32(chs[[i]]$first), end_time = u32(chs[[i]]$last),
                          count = u32(2)),
        c(u32(0), u32(n_imu), u32(1), u32(length(chunk_kind) - n_imu)))
      pos <- pos + length(ch)
    }
  }
  index_pos <- pos
  writeBin(c(conns, unlist(infos)), con)
  h <- bag_header_fields(op = u8(3), index_pos = u64(index_pos), conn_count = u32(2),
                         chunk_count = u32(n_chunks))
  seek(con, 13, rw = "write")
  writeBin(bag_record(h, charToRaw(strrep(" ", 4096 - (8 + length(h))))), con)
  invisible(file)
}

write_big_mcap <- function(file, compression) {
  con <- file(file, "wb")
  on.exit(close(con))
  schema <- c(mcap_rec(3, c(u16(1), str32("sensor_msgs/msg/Imu"), str32("ros2msg"), str32("x"))),
              mcap_rec(3, c(u16(2), str32("sensor_msgs/msg/Image"), str32("ros2msg"), str32("x"))))
  chans <- c(mcap_rec(4, c(u16(1), u16(1), str32("/imu0"), str32("cdr"), u32(0))),
             mcap_rec(4, c(u16(2), u16(2), str32("/cam0/image_raw"), str32("cdr"), u32(0))))
  head <- c(as.raw(c(0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a)),
            mcap_rec(1, c(str32("ros2"), str32("allanvar bench"))), schema, chans)
  writeBin(head, con)
  pos <- as.numeric(length(head))  # double: offsets pass 2^31
  tmpls <- make_templates("cdr")
  idx <- vector("list", n_chunks)
  comp_name <- if (compression == "none") "" else compression
  for (k0 in seq(0, n_chunks - 1, by = 200)) {
    ks <- k0:min(n_chunks - 1, k0 + 199)
    chs <- lapply(ks, function(k) chunk_bytes(tmpls, k))
    raws <- lapply(chs, `[[`, "bytes")
    comp <- if (compression == "none") raws else
      compress_batch(raws, compression, if (k0 == 0) keepdir)
    for (i in seq_along(ks)) {
      st <- u64_sn(chs[[i]]$first[1], chs[[i]]$first[2])
      en <- u64_sn(chs[[i]]$last[1], chs[[i]]$last[2])
      rec <- mcap_rec(6, c(st, en, u64(length(raws[[i]])), u32(0),
                           str32(comp_name), u64(length(comp[[i]])), comp[[i]]))
      # Message index records after the chunk, one per channel: each
      # message's log time and offset in the chunk's records.
      ch <- chs[[i]]
      mi <- lapply(0:1, function(kind) {
        w <- which(chunk_kind == kind)
        e <- as.vector(rbind(matrix(u64_sn(ch$sec[w], ch$nsec[w]), 8L), matrix(u64(ch$rec_at[w]), 8L)))
        mcap_rec(7, c(u16(kind + 1L), u32(length(e)), e))
      })
      mi_at <- pos + length(rec) + c(0, length(mi[[1]]))
      writeBin(c(rec, unlist(mi)), con)
      idx[[ks[i] + 1L]] <- mcap_rec(8, c(st, en, u64(pos), u64(length(rec)),
                                         u32(20), u16(1), u64(mi_at[1]), u16(2), u64(mi_at[2]),
                                         u64(sum(lengths(mi))),
                                         str32(comp_name), u64(length(comp[[i]])),
                                         u64(length(raws[[i]]))))
      pos <- pos + length(rec) + sum(lengths(mi))
    }
  }
  de <- mcap_rec(0x0F, u32(0))
  writeBin(de, con)
  summary_start <- pos + length(de)
  n_img <- length(chunk_kind) - n_imu
  stats <- mcap_rec(0x0B, c(u64(n_chunks * length(chunk_kind)), u16(2), u32(2), u32(0), u32(0),
                            u32(n_chunks), u64_sn(t0, 0), u64_sn(t0 + secs, 0), u32(20),
                            u16(1), u64(n_chunks * n_imu), u16(2), u64(n_chunks * n_img)))
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
    "iod <- function() as.numeric(sub('read_bytes: ', '', grep('^read_bytes', readLines('/proc/self/io'), value = TRUE)));",
    "b0 <- io(); d0 <- iod(); t <- system.time(r <- %s)[['elapsed']];",
    "cat('RESULT', t, io() - b0, if (is.list(r) && !is.data.frame(r)) nrow(r$data) else nrow(r), iod() - d0, '\\n')"),
    deparse(file), expr)
  env <- if (nzchar(lib)) paste0("R_LIBS=", lib) else character()
  out <- system2("/usr/bin/time", c("-v", file.path(R.home("bin"), "Rscript"), "-e", shQuote(code)),
                 stdout = TRUE, stderr = TRUE, env = env)
  res <- strsplit(grep("^RESULT", out, value = TRUE), " ")[[1]]
  rss <- as.numeric(sub(".*: ", "", grep("Maximum resident", out, value = TRUE))) / 1024
  data.frame(s = as.numeric(res[2]), MB_read = as.numeric(res[3]) / 1e6,
             rows = as.numeric(res[4]), disk_MB = as.numeric(res[5]) / 1e6, peak_rss_MB = rss)
}

# The file's pages dropped from the page cache (GNU dd; this file only),
# for the cold-cache runs.
drop_cache <- function(f) system2("dd", c(paste0("if=", f), "iflag=nocache", "count=0", "status=none"))
cat_time <- function(f) system.time(system2("sh", c("-c", shQuote(paste("cat", shQuote(f), "> /dev/null")))))[["elapsed"]]

specs <- list(c("bag", "none"), c("mcap", "none"), c("bag", "lz4"), c("mcap", "zstd"))
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
  # ALLANVAR_BENCH_WRITE_ONLY=1: the files written and kept, nothing
  # measured (tools/check-bench-writers.sh reads them with the formats' own
  # libraries).
  if (Sys.getenv("ALLANVAR_BENCH_WRITE_ONLY") == "1") next
  size <- file.size(f)
  tc <- cat_time(f)
  tp <- child(f, "imu_topics(f)")
  full <- child(f, "read_imu(f, topic = '/imu0')")
  # Cold: `cat` and the reader each after the file's pages were dropped.
  drop_cache(f)
  tc_cold <- cat_time(f)
  drop_cache(f)
  cold <- child(f, "read_imu(f, topic = '/imu0')")
  part <- child(f, sprintf("read_imu(f, topic = '/imu0', from = %f, to = %f)", 0.45 * secs, 0.55 * secs))
  dec <- dec_pkg <- NA_real_
  if (spec[2] != "none") {
    ks <- list.files(keepdir, pattern = "[.](lz4|zst)$", full.names = TRUE)
    kb <- sum(file.size(ks))
    cmd <- if (spec[2] == "lz4") "lz4 -dc" else "zstd -dc"
    td <- system.time(system2("sh", c("-c", shQuote(paste("cat", paste(shQuote(ks), collapse = " "), "|", cmd, "> /dev/null")))))[["elapsed"]]
    dec <- td * size / kb  # the decompressor's time for the whole file
    # The package's own decoder alone on the same chunks (in memory).
    ks <- ks[grepl("[.](lz4|zst)$", ks)]
    sz <- as.numeric(readLines(file.path(keepdir, "sizes.txt")))
    cs <- lapply(ks, function(k) readBin(k, "raw", file.size(k)))
    fn <- if (spec[2] == "lz4") allanvar:::lz4_decompress_cpp else allanvar:::zstd_decompress_cpp
    tpk <- system.time(for (i in seq_along(cs)) fn(cs[[i]], sz[i]))[["elapsed"]]
    dec_pkg <- tpk * size / sum(lengths(cs))
    rm(cs)
  }
  unlink(keepdir, recursive = TRUE)
  rows[[length(rows) + 1L]] <- data.frame(
    file = basename(f), GB = round(size / 1e9, 2), write_s = round(tw, 1),
    cat_s = round(tc, 2), decomp_s = round(dec, 2), decoder_s = round(dec_pkg, 2), topics_s = round(tp$s, 3),
    read_s = round(full$s, 2), read_MB = round(full$MB_read), rss_MB = round(full$peak_rss_MB),
    cold_cat_s = round(tc_cold, 2), cold_read_s = round(cold$s, 2), cold_disk_MB = round(cold$disk_MB),
    imu_rows = full$rows, imu_MB = round(full$rows * 10 * 8 / 1e6, 1),
    range10_s = round(part$s, 2), range10_read_pct = round(100 * part$MB_read * 1e6 / size, 1),
    range10_rows = part$rows)
  print(rows[[length(rows)]])
  # ALLANVAR_BENCH_KEEP=1 keeps every file, "bag:none" only that one.
  keep <- Sys.getenv("ALLANVAR_BENCH_KEEP")
  if (!(keep == "1" || paste(spec, collapse = ":") %in% strsplit(keep, ",")[[1]])) unlink(f)
}
cat("\n", format(Sys.time(), "%Y-%m-%d %H:%M UTC", tz = "UTC"), " git ",
    system("git rev-parse --short HEAD", intern = TRUE), ", ", gb, " GB target\n", sep = "")
print(do.call(rbind, rows), row.names = FALSE)
