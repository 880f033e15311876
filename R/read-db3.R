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

db3_read_imu <- function(file, topic, progress) {
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
  res <- DBI::dbGetQuery(con, "SELECT timestamp, data FROM messages WHERE topic_id = ? ORDER BY id",
                         params = list(attr(tp, "id")[k]))
  ts <- res$timestamp
  if (!inherits(ts, "integer64")) ts <- bit64::as.integer64(ts)
  imu <- decode_imu_blobs(res$data, 1L, ts)
  bad <- sum(is.na(imu[, 1L]))
  list(imu = imu[!is.na(imu[, 1L]), , drop = FALSE], bad = bad, topic = topic,
       format = "db3")
}
