# Writers of ROS1 bags, rosbag2 db3 and MCAP files holding sensor_msgs/Imu,
# written from the formats' published specifications, not with ROS:
#   ROS1 bag format 2.0   wiki.ros.org/Bags/Format/2.0
#   ROS1 serialization    wiki.ros.org/msg#Serialization (little-endian, packed)
#   MCAP                  mcap.dev/spec
#   CDR (ROS2 messages)   OMG DDS-XTypes 1.3, 7.4 (XCDR1 plain: encapsulation
#                         header 00 01 00 00, alignment to the value's size)
#   rosbag2 sqlite3       rosbag2_storage_default_plugins (tables `topics`,
#                         `messages`)
# Used by the tests' fixtures (Rscript tools/make-bag-fixtures.R writes
# tests/testthat/fixtures/ros/) and by bench/bench-read.R (source() it and
# call the writers). LZ4 and zstd chunks are compressed with the `lz4` and
# `zstd` command-line tools (Debian packages lz4, zstd).

# ---- the recording ---------------------------------------------------------

# n IMU samples at `freq` Hz: list(sec, nsec, gyro (n x 3), accel (n x 3)).
fixture_recording <- function(n = 300L, freq = 200, seed = 42L, t0 = 1403636579) {
  set.seed(seed)
  step <- round(1e9 / freq)
  off <- (seq_len(n) - 1) * step
  list(sec = t0 + off %/% 1e9, nsec = off %% 1e9,
       gyro = matrix(rnorm(3 * n, sd = 1e-3), n) + rep(c(1e-4, -2e-4, 5e-5), each = n),
       accel = cbind(rnorm(n, sd = 0.02), rnorm(n, sd = 0.02), 9.81 + rnorm(n, sd = 0.02)))
}

# Kalibr CSV: ns stamps written as exact integers, values with 17 digits.
write_imu_csv <- function(rec, file) {
  stamp <- sprintf("%.0f%09.0f", rec$sec, rec$nsec)
  v <- cbind(rec$gyro, rec$accel)
  body <- do.call(paste, c(list(stamp), lapply(1:6, function(j)
    formatC(v[, j], digits = 17, format = "g")), sep = ","))
  writeLines(c("timestamp,omega_x,omega_y,omega_z,alpha_x,alpha_y,alpha_z", body), file)
  invisible(file)
}

# ---- bytes -----------------------------------------------------------------

u8 <- function(x) as.raw(x)
u16 <- function(x) writeBin(as.integer(x), raw(), size = 2L, endian = "little")
u32 <- function(x) {
  x <- as.numeric(x)
  as.raw(as.vector(rbind(x %% 256, (x %/% 256) %% 256, (x %/% 65536) %% 256,
                         (x %/% 16777216) %% 256)))
}
u64 <- function(x) {
  x <- as.numeric(x)
  as.vector(rbind(matrix(u32(x %% 2^32), 4L), matrix(u32(x %/% 2^32), 4L)))
}
f64 <- function(x) writeBin(as.double(x), raw(), size = 8L, endian = "little")
str32 <- function(s) c(u32(nchar(s, "bytes")), charToRaw(s))

# The 37 float64 of each message (orientation, covariances, angular
# velocity, linear acceleration), one message per column.
imu_doubles <- function(rec) {
  n <- length(rec$sec)
  d <- matrix(0, 37L, n)
  d[4L, ] <- 1                      # orientation w
  d[5L, ] <- -1                     # orientation covariance[0] = -1: no estimate
  d[14:16, ] <- t(rec$gyro)
  d[17L, ] <- 1e-6
  d[26:28, ] <- t(rec$accel)
  d[29L, ] <- 1e-4
  d
}

# ROS1-serialized sensor_msgs/Imu, one raw vector per message (as columns
# of a raw matrix, all of the same length).
ros1_messages <- function(rec, frame_id = "imu_link") {
  n <- length(rec$sec)
  fid <- charToRaw(frame_id)
  head <- matrix(u32(as.vector(rbind(seq_len(n) - 1, rec$sec, rec$nsec, length(fid)))), 16L, n)
  body <- matrix(f64(imu_doubles(rec)), 296L, n)
  rbind(head, matrix(rep(fid, n), length(fid), n), body)
}

