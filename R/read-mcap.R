# MCAP files (mcap.dev/spec) without ROS, read from the file a chunk at a
# time (src/mcap.cpp): the summary section (schemas, channels, statistics,
# chunk indexes) when there is one, else one pass over the record headers.

mcap_magic <- as.raw(c(0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a))

mcap_scan <- function(file) {
  s <- mcap_index_cpp(path.expand(file))
  ch <- s$channels
  type <- s$schemas$name[match(ch$schema, s$schemas$id)]
  counts <- s$counts$n[match(ch$id, s$counts$id)]
  u <- !duplicated(ch$topic)
  n_msg <- vapply(ch$topic[u], function(tp) {
    v <- counts[ch$topic == tp]
    if (anyNA(v)) NA_real_ else sum(v)
  }, 0)
  s$channels <- cbind(ch, type = type)
  s$topics <- topic_table(ch$topic[u], type[u], n_msg, ch$encoding[u])
  s
}

mcap_read_imu <- function(file, topic, progress, range = NULL) {
  path <- path.expand(file)
  if (!is.null(progress)) progress("scanning the MCAP file")
  s <- mcap_scan(file)
  no_topics_before_fault(file, s)
  topic <- select_topic(s$topics, topic, file)
  ch <- s$channels[s$channels$topic == topic, , drop = FALSE]
  enc <- match(ch$encoding, c("ros1", "cdr")) - 1L
  if (anyNA(enc)) {
    abort("topic ", topic, " of \"", basename(file), "\" is encoded as \"",
          ch$encoding[is.na(enc)][1L], "\"; \"cdr\" (ROS2) and \"ros1\" are read.",
          class = "file_format")
  }
  chunks <- s$chunks
  keep <- rep(TRUE, nrow(chunks))
  from <- -Inf
  to <- Inf
  if (!is.null(range) && nrow(chunks)) {
    t0 <- min(chunks$start)
    from <- t0 + range[1L] * 1e9
    to <- t0 + range[2L] * 1e9
    keep <- !(chunks$end < from | chunks$start > to)
  }
  pos <- chunks$pos[keep]
  got <- ros_stream(file, length(pos), progress, function(k) {
    mcap_read_cpp(path, pos[k], as.integer(ch$id), as.integer(enc), from, to)
  }, s$fault)
  got$topic <- topic
  got$format <- "mcap"
  got
}
