#' Datasheet table of an IMU analysis
#'
#' One table per sensor, one row per axis: white noise N (angle / velocity
#' random walk), bias instability B with the tau where the Allan deviation
#' is minimal (the flat region where B is read), rate random walk K, each in
#' SI and in datasheet units, how each was obtained, and the effects the
#' closed-loop refinement ([avrefine()]) added to the model (with a note for
#' each added term whose fitted values the record does not determine, e.g.
#' a Gauss-Markov Tc whose 95% interval is wider than a factor 2 either
#' way). Axes are never averaged unless `average = TRUE`, which appends a
#' row with the arithmetic mean of the axes.
#'
#' Units (see [av_units()]): gyroscope N in rad/s/sqrt(Hz) and deg/sqrt(h),
#' B in rad/s and deg/h, K in rad/s^2/sqrt(Hz) and deg/h/sqrt(h);
#' accelerometer N in m/s^2/sqrt(Hz), m/s/sqrt(h) and ug/sqrt(Hz), B in
#' m/s^2, ug and mg, K in m/s^3/sqrt(Hz) and m/s/h^(3/2).
#'
#' A fit of a curve alone ([avfit()] of another tool's curve, of an
#' [allan()] result or of a table) gets the same table, as one axis: its
#' readings in SI when the unit of the curve is known (`unit`, or the unit a
#' curve read by [read_allan_variance_ros_curve()] or [read_imu_utils_curve()] carries),
#' else in the input's unit u (`u*sqrt(s)` for N, ...).
#'
#' An axis whose analysis failed (a dead, constant channel) is listed with
#' `NA` values and the reason in `method`.
#'
#' @param x An `imu_analysis` or `imu_analysis_list` ([analyze_imu()]), or
#'   an `avfit`.
#' @param average Append the mean of the axes per sensor (logical).
#' @param unit For an `avfit`: the rate unit of the fitted curve (see
#'   [av_units()]); `NULL` for the unit the curve carried, if any.
#' @param ... Unused.
#' @return An object of class `"imu_datasheet"`: a list with one wide data
#'   frame per sensor (`gyro`, `accel`; columns named with their units) and
#'   `long`, the same numbers as a long data frame (`record`, `sensor`,
#'   `axis`, `term`, `value`, `unit`, `tau`, `method`, `effects`, and each
#'   reading's verdict: `verdict` ("measured", "upper_bound",
#'   "lower_bound", "not_determined"), `why`, `tau_lo`, `tau_hi` (the taus
#'   the reading rests on), `biased_by` and `bias_change` (series effects
#'   left in that change it, and by how much), `removed` (kinds taken out
#'   first), `warning` (failed unit checks of the axis)), which is what
#'   `as.data.frame()` returns and [write_datasheet()] writes.
#' @export
#' @examples
#' \donttest{
#' set.seed(1)
#' m <- cbind(gyro_x = rnorm(2e4, sd = 0.01), gyro_y = rnorm(2e4, sd = 0.02))
#' a <- analyze_imu(imu_record(m, freq = 100), refine = FALSE, progress = FALSE)
#' datasheet(a)
#' datasheet(a, average = TRUE)$gyro
#' }
datasheet <- function(x, average = FALSE, ...) UseMethod("datasheet")

#' @export
datasheet.default <- function(x, average = FALSE, ...) {
  abort("`x` must be an imu_analysis (analyze_imu()), an imu_analysis_list ",
        "or an avfit, not ", describe_type(x), ".", class = "argument")
}

#' @rdname datasheet
#' @export
datasheet.avfit <- function(x, average = FALSE, unit = NULL, ...) {
  check_average(average)
  datasheet(fit_analysis(x, unit = unit), average = average)
}

#' @export
datasheet.imu_analysis_list <- function(x, average = FALSE, ...) {
  check_average(average)
  parts <- lapply(x, datasheet, average = average)
  out <- list(long = do.call(rbind, lapply(parts, function(p) p$long)))
  for (s in datasheet_sensors) {
    tabs <- lapply(parts, function(p) p[[s]])
    tabs <- tabs[!vapply(tabs, is.null, logical(1))]
    if (length(tabs)) out[[s]] <- do.call(rbind, tabs)
  }
  rownames(out$long) <- NULL
  class(out) <- "imu_datasheet"
  out
}

