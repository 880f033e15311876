#' Read an IMU recording: delimited text, ROS1 bag, ROS2 db3 or MCAP
#'
#' Reads a recording of gyroscope and/or accelerometer samples, converts them
#' to SI units (rad/s, m/s^2), takes the sampling rate from the timestamps
#' and checks them. The format is recognized from the file's first bytes:
#'
#' * **Delimited text** (read with [data.table::fread()]; integer stamps are
#'   kept exact through bit64). The Kalibr/EuRoC layout is recognized without
#'   arguments: `timestamp,omega_x,omega_y,omega_z,alpha_x,alpha_y,alpha_z`
#'   (timestamps in ns, rad/s, m/s^2), and EuRoC's
#'   `#timestamp [ns],w_RS_S_x [rad s^-1],...,a_RS_S_z [m s^-2]`. Other
#'   layouts are described with `time`, `columns`, `units` and `sensors`.
#' * **ROS bags**, without ROS: `sensor_msgs/Imu` messages of one topic from a
#'   ROS1 `.bag` (format 2.0; chunks uncompressed, bz2 or lz4), a ROS2
#'   `.db3` (rosbag2 SQLite storage, CDR messages) or an `.mcap` file (chunks
#'   uncompressed, lz4 or zstd; CDR or ROS1 messages). The messages' header
#'   stamps are the timestamps (the receive times when every header stamp is
#'   zero, reported). `topic` names the topic; without it the only IMU topic
#'   is used, and with several the call stops and lists them (see
#'   [imu_topics()]). ROS holds angular velocity in rad/s and linear
#'   acceleration in m/s^2 (REP 103); `units` overrides that for drivers that
#'   publish other units.
#'
#' @section Timestamp checks (never silent):
#' Each problem found is listed in the result's `problems` table and in one
#' warning, and handled by this rule:
#' * **out-of-order** stamps: the rows are sorted by time (stable sort);
#' * **duplicated** stamps: only the first row with a given stamp is kept;
#' * **gaps**, steps longer than 1.5 times the median step: with
#'   `gap = "segments"` (default) the record is split into gap-free
#'   segments (listed in `segments`; [analyze_imu()] uses the longest unless
#'   told otherwise); `gap = "error"` stops and says what to do;
#'   `gap = "ignore"` keeps the samples as if contiguous (the Allan variance
#'   is then biased near the gap's duration; still reported);
#' * **jitter**: the RMS deviation of the gap-free steps from the median step
#'   is always computed (`sampling$jitter_rms`, seconds); above 1% of the
#'   step it is listed as a problem. Samples are used as they are (the Allan
#'   variance assumes a regular grid).
#' * a sampling rate that no IMU has (above 100 kHz or below 0.001 Hz) for
#'   the time unit in use stops the reading, naming the time column and the
#'   unit that would give a plausible rate.
#'
#' The sampling rate is `1 / median(step)` unless `freq` is given.
#' Integer stamps (ns, us, ms) are read as 64-bit integers and made relative
#' to the first stamp exactly: `t = (stamp - first) / 1e9` for ns.
#'
#' @section File faults (never silent):
#' Every fault of a text file is reported with its line (the file's own line
#' number, the header being line 1) and column, in `problems`, and handled
#' by one rule:
#' * a **cell that is not a number** (`abc`): its row is dropped; when more
#'   than half of a column is not numbers the reading stops, saying what to
#'   do (decimal commas are recognized: use `dec = ","`);
#' * a **line with the wrong number of fields**, or a blank line: dropped;
#'   when more than half of the lines are wrong the reading stops (decimal
#'   commas in a comma-separated file are recognized and explained);
#' * **missing** (`NA`, `NaN`, empty) or **infinite** (`Inf`) values: the
#'   row is dropped;
#' * **stamps in a unit other than the layout's** (a Kalibr header holding
#'   seconds): read in the unit they show, reported as `time unit`;
#' * a **byte that is not UTF-8** in the header: shown as `<xx>` in the
#'   column name, reported as `encoding`;
#' * a directory, a missing or an empty file: an error.
#'
#' @section Units (checked, never only assumed):
#' With no `units` and none in the header or layout, gyroscopes are taken
#' as rad/s and accelerometers as m/s^2, unless three accelerometer axes
#' show gravity: the norm of their means near 1 (g), 9.81 (m/s^2) or 1000
#' (mg), within 10%, then that unit is used. Given units are checked the
#' same way (a warning of class `allanvar_warning_accel_units` when gravity
#' says otherwise). Each gyroscope's white-noise level is estimated from the
#' Allan deviation at 1 s; outside 1e-5 to 60 deg/sqrt(h), which real gyros
#' span, a warning of class `allanvar_warning_gyro_units` says which unit
#' the samples seem to be in (deg/s samples read as rad/s make N 57 times
#' too large). The findings are in the record's `unit_checks`.
#'
#' @param file Path of the recording.
#' @param time Timestamp column (text files): `NULL` to detect it (a column
#'   named `timestamp`, `time`, `t`, `stamp`, ...), a column name or index,
#'   or `FALSE` when there is none (then `freq` is required).
#' @param time_unit Unit of the timestamps (text files). `"auto"` uses the
#'   header (e.g. `[ns]`), then ns for the Kalibr layout (unless the stamps
#'   clearly are not), then the magnitude of the stamps (absolute epochs
#'   above 1e17 are ns, above 1e14 us, above 1e11 ms) or of the median step
#'   (below 0.5: s, below 500: ms, below 5e5: us, else ns); the choice is
#'   reported in `time_unit`.
#' @param columns Data columns: `NULL` for every recognized gyro/accel
#'   column, or a character (names) or integer (indices) vector, optionally
#'   named with the channel names to use (e.g.
#'   `c(gyro_x = "gx", gyro_y = "gy")`). For bags: a subset of `gyro_x`,
#'   ..., `accel_z`.
#' @param units Units of the input: `NULL` (from the header's brackets,
#'   else checked against gravity as described above), a vector named by
#'   sensor (`c(gyro = "deg/s", accel = "g")`) or by channel, or a single
#'   unit for every channel of its sensor. See [av_units()].
#' @param sep Field separator (`""` for white space).
#' @param gap What to do with gaps: `"segments"`, `"error"` or `"ignore"`.
#' @param freq Optional sampling frequency in Hz; required when there is no
#'   time column, otherwise overrides the rate estimated from the stamps
#'   (with a warning when they differ by more than 1%).
#' @param sensors Optional sensor type per channel (`"gyro"` or `"accel"`),
#'   named by channel, for columns whose names do not say it.
#' @param topic For bags: the topic of the `sensor_msgs/Imu` messages.
#' @param dec Decimal mark of a text file: `"."` (default) or `","` (then
#'   `sep` must be another character, e.g. `";"`).
#' @param from,to For bags: the time range to read, in seconds from the
#'   start of the recording (its first chunk, or first message), by the
#'   time each message was recorded. Only the chunks overlapping the range
#'   are read from the file. `NULL`: from the start, to the end.
#' @param ... Unused; an error if given, to catch misspelled arguments.
#' @return An object of class `"imu_record"`: a list with `data` (numeric
#'   matrix, one column per channel, SI units), `time` (seconds since the
#'   first sample), `freq` (Hz), `dt` (s), `sensors` and `units` (input
#'   units) per channel, `si_units`, `time_unit`, `segments` (data frame
#'   `start`, `end`, `n`, `t_start`, `duration`), `problems` (data frame
#'   `type`, `count`, `detail`, `action`), `sampling` (list: `dt_median`,
#'   `jitter_rms`, `jitter_rel`, `gaps`), `unit_checks` (data frame
#'   `channel`, `sensor`, `unit`, `source`, `evidence`), `layout`
#'   (`"kalibr"`, `"euroc"`, `"custom"`, `"rosbag"`, `"db3"`, `"mcap"`),
#'   `topic` (bags) and `file`.
#' @seealso [imu_record()] for data already in memory, [imu_topics()],
#'   [analyze_imu()].
#' @export
#' @examples
#' f <- tempfile(fileext = ".csv")
#' set.seed(1)
#' n <- 1000
#' k <- 0:(n - 1)   # 200 Hz stamps in ns, written as exact integers
#' d <- data.frame(timestamp = sprintf("%d%09d", 1600000000L + k %/% 200L,
#'                                     (k %% 200L) * 5000000L),
#'                 omega_x = rnorm(n, sd = 1e-3), omega_y = rnorm(n, sd = 1e-3),
#'                 omega_z = rnorm(n, sd = 1e-3), alpha_x = rnorm(n, sd = 1e-2),
#'                 alpha_y = rnorm(n, sd = 1e-2), alpha_z = 9.8 + rnorm(n, sd = 1e-2))
#' write.csv(d, f, row.names = FALSE, quote = FALSE)
#' r <- read_imu(f)
#' r
#' unlink(f)
#'
#' # A ROS2 recording in MCAP (300 sensor_msgs/Imu messages at 200 Hz)
#' bag <- system.file("extdata", "imu_small.mcap", package = "allanvar")
#' imu_topics(bag)
#' read_imu(bag, topic = "/imu0")
read_imu <- function(file, time = NULL,
                     time_unit = c("auto", "s", "ns", "us", "ms"),
                     columns = NULL, units = NULL, sep = ",",
                     gap = c("segments", "error", "ignore"),
                     freq = NULL, sensors = NULL, topic = NULL, dec = ".",
                     from = NULL, to = NULL, ...) {
  check_present(missing(file), "file", "the path of a recording")
  if (...length()) {
    abort("unknown argument(s) to read_imu(): ",
          paste(names(list(...)), collapse = ", "), ".", class = "argument")
  }
  check_file(file)
  time_unit <- choice_arg(time_unit, c("auto", "s", "ns", "us", "ms"), "time_unit")
  gap <- choice_arg(gap, c("segments", "error", "ignore"), "gap")
  if (!is.character(sep) || length(sep) != 1L || is.na(sep) || nchar(sep) > 1L) {
    abort("`sep` must be a single character (\"\" for white space), not ",
          format_value(sep), ".", class = "argument")
  }
  dec <- check_choice(dec, c(".", ","), "dec")
  if (identical(dec, sep)) {
    abort("`dec` and `sep` must differ; both are \"", sep, "\".",
          class = "argument")
  }
  if (!is.null(freq)) freq <- check_imu_freq(freq)
  if (!is.null(time) && !isFALSE(time) &&
      (!(is.character(time) || is.numeric(time)) || is.object(time) ||
       length(time) != 1L || is.na(time))) {
    abort("`time` must be NULL (detect), a column name or index, or FALSE ",
          "(no timestamp column); not ", if (length(time) == 1L && is.atomic(time))
            format_value(time) else describe_type(time), ".", class = "argument")
  }
  if (!is.null(columns) && (!(is.character(columns) || is.numeric(columns)) ||
                            is.object(columns) || !length(columns) || anyNA(columns))) {
    abort("`columns` must be NULL or a vector of column names or indices, not ",
          describe_type(columns), if (length(columns)) " holding NA", ".",
          class = "argument")
  }
  if (!is.null(topic) && (!is.character(topic) || length(topic) != 1L ||
                          is.na(topic))) {
    abort("`topic` must be a single topic name, not ", describe_type(topic),
          ".", class = "argument")
  }
  range <- check_read_range(from, to)
  p <- read_progress(4L)
  fmt <- detect_format(file)
  if (!is.null(range) && fmt == "text") {
    abort("`from` and `to` select a time range of a ROS bag, db3 or MCAP ",
          "file; \"", basename(file), "\" is a text file.", class = "argument")
  }
  src <- if (fmt == "text") {
    read_csv_imu(file, time, time_unit, columns, units, sep, dec, sensors,
                 freq, p)
  } else {
    read_ros_imu(file, fmt, topic, columns, units, p, range)
  }
  p("checking stamps and units")
  rec <- new_imu_record(src$x, time = src$time, time_unit = "s", freq = freq,
                        units = src$units, sensors = src$sensors, gap = gap,
                        source = file, problems = src$problems,
                        rows = src$lines, row_word = src$row_word %||% "line",
                        time_label = src$time_label,
                        units_assumed = src$units_assumed,
                        units_source = if (is.null(units)) "file" else "given")
  p("done")
  rec$time_unit <- src$time_unit
  rec$layout <- src$layout
  if (!is.null(src$topic)) rec$topic <- src$topic
  rec
}

