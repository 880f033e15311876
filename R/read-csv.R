# Delimited text files for read_imu(): header, columns, units from the header,
# the table through data.table::fread, and every fault of the file reported
# with its line and column (see the "File faults" section of ?read_imu).

read_csv_imu <- function(file, time, time_unit, columns, units, sep, dec,
                         sensors, freq, progress) {
  first <- readLines(file, n = 1L, warn = FALSE)
  if (!length(first)) abort("`file` \"", file, "\" is empty.", class = "file")
  problems <- empty_problems()
  fields <- split_fields(first, sep)
  if (!all(validUTF8(fields))) {
    # A byte that is not UTF-8: kept visible as <xx> so that names still work.
    k <- which(!validUTF8(fields))
    fields <- iconv(fields, "UTF-8", "UTF-8", sub = "byte")
    problems <- add_problem(problems, "encoding", length(k), sprintf(
      "line 1, column %d (%s): a byte that is not UTF-8", k[1L],
      encodeString(fields[k[1L]], quote = "\"")), "shown as <xx> in the name")
  }
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
    if (length(time_col) != 1L) {
      abort("`time` must name a single column.", class = "argument")
    }
  }
  if (is.null(time_col) && is.null(freq)) {
    abort("no timestamp column found in \"", basename(file), "\" (columns: ",
          paste(raw_names, collapse = ", "), "); name it with `time = ` ",
          "or give the sampling rate with `freq = `.", class = "no_time")
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
            "); choose them with `columns = ` (and `sensors = `).",
            class = "no_columns")
    }
    check_unplaced(clean, raw_names, data_cols, time_col, file)
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
  ch_sensor <- apply_sensors(sensors, ch_names, ch_sensor, raw_names[data_cols])
  if (anyDuplicated(ch_names)) {
    abort("channel names must be unique; got ", paste(ch_names, collapse = ", "),
          ".", class = "argument")
  }
  assumed <- FALSE
  if (is.null(units)) {
    hu <- hdr_units[data_cols]
    if (layout %in% c("kalibr", "euroc") || all(!is.na(hu))) {
      units <- ifelse(is.na(hu), ifelse(ch_sensor == "gyro", "rad/s", "m/s^2"), hu)
      names(units) <- ch_names
    } else {
      assumed <- TRUE
    }
  }

  if (!is.null(progress)) progress("reading the table")
  sel <- sort(unique(c(time_col, data_cols)))
  tab <- read_table_fields(file, sep, dec, has_header, length(fields), sel,
                           raw_names)
  problems <- rbind(problems, tab$problems)
  lines <- tab$lines
  cols <- tab$columns
  names(cols) <- as.character(sel)

  # Cells that are not numbers: the rows are dropped and reported.
  num <- list()
  bad <- logical(length(lines))
  first_bad <- NULL
  n_bad <- 0L
  for (j in sel) {
    v <- cols[[as.character(j)]]
    if (is.character(v) || is.logical(v)) {
      vn <- suppressWarnings(as.numeric(v))
      nn <- which(is.na(vn) & !is.na(v) & !(trimws(v) %in% csv_na_strings))
      if (length(nn) > 0.5 * length(v)) {
        abort_column_text(file, raw_names[j], v[nn[1L]], lines[nn[1L]], j,
                          length(nn), length(v), sep)
      }
      if (length(nn)) {
        n_bad <- n_bad + length(nn)
        if (is.null(first_bad) || nn[1L] < first_bad$i) {
          first_bad <- list(i = nn[1L], col = j, value = v[nn[1L]])
        }
        bad[nn] <- TRUE
      }
      v <- vn
    } else if (inherits(v, "integer64") && j != time_col[1L]) {
      v <- int64_to_double(v)
    }
    num[[as.character(j)]] <- v
  }
  if (any(bad)) {
    problems <- add_problem(problems, "not a number", sum(bad), sprintf(
      "%d cell(s) that are not numbers (first at line %d, column %d %s: %s)",
      n_bad, lines[first_bad$i], first_bad$col, raw_names[first_bad$col],
      encodeString(first_bad$value, quote = "\"")), "rows dropped")
    keep <- !bad
    num <- lapply(num, function(v) v[keep])
    lines <- lines[keep]
  }
  x <- do.call(cbind, lapply(as.character(data_cols), function(j) as.double(num[[j]])))
  colnames(x) <- ch_names

  t_sec <- NULL
  time_label <- NULL
  if (!is.null(time_col)) {
    tv <- num[[as.character(time_col)]]
    is64 <- inherits(tv, "integer64")
    # The unit is guessed from the first stamps (and the last, for size).
    probe <- c(utils::head(tv, 100001L), utils::tail(tv, 1L))
    approx <- if (is64) int64_to_double(probe) else as.double(probe)
    integral <- is64 || is.integer(tv) ||
      isTRUE(all(approx == round(approx), na.rm = TRUE))
    declared <- time_unit
    if (time_unit == "auto") {
      g <- guess_time_unit(approx, hdr_units[time_col], layout, integral)
      time_unit <- g$unit
      if (!is.null(g$note)) {
        i <- which(!is.na(approx))[1L]
        problems <- add_problem(problems, "time unit", 1L, sprintf(
          "the %s layout has stamps in ns, but column %d %s holds %s at line %d with a median step of %.3g: read as %s",
          layout, time_col, raw_names[time_col], format(approx[i], digits = 12),
          lines[i], stats::median(diff(utils::head(approx, 1001L)), na.rm = TRUE),
          time_unit), "give time_unit = \"ns\" to override")
      }
    }
    ok <- which(!is.na(approx))
    per_s <- c(s = 1, ms = 1e3, us = 1e6, ns = 1e9)[[time_unit]]
    t_sec <- if (!length(ok)) rep(NA_real_, length(tv)) else if (is64) {
      int64_rel_seconds(tv, i0 <- probe_index(ok[1L], length(tv)), per_s)
    } else {
      (as.double(tv) - as.double(tv[i0 <- probe_index(ok[1L], length(tv))])) / per_s
    }
    time_label <- list(what = sprintf("column %d %s", time_col, raw_names[time_col]),
                       unit = time_unit, declared = declared != "auto",
                       line = lines[if (length(ok)) i0 else 1L])
  }
  list(x = x, time = t_sec, units = units, sensors = ch_sensor,
       units_assumed = assumed, problems = problems, lines = lines,
       time_unit = time_unit, layout = layout, time_label = time_label)
}