# CDR-serialized (XCDR1, little-endian) sensor_msgs/msg/Imu.
cdr_messages <- function(rec, frame_id = "imu_link") {
  n <- length(rec$sec)
  fid <- c(charToRaw(frame_id), as.raw(0))       # CDR strings end with NUL
  q <- 12L + length(fid)                          # after sec, nanosec, len, chars
  pad <- (8L - q %% 8L) %% 8L                     # float64 aligned to 8
  head <- matrix(c(as.raw(c(0, 1, 0, 0))), 4L, n)
  stamp <- matrix(u32(as.vector(rbind(rec$sec, rec$nsec, length(fid)))), 12L, n)
  body <- matrix(f64(imu_doubles(rec)), 296L, n)
  rbind(head, stamp, matrix(rep(fid, n), length(fid), n),
        matrix(as.raw(0), pad, n), body)
}

compress <- function(r, type) {
  if (type %in% c("", "none")) return(r)
  switch(type,
    bz2 = memCompress(r, type = "bzip2"),
    lz4 = , zstd = {
      i <- tempfile(); o <- tempfile()
      on.exit(unlink(c(i, o)))
      writeBin(r, i)
      args <- if (type == "lz4") c("-q", "-z", "-f", i, o) else c("-q", "-f", i, "-o", o)
      st <- system2(type, args, stdout = FALSE, stderr = FALSE)
      if (st != 0) stop("the `", type, "` command failed (install Debian's ", type, ")")
      readBin(o, "raw", file.size(o))
    })
}

# ---- ROS1 bag --------------------------------------------------------------

imu_msg_def <- "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n"

bag_header_fields <- function(...) {
  f <- list(...)
  unlist(lapply(names(f), function(k) {
    v <- if (is.raw(f[[k]])) f[[k]] else charToRaw(f[[k]])
    c(u32(nchar(k) + 1L + length(v)), charToRaw(k), charToRaw("="), v)
  }), use.names = FALSE)
}

bag_record <- function(header, data) c(u32(length(header)), header, u32(length(data)), data)