# `from`, `to`: seconds from the start of a ROS recording, or NULL.
check_read_range <- function(from, to) {
  if (is.null(from) && is.null(to)) return(NULL)
  one <- function(x, arg, default) {
    if (is.null(x)) return(default)
    if (!is.numeric(x) || length(x) != 1L || is.na(x) || x < 0 || is.object(x)) {
      abort("`", arg, "` must be a single non-negative number of seconds from ",
            "the start of the recording, not ", if (length(x) == 1L && is.atomic(x))
              format_value(x) else describe_type(x), ".", class = "argument")
    }
    as.numeric(x)
  }
  r <- c(one(from, "from", 0), one(to, "to", Inf))
  if (r[2L] <= r[1L]) {
    abort("`to` must be after `from`; they are ", r[1L], " and ", r[2L], ".",
          class = "argument")
  }
  r
}

# A file path that exists and is a regular, non-empty file.
check_file <- function(file, arg = "file") {
  if (!is.character(file) || length(file) != 1L || is.na(file) || !nzchar(file)) {
    abort("`", arg, "` must be a single file path, not ",
          if (is.character(file) && length(file) == 1L) format_value(file)
          else describe_type(file), ".", class = "argument")
  }
  if (dir.exists(file)) {
    abort("`", arg, "` \"", file, "\" is a directory, not a file; give the ",
          "path of the recording inside it.", class = "file")
  }
  if (!file.exists(file)) {
    abort("`", arg, "` \"", file, "\" does not exist.", class = "file")
  }
  if (isTRUE(file.size(file) == 0)) {
    abort("`", arg, "` \"", file, "\" is empty.", class = "file")
  }
  invisible(file)
}