csv_na_strings <- c("NA", "NaN", "nan", "")

# Position in the full column of element i of c(head(v, 100001), tail(v, 1)).
probe_index <- function(i, n) if (i <= min(100001L, n)) i else n

# The selected columns of the file as a list, with the line number of each
# row. Fast path: fread. When fread stops early, or the file's rows do not
# have the header's number of fields, the slow path finds every such line,
# drops it (reported) and reads the rest.
read_table_fields <- function(file, sep, dec, has_header, n_fields, sel,
                              raw_names) {
  fsep <- if (identical(sep, "")) " " else sep
  threads <- allanvar_threads()
  problems <- empty_problems()
  warns <- character()
  fr <- function(input, nrows = Inf, skip = as.integer(has_header), select = sel) {
    args <- list(sep = fsep, dec = dec, header = FALSE, skip = skip,
                 nrows = nrows, select = select,
                 na.strings = csv_na_strings, nThread = min(2L, threads),
                 showProgress = FALSE, data.table = FALSE, fill = FALSE,
                 blank.lines.skip = FALSE, strip.white = TRUE,
                 integer64 = "integer64", check.names = FALSE)
    if (is.character(input) && length(input) == 1L && file.exists(input)) {
      args$file <- input
    } else {
      args$text <- input
    }
    tryCatch(withCallingHandlers(
      do.call(data.table::fread, args),
      warning = function(w) {
        warns <<- c(warns, conditionMessage(w))
        invokeRestart("muffleWarning")
      }),
      error = function(e) {
        abort("cannot read \"", basename(file), "\" as a table separated by ",
              encodeString(sep, quote = "\""), ": ", conditionMessage(e),
              class = "file")
      })
  }
  probe <- fr(file, nrows = 50L, select = NULL)
  slow <- length(warns) > 0L || ncol(probe) != n_fields
  if (!slow) {
    tab <- fr(file)
    slow <- length(warns) > 0L
  }
  if (!slow) {
    return(list(columns = as.list(tab), lines = seq_len(nrow(tab)) + as.integer(has_header),
                problems = problems))
  }
  # Slow path: count the fields of every line.
  bytes <- readBin(file, "raw", file.size(file))
  sep_byte <- if (identical(sep, "")) 0L else as.integer(charToRaw(sep)[1L])
  ff <- csv_field_faults(bytes, sep_byte, n_fields)
  hdr <- as.integer(has_header)
  is_bad <- ff$line > hdr
  bad_line <- ff$line[is_bad]
  bad_n <- ff$fields[is_bad]
  n_data <- ff$n_lines - hdr
  blank <- bad_n == 0L
  wrong <- !blank
  if (sum(wrong) > 0.5 * n_data) {
    all_text <- readLines(file, n = min(ff$n_lines, 5L), warn = FALSE)
    example <- all_text[min(bad_line[wrong][1L], length(all_text))]
    hint <- if (identical(sep, ",") && grepl("[0-9],[0-9]", example)) {
      paste0(" The numbers seem to use decimal commas (", example, "), which ",
             "cannot be told from the separator: save the file with \".\" ",
             "decimals, or with \";\" as separator and read it with ",
             "sep = \";\", dec = \",\".")
    } else {
      " Check the separator (`sep`) and the header line."
    }
    abort(sum(wrong), " of the ", n_data, " data lines of \"", basename(file),
          "\" do not have the header's ", n_fields, " fields (first at line ",
          bad_line[wrong][1L], ", which has ", bad_n[wrong][1L], ").", hint,
          class = "file_fields")
  }
  if (any(wrong)) {
    i <- which(wrong)[1L]
    problems <- add_problem(problems, "fields", sum(wrong), sprintf(
      "%d line(s) without the header's %d fields (first at line %d, which has %d; %s at column %d)",
      sum(wrong), n_fields, bad_line[i], bad_n[i],
      if (bad_n[i] > n_fields) "the extra field begins" else "the line ends",
      min(bad_n[i], n_fields) + as.integer(bad_n[i] > n_fields)),
      "lines dropped")
  }
  if (any(blank)) {
    problems <- add_problem(problems, "blank", sum(blank), sprintf(
      "%d blank line(s) (first at line %d)", sum(blank), bad_line[blank][1L]),
      "skipped")
  }
  keep <- setdiff(seq.int(hdr + 1L, length.out = n_data), bad_line)
  if (!length(keep)) {
    abort("no data line of \"", basename(file), "\" has the header's ",
          n_fields, " fields.", class = "file_fields")
  }
  txt <- readLines(file, warn = FALSE)[keep]
  warns <- character()
  tab <- fr(txt, skip = 0L)
  if (length(warns)) {
    abort("cannot read \"", basename(file), "\": ", warns[1L], class = "file")
  }
  list(columns = as.list(tab), lines = keep, problems = problems)
}