#' @export
datasheet.imu_analysis <- function(x, average = FALSE, ...) {
  check_average(average)
  check_analysis(x)
  long <- list()
  uw <- unit_warnings(x)
  for (ch in x$channels) {
    rd <- ch$readings
    eff <- if (is.null(ch$dead)) added_effects(ch$fit) else "none"
    # an added term whose fitted values the record does not determine says
    # so beside its values (a Gauss-Markov Tc of 84 s, 95% interval 31-230 s)
    if (is.null(ch$dead)) {
      nd <- undetermined_own_terms(ch, rd)
      if (length(nd)) {
        note <- paste(sprintf("%s %s: %s", names(nd),
                              verdict_label(vapply(nd, `[[`, "", "verdict")),
                              vapply(nd, `[[`, "", "why")), collapse = "; ")
        eff <- if (identical(eff, "none")) note else paste0(eff, "; ", note)
      }
    }
    for (j in seq_len(nrow(rd))) {
      r <- rd[j, ]
      si <- r$unit
      us <- c(si, datasheet_units(ch$sensor)[[unit_dim(ch$sensor, si)]])
      long[[length(long) + 1L]] <- data.frame(
        record = x$name, sensor = sensor_label(ch$sensor), axis = ch$channel,
        term = r$term,
        value = vapply(us, function(u) if (u == si) r$value else
          convert_units(r$value, si, u), 0),
        unit = us, tau = r$tau, method = r$method, effects = eff,
        verdict = r$verdict, why = r$why, tau_lo = r$tau_lo, tau_hi = r$tau_hi,
        biased_by = r$biased_by, bias_change = r$bias_change, removed = r$removed,
        warning = channel_unit_warning(uw, ch$channel),
        stringsAsFactors = FALSE)
    }
  }
  long <- do.call(rbind, long)
  rownames(long) <- NULL
  if (average) {
    avg <- stats::aggregate(value ~ record + sensor + term + unit, data = long,
                            FUN = mean)
    tau_avg <- stats::aggregate(tau ~ record + sensor + term + unit, data = long,
                                FUN = mean)
    avg$tau <- tau_avg$tau
    avg$axis <- "mean of axes"
    avg$method <- "arithmetic mean of the axes"
    avg$effects <- ""
    # the mean is measured only where every axis is
    worst <- stats::aggregate(verdict ~ record + sensor + term + unit, data = long,
                              FUN = mean_verdict)
    avg$verdict <- worst$verdict
    avg$why <- ifelse(avg$verdict == "measured", "",
                      "not every axis is measured: see each axis")
    avg$tau_lo <- avg$tau_hi <- avg$bias_change <- NA_real_
    avg$biased_by <- avg$removed <- ""
    avg$warning <- paste(unique(uw$warning), collapse = "; ")
    long <- rbind(long, avg[names(long)])
  }
  out <- list(long = long)
  for (s in datasheet_sensors) {
    l <- long[long$sensor == s, ]
    if (nrow(l)) out[[s]] <- wide_table(l)
  }
  class(out) <- "imu_datasheet"
  out
}

# An imu_analysis whose parts the readers of it need: channels, each with
# its name, sensor and readings (with the verdict columns).
check_analysis <- function(x, arg = "x") {
  need <- c("term", "value", "unit", "tau", "method", "verdict", "why")
  ok <- is.list(x) && is.list(x$channels) && length(x$channels) > 0L &&
    all(vapply(x$channels, function(ch) {
      is.list(ch) && is.character(ch$channel) && length(ch$channel) == 1L &&
        length(ch$sensor) == 1L && is.data.frame(ch$readings) &&
        all(need %in% names(ch$readings))
    }, logical(1)))
  if (!ok) {
    abort("`", arg, "` is not a well-formed imu_analysis: its `channels` must ",
          "each hold `channel`, `sensor` and `readings` (as analyze_imu() ",
          "makes them); analyse the record again with analyze_imu().",
          class = "argument")
  }
  invisible(x)
}

check_average <- function(average) {
  if (!is.logical(average) || length(average) != 1L || is.na(average)) {
    abort("`average` must be TRUE or FALSE, not ", format_value(average), ".",
          class = "argument")
  }
  average
}

# The tables of a datasheet: gyroscopes, accelerometers, and a fit whose
# sensor is not known (values in the input's unit u).
datasheet_sensors <- c("gyro", "accel", "unknown")
sensor_label <- function(sensor) if (is.na(sensor)) "unknown" else sensor

# The dimension ("u*sqrt(s)", ...) of a unit of `sensor`; for an unknown
# sensor the unit is the dimension.
unit_dim <- function(sensor, unit) {
  if (is.na(sensor)) return(unit)
  tab <- unit_table()
  tab$dim[tab$sensor == sensor & tab$unit == unit][1L]
}