# `topics`: list of list(topic, type, conn, rec (or NULL), raw messages
# matrix). Messages are written in time order, `per_chunk` per chunk.
write_ros1_bag <- function(file, topics, compression = "none", per_chunk = 2000L) {
  conn_rec <- function(tp) {
    bag_record(bag_header_fields(op = u8(7), conn = u32(tp$conn), topic = tp$topic),
               bag_header_fields(topic = tp$topic, type = tp$type,
                                 md5sum = "6a62c6daae103f4ff57a132d6f95cec2",
                                 message_definition = tp$def))
  }
  # One table of every message: topic index, time, column.
  ord <- do.call(rbind, lapply(seq_along(topics), function(k) {
    tp <- topics[[k]]
    data.frame(k = k, i = seq_len(ncol(tp$msgs)), sec = tp$sec, nsec = tp$nsec)
  }))
  ord <- ord[order(ord$sec, ord$nsec, ord$k), ]
  chunk_of <- (seq_len(nrow(ord)) - 1L) %/% per_chunk
  out <- list(charToRaw("#ROSBAG V2.0\n"), NULL)  # the bag header goes in slot 2
  pos <- 13 + 4096
  infos <- list()
  for (cidx in unique(chunk_of)) {
    rows <- ord[chunk_of == cidx, ]
    parts <- list()
    off <- 0
    index <- list()
    for (k in unique(rows$k)) parts[[length(parts) + 1L]] <- conn_rec(topics[[k]])
    off <- sum(lengths(parts))
    # message data records: header (op, conn, time) + data, built for all
    # messages of a topic at once (fixed-size headers)
    recs <- vector("list", nrow(rows))
    for (k in unique(rows$k)) {
      tp <- topics[[k]]
      sel <- which(rows$k == k)
      nm <- length(sel)
      h <- rbind(matrix(c(u32(4), charToRaw("op="), u8(2), u32(9), charToRaw("conn="),
                          u32(tp$conn), u32(13), charToRaw("time=")), 30L, nm),
                 matrix(u32(as.vector(rbind(rows$sec[sel], rows$nsec[sel]))), 8L, nm))
      body <- tp$msgs[, rows$i[sel], drop = FALSE]
      m <- rbind(matrix(u32(38), 4L, nm), h, matrix(u32(nrow(body)), 4L, nm), body)
      for (j in seq_len(nm)) recs[[sel[j]]] <- m[, j]
    }
    lens <- lengths(recs)
    offs <- off + c(0, cumsum(lens))[seq_along(lens)]
    raw <- c(unlist(parts), unlist(recs))
    comp <- compress(raw, compression)
    chunk <- bag_record(bag_header_fields(op = u8(5), compression = compression,
                                          size = u32(length(raw))), comp)
    idx <- lapply(unique(rows$k), function(k) {
      sel <- rows$k == k
      d <- unlist(lapply(which(sel), function(r)
        c(u32(rows$sec[r]), u32(rows$nsec[r]), u32(offs[r]))))
      bag_record(bag_header_fields(op = u8(4), ver = u32(1), conn = u32(topics[[k]]$conn),
                                   count = u32(sum(sel))), d)
    })
    counts <- vapply(unique(rows$k), function(k) sum(rows$k == k), 0)
    infos[[length(infos) + 1L]] <- list(pos = pos, rows = rows, counts = counts,
                                        conns = vapply(unique(rows$k), function(k) topics[[k]]$conn, 0))
    out[[length(out) + 1L]] <- c(chunk, unlist(idx))
    pos <- pos + length(chunk) + sum(lengths(idx))
  }
  index_pos <- pos
  tail <- c(unlist(lapply(topics, conn_rec)), unlist(lapply(infos, function(ci) {
    st <- ci$rows[1L, ]; en <- ci$rows[nrow(ci$rows), ]
    bag_record(bag_header_fields(op = u8(6), ver = u32(1), chunk_pos = u64(ci$pos),
                                 start_time = c(u32(st$sec), u32(st$nsec)),
                                 end_time = c(u32(en$sec), u32(en$nsec)),
                                 count = u32(length(ci$conns))),
               unlist(lapply(seq_along(ci$conns), function(j)
                 c(u32(ci$conns[j]), u32(ci$counts[j])))))
  })))
  h <- bag_header_fields(op = u8(3), index_pos = u64(index_pos),
                         conn_count = u32(length(topics)), chunk_count = u32(length(infos)))
  pad <- 4096 - (4 + length(h) + 4)
  out[[2L]] <- bag_record(h, charToRaw(strrep(" ", pad)))
  writeBin(c(unlist(out), tail), file)
  invisible(file)
}

# ---- MCAP ------------------------------------------------------------------

mcap_rec <- function(op, content) c(u8(op), u64(length(content)), content)