# The format from the first bytes: ROS1 bag, MCAP, SQLite (rosbag2) or text.
detect_format <- function(file) {
  head <- readBin(file, "raw", 16L)
  starts <- function(magic) {
    length(head) >= length(magic) && identical(head[seq_along(magic)], magic)
  }
  if (starts(charToRaw("#ROSBAG V2.0"))) return("rosbag")
  if (starts(as.raw(c(0x89, charToRaw("MCAP"))))) return("mcap")
  if (starts(charToRaw("SQLite format 3"))) return("db3")
  if (starts(charToRaw("#ROSBAG"))) {
    abort("\"", basename(file), "\" is a ROS bag of a format older than 2.0; ",
          "only format 2.0 (ROS Groovy and later) is read. Run `rosbag fix` ",
          "on it, or export the topic to CSV.", class = "file_format")
  }
  "text"
}

# An argument whose default is the vector of its choices (first = default).
choice_arg <- function(x, choices, arg) {
  if (identical(x, choices)) return(choices[1L])
  check_choice(x, choices, arg)
}

# progressr's progressor for long reads: silent unless handlers are set
# (progressr::handlers()), as everywhere in the package.
read_progress <- function(steps) {
  if (requireNamespace("progressr", quietly = TRUE)) {
    pr <- progressr::progressor(steps = steps, envir = parent.frame())
    function(msg = NULL) pr(msg)
  } else {
    function(msg = NULL) invisible(NULL)
  }
}

