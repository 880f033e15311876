# ROS1 bags, format 2.0 (wiki.ros.org/Bags/Format/2.0), without ROS. The
# records are walked in C++ (src/rosbag.cpp); here: the few header fields
# of connection, chunk and chunk-info records, and bz2 chunks through base
# R's memDecompress().

bag_version <- "#ROSBAG V2.0\n"

# Fields of a record header: a named list of raw values.
bag_fields <- function(r) {
  out <- list()
  i <- 1L
  n <- length(r)
  while (i + 3L <= n) {
    len <- raw_u32(r, i)
    f <- r[i + 4L + seq_len(len) - 1L]
    eq <- match(as.raw(0x3d), f)
    if (!is.na(eq)) out[[rawToChar(f[seq_len(eq - 1L)])]] <- f[-seq_len(eq)]
    i <- i + 4L + len
  }
  out
}

slice <- function(buf, off, len) buf[off + seq_len(len)]

bag_scan <- function(file, buf = NULL) {
  if (is.null(buf)) buf <- readBin(file, "raw", file.size(file))
  recs <- rosbag_records(buf, nchar(bag_version), length(buf))
  conns <- bag_conn_table(buf, recs, which(recs$op == 7L))
  chunk <- which(recs$op == 5L)
  chunks <- data.frame(off = recs$data[chunk], len = recs$data_len[chunk],
                       compression = recs$compression[chunk],
                       size = recs$size[chunk], stringsAsFactors = FALSE)
  if (!nrow(conns) && nrow(chunks)) {
    # An unindexed bag: connection records only inside the chunks.
    parts <- lapply(seq_len(nrow(chunks)), function(k) {
      raw <- bag_chunk_raw(buf, chunks[k, ], file)
      inner <- rosbag_records(raw, 0, length(raw))
      bag_conn_table(raw, inner, which(inner$op == 7L))
    })
    conns <- unique(do.call(rbind, parts))
  }
  # Message counts per connection from the chunk-info records.
  counts <- numeric()
  for (k in which(recs$op == 6L)) {
    d <- slice(buf, recs$data[k], recs$data_len[k])
    for (e in seq_len(length(d) %/% 8L)) {
      id <- as.character(raw_u32(d, 8L * (e - 1L) + 1L))
      counts[id] <- (if (is.na(counts[id])) 0 else counts[id]) +
        raw_u32(d, 8L * (e - 1L) + 5L)
    }
  }
  topics <- if (nrow(conns)) {
    u <- conns[!duplicated(conns$topic), , drop = FALSE]
    n <- vapply(u$topic, function(tp) {
      v <- counts[as.character(conns$conn[conns$topic == tp])]
      if (anyNA(v)) NA_real_ else sum(v)
    }, 0)
    topic_table(u$topic, u$type, n, "ros1")
  } else {
    topic_table(character(), character(), numeric(), character())
  }
  list(buf = buf, chunks = chunks, conns = conns, topics = topics)
}

# Connection records (op 7): id from the record header, topic and type from
# the connection header in the data.
bag_conn_table <- function(buf, recs, idx) {
  rows <- lapply(idx, function(k) {
    h <- bag_fields(slice(buf, recs$hdr[k], recs$hdr_len[k]))
    d <- bag_fields(slice(buf, recs$data[k], recs$data_len[k]))
    data.frame(conn = raw_u32(h$conn, 1L), topic = rawToChar(h$topic),
               type = if (is.null(d$type)) NA_character_ else rawToChar(d$type),
               stringsAsFactors = FALSE)
  })
  if (!length(rows)) {
    return(data.frame(conn = numeric(), topic = character(), type = character(),
                      stringsAsFactors = FALSE))
  }
  do.call(rbind, rows)
}

bag_chunk_raw <- function(buf, ch, file) {
  d <- slice(buf, ch$off, ch$len)
  switch(ch$compression,
    none = d,
    bz2 = memDecompress(d, type = "bzip2"),
    lz4 = lz4_decompress_cpp(d, ch$size),
    abort("\"", basename(file), "\" has chunks compressed with \"",
          ch$compression, "\"; none, bz2 and lz4 are read.", class = "file_format"))
}

bag_read_imu <- function(file, topic, progress) {
  if (!is.null(progress)) progress("scanning the bag")
  s <- bag_scan(file)
  topic <- select_topic(s$topics, topic, file)
  ids <- as.integer(s$conns$conn[s$conns$topic == topic])
  if (!is.null(progress)) progress("decoding chunks")
  ch <- s$chunks
  comp <- match(ch$compression, c("none", "lz4", "bz2")) - 1L
  if (anyNA(comp)) {
    abort("\"", basename(file), "\" has chunks compressed with \"",
          ch$compression[is.na(comp)][1L], "\"; none, bz2 and lz4 are read.",
          class = "file_format")
  }
  if (any(comp == 2L) && !bz2_available_cpp()) {
    # No libbz2 to load: base R decompresses each bz2 chunk.
    parts <- vector("list", nrow(ch))
    bad <- 0
    for (k in seq_len(nrow(ch))) {
      res <- if (comp[k] == 2L) {
        raw <- memDecompress(slice(s$buf, ch$off[k], ch$len[k]), type = "bzip2")
        rosbag_imu(raw, 0, length(raw), 0L, length(raw), ids)
      } else {
        rosbag_imu(s$buf, ch$off[k], ch$len[k], comp[k], ch$size[k], ids)
      }
      parts[[k]] <- res$imu
      bad <- bad + res$bad
    }
    imu <- if (length(parts)) do.call(rbind, parts) else matrix(numeric(), 0, 10)
    return(list(imu = imu, bad = bad, topic = topic, format = "rosbag"))
  }
  # Every chunk in one C++ call (src/rosbag.cpp): no R work per chunk.
  res <- rosbag_imu(s$buf, ch$off, ch$len, comp, ch$size, ids, allanvar_threads())
  list(imu = res$imu, bad = res$bad, topic = topic, format = "rosbag")
}
