#' Read an IMU recording from a delimited file
#'
#' Reads a text file with a timestamp column and gyroscope and/or
#' accelerometer columns, converts the samples to SI units (rad/s, m/s^2),
#' takes the sampling rate from the timestamps and checks them. The
#' Kalibr/EuRoC layout is recognized without arguments:
#' `timestamp,omega_x,omega_y,omega_z,alpha_x,alpha_y,alpha_z` (timestamps in
#' ns, rad/s, m/s^2), and EuRoC's
#' `#timestamp [ns],w_RS_S_x [rad s^-1],...,a_RS_S_z [m s^-2]`.
#' Other layouts are described with `time`, `columns`, `units` and `sensors`.
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
#' * rows with missing or non-numeric values are dropped.
#'
#' The sampling rate is `1 / median(step)` unless `freq` is given.
#' Nanosecond stamps near 1.6e18 are held as doubles (resolution 256 ns);
#' they are made relative to the first stamp before use.
#'
#' @param file Path of the delimited text file.
#' @param time Timestamp column: `NULL` to detect it (a column named
#'   `timestamp`, `time`, `t`, `stamp`, ...), a column name or index, or
#'   `FALSE` when there is none (then `freq` is required).
#' @param time_unit Unit of the timestamps. `"auto"` uses the header (e.g.
#'   `[ns]`), then ns for the Kalibr layout, then the magnitude of the stamps
#'   (absolute epochs: > 1e17 ns, > 1e14 us, > 1e11 ms) or of the median
#'   step (< 0.5 s, < 500 ms, < 5e5 us, else ns); the choice is reported in
#'   `time_unit`.
#' @param columns Data columns: `NULL` for every recognized gyro/accel
#'   column, or a character (names) or integer (indices) vector, optionally
#'   named with the channel names to use (e.g.
#'   `c(gyro_x = "gx", gyro_y = "gy")`).
#' @param units Units of the input: `NULL` (from the header's brackets,
#'   else SI, with a message), a vector named by sensor (`c(gyro = "deg/s", accel = "g")`) or
#'   by channel, or a single unit for every channel of its sensor. See
#'   [av_units()].
#' @param sep Field separator (`""` for white space).
#' @param gap What to do with gaps: `"segments"`, `"error"` or `"ignore"`.
#' @param freq Optional sampling frequency in Hz; required when there is no
#'   time column, otherwise overrides the rate estimated from the stamps
#'   (with a warning when they differ by more than 1%).
#' @param sensors Optional sensor type per channel (`"gyro"` or `"accel"`),
#'   named by channel, for columns whose names do not say it.
#' @param ... Unused; an error if given, to catch misspelled arguments.
#' @return An object of class `"imu_record"`: a list with `data` (numeric
#'   matrix, one column per channel, SI units), `time` (seconds since the
#'   first sample), `freq` (Hz), `dt` (s), `sensors` and `units` (input
#'   units) per channel, `si_units`, `time_unit`, `segments` (data frame
#'   `start`, `end`, `n`, `t_start`, `duration`), `problems` (data frame
#'   `type`, `count`, `detail`, `action`), `sampling` (list: `dt_median`,
#'   `jitter_rms`, `jitter_rel`, `gaps`) and `file`.
#' @seealso [imu_record()] for data already in memory, [analyze_imu()].
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
read_imu <- function(file, time = NULL,
                     time_unit = c("auto", "s", "ns", "us", "ms"),
                     columns = NULL, units = NULL, sep = ",",
                     gap = c("segments", "error", "ignore"),
                     freq = NULL, sensors = NULL, ...) {
  check_present(missing(file), "file", "the path of a delimited text file")
  if (...length()) {
    abort("unknown argument(s) to read_imu(): ",
          paste(names(list(...)), collapse = ", "), ".")
  }
  if (!is.character(file) || length(file) != 1L || is.na(file)) {
    abort("`file` must be a single file path, not ", describe_type(file), ".")
  }
  if (!file.exists(file)) abort("`file` \"", file, "\" does not exist.")
  time_unit <- match.arg(time_unit)
  gap <- match.arg(gap)
  if (!is.character(sep) || length(sep) != 1L) {
    abort("`sep` must be a single character string, not ", describe_type(sep), ".")
  }
  if (!is.null(freq)) freq <- check_freq(freq)

  # Header: the first line, when its first field is not a number.
  first <- readLines(file, n = 1L, warn = FALSE)
  if (!length(first)) abort("`file` \"", file, "\" is empty.")
  fields <- split_fields(first, sep)
  has_header <- is.na(suppressWarnings(as.numeric(fields[1L])))
  raw_names <- if (has_header) fields else paste0("V", seq_along(fields))
  clean <- clean_names(raw_names)
  hdr_units <- bracket_units(raw_names)

  # Time column.
  time_col <- NULL
  if (is.null(time)) {
    hit <- which(clean %in% c("timestamp", "time", "t", "stamp", "time_s",
                              "time_ns", "timestamp_ns", "sec", "seconds",
                              "field.header.stamp", "%time"))
    if (length(hit)) time_col <- hit[1L]
  } else if (!isFALSE(time)) {
    time_col <- pick_columns(time, raw_names, clean, "time")
    if (length(time_col) != 1L) abort("`time` must name a single column.")
  }
  if (is.null(time_col) && is.null(freq)) {
    abort("no timestamp column found in \"", basename(file), "\" (columns: ",
          paste(raw_names, collapse = ", "), "); name it with `time = ` ",
          "or give the sampling rate with `freq = `.")
  }

  # Data columns and their channel names and sensors.
  layout <- "custom"
  if (is.null(columns)) {
    known <- known_channel(clean)
    data_cols <- which(!is.na(known$name))
    data_cols <- setdiff(data_cols, time_col)
    if (!length(data_cols)) {
      abort("no gyroscope or accelerometer columns recognized in \"",
            basename(file), "\" (columns: ", paste(raw_names, collapse = ", "),
            "); choose them with `columns = ` (and `sensors = `).")
    }
    ch_names <- known$name[data_cols]
    ch_sensor <- known$sensor[data_cols]
    if (any(known$layout[data_cols] %in% c("kalibr", "euroc"))) {
      layout <- known$layout[data_cols][1L]
    }
  } else {
    data_cols <- pick_columns(columns, raw_names, clean, "columns")
    ch_names <- if (!is.null(names(columns)) && all(nzchar(names(columns))))
      names(columns) else raw_names[data_cols]
    known <- known_channel(clean_names(ch_names))
    ch_sensor <- known$sensor
    ch_names <- ifelse(is.na(known$name), ch_names, known$name)
  }
  if (!is.null(sensors)) {
    if (!is.character(sensors) || !all(sensors %in% c("gyro", "accel"))) {
      abort("`sensors` must be \"gyro\" or \"accel\" per channel.")
    }
    if (is.null(names(sensors))) {
      if (length(sensors) != length(ch_names)) {
        abort("`sensors` must have one entry per channel (", length(ch_names),
              ") or be named by channel.")
      }
      ch_sensor <- unname(sensors)
    } else {
      idx <- match(names(sensors), ch_names)
      by_col <- match(names(sensors), raw_names[data_cols])
      idx[is.na(idx)] <- by_col[is.na(idx)]
      if (anyNA(idx)) {
        abort("`sensors` names ", paste(names(sensors)[is.na(idx)], collapse = ", "),
              " are not among the channels (", paste(ch_names, collapse = ", "), ").")
      }
      ch_sensor[idx] <- unname(sensors)
    }
  }
  if (anyNA(ch_sensor)) {
    abort("the sensor type of column(s) ",
          paste(ch_names[is.na(ch_sensor)], collapse = ", "),
          " is unknown; say it with `sensors = c(", ch_names[is.na(ch_sensor)][1L],
          " = \"gyro\")` (or \"accel\").")
  }
  if (anyDuplicated(ch_names)) {
    abort("channel names must be unique; got ", paste(ch_names, collapse = ", "), ".")
  }
  if (is.null(units)) {
    hu <- hdr_units[data_cols]
    if (layout %in% c("kalibr", "euroc") || all(!is.na(hu))) {
      units <- ifelse(is.na(hu), ifelse(ch_sensor == "gyro", "rad/s", "m/s^2"), hu)
      names(units) <- ch_names
    } else {
      message("read_imu(): no units given for ", basename(file), "; assuming ",
              "rad/s for gyroscopes and m/s^2 for accelerometers (set `units`).")
    }
  }

  # The time column is read as text: nanosecond epochs (~1.6e18) do not fit
  # a double exactly, so they are split into whole and fractional seconds.
  what <- rep(list(0), length(fields))
  if (!is.null(time_col)) what[[time_col]] <- ""
  keep <- seq_along(fields) %in% c(time_col, data_cols)
  what[!keep] <- list(NULL)
  cols <- scan(file, what = what, sep = sep,
               skip = as.integer(has_header), quiet = TRUE,
               na.strings = c("NA", "NaN", "nan", ""), fill = TRUE,
               strip.white = TRUE, comment.char = "", flush = TRUE)
  x <- do.call(cbind, cols[data_cols])
  colnames(x) <- ch_names
  t_sec <- NULL
  if (!is.null(time_col)) {
    t_txt <- cols[[time_col]]
    t_num <- suppressWarnings(as.numeric(t_txt))
    if (time_unit == "auto") {
      time_unit <- guess_time_unit(t_num, hdr_units[time_col], layout)
    }
    t_sec <- stamps_to_seconds(t_txt, t_num, time_unit)
  }
  rec <- new_imu_record(x, time = t_sec, time_unit = "s", freq = freq,
                        units = units, sensors = ch_sensor, gap = gap,
                        source = file)
  rec$time_unit <- time_unit
  rec$layout <- layout
  rec
}