# A column that is mostly text: stop, with what to do.
abort_column_text <- function(file, name, value, line, j, n_bad, n, sep) {
  hint <- if (grepl("^[-+]?[0-9]*,[0-9]+([eE][-+]?[0-9]+)?$", trimws(value))) {
    " The numbers use decimal commas: read the file with dec = \",\" (and a separator other than \",\")."
  } else {
    " Choose the numeric columns with `columns = ` (and `time = `), or check `sep`."
  }
  abort(n_bad, " of the ", n, " values of column ", j, " (", name, ") of \"",
        basename(file), "\" are not numbers (first at line ", line, ": ",
        encodeString(value, quote = "\""), ").", hint, class = "file_values")
}

# Fields of the header line, split byte-wise so that a byte that is not
# UTF-8 stays in its own field (the caller reports it).
split_fields <- function(line, sep) {
  line <- sub("^\xef\xbb\xbf", "", line, useBytes = TRUE)   # UTF-8 BOM
  f <- if (identical(sep, "")) {
    strsplit(line, "[ \t]+", useBytes = TRUE)[[1L]]
  } else {
    strsplit(line, sep, fixed = TRUE, useBytes = TRUE)[[1L]]
  }
  f <- f[nzchar(f) | !identical(sep, "")]
  f <- gsub("^[ \t\r]+|[ \t\r]+$", "", f, useBytes = TRUE)
  f <- gsub("^[\"']|[\"']$", "", f, useBytes = TRUE)
  ok <- validUTF8(f)
  Encoding(f[ok]) <- "UTF-8"
  f
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

pick_columns <- function(spec, raw, clean, arg) {
  if (is.numeric(spec)) {
    if (any(spec < 1 | spec > length(raw) | spec != round(spec))) {
      abort("`", arg, "` indices must be in 1..", length(raw), ".",
            class = "argument")
    }
    return(as.integer(spec))
  }
  if (!is.character(spec)) {
    abort("`", arg, "` must be column names or indices, not ",
          describe_type(spec), ".", class = "argument")
  }
  i <- match(spec, raw)
  j <- match(clean_names(spec), clean)
  i[is.na(i)] <- j[is.na(i)]
  if (anyNA(i)) {
    abort("`", arg, "`: column(s) ", paste(spec[is.na(i)], collapse = ", "),
          " not found; the file has ", paste(raw, collapse = ", "), ".",
          class = "argument")
  }
  i
}

# Unit of the stamps: the header's, else their magnitude (absolute epochs)
# or median step. The Kalibr/EuRoC layouts promise ns; stamps that are
# clearly not ns (fractional, or steps of a fraction of a unit) are read in
# the unit they show, and the disagreement is reported (`note`).
guess_time_unit <- function(t, hdr, layout, integral = TRUE) {
  if (!is.na(hdr) && hdr %in% c("s", "ms", "us", "ns")) return(list(unit = hdr))
  ok <- t[is.finite(t)]
  if (!length(ok)) return(list(unit = "s"))
  big <- max(abs(ok))
  st <- stats::median(abs(diff(utils::head(ok, 100001L))))
  if (!is.finite(st)) st <- 1
  g <- if (big > 1e17) "ns" else if (big > 1e14) "us" else if (big > 1e11) "ms"
       else if (st < 0.5) "s" else if (st < 500) "ms" else if (st < 5e5) "us"
       else "ns"
  if (layout %in% c("kalibr", "euroc")) {
    if (g == "ns" || (integral && st >= 1)) return(list(unit = "ns"))
    return(list(unit = g, note = TRUE))
  }
  list(unit = g)
}

# Columns that are neither data nor time: those whose names say what else
# they hold (sequence numbers, temperature, magnetometer, orientation,
# covariances, ROS header fields) are left out with a message; any other is
# an error, never a silent drop: it may be an axis under a name not known.
other_columns_re <- paste0(
  "^(seq|sequence|count|counter|index|id|status|flags?|header.*|frame.*|",
  "temp.*|temperature.*|mag.*|m[xyz]|q[wxyz]|quat.*|orientation.*|.*cov.*|",
  "time.*|.*stamp.*|secs|nsecs|sec|nsec|t|x|unnamed.*|v[0-9]+)$")

check_unplaced <- function(clean, raw_names, data_cols, time_col, file) {
  rest <- setdiff(seq_along(clean), c(data_cols, time_col))
  if (!length(rest)) return(invisible())
  other <- grepl(other_columns_re, clean[rest])
  if (any(!other)) {
    bad <- raw_names[rest[!other]]
    example <- encodeString(c(raw_names[data_cols], bad), quote = "\"")
    abort("column(s) ", paste(bad, collapse = ", "), " of \"", basename(file),
          "\" could not be placed as gyroscope or accelerometer axes or time; ",
          "choose the data columns with `columns = ` (and `sensors = `), e.g. ",
          "columns = c(", paste(example, collapse = ", "), ").",
          class = "unplaced_columns")
  }
  message(basename(file), ": column(s) ", paste(raw_names[rest], collapse = ", "),
          " left out (not IMU axes).")
  invisible()
}