# Sensor per channel from `sensors` (unnamed: one per channel; named: by
# channel or column name).
apply_sensors <- function(sensors, ch_names, ch_sensor, col_names = ch_names) {
  if (is.null(sensors)) {
    if (anyNA(ch_sensor)) {
      abort("the sensor type of column(s) ",
            paste(ch_names[is.na(ch_sensor)], collapse = ", "),
            " is unknown; say it with `sensors = c(", ch_names[is.na(ch_sensor)][1L],
            " = \"gyro\")` (or \"accel\").", class = "sensors")
    }
    return(ch_sensor)
  }
  if (!is.character(sensors) || anyNA(sensors) ||
      !all(sensors %in% c("gyro", "accel"))) {
    abort("`sensors` must be \"gyro\" or \"accel\" per channel, not ",
          format_value(sensors), ".", class = "argument")
  }
  if (is.null(names(sensors))) {
    if (length(sensors) != length(ch_names)) {
      abort("`sensors` must have one entry per channel (", length(ch_names),
            ") or be named by channel.", class = "argument")
    }
    ch_sensor <- unname(sensors)
  } else {
    idx <- match(names(sensors), ch_names)
    by_col <- match(names(sensors), col_names)
    idx[is.na(idx)] <- by_col[is.na(idx)]
    if (anyNA(idx)) {
      abort("`sensors` names ", paste(names(sensors)[is.na(idx)], collapse = ", "),
            " are not among the channels (", paste(ch_names, collapse = ", "), ").",
            class = "argument")
    }
    ch_sensor[idx] <- unname(sensors)
  }
  apply_sensors(NULL, ch_names, ch_sensor)
}