# `topics`: list of list(topic, type, id, msgs (raw matrix), sec, nsec);
# `encoding`: "cdr" (ROS2, schema encoding ros2msg) or "ros1".
write_mcap <- function(file, topics, compression = "", encoding = "cdr",
                       per_chunk = 2000L) {
  sch_enc <- if (encoding == "cdr") "ros2msg" else "ros1msg"
  schema <- function(tp) mcap_rec(3, c(u16(tp$id), str32(tp$type), str32(sch_enc),
                                       str32(tp$def)))
  channel <- function(tp) mcap_rec(4, c(u16(tp$id), u16(tp$id), str32(tp$topic),
                                        str32(encoding), u32(0)))
  ord <- do.call(rbind, lapply(seq_along(topics), function(k) {
    tp <- topics[[k]]
    data.frame(k = k, i = seq_len(ncol(tp$msgs)), sec = tp$sec, nsec = tp$nsec)
  }))
  ord <- ord[order(ord$sec, ord$nsec, ord$k), ]
  ns <- ord$sec * 1e9 + ord$nsec
  chunk_of <- (seq_len(nrow(ord)) - 1L) %/% per_chunk
  out <- list(as.raw(c(0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a)),
              mcap_rec(1, c(str32(if (encoding == "cdr") "ros2" else "ros1"),
                            str32("allanvar fixtures"))))
  first <- TRUE
  for (cidx in unique(chunk_of)) {
    sel <- which(chunk_of == cidx)
    rows <- ord[sel, ]
    recs <- vector("list", nrow(rows))
    for (k in unique(rows$k)) {
      tp <- topics[[k]]
      w <- which(rows$k == k)
      nm <- length(w)
      body <- tp$msgs[, rows$i[w], drop = FALSE]
      t <- ns[sel[w]]
      m <- rbind(matrix(c(u8(5), u64(22 + nrow(body)), u16(tp$id)), 11L, nm),
                 matrix(u32(rows$i[w] - 1), 4L, nm),
                 matrix(u64(t), 8L, nm), matrix(u64(t), 8L, nm), body)
      for (j in seq_len(nm)) recs[[w[j]]] <- m[, j]
    }
    pre <- if (first) c(unlist(lapply(topics, schema)), unlist(lapply(topics, channel)))
    first <- FALSE
    raw <- c(pre, unlist(recs))
    comp <- compress(raw, if (compression == "") "none" else compression)
    out[[length(out) + 1L]] <- mcap_rec(6, c(u64(min(ns[sel])), u64(max(ns[sel])),
                                             u64(length(raw)), u32(0), str32(compression),
                                             u64(length(comp)), comp))
  }
  out[[length(out) + 1L]] <- mcap_rec(0x0F, u32(0))
  data <- unlist(out)
  summary_start <- length(data)
  counts <- unlist(lapply(topics, function(tp) c(u16(tp$id), u64(ncol(tp$msgs)))))
  stats <- mcap_rec(0x0B, c(u64(nrow(ord)), u16(length(topics)), u32(length(topics)),
                            u32(0), u32(0), u32(length(unique(chunk_of))),
                            u64(min(ns)), u64(max(ns)), u32(length(counts)), counts))
  summ <- c(unlist(lapply(topics, schema)), unlist(lapply(topics, channel)), stats)
  footer <- mcap_rec(2, c(u64(summary_start), u64(0), u32(0)))
  writeBin(c(data, summ, footer, as.raw(c(0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a))),
           file)
  invisible(file)
}

# ---- rosbag2 SQLite --------------------------------------------------------

write_db3 <- function(file, topics) {
  unlink(file)
  con <- DBI::dbConnect(RSQLite::SQLite(), file)
  on.exit(DBI::dbDisconnect(con))
  DBI::dbExecute(con, "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL)")
  DBI::dbExecute(con, "INSERT INTO schema VALUES (3, 'humble')")
  DBI::dbExecute(con, paste("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL,",
                            "type TEXT NOT NULL, serialization_format TEXT NOT NULL,",
                            "offered_qos_profiles TEXT NOT NULL)"))
  DBI::dbExecute(con, paste("CREATE TABLE messages(id INTEGER PRIMARY KEY,",
                            "topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL,",
                            "data BLOB NOT NULL)"))
  for (tp in topics) {
    DBI::dbExecute(con, "INSERT INTO topics VALUES (?, ?, ?, 'cdr', '')",
                   params = list(tp$id, tp$topic, tp$type))
  }
  ord <- do.call(rbind, lapply(seq_along(topics), function(k) {
    tp <- topics[[k]]
    data.frame(k = k, i = seq_len(ncol(tp$msgs)), sec = tp$sec, nsec = tp$nsec)
  }))
  ord <- ord[order(ord$sec, ord$nsec, ord$k), ]
  blobs <- lapply(seq_len(nrow(ord)), function(r) topics[[ord$k[r]]]$msgs[, ord$i[r]])
  ts <- bit64::as.integer64(ord$sec) * bit64::as.integer64(1e9) + bit64::as.integer64(ord$nsec)
  df <- data.frame(id = seq_len(nrow(ord)),
                   topic_id = vapply(ord$k, function(k) topics[[k]]$id, 0))
  df$timestamp <- ts
  df$data <- blob::as_blob(blobs)
  DBI::dbWriteTable(con, "messages", df, append = TRUE)
  invisible(file)
}