# One row per axis; one column per (term, unit), plus the tau of the reading
# read at the flat minimum (tau_B), method, effects.
wide_table <- function(l) {
  tau_term <- reading_symbol("flicker")
  tau_col <- sprintf("tau_%s [s]", tau_term)
  axes <- unique(l$axis)
  key <- unique(l[c("term", "unit")])
  cols <- list(record = vapply(axes, function(a) l$record[l$axis == a][1L], ""),
               axis = axes)
  for (i in seq_len(nrow(key))) {
    nm <- sprintf("%s [%s]", key$term[i], key$unit[i])
    cols[[nm]] <- vapply(axes, function(a) {
      v <- l$value[l$axis == a & l$term == key$term[i] & l$unit == key$unit[i]]
      if (length(v)) v[1L] else NA_real_
    }, 0)
    if (key$term[i] %in% tau_term && !tau_col %in% names(cols)) {
      cols[[tau_col]] <- vapply(axes, function(a)
        l$tau[l$axis == a & l$term == tau_term][1L], 0)
    }
  }
  cols$method <- vapply(axes, function(a) {
    r <- l[l$axis == a, ]
    r <- r[!duplicated(r$term), ]
    if (length(unique(r$method)) == 1L) r$method[1L]
    else paste0(r$term, ": ", r$method, collapse = "; ")
  }, "")
  cols$verdict <- vapply(axes, function(a) {
    r <- l[l$axis == a, ]
    r <- r[!duplicated(r$term), ]
    lab <- verdict_label(r$verdict)
    lab <- ifelse(nzchar(r$biased_by) & r$verdict == "measured",
                  paste0(lab, " (", r$biased_by, " left in)"), lab)
    if (all(r$verdict == "measured") && !any(nzchar(r$biased_by))) "measured"
    else paste0(r$term, ": ", lab, collapse = "; ")
  }, "")
  cols$effects <- vapply(axes, function(a) l$effects[l$axis == a][1L], "")
  df <- as.data.frame(cols, stringsAsFactors = FALSE, check.names = FALSE)
  rownames(df) <- NULL
  df
}

# The effects the closed loop added, as the catalogue describes them (with
# the fitted values of every instance of that kind).
added_effects <- function(fit) {
  st <- fit$steps
  if (is.null(st) || !nrow(st)) return("none")
  eff <- as.character(st$effect)
  cf <- fit$coefficients
  lay <- if (length(cf)) check_coef(cf) else NULL
  lab <- vapply(eff, function(term) {
    sp <- split_term(term)
    e <- effect_entry(sp$kind, sp$variant)
    rows <- if (is.null(lay)) NULL else lay[lay$kind == sp$kind, , drop = FALSE]
    if (is.null(rows) || !nrow(rows)) return(term)
    values <- do.call(rbind, lapply(unique(rows$label), function(l) {
      r <- rows[rows$label == l, , drop = FALSE]
      as.data.frame(as.list(stats::setNames(r$value, r$param)))
    }))
    e$describe(values)
  }, "")
  paste(unique(lab), collapse = ", ")
}

#' @export
as.data.frame.imu_datasheet <- function(x, row.names = NULL, optional = FALSE, ...) {
  x$long
}

#' @export
print.imu_datasheet <- function(x, digits = 3, ...) {
  for (s in datasheet_sensors) {
    tab <- x[[s]]
    if (is.null(tab)) next
    cat(switch(s, gyro = "Gyroscopes", accel = "Accelerometers",
               "Sensor of unknown unit (u: the rate unit of the input)"),
        "\n", sep = "")
    show <- tab
    num <- vapply(show, is.numeric, logical(1))
    show[num] <- lapply(show[num], function(v) formatC(v, digits = digits,
                                                       format = "g"))
    if (length(unique(show$record)) == 1L) show$record <- NULL
    print(show, row.names = FALSE, right = TRUE)
    cat("\n")
  }
  invisible(x)
}

#' Write a datasheet table to CSV
#'
#' @param x An `imu_datasheet` ([datasheet()]), or an `imu_analysis` /
#'   `imu_analysis_list` whose datasheet is written.
#' @param file Path of the CSV file.
#' @param format `"long"` (default; one row per axis, term and unit: `record`,
#'   `sensor`, `axis`, `term`, `value`, `unit`, `tau`, `method`, `effects`)
#'   or `"wide"` (the printed tables, one block per sensor, stacked).
#' @return `file`, invisibly.
#' @export
#' @examples
#' \donttest{
#' set.seed(1)
#' m <- cbind(gyro_x = rnorm(2e4, sd = 0.01))
#' a <- analyze_imu(imu_record(m, freq = 100), refine = FALSE, progress = FALSE)
#' f <- tempfile(fileext = ".csv")
#' write_datasheet(a, f)
#' read.csv(f)
#' }
write_datasheet <- function(x, file, format = "long") {
  check_present(missing(x), "x", "an imu_datasheet or imu_analysis")
  check_present(missing(file), "file", "the path of the CSV file")
  format <- check_choice(format, c("long", "wide"), "format")
  file <- check_output_path(file)
  if (inherits(x, c("imu_analysis", "imu_analysis_list", "avfit"))) x <- datasheet(x)
  if (!inherits(x, "imu_datasheet")) {
    abort("`x` must be an imu_datasheet or imu_analysis, not ",
          describe_type(x), ".", class = "argument")
  }
  # write.csv quotes every text field (record, axis, method names copied
  # from the user) and doubles embedded quotes (RFC 4180).
  write_atomic(file, function(path) {
    if (format == "long") {
      utils::write.csv(x$long, path, row.names = FALSE)
    } else {
      con <- file(path, "w")
      on.exit(close(con))
      first <- TRUE
      for (s in datasheet_sensors) {
        if (is.null(x[[s]])) next
        if (!first) writeLines("", con)
        first <- FALSE
        tab <- cbind(sensor = s, x[[s]])
        utils::write.csv(tab, con, row.names = FALSE)
      }
    }
  })
  invisible(file)
}