#' Build an IMU record from data in memory
#'
#' The in-memory counterpart of [read_imu()]: takes a matrix or data frame
#' of samples (and optionally timestamps), converts to SI and runs the same
#' timestamp and unit checks.
#'
#' @param x Numeric matrix or data frame, one column per channel, with
#'   column names. Names such as `gyro_x`, `omega_x`, `accel_x`, `alpha_x`
#'   give the sensor type; otherwise use `sensors`. Dates, factors, text and
#'   arrays of more than two dimensions are refused.
#' @param freq Sampling frequency in Hz (required without `time`; taken from
#'   `attr(x, "freq")` when present).
#' @param units Input units, as in [read_imu()]. `NULL` means SI, unless
#'   three accelerometer axes show gravity in another unit (see
#'   [read_imu()], section Units).
#' @param sensors Sensor per channel, as in [read_imu()].
#' @param time Optional timestamps (one per row): numbers, or
#'   `bit64::integer64` for exact integer stamps.
#' @param time_unit Unit of `time`: `"s"`, `"ms"`, `"us"` or `"ns"`.
#' @param gap As in [read_imu()].
#' @param name A name for the record (used in tables and plots).
#' @return An object of class `"imu_record"` (see [read_imu()]).
#' @export
#' @examples
#' set.seed(1)
#' m <- cbind(gyro_x = rnorm(500, sd = 0.1), accel_x = rnorm(500, sd = 0.001))
#' imu_record(m, freq = 100, units = c(gyro = "deg/s", accel = "g"))
imu_record <- function(x, freq = NULL, units = NULL, sensors = NULL,
                       time = NULL, time_unit = "s",
                       gap = c("segments", "error", "ignore"), name = NULL) {
  check_present(missing(x), "x", "a matrix or data frame of samples")
  if (is.null(x) || !length(x)) {
    abort("`x` must be a matrix or data frame of samples, not ",
          if (is.null(x)) "NULL" else "an empty object", ".", class = "argument")
  }
  if (!is.data.frame(x) && !is.atomic(x)) {
    abort("`x` must be a matrix or data frame of samples, not ", describe_type(x),
          ".", class = "argument")
  }
  gap <- choice_arg(gap, c("segments", "error", "ignore"), "gap")
  if (!is.null(name)) check_string(name, "name")
  if (is.null(freq)) freq <- attr(x, "freq")
  if (!is.null(freq)) freq <- check_imu_freq(freq)
  if (inherits(x, c("Date", "POSIXt", "difftime", "factor")) ||
      (is.data.frame(x) && any(vapply(x, function(v)
        inherits(v, c("Date", "POSIXt", "difftime", "factor")) || !is.numeric(v),
        logical(1))))) {
    abort("`x` must hold numeric samples, not dates, times, factors or text ",
          "(got ", if (is.data.frame(x)) "a data frame with such columns"
          else paste0("a ", class(x)[1L], " vector"), ").", class = "argument")
  }
  if (length(dim(x)) > 2L) {
    abort("`x` must be a matrix or data frame (one column per channel), not ",
          "an array of ", length(dim(x)), " dimensions.", class = "argument")
  }
  if (is.data.frame(x)) x <- as.matrix(x)
  if (is.null(dim(x))) x <- matrix(x, ncol = 1L, dimnames = list(NULL, "x"))
  if (!is.numeric(x) || is.list(x)) {
    abort("`x` must be numeric, not ", describe_type(x), ".", class = "argument")
  }
  if (is.null(colnames(x))) {
    abort("`x` must have column names (e.g. gyro_x, accel_x).", class = "argument")
  }
  known <- known_channel(clean_names(colnames(x)))
  ch_sensor <- known$sensor
  if (!is.null(sensors)) {
    if (!is.character(sensors) || anyNA(sensors) ||
        !all(sensors %in% c("gyro", "accel"))) {
      abort("`sensors` must be \"gyro\" or \"accel\" per column, not ",
            format_value(sensors), ".", class = "argument")
    }
    if (is.null(names(sensors))) ch_sensor <- rep_len(sensors, ncol(x))
    else ch_sensor[match(names(sensors), colnames(x))] <- unname(sensors)
  }
  if (anyNA(ch_sensor) || !all(ch_sensor %in% c("gyro", "accel"))) {
    abort("the sensor type of column(s) ",
          paste(colnames(x)[is.na(ch_sensor)], collapse = ", "),
          " is unknown; give `sensors` (\"gyro\" or \"accel\" per column).",
          class = "sensors")
  }
  time_unit <- check_choice(time_unit, c("s", "ms", "us", "ns"), "time_unit")
  if (is.null(time) && is.null(freq)) {
    abort("give `freq` (the sampling frequency in Hz) or `time` (timestamps).",
          class = "no_time")
  }
  label <- NULL
  if (!is.null(time)) {
    if (inherits(time, "integer64")) {
      ok <- which(!is.na(int64_to_double(time)))
      per_s <- c(s = 1, ms = 1e3, us = 1e6, ns = 1e9)[[time_unit]]
      time <- if (length(ok)) int64_rel_seconds(time, ok[1L], per_s) else
        rep(NA_real_, length(time))
      label <- list(what = "`time`", unit = time_unit, declared = TRUE, line = 1L)
      time_unit <- "s"
    } else if (!is.numeric(time) || is.factor(time) || !is.null(dim(time))) {
      abort("`time` must be a numeric vector of stamps (or bit64::integer64), ",
            "not ", describe_type(time), ".", class = "argument")
    } else {
      label <- list(what = "`time`", unit = time_unit, declared = TRUE, line = 1L)
    }
  }
  storage.mode(x) <- "double"
  rec <- new_imu_record(x, time = time, time_unit = time_unit, freq = freq,
                        units = units, sensors = ch_sensor, gap = gap,
                        source = if (is.null(name)) "in memory" else name,
                        row_word = "row", time_label = label,
                        units_assumed = is.null(units), quiet_units = TRUE,
                        units_source = if (is.null(units)) "default" else "given")
  rec$layout <- "memory"
  if (!is.null(name)) rec$name <- name
  rec
}

empty_problems <- function() {
  data.frame(type = character(), count = integer(), detail = character(),
             action = character(), stringsAsFactors = FALSE)
}

add_problem <- function(problems, type, count, detail, action) {
  problems[nrow(problems) + 1L, ] <- list(type, as.integer(count), detail, action)
  problems
}

