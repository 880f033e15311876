# ROS2 bags in rosbag2's SQLite storage (.db3): tables `topics` (id, name,
# type, serialization_format) and `messages` (id, topic_id, timestamp,
# data), read through DBI/RSQLite; messages are CDR, decoded in C++
# (src/ros_msgs.cpp).

db3_connect <- function(file) {
  con <- tryCatch(DBI::dbConnect(RSQLite::SQLite(), file,
                                 flags = RSQLite::SQLITE_RO, bigint = "integer64"),
                  error = function(e) abort("cannot open \"", basename(file),
                                            "\" as SQLite: ", conditionMessage(e),
                                            class = "file"))
  tabs <- DBI::dbListTables(con)
  if (!all(c("topics", "messages") %in% tabs)) {
    DBI::dbDisconnect(con)
    abort("\"", basename(file), "\" is an SQLite file but not a rosbag2 bag ",
          "(no `topics` and `messages` tables).", class = "file_format")
  }
  con
}

# `count = FALSE` skips the message counts: counting scans the whole
# messages table (blobs included), 0.7 s for 1e6 messages, which reading one
# topic does not need.
db3_topics <- function(file, con = NULL, count = TRUE) {
  if (is.null(con)) {
    con <- db3_connect(file)
    on.exit(DBI::dbDisconnect(con))
  }
  tp <- DBI::dbGetQuery(con, "SELECT id, name, type, serialization_format FROM topics")
  n <- if (count) {
    DBI::dbGetQuery(con, "SELECT topic_id, COUNT(*) AS n FROM messages GROUP BY topic_id")
  } else {
    data.frame(topic_id = tp$id, n = NA_real_)
  }
  out <- topic_table(tp$name, tp$type, as.numeric(n$n[match(as.numeric(tp$id),
                                                            as.numeric(n$topic_id))]),
                     tp$serialization_format)
  if (count) out$messages[is.na(out$messages)] <- 0
  attr(out, "id") <- as.numeric(tp$id)
  out
}

db3_read_imu <- function(file, topic, progress, range = NULL) {
  con <- db3_connect(file)
  on.exit(DBI::dbDisconnect(con))
  tp <- db3_topics(file, con, count = FALSE)
  # Counts only for the message that lists the topics.
  topic <- tryCatch(select_topic(tp, topic, file),
                    allanvar_error_topic = function(e) select_topic(db3_topics(file, con), topic, file))
  k <- match(topic, tp$topic)
  if (!identical(tp$encoding[k], "cdr")) {
    abort("topic ", topic, " of \"", basename(file), "\" is serialized as \"",
          tp$encoding[k], "\"; \"cdr\" is read.", class = "file_format")
  }
  if (!is.null(progress)) progress("reading messages")
  id <- attr(tp, "id")[k]
  where <- "WHERE topic_id = ?"
  params <- list(id)
  if (!is.null(range)) {
    # Seconds from the first message of the bag.
    t0 <- DBI::dbGetQuery(con, "SELECT MIN(timestamp) AS t0 FROM messages")$t0
    t0 <- bit64::as.integer64(t0)
    where <- paste(where, "AND timestamp >= ?")
    params <- c(params, list(t0 + bit64::as.integer64(round(range[1L] * 1e9))))
    if (is.finite(range[2L])) {
      where <- paste(where, "AND timestamp <= ?")
      params <- c(params, list(t0 + bit64::as.integer64(round(range[2L] * 1e9))))
    }
  }
  # Streamed in pages: one page of blobs in memory at a time.
  q <- DBI::dbSendQuery(con, paste("SELECT timestamp, data FROM messages", where,
                                   "ORDER BY id"), params = params)
  on.exit(DBI::dbClearResult(q), add = TRUE, after = FALSE)
  parts <- list()
  bad <- 0
  while (!DBI::dbHasCompleted(q)) {
    res <- DBI::dbFetch(q, n = 50000L)
    if (!nrow(res)) break
    ts <- res$timestamp
    if (!inherits(ts, "integer64")) ts <- bit64::as.integer64(ts)
    imu <- decode_imu_blobs(res$data, 1L, ts)
    bad <- bad + sum(is.na(imu[, 1L]))
    parts[[length(parts) + 1L]] <- imu[!is.na(imu[, 1L]), , drop = FALSE]
  }
  imu <- do.call(rbind, c(list(matrix(numeric(), 0L, 10L)), parts))
  list(imu = imu, bad = bad, topic = topic, format = "db3")
}
