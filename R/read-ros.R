# ROS recordings for read_imu(): the parts shared by ROS1 bags (read-bag.R),
# MCAP (read-mcap.R) and rosbag2 SQLite (read-db3.R): topic choice, and the
# decoded sensor_msgs/Imu table turned into read_imu()'s source.

imu_types <- c("sensor_msgs/Imu", "sensor_msgs/msg/Imu")
ros_channels <- c("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")

#' List the topics of a ROS bag, db3 or MCAP file
#'
#' Lists every topic of a ROS1 `.bag`, a ROS2 `.db3` or an `.mcap` file, with
#' its message type and number of messages; [read_imu()] reads those of
#' type `sensor_msgs/Imu` (`imu` column).
#'
#' @param file Path of the recording.
#' @return A data frame with columns `topic`, `type`, `messages` (`NA` when
#'   the file does not say without reading every message), `encoding` and
#'   `imu` (logical).
#' @seealso [read_imu()]
#' @export
#' @examples
#' f <- system.file("extdata", "imu_small.mcap", package = "allanvar")
#' imu_topics(f)
imu_topics <- function(file) {
  check_present(missing(file), "file", "the path of a ROS bag, db3 or MCAP file")
  check_file(file)
  fmt <- detect_format(file)
  switch(fmt,
    rosbag = ros_call(bag_scan(file)$topics, file),
    mcap = ros_call(mcap_scan(file)$topics, file),
    db3 = ros_call(db3_topics(file), file),
    abort("\"", basename(file), "\" is not a ROS bag (format 2.0), a rosbag2 ",
          "db3 or an MCAP file.", class = "file_format"))
}

topic_table <- function(topic, type, messages, encoding) {
  data.frame(topic = as.character(topic), type = as.character(type),
             messages = as.numeric(messages), encoding = as.character(encoding),
             imu = as.character(type) %in% imu_types, stringsAsFactors = FALSE)
}

# The topic to read: the one named, or the only sensor_msgs/Imu topic.
select_topic <- function(topics, topic, file) {
  imu <- topics[topics$imu, , drop = FALSE]
  describe <- function(t) {
    paste0(t$topic, " (", t$type,
           ifelse(is.na(t$messages), "", paste0(", ", t$messages, " messages")), ")",
           collapse = ", ")
  }
  if (!is.null(topic)) {
    if (!topic %in% topics$topic) {
      abort("`topic` \"", topic, "\" is not in \"", basename(file), "\"; its ",
            if (nrow(imu)) paste0("IMU topics are ", describe(imu))
            else paste0("topics are ", describe(topics), ", none of type sensor_msgs/Imu"),
            ".", class = "topic")
    }
    if (!topic %in% imu$topic) {
      abort("`topic` \"", topic, "\" holds ", topics$type[topics$topic == topic][1L],
            ", not sensor_msgs/Imu; ",
            if (nrow(imu)) paste0("the IMU topics are ", describe(imu))
            else "the file has no IMU topic", ".", class = "topic")
    }
    return(topic)
  }
  if (!nrow(imu)) {
    abort("\"", basename(file), "\" has no sensor_msgs/Imu topic (topics: ",
          if (nrow(topics)) describe(topics) else "none", ").", class = "topic")
  }
  if (nrow(imu) > 1L) {
    abort("\"", basename(file), "\" has ", nrow(imu), " IMU topics: ",
          describe(imu), "; choose one with `topic = `.", class = "topic")
  }
  imu$topic
}

read_ros_imu <- function(file, fmt, topic, columns, units, progress, range = NULL) {
  got <- ros_call(switch(fmt,
    rosbag = bag_read_imu(file, topic, progress, range),
    mcap = mcap_read_imu(file, topic, progress, range),
    db3 = db3_read_imu(file, topic, progress, range)), file)
  ros_source(got, columns, units)
}

# A file damaged before its first connection or channel record.
no_topics_before_fault <- function(file, s) {
  if (length(s$fault) && !nrow(s$topics)) {
    abort("\"", basename(file), "\" is damaged at byte ",
          format(s$fault$off, scientific = FALSE), " (", s$fault$what,
          ") and no topic is described before it.", class = "file_format")
  }
}