# Shared by read_imu() and imu_record(): drops and reports bad rows, checks
# the stamps and the units, converts to SI. `rows`: the file line (or
# message) number of each row, for the reports; `time_label`: where the
# stamps came from and their unit, for the rate check.
new_imu_record <- function(x, time, time_unit, freq, units, sensors, gap,
                           source, problems = NULL, rows = NULL,
                           row_word = "row", time_label = NULL,
                           units_assumed = FALSE, quiet_units = FALSE,
                           units_source = "given") {
  ch <- colnames(x)
  names(sensors) <- ch
  in_units <- resolve_units(units, ch, sensors)
  if (is.null(problems)) problems <- empty_problems()
  add <- function(type, count, detail, action) {
    problems <<- add_problem(problems, type, count, detail, action)
  }
  scale <- c(s = 1, ms = 1e-3, us = 1e-6, ns = 1e-9)[[time_unit]]
  where <- function(i) {
    sprintf("%s %d", row_word, if (is.null(rows)) i else rows[i])
  }

  if (!is.null(time) && length(time) != nrow(x)) {
    abort("`time` must have one stamp per row (", nrow(x), "), not ",
          length(time), ".", class = "argument")
  }
  # Missing and infinite values, by column, first one named.
  miss <- logical(nrow(x))
  inf <- logical(nrow(x))
  first_miss <- first_inf <- NULL
  nonfinite <- col_first_nonfinite(x)
  for (j in which(nonfinite > 0)) {
    v <- x[, j]
    m <- is.na(v)
    f <- is.infinite(v)
    if (any(m) && (is.null(first_miss) || which(m)[1L] < first_miss$i)) {
      first_miss <- list(i = which(m)[1L], col = ch[j])
    }
    if (any(f) && (is.null(first_inf) || which(f)[1L] < first_inf$i)) {
      first_inf <- list(i = which(f)[1L], col = ch[j], value = v[which(f)[1L]])
    }
    miss <- miss | m
    inf <- inf | f
  }
  if (!is.null(time)) {
    tm <- !is.finite(time)
    if (any(tm) && (is.null(first_miss) || which(tm)[1L] < first_miss$i)) {
      first_miss <- list(i = which(tm)[1L], col = "time")
    }
    miss <- miss | tm
  }
  inf <- inf & !miss
  if (any(miss)) {
    add("missing", sum(miss), sprintf(
      "%d row(s) with missing values (first at %s, column %s)",
      sum(miss), where(first_miss$i), first_miss$col), "rows dropped")
  }
  if (any(inf)) {
    add("infinite", sum(inf), sprintf(
      "%d row(s) with infinite values (first at %s, column %s: %s)",
      sum(inf), where(first_inf$i), first_inf$col, format(first_inf$value)),
      "rows dropped")
  }
  bad <- miss | inf
  if (any(bad)) {
    x <- x[!bad, , drop = FALSE]
    if (!is.null(time)) time <- time[!bad]
    if (!is.null(rows)) rows <- rows[!bad] else rows <- which(!bad)
  }
  if (nrow(x) < 2L) {
    abort("fewer than 2 valid samples in ", source, ".", class = "too_short")
  }

  gaps <- data.frame(after = integer(), t = numeric(), length = numeric())
  jitter_rms <- NA_real_
  jitter_rel <- NA_real_
  if (is.null(time)) {
    dt <- 1 / freq
    t <- (seq_len(nrow(x)) - 1) * dt
    segments <- data.frame(start = 1L, end = nrow(x), n = nrow(x),
                           t_start = 0, duration = nrow(x) * dt)
  } else {
    # Stamps already relative seconds (the readers' output) are not copied.
    t <- if (scale == 1 && time[1L] == 0) time else (time - time[1L]) * scale
    if (is.unsorted(t)) {
      back <- sum(diff(t) < 0)
      o <- order(t, method = "radix")
      add("out-of-order", back, sprintf("%d step(s) go back in time (first at %s)",
                                        back, where(which(diff(t) < 0)[1L] + 1L)),
          "rows sorted by time")
      x <- x[o, , drop = FALSE]
      t <- t[o]
      if (!is.null(rows)) rows <- rows[o]
    }
    rep1 <- stamp_repeats(t)
    if (rep1[2L] > 0) {
      dup <- c(FALSE, diff(t) == 0)
      add("duplicate", sum(dup), sprintf("%d duplicated stamp(s) (first at t = %.6g s, %s)",
                                         sum(dup), t[which(dup)[1L]],
                                         where(which(dup)[1L])),
          "later rows with the same stamp dropped")
      x <- x[!dup, , drop = FALSE]
      t <- t[!dup]
    }
    if (t[1L] != 0) t <- t - t[1L]
    # Median step, gaps and jitter in one pass (src/read_text.cpp).
    st <- stamp_steps(t)
    if (!st$n) {
      abort("fewer than 2 distinct timestamps in ", source, ".", class = "too_short")
    }
    dt_med <- st$median
    check_stamp_rate(1 / dt_med, time_label, source)
    jitter_rms <- sqrt(st$mean_sq)
    jitter_rel <- jitter_rms / dt_med
    if (jitter_rel > 0.01) {
      add("jitter", st$over,
          sprintf("irregular sampling: RMS step deviation %.3g s (%.1f%% of the %.6g s step)",
                  jitter_rms, 100 * jitter_rel, dt_med),
          "samples used as if regular")
    }
    gi <- as.integer(st$gap_at)
    steps_gi <- st$gap_len
    gaps <- data.frame(after = gi, t = t[gi], length = steps_gi)
    if (length(gi)) {
      detail <- sprintf("%d gap(s) longer than 1.5 steps; longest %.6g s at t = %.6g s, %.6g s missing in all",
                        length(gi), max(steps_gi), t[gi[which.max(steps_gi)]],
                        sum(steps_gi - dt_med))
      if (gap == "error") {
        abort(source, ": ", detail, ". Use gap = \"segments\" to split the ",
              "record at the gaps (analyze_imu() then uses the longest ",
              "gap-free segment, or each with segment = \"each\"), or gap = ",
              "\"ignore\" to treat the samples as contiguous.", class = "gap")
      }
      add("gap", length(gi), detail,
          if (gap == "segments") sprintf("split into %d segments", length(gi) + 1L)
          else "ignored: samples treated as contiguous")
    }
    if (gap == "segments" && length(gi)) {
      start <- c(1L, gi + 1L)
      end <- c(gi, length(t))
    } else {
      start <- 1L
      end <- length(t)
    }
    segments <- data.frame(start = start, end = end, n = end - start + 1L,
                           t_start = t[start],
                           duration = (end - start + 1L) * dt_med)
    if (is.null(freq)) {
      freq <- 1 / dt_med
    } else if (abs(freq * dt_med - 1) > 0.01) {
      # one of the two is wrong, and every reading would scale with it
      abort(source, ": `freq` = ", format(freq), " Hz but the timestamps",
            if (!is.null(time_label)) paste0(" (read as ", time_label$unit, ")"),
            " say ", format(signif(1 / dt_med, 6)), " Hz, ",
            format(signif(abs(freq * dt_med - 1) * 100, 3)), "% apart (more than 1%). ",
            "Give the rate the stamps say, or check `time_unit`; ",
            "or give `freq = ` without the time column.", class = "rate_mismatch")
    }
    dt <- 1 / freq
  }

  # Units: accelerometers checked against gravity, gyroscopes against the
  # noise levels of real gyros (R/units.R); then everything to SI.
  uc <- check_imu_units(x, sensors, in_units, freq, units_assumed,
                        units_source, source, quiet = quiet_units)
  in_units <- uc$units
  for (j in seq_along(ch)) {
    f <- lookup_unit(in_units[[j]], "units", sensor = sensors[[j]], kind = "rate")
    if (f$to_si != 1) x[, j] <- x[, j] * f$to_si
  }
  si <- ifelse(sensors == "gyro", "rad/s", "m/s^2")
  names(si) <- ch
  uc <- check_gyro_noise(x, sensors, in_units, freq, uc$checks, source,
                         assumed = units_assumed)

  rec <- list(data = x, time = t, freq = freq, dt = dt, sensors = sensors,
              units = in_units, si_units = si, time_unit = time_unit,
              segments = segments, problems = problems,
              sampling = list(dt_median = if (is.null(time)) dt else dt_med,
                              jitter_rms = jitter_rms, jitter_rel = jitter_rel,
                              gaps = gaps),
              unit_checks = uc,
              file = source, name = basename(source))
  class(rec) <- "imu_record"
  if (nrow(problems)) {
    warn(source, ": ", nrow(problems), " problem(s) in the record:\n",
         paste0("  - ", problems$type, ": ", problems$detail, " -> ",
                problems$action, collapse = "\n"),
         class = "record_problems")
  }
  rec
}

