# ROS1 bags, format 2.0 (wiki.ros.org/Bags/Format/2.0), without ROS, read
# from the file a chunk at a time (src/rosbag.cpp): the index at the end
# says which chunks hold the topic and when; bz2 chunks are decompressed
# here by R's own bzip2 (memDecompress), one at a time.

bag_version <- "#ROSBAG V2.0\n"

# The index: connections, chunks and their time spans, topics with counts.
bag_scan <- function(file) {
  s <- rosbag_index_cpp(path.expand(file))
  if (!s$indexed && s$bz2) s <- bag_bz2_conns(file, s)
  conns <- s$conns
  topics <- if (nrow(conns)) {
    u <- !duplicated(conns$topic)
    n <- vapply(conns$topic[u], function(tp) sum(conns$n[conns$topic == tp]), 0)
    topic_table(conns$topic[u], conns$type[u], n, "ros1")
  } else {
    topic_table(character(), character(), numeric(), character())
  }
  s$topics <- topics
  s
}

# Without an index, the connection records inside bz2 chunks (which the C++
# pass leaves to R): each chunk decompressed in turn.
bag_bz2_conns <- function(file, s) {
  path <- path.expand(file)
  for (pos in s$chunks$pos) {
    d <- rosbag_chunk_cpp(path, pos)
    if (d$compression != "bz2") next
    raw <- memDecompress(d$data, type = "bzip2")
    cn <- rosbag_decode_cpp(raw, integer(), -Inf, Inf)$conns
    s$conns <- rbind(s$conns, cn[!cn$conn %in% s$conns$conn, , drop = FALSE])
  }
  s$conns$n <- NA_real_
  s
}

bag_read_imu <- function(file, topic, progress, range = NULL) {
  path <- path.expand(file)
  if (!is.null(progress)) progress("scanning the bag")
  s <- bag_scan(file)
  if (!s$indexed) {
    warn("\"", basename(file), "\" has no index (a recording cut off?); ",
         "its chunks were read one after the other.", class = "unindexed")
  }
  no_topics_before_fault(file, s)
  topic <- select_topic(s$topics, topic, file)
  ids <- as.integer(s$conns$conn[s$conns$topic == topic])
  ch <- s$chunks
  keep <- rep(TRUE, nrow(ch))
  if (s$indexed) {
    # Chunks holding the topic's connections, overlapping the time range.
    cc <- s$chunk_conns
    keep <- seq_len(nrow(ch)) %in% (cc$chunk[cc$conn %in% ids & cc$n > 0] + 1)
  }
  from <- -Inf
  to <- Inf
  if (!is.null(range)) {
    t0 <- bag_start_ns(s)
    from <- t0 + range[1L] * 1e9
    to <- t0 + range[2L] * 1e9
    if (s$indexed) keep <- keep & !(ch$end < from | ch$start > to)
  }
  pos <- ch$pos[keep]
  got <- ros_stream(file, length(pos), progress, function(k) {
    out <- list(imu = matrix(numeric(), 0L, 10L), bad = 0, bytes = 0, fault = NULL)
    while (length(k)) {
      res <- rosbag_read_cpp(path, pos[k], ids, from, to)
      out$imu <- rbind(out$imu, res$imu)
      out$bad <- out$bad + res$bad
      out$bytes <- out$bytes + res$bytes
      if (length(res$fault)) {
        out$fault <- res$fault
        break
      }
      if (!isTRUE(res$bz2)) break
      # R's own bzip2 for the chunk the C++ reader stopped at.
      at <- k[res$done + 1]
      d <- rosbag_chunk_cpp(path, pos[at])
      out$bytes <- out$bytes + length(d$data)
      raw <- tryCatch(memDecompress(d$data, type = "bzip2"), error = function(e) NULL)
      if (is.null(raw) || length(raw) != d$size) {
        out$fault <- list(off = pos[at], what = "a bz2 chunk that does not decompress to its stated size")
        break
      }
      one <- rosbag_decode_cpp(raw, ids, from, to)
      out$imu <- rbind(out$imu, one$imu)
      out$bad <- out$bad + one$bad
      k <- k[-seq_len(res$done + 1)]
    }
    out
  }, s$fault)
  if (!is.null(range) && is.na(bag_start_ns(s)) && nrow(got$imu)) {
    # No index, no chunk times: the range from the first message received.
    recv <- got$imu[, 9L] * 1e9 + got$imu[, 10L]
    rel <- (recv - min(recv)) / 1e9
    got$imu <- got$imu[rel >= range[1L] & rel <= range[2L], , drop = FALSE]
  }
  got$topic <- topic
  got$format <- "rosbag"
  got
}

# The start of a bag in ns: its first chunk, or its first message.
bag_start_ns <- function(s) {
  st <- s$chunks$start
  if (length(st) && !all(is.na(st))) min(st, na.rm = TRUE) else NA_real_
}
