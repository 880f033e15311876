# MCAP files (mcap.dev/spec) without ROS. Records are walked and chunks
# decompressed (none, lz4, zstd) in C++ (src/mcap.cpp); here: the Schema,
# Channel and Statistics records, and the choice of channels.

mcap_magic <- as.raw(c(0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a))

mcap_scan <- function(file) {
  buf <- readBin(file, "raw", file.size(file))
  n <- length(buf)
  end <- if (n >= 16 && identical(buf[(n - 7):n], mcap_magic)) n - 8 else n
  recs <- mcap_records(buf, 8, end)
  tabs <- mcap_tables(buf, recs)
  if (!nrow(tabs$channels)) {
    # Channels only inside chunks (no summary section).
    for (k in which(recs$op == 6L)) {
      raw <- mcap_chunk_raw(buf, recs$off[k], recs$len[k])
      t2 <- mcap_tables(raw, mcap_records(raw, 0, length(raw)))
      tabs$channels <- unique(rbind(tabs$channels, t2$channels))
      tabs$schemas <- unique(rbind(tabs$schemas, t2$schemas))
    }
  }
  ch <- tabs$channels
  type <- tabs$schemas$name[match(ch$schema, tabs$schemas$id)]
  counts <- tabs$counts[as.character(ch$id)]
  u <- !duplicated(ch$topic)
  n_msg <- vapply(ch$topic[u], function(tp) {
    v <- counts[ch$topic == tp]
    if (anyNA(v)) NA_real_ else sum(v)
  }, 0)
  list(buf = buf, recs = recs, channels = cbind(ch, type = type),
       topics = topic_table(ch$topic[u], type[u], n_msg, ch$encoding[u]))
}

# Schema (0x03), Channel (0x04) and Statistics (0x0B) records.
mcap_tables <- function(buf, recs) {
  sch <- lapply(which(recs$op == 3L), function(k) {
    at <- recs$off[k] + 1
    nl <- raw_u32(buf, at + 2)
    data.frame(id = raw_u16(buf, at), name = raw_str(buf, at + 6, nl),
               stringsAsFactors = FALSE)
  })
  chs <- lapply(which(recs$op == 4L), function(k) {
    at <- recs$off[k] + 1
    tl <- raw_u32(buf, at + 4)
    el <- raw_u32(buf, at + 8 + tl)
    data.frame(id = raw_u16(buf, at), schema = raw_u16(buf, at + 2),
               topic = raw_str(buf, at + 8, tl),
               encoding = raw_str(buf, at + 12 + tl, el), stringsAsFactors = FALSE)
  })
  counts <- numeric()
  for (k in which(recs$op == 0x0BL)) {
    at <- recs$off[k] + 1 + 42  # after the 42 bytes of fixed fields of Statistics
    len <- raw_u32(buf, at)
    for (e in seq_len(len %/% 10)) {
      p <- at + 4 + 10 * (e - 1)
      counts[as.character(raw_u16(buf, p))] <- raw_u64(buf, p + 2)
    }
  }
  list(schemas = if (length(sch)) unique(do.call(rbind, sch)) else
         data.frame(id = numeric(), name = character()),
       channels = if (length(chs)) unique(do.call(rbind, chs)) else
         data.frame(id = numeric(), schema = numeric(), topic = character(),
                    encoding = character()),
       counts = counts)
}

mcap_read_imu <- function(file, topic, progress) {
  if (!is.null(progress)) progress("scanning the MCAP file")
  s <- mcap_scan(file)
  topic <- select_topic(s$topics, topic, file)
  ch <- s$channels[s$channels$topic == topic, , drop = FALSE]
  enc <- match(ch$encoding, c("ros1", "cdr")) - 1L
  if (anyNA(enc)) {
    abort("topic ", topic, " of \"", basename(file), "\" is encoded as \"",
          ch$encoding[is.na(enc)][1L], "\"; \"cdr\" (ROS2) and \"ros1\" are read.",
          class = "file_format")
  }
  if (!is.null(progress)) progress("decoding messages")
  r <- s$recs
  keep <- r$op %in% c(5L, 6L)
  res <- mcap_imu(s$buf, r$op[keep], r$off[keep], r$len[keep],
                  as.integer(ch$id), as.integer(enc))
  list(imu = res$imu, bad = res$bad, topic = topic, format = "mcap")
}