# A rate no IMU has, for the unit the stamps were read in: stop, naming
# the column and the unit that would give a plausible rate.
check_stamp_rate <- function(rate, label, source) {
  lim <- imu_rate_range
  if (is.null(label) || (rate <= lim[2L] && rate >= lim[1L])) return(invisible())
  per <- c(s = 1, ms = 1e3, us = 1e6, ns = 1e9)
  cur <- per[[label$unit]]
  as_unit <- rate * per / cur
  alt <- names(per)[as_unit >= lim[1L] & as_unit <= lim[2L]]
  abort(source, ": the stamps of ", label$what, ", read as ", label$unit,
        if (!isTRUE(label$declared)) " (detected)", ", give a sampling rate of ",
        format(signif(rate, 4)), " Hz (from line ", label$line %||% 1L,
        " on), which no IMU has (", format(lim[1L]), " Hz to ",
        format(lim[2L], scientific = FALSE), " Hz). Read as ",
        paste0(names(per), ": ", vapply(as_unit, function(v) format(signif(v, 4)), ""),
               " Hz", collapse = "; "), ".",
        if (length(alt)) paste0(" They look like ", alt[1L], ": use time_unit = \"",
                                alt[1L], "\"."),
        " (Or give the rate with `freq = ` and no time column.)",
        class = "time_unit")
}