#' Build an IMU record from data in memory
#'
#' The in-memory counterpart of [read_imu()]: takes a matrix or data frame
#' of samples (and optionally timestamps), converts to SI and runs the same
#' timestamp checks.
#'
#' @param x Numeric matrix or data frame, one column per channel, with
#'   column names. Names such as `gyro_x`, `omega_x`, `accel_x`, `alpha_x`
#'   give the sensor type; otherwise use `sensors`.
#' @param freq Sampling frequency in Hz (required without `time`; taken from
#'   `attr(x, "freq")` when present).
#' @param units Input units, as in [read_imu()]. `NULL` means SI.
#' @param sensors Sensor per channel, as in [read_imu()].
#' @param time Optional timestamps (one per row).
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
  gap <- match.arg(gap)
  if (is.null(freq)) freq <- attr(x, "freq")
  if (!is.null(freq)) freq <- check_freq(freq)
  if (is.data.frame(x)) x <- as.matrix(x)
  if (is.null(dim(x))) x <- matrix(x, ncol = 1L, dimnames = list(NULL, "x"))
  if (!is.numeric(x)) abort("`x` must be numeric, not ", describe_type(x), ".")
  if (is.null(colnames(x))) {
    abort("`x` must have column names (e.g. gyro_x, accel_x).")
  }
  known <- known_channel(clean_names(colnames(x)))
  ch_sensor <- known$sensor
  if (!is.null(sensors)) {
    if (is.null(names(sensors))) ch_sensor <- rep_len(sensors, ncol(x))
    else ch_sensor[match(names(sensors), colnames(x))] <- unname(sensors)
  }
  if (anyNA(ch_sensor) || !all(ch_sensor %in% c("gyro", "accel"))) {
    abort("the sensor type of column(s) ",
          paste(colnames(x)[is.na(ch_sensor)], collapse = ", "),
          " is unknown; give `sensors` (\"gyro\" or \"accel\" per column).")
  }
  time_unit <- match.arg(time_unit, c("s", "ms", "us", "ns"))
  if (is.null(time) && is.null(freq)) {
    abort("give `freq` (the sampling frequency in Hz) or `time` (timestamps).")
  }
  storage.mode(x) <- "double"
  rec <- new_imu_record(x, time = time, time_unit = time_unit, freq = freq,
                        units = units, sensors = ch_sensor, gap = gap,
                        source = if (is.null(name)) "in memory" else name)
  rec$layout <- "memory"
  if (!is.null(name)) rec$name <- name
  rec
}