# ---- the fixtures ----------------------------------------------------------

# The topics of the fixtures: /imu0 (the recording), /imu1 (a second IMU,
# 20 messages) and /temperature (not an IMU).
fixture_topics <- function(rec, encoding) {
  ser <- if (encoding == "ros1") ros1_messages else cdr_messages
  ty <- function(t) if (encoding == "ros1") t else sub("/", "/msg/", t)
  rec2 <- fixture_recording(20L, freq = 10, seed = 7L)
  temp_sec <- rec$sec[1L] + 0:4
  temp <- matrix(f64(20 + 0:4 / 10), 8L, 5L)     # not an Imu: 8 bytes each
  if (encoding == "cdr") temp <- rbind(matrix(as.raw(c(0, 1, 0, 0)), 4L, 5L), temp)
  list(list(topic = "/imu0", type = ty("sensor_msgs/Imu"), conn = 0, id = 1,
            def = imu_msg_def, msgs = ser(rec), sec = rec$sec, nsec = rec$nsec),
       list(topic = "/imu1", type = ty("sensor_msgs/Imu"), conn = 1, id = 2,
            def = imu_msg_def, msgs = ser(rec2), sec = rec2$sec, nsec = rec2$nsec),
       list(topic = "/temperature", type = ty("std_msgs/Float64"), conn = 2, id = 3,
            def = "float64 data\n", msgs = temp, sec = temp_sec, nsec = rep(0, 5)))
}

make_fixtures <- function(dir) {
  dir.create(dir, showWarnings = FALSE, recursive = TRUE)
  rec <- fixture_recording()
  write_imu_csv(rec, file.path(dir, "imu.csv"))
  t1 <- fixture_topics(rec, "ros1")
  t2 <- fixture_topics(rec, "cdr")
  for (cmp in c("none", "bz2", "lz4")) {
    write_ros1_bag(file.path(dir, paste0("imu_", cmp, ".bag")), t1, cmp, per_chunk = 128L)
  }
  for (cmp in c("", "lz4", "zstd")) {
    write_mcap(file.path(dir, paste0("imu_", if (cmp == "") "none" else cmp, ".mcap")),
               t2, cmp, "cdr", per_chunk = 128L)
  }
  write_mcap(file.path(dir, "imu_ros1.mcap"), t1, "lz4", "ros1", per_chunk = 128L)
  write_db3(file.path(dir, "imu.db3"), t2)
  invisible(list.files(dir, full.names = TRUE))
}

# Damaged copies of the lz4 bag and the zstd MCAP: one bit flipped 200
# bytes into the compressed data of the second chunk (found by its frame's
# magic number), so that the reader's checks, not a cut, must find it.
damage_second_frame <- function(src, dst, magic) {
  b <- readBin(src, "raw", file.size(src))
  at <- which(b == magic[1L])
  at <- at[vapply(at, function(i) identical(b[i + 0:3], magic), NA)]
  if (length(at) < 2L) stop("fewer than two compressed chunks in ", src)
  k <- at[2L] + 200L
  b[k] <- xor(b[k], as.raw(1L))
  writeBin(b, dst)
  invisible(k - 1L)  # the flipped byte's 0-based offset
}

make_damaged_fixtures <- function(dir) {
  c(lz4_bag = damage_second_frame(file.path(dir, "imu_lz4.bag"),
                                  file.path(dir, "imu_lz4_damaged.bag"),
                                  as.raw(c(0x04, 0x22, 0x4D, 0x18))),
    zstd_mcap = damage_second_frame(file.path(dir, "imu_zstd.mcap"),
                                    file.path(dir, "imu_zstd_damaged.mcap"),
                                    as.raw(c(0x28, 0xB5, 0x2F, 0xFD))))
}

if (sys.nframe() == 0L) {
  dir <- file.path("tests", "testthat", "fixtures", "ros")
  print(make_fixtures(dir))
  print(make_damaged_fixtures(dir))
}