# Chunks read in batches of `batch` (one C++ call each: `read_batch(k)`
# returns imu, bad, done, fault, bytes), with progress between batches
# (progressr, bytes read) and the first fault turned into a classed warning
# that keeps the messages before it, or an error when there are none.
ros_stream <- function(file, n_chunks, progress, read_batch, scan_fault = NULL,
                       batch = 64L) {
  if (!is.null(progress)) progress("decoding chunks")
  starts <- seq(1L, n_chunks, by = batch)
  if (!n_chunks) starts <- integer()
  pr <- if (length(starts) > 4L && requireNamespace("progressr", quietly = TRUE)) {
    progressr::progressor(steps = length(starts))
  }
  parts <- vector("list", length(starts))
  bad <- 0
  bytes <- 0
  fault <- NULL
  for (b in seq_along(starts)) {
    k <- starts[b]:min(n_chunks, starts[b] + batch - 1L)
    res <- read_batch(k)
    parts[[b]] <- res$imu
    bad <- bad + res$bad
    bytes <- bytes + res$bytes
    if (!is.null(pr)) pr(sprintf("%.0f MB read", bytes / 1e6))
    if (length(res$fault)) {
      fault <- res$fault
      break
    }
  }
  if (is.null(fault) && length(scan_fault)) fault <- scan_fault
  imu <- do.call(rbind, c(list(matrix(numeric(), 0L, 10L)), parts))
  if (!is.null(fault)) {
    if (grepl("no zstd support", fault$what, fixed = TRUE)) stop(fault$what, call. = FALSE)
    size <- file.size(file)
    if (!nrow(imu)) {
      abort("\"", basename(file), "\" is damaged at byte ", format(fault$off, scientific = FALSE),
            " (", fault$what, ") and no message of the topic precedes it.",
            class = "file_format")
    }
    warn("\"", basename(file), "\" is damaged at byte ", format(fault$off, scientific = FALSE),
         " (", fault$what, "): the ", nrow(imu), " messages before it are ",
         "returned; the last ", format(size - fault$off, scientific = FALSE),
         " bytes of the file are not read.", class = "damaged_file")
  }
  list(imu = imu, bad = bad, bytes = bytes)
}

# Malformed files: the decoders' messages (which say what and where) as
# classed errors naming the file.
ros_call <- function(expr, file) {
  tryCatch(expr, error = function(e) {
    if (inherits(e, "allanvar_error")) stop(e)
    if (grepl("no zstd support", conditionMessage(e), fixed = TRUE)) {
      abort("\"", basename(file), "\" has zstd-compressed chunks, but there is ",
            sub("^zstd: ", "", conditionMessage(e)), ".", class = "dependency")
    }
    abort("\"", basename(file), "\" is malformed: ", conditionMessage(e),
          class = "file_format")
  })
}

# The decoded table (columns sec, nsec, wx, wy, wz, ax, ay, az, recv_sec,
# recv_nsec) as read_imu()'s source: header stamps in seconds since the
# first message, exactly as integer ns stamps of a CSV would be.
ros_source <- function(got, columns, units) {
  m <- got$imu
  problems <- empty_problems()
  if (got$bad > 0) {
    problems <- add_problem(problems, "undecodable", got$bad, sprintf(
      "%d message(s) of %s too short for sensor_msgs/Imu", got$bad, got$topic),
      "messages dropped")
  }
  if (!nrow(m)) abort("topic ", got$topic, " has no message.", class = "too_short")
  sec <- m[, 1L]
  nsec <- m[, 2L]
  if (sec[1L] == 0 && nsec[1L] == 0 && all(sec == 0 & nsec == 0)) {
    problems <- add_problem(problems, "stamps", nrow(m), sprintf(
      "every header stamp of %s is zero", got$topic),
      "the recording (receive) times used instead")
    sec <- m[, 9L]
    nsec <- m[, 10L]
  }
  t <- stamp_rel_seconds(sec, nsec, 1)
  x <- m[, 3:8, drop = FALSE]
  colnames(x) <- ros_channels
  if (!is.null(columns)) {
    j <- if (is.numeric(columns)) columns else match(columns, ros_channels)
    if (anyNA(j) || any(j < 1 | j > 6 | j != round(j))) {
      abort("`columns` must name channels of an IMU message (",
            paste(ros_channels, collapse = ", "), ") or be indices 1..6.",
            class = "argument")
    }
    x <- x[, j, drop = FALSE]
  }
  list(x = x, time = t, units = units,
       sensors = ifelse(startsWith(colnames(x), "gyro"), "gyro", "accel"),
       units_assumed = FALSE, problems = problems, lines = seq_len(nrow(x)),
       row_word = "message", time_unit = "ns", layout = got$format,
       topic = got$topic,
       time_label = list(what = paste("the header stamps of", got$topic),
                         unit = "ns", declared = TRUE, line = 1L))
}

# Little-endian fields of raw vectors.
raw_u32 <- function(r, at) {
  sum(as.numeric(r[at + 0:3]) * 256^(0:3))
}
raw_u16 <- function(r, at) as.numeric(r[at]) + 256 * as.numeric(r[at + 1L])
raw_u64 <- function(r, at) raw_u32(r, at) + 2^32 * raw_u32(r, at + 4L)
raw_str <- function(r, at, n) {
  if (n <= 0) return("")
  rawToChar(r[at + seq_len(n) - 1L])
}