#' @export
print.imu_record <- function(x, ...) {
  n <- nrow(x$data)
  cat("<imu_record> ", x$name, "\n", sep = "")
  cat(sprintf("  %d samples at %.6g Hz (%.4g s = %.3g h), %d segment(s)\n",
              n, x$freq, n / x$freq, n / x$freq / 3600, nrow(x$segments)))
  for (s in c("gyro", "accel")) {
    ch <- names(x$sensors)[x$sensors == s]
    if (length(ch)) {
      cat(sprintf("  %-5s: %s  (read in %s, held in %s)\n", s,
                  paste(ch, collapse = ", "),
                  paste(unique(x$units[ch]), collapse = ", "),
                  x$si_units[ch][1L]))
    }
  }
  if (!is.na(x$sampling$jitter_rms)) {
    cat(sprintf("  timestamps in %s; jitter RMS %.3g s (%.2f%% of the step)\n",
                x$time_unit, x$sampling$jitter_rms, 100 * x$sampling$jitter_rel))
  }
  if (nrow(x$problems)) {
    cat("  problems:\n")
    cat(paste0("    - ", x$problems$type, ": ", x$problems$detail, " -> ",
               x$problems$action, "\n"), sep = "")
  } else {
    cat("  no timestamp problems found\n")
  }
  if (nrow(x$segments) > 1L) {
    cat("  segments (samples): ", paste(x$segments$n, collapse = ", "), "\n", sep = "")
  }
  invisible(x)
}

# The samples of one segment ("longest", or an index), as a matrix.
record_segment <- function(x, segment = "longest") {
  seg <- x$segments
  i <- if (identical(segment, "longest")) which.max(seg$n) else segment
  if (!is.numeric(i) || length(i) != 1L || i < 1 || i > nrow(seg)) {
    abort("`segment` must be \"longest\", \"each\" or a segment number in 1..",
          nrow(seg), ".")
  }
  if (seg$start[i] == 1L && seg$end[i] == nrow(x$data)) return(x$data)
  x$data[seg$start[i]:seg$end[i], , drop = FALSE]
}

# Recognized channel names -> (standard name, sensor, layout).
known_channel <- function(clean) {
  name <- rep(NA_character_, length(clean))
  sensor <- rep(NA_character_, length(clean))
  layout <- rep(NA_character_, length(clean))
  set <- function(re, prefix, s, lay) {
    hit <- grepl(re, clean) & is.na(name)
    ax <- sub(re, "\\1", clean[hit])
    name[hit] <<- paste0(prefix, ax)
    sensor[hit] <<- s
    layout[hit] <<- lay
  }
  set("^omega_([xyz])$", "gyro_", "gyro", "kalibr")
  set("^alpha_([xyz])$", "accel_", "accel", "kalibr")
  set("^w_rs_s_([xyz])$", "gyro_", "gyro", "euroc")
  set("^a_rs_s_([xyz])$", "accel_", "accel", "euroc")
  set("^(?:gyro|gyr|gyroscope|angular_velocity|w|g|omega)[._]?([xyz])$", "gyro_", "gyro", "generic")
  set("^(?:accel|acc|accelerometer|linear_acceleration|a|f|alpha)[._]?([xyz])$", "accel_", "accel", "generic")
  # Other names that still say their sensor keep their name.
  g <- is.na(sensor) & grepl("^(gyro|gyr|omega)", clean)
  sensor[g] <- "gyro"; name[g] <- clean[g]
  a <- is.na(sensor) & grepl("^(acc|alpha)", clean)
  sensor[a] <- "accel"; name[a] <- clean[a]
  list(name = name, sensor = sensor, layout = layout)
}

resolve_units <- function(units, ch, sensors) {
  default <- ifelse(sensors == "gyro", "rad/s", "m/s^2")
  names(default) <- ch
  if (is.null(units)) return(default)
  if (!is.character(units)) {
    abort("`units` must be a character vector of unit names, not ",
          describe_type(units), ".")
  }
  out <- default
  if (is.null(names(units))) {
    if (length(units) == length(ch)) return(stats::setNames(units, ch))
    for (u in units) {
      s <- unit_table()$sensor[unit_table()$unit == normalize_unit(u) &
                               unit_table()$kind == "rate"]
      if (!length(s)) lookup_unit(u, "units", kind = "rate")
      out[sensors == s[1L]] <- u
    }
    return(out)
  }
  for (nm in names(units)) {
    if (nm %in% c("gyro", "accel")) out[sensors == nm] <- units[[nm]]
    else if (nm %in% ch) out[nm] <- units[[nm]]
    else abort("`units` names must be \"gyro\", \"accel\" or channel names (",
               paste(ch, collapse = ", "), "), not \"", nm, "\".")
  }
  out
}