# Shared by read_imu() and imu_record(): checks the stamps, converts units.
new_imu_record <- function(x, time, time_unit, freq, units, sensors, gap,
                           source) {
  ch <- colnames(x)
  names(sensors) <- ch
  in_units <- resolve_units(units, ch, sensors)
  problems <- data.frame(type = character(), count = integer(),
                         detail = character(), action = character(),
                         stringsAsFactors = FALSE)
  add <- function(type, count, detail, action) {
    problems[nrow(problems) + 1L, ] <<- list(type, as.integer(count), detail, action)
  }
  scale <- c(s = 1, ms = 1e-3, us = 1e-6, ns = 1e-9)[[time_unit]]

  if (!is.null(time) && length(time) != nrow(x)) {
    abort("`time` must have one stamp per row (", nrow(x), "), not ",
          length(time), ".")
  }
  bad <- !stats::complete.cases(x)
  if (!is.null(time)) bad <- bad | !is.finite(time)
  if (any(bad)) {
    add("missing", sum(bad), sprintf("%d row(s) with missing or non-numeric values (first at row %d)",
                                     sum(bad), which(bad)[1L]), "dropped")
    x <- x[!bad, , drop = FALSE]
    if (!is.null(time)) time <- time[!bad]
  }
  if (nrow(x) < 2L) abort("fewer than 2 valid samples in ", source, ".")

  gaps <- data.frame(after = integer(), t = numeric(), length = numeric())
  jitter_rms <- NA_real_
  jitter_rel <- NA_real_
  if (is.null(time)) {
    dt <- 1 / freq
    t <- (seq_len(nrow(x)) - 1) * dt
    segments <- data.frame(start = 1L, end = nrow(x), n = nrow(x),
                           t_start = 0, duration = nrow(x) * dt)
  } else {
    t <- (time - time[1L]) * scale
    if (is.unsorted(t)) {
      back <- sum(diff(t) < 0)
      o <- order(t, method = "radix")
      add("out-of-order", back, sprintf("%d step(s) go back in time (first at row %d)",
                                        back, which(diff(t) < 0)[1L] + 1L),
          "rows sorted by time")
      x <- x[o, , drop = FALSE]
      t <- t[o]
    }
    dup <- c(FALSE, diff(t) == 0)
    if (any(dup)) {
      add("duplicate", sum(dup), sprintf("%d duplicated stamp(s) (first at t = %.6g s)",
                                         sum(dup), t[which(dup)[1L]]),
          "later rows with the same stamp dropped")
      x <- x[!dup, , drop = FALSE]
      t <- t[!dup]
    }
    t <- t - t[1L]
    steps <- diff(t)
    if (!length(steps)) abort("fewer than 2 distinct timestamps in ", source, ".")
    dt_med <- stats::median(steps)
    is_gap <- steps > 1.5 * dt_med
    regular <- steps[!is_gap]
    jitter_rms <- sqrt(mean((regular - dt_med)^2))
    jitter_rel <- jitter_rms / dt_med
    if (jitter_rel > 0.01) {
      add("jitter", sum(abs(regular - dt_med) > 0.01 * dt_med),
          sprintf("irregular sampling: RMS step deviation %.3g s (%.1f%% of the %.6g s step)",
                  jitter_rms, 100 * jitter_rel, dt_med),
          "samples used as if regular")
    }
    gi <- which(is_gap)
    gaps <- data.frame(after = gi, t = t[gi], length = steps[gi])
    if (length(gi)) {
      detail <- sprintf("%d gap(s) longer than 1.5 steps; longest %.6g s at t = %.6g s, %.6g s missing in all",
                        length(gi), max(steps[gi]), t[gi[which.max(steps[gi])]],
                        sum(steps[gi] - dt_med))
      if (gap == "error") {
        abort(source, ": ", detail, ". Use gap = \"segments\" to split the ",
              "record at the gaps (analyze_imu() then uses the longest ",
              "gap-free segment, or each with segment = \"each\"), or gap = ",
              "\"ignore\" to treat the samples as contiguous.")
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
      add("rate", 1L, sprintf("given freq = %g Hz but the stamps say %.6g Hz",
                              freq, 1 / dt_med), "given freq used")
    }
    dt <- 1 / freq
  }

  # Convert to SI.
  for (j in seq_along(ch)) {
    f <- lookup_unit(in_units[[j]], "units", sensor = sensors[[j]], kind = "rate")
    if (f$to_si != 1) x[, j] <- x[, j] * f$to_si
  }
  si <- ifelse(sensors == "gyro", "rad/s", "m/s^2")
  names(si) <- ch

  rec <- list(data = x, time = t, freq = freq, dt = dt, sensors = sensors,
              units = in_units, si_units = si, time_unit = time_unit,
              segments = segments, problems = problems,
              sampling = list(dt_median = if (is.null(time)) dt else dt_med,
                              jitter_rms = jitter_rms, jitter_rel = jitter_rel,
                              gaps = gaps),
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
  x$data[seg$start[i]:seg$end[i], , drop = FALSE]
}

split_fields <- function(line, sep) {
  f <- if (identical(sep, "")) strsplit(trimws(line), "[[:space:]]+")[[1L]]
  else trimws(strsplit(line, sep, fixed = TRUE)[[1L]])
  gsub("^[\"']|[\"']$", "", f)
}

clean_names <- function(x) {
  x <- tolower(trimws(x))
  x <- sub("^#+[[:space:]]*", "", x)
  x <- gsub("\\[[^]]*\\]|\\([^)]*\\)", "", x)
  x <- trimws(x)
  gsub("[[:space:]]+", "_", x)
}

# Units written in brackets in a header, e.g. "[rad s^-1]", "[m s^-2]", "[ns]".
bracket_units <- function(x) {
  u <- ifelse(grepl("\\[[^]]*\\]", x), sub("^.*\\[([^]]*)\\].*$", "\\1", x), NA)
  u <- trimws(u)
  map <- c("rad s^-1" = "rad/s", "rad/s" = "rad/s", "deg s^-1" = "deg/s",
           "deg/s" = "deg/s", "m s^-2" = "m/s^2", "m/s^2" = "m/s^2",
           "m/s2" = "m/s^2", "g" = "g", "ns" = "ns", "us" = "us",
           "ms" = "ms", "s" = "s")
  unname(ifelse(u %in% names(map), map[u], NA_character_))
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

pick_columns <- function(spec, raw, clean, arg) {
  if (is.numeric(spec)) {
    if (any(spec < 1 | spec > length(raw) | spec != round(spec))) {
      abort("`", arg, "` indices must be in 1..", length(raw), ".")
    }
    return(as.integer(spec))
  }
  if (!is.character(spec)) {
    abort("`", arg, "` must be column names or indices, not ",
          describe_type(spec), ".")
  }
  i <- match(spec, raw)
  j <- match(clean_names(spec), clean)
  i[is.na(i)] <- j[is.na(i)]
  if (anyNA(i)) {
    abort("`", arg, "`: column(s) ", paste(spec[is.na(i)], collapse = ", "),
          " not found; the file has ", paste(raw, collapse = ", "), ".")
  }
  i
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

# Seconds relative to the first valid stamp; integer stamps in ms/us/ns are
# split into whole seconds and the remainder so that no digit is lost.
stamps_to_seconds <- function(txt, num, unit) {
  scale <- c(s = 1, ms = 1e-3, us = 1e-6, ns = 1e-9)[[unit]]
  k <- c(s = 0L, ms = 3L, us = 6L, ns = 9L)[[unit]]
  ok <- !is.na(num)
  if (k == 0L || !any(ok) || !all(grepl("^[0-9]+$", txt[ok]))) {
    return((num - num[ok][1L]) * scale)
  }
  nc <- nchar(txt)
  hi <- suppressWarnings(as.numeric(substr(txt, 1L, nc - k)))
  hi[is.na(hi) & ok] <- 0
  lo <- as.numeric(substr(txt, pmax(nc - k + 1L, 1L), nc))
  i <- which(ok)[1L]
  (hi - hi[i]) + (lo - lo[i]) * scale
}

guess_time_unit <- function(t, hdr, layout) {
  if (!is.na(hdr) && hdr %in% c("s", "ms", "us", "ns")) return(hdr)
  if (layout %in% c("kalibr", "euroc")) return("ns")
  big <- max(abs(t), na.rm = TRUE)
  if (big > 1e17) return("ns")
  if (big > 1e14) return("us")
  if (big > 1e11) return("ms")
  st <- stats::median(abs(diff(t)), na.rm = TRUE)
  if (st < 0.5) "s" else if (st < 500) "ms" else if (st < 5e5) "us" else "ns"
}
