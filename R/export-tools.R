# Other tools' parameter files out: imu_utils' *_imu_param.yaml, a VINS
# config block, an OpenVINS kalibr_imu_chain.yaml and MATLAB's gyroparams /
# accelparams. One table (tool_params()) holds every conversion with its
# formula; the writers only lay that table out. The conventions are
# tabulated in ?conventions (R/conventions.R).

#' Noise parameters in the conventions of other tools
#'
#' Converts the readings of an analysis (white noise N, bias instability B,
#' rate random walk K, in SI) into the values other tools expect, one row
#' per value, with the formula used. See [conventions] for the table of
#' every tool's convention and its source.
#'
#' * `"kalibr"`, `"openvins"`: `*_noise_density = N`, `*_random_walk = K`
#'   (continuous time, SI).
#' * `"imu_utils"`: `gyr_n = N * sqrt(freq)` (imu_utils scales its ADEV at
#'   1 s by sqrt(freq)), `gyr_w = 0.664 * B` (the floor: the minimum of the
#'   Allan deviation, not divided by 0.664); one row per axis and their mean
#'   (`avg-axis`).
#' * `"vins"`: `gyr_n = N * sqrt(freq)`, `gyr_w = K * sqrt(freq)`: VINS-Mono
#'   propagates its covariance per IMU sample with noise blocks of `dt *
#'   gyr_n` and `dt * gyr_w`, so both are per-sample (discrete) standard
#'   deviations.
#' * `"matlab"`: `NoiseDensity = N`, `BiasInstability = B`, `RandomWalk = K`
#'   for `gyroparams()` / `accelparams()`, whose `NoiseType` default is
#'   `"double-sided"`. With `noise_type = "single-sided"` NoiseDensity and
#'   RandomWalk are multiplied by `sqrt(2)` (a one-sided PSD holds the power
#'   of both signs of frequency).
#'
#' Dead axes ([analyze_imu()]) are left out. Every value carries the
#' verdict of the reading it comes from (see [analyze_imu()]): `verdict`
#' and `note` (the verdict with its reason, as the files' comments say it);
#' `bound` is TRUE for an upper bound.
#'
#' @param x An `imu_analysis` ([analyze_imu()]) or an [avfit()] of a curve
#'   of known unit (see [datasheet()]).
#' @param tool One of `"kalibr"`, `"openvins"`, `"imu_utils"`, `"vins"`,
#'   `"matlab"`.
#' @param axis `"max"` (the worst axis) or `"mean"` of the axes, for the
#'   tools that take one value per sensor (Kalibr, OpenVINS, VINS); `"each"`
#'   for one row per axis (always so for imu_utils and MATLAB, which also
#'   hold per-axis values).
#' @param freq Sampling rate in Hz, for imu_utils and VINS; `NULL` takes the
#'   analysis' rate.
#' @param noise_type For MATLAB: `"double-sided"` (its default) or
#'   `"single-sided"`.
#' @return A data frame with columns `tool`, `sensor`, `axis` (a channel,
#'   `"max"`, `"mean"`), `key` (the tool's name of the value), `value`,
#'   `unit`, `formula`, `verdict`, `note`, `bound` (TRUE for an upper
#'   bound).
#' @seealso [conventions], [write_tool_params()], [write_kalibr_yaml()].
#' @export
#' @examples
#' \donttest{
#' set.seed(1)
#' r <- imu_record(cbind(gyro_x = rnorm(2e4) * 1e-3), freq = 100,
#'                 units = "rad/s")
#' a <- analyze_imu(r, refine = FALSE, progress = FALSE)
#' tool_params(a, "imu_utils")
#' }
tool_params <- function(x, tool, axis = "max", freq = NULL,
                        noise_type = "double-sided") {
  check_present(missing(x), "x", "an imu_analysis or an avfit")
  check_present(missing(tool), "tool", "the name of a tool")
  tool <- check_choice(tool, tool_names, "tool")
  axis <- check_choice(axis, c("max", "mean", "each"), "axis")
  noise_type <- check_choice(noise_type, c("double-sided", "single-sided"),
                             "noise_type")
  if (!is.null(freq)) freq <- check_freq(freq)
  rd <- tool_readings(x)
  freq <- freq %||% x$freq
  if (tool %in% c("imu_utils", "vins") && (is.null(freq) || !is.finite(freq))) {
    abort("`freq` is needed for ", tool, ": the analysis has no sampling ",
          "rate; give it in Hz.", class = "missing_argument")
  }
  if (tool %in% c("imu_utils", "matlab")) axis <- "each"
  rows <- list()
  for (s in intersect(c("gyro", "accel"), rd$sensor)) {
    d <- rd[rd$sensor == s, , drop = FALSE]
    if (axis != "each") d <- combine_axes(d, axis)
    if (tool == "imu_utils") d <- rbind(d, combine_axes(d, "mean", "avg"))
    rows[[s]] <- tool_rows(tool, s, d, freq, noise_type)
  }
  out <- do.call(rbind, rows)
  if (is.null(out)) {
    abort("`x` holds no live gyroscope or accelerometer axis: nothing to ",
          "convert.", class = "argument")
  }
  rownames(out) <- NULL
  out
}

tool_names <- c("kalibr", "openvins", "imu_utils", "vins", "matlab")

# Per axis: sensor, axis, and per reading of the catalogue (N, B, K) its
# value (SI), verdict and note in columns named by its symbol (`N`,
# `N_verdict`, `N_note`, ...; R/verdicts.R); dead axes left out.
tool_readings <- function(x) {
  if (inherits(x, "avfit")) x <- fit_analysis(x)
  if (!inherits(x, "imu_analysis")) {
    abort("`x` must be an imu_analysis (analyze_imu()) or an avfit, not ",
          describe_type(x), ".", class = "argument")
  }
  check_analysis(x)
  re <- reading_entries()
  rows <- lapply(x$channels, function(ch) {
    if (!is.null(ch$dead) || is.na(ch$sensor)) return(NULL)
    out <- data.frame(sensor = ch$sensor, axis = ch$channel, stringsAsFactors = FALSE)
    for (i in seq_len(nrow(re))) {
      k <- re$symbol[i]
      r <- reading_of(ch$readings, re$role[i])
      have <- nrow(r) > 0L
      out[[k]] <- if (have) r$value[1L] else NA_real_
      out[[paste0(k, "_verdict")]] <- if (have) r$verdict[1L] else "not_determined"
      out[[paste0(k, "_note")]] <- if (have)
        verdict_note(r$verdict[1L], r$why[1L], r$biased_by[1L], r$bias_change[1L])
        else "NOT DETERMINED"
    }
    out
  })
  out <- do.call(rbind, rows)
  if (is.null(out)) {
    abort("`x` holds no live axis of known sensor (gyro or accel): give the ",
          "unit of a fitted curve (see datasheet()).", class = "argument")
  }
  out
}

# One row of the worst ("max") or mean axis; `label` names it. The max
# carries the verdict of the axis it comes from; the mean is measured only
# when every axis is.
combine_axes <- function(d, how, label = how) {
  out <- data.frame(sensor = d$sensor[1L], axis = label, stringsAsFactors = FALSE)
  for (k in reading_entries()$symbol) {
    v <- d[[k]]
    vk <- d[[paste0(k, "_verdict")]]
    nk <- d[[paste0(k, "_note")]]
    if (!any(is.finite(v))) {
      out[[k]] <- NA_real_
      out[[paste0(k, "_verdict")]] <- "not_determined"
      out[[paste0(k, "_note")]] <- "NOT DETERMINED on any axis"
    } else if (how == "max") {
      i <- which.max(v)
      out[[k]] <- v[i]
      out[[paste0(k, "_verdict")]] <- vk[i]
      out[[paste0(k, "_note")]] <- nk[i]
    } else {
      out[[k]] <- mean(v, na.rm = TRUE)
      ok <- all(vk == "measured")
      out[[paste0(k, "_verdict")]] <- mean_verdict(vk)
      out[[paste0(k, "_note")]] <- if (ok) nk[1L] else
        paste0(toupper(verdict_label(out[[paste0(k, "_verdict")]])),
               ": mean of axes not all measured (",
               paste0(d$axis, " ", verdict_label(vk), collapse = ", "), ")")
    }
  }
  out
}

# The tool's values of one sensor, one row per (axis, key): the tool's
# conventions, one row per key: its name, the reading it holds (by role),
# the factor on it, its unit and its formula (`%s` the reading's symbol).
tool_rows <- function(tool, sensor, d, freq, noise_type) {
  g <- sensor == "gyro"
  u <- if (g) "rad/s" else "m/s^2"
  nd <- si_unit(sensor, "u*sqrt(s)")      # rad/s/sqrt(Hz), m/s^2/sqrt(Hz)
  kd <- si_unit(sensor, "u/sqrt(s)")      # rad/s^2/sqrt(Hz), m/s^3/sqrt(Hz)
  pre <- if (g) "gyr" else "acc"
  long <- if (g) "gyroscope" else "accelerometer"
  spec <- switch(tool,
    kalibr = , openvins = list(
      list(paste0(long, "_noise_density"), "white", 1, nd, "%s"),
      list(paste0(long, "_random_walk"), "random_walk", 1, kd, "%s")),
    imu_utils = list(
      list(paste0(pre, "_n"), "white", sqrt(freq), u, "%s * sqrt(freq)"),
      list(paste0(pre, "_w"), "flicker", bias_floor, u,
           "0.664 * %s (min ADEV, the flat floor)")),
    vins = list(
      list(paste0(pre, "_n"), "white", sqrt(freq), u, "%s * sqrt(freq)"),
      list(paste0(pre, "_w"), "random_walk", sqrt(freq), u, "%s * sqrt(freq)")),
    matlab = {
      s2 <- if (noise_type == "single-sided") sqrt(2) else 1
      f2 <- if (s2 == 1) "" else " * sqrt(2) (single-sided)"
      list(list("NoiseDensity", "white", s2, paste0("(", u, ")/sqrt(Hz)"),
                paste0("%s", f2)),
           list("BiasInstability", "flicker", 1, u, "%s"),
           list("RandomWalk", "random_walk", s2, paste0("(", u, ")*sqrt(Hz)"),
                paste0("%s", f2)))
    })
  do.call(rbind, lapply(spec, function(s) {
    k <- reading_symbol(s[[2L]])
    verdict <- d[[paste0(k, "_verdict")]]
    data.frame(tool = tool, sensor = sensor, axis = d$axis, key = s[[1L]],
               value = d[[k]] * s[[3L]], unit = s[[4L]],
               formula = sprintf(s[[5L]], k), verdict = verdict,
               note = d[[paste0(k, "_note")]], bound = verdict == "upper_bound",
               stringsAsFactors = FALSE)
  }))
}

# ADEV of bias instability on its flat region: B * sqrt(2 ln 2 / pi)
# (IEEE Std 952-1997, annex C), written 0.664 by most tools.
bias_floor <- sqrt(2 * log(2) / pi)

#' Write another tool's noise parameter file
#'
#' Writes the values of [tool_params()] in the layout the tool reads:
#' * `"imu_utils"`: imu_utils' `<name>_imu_param.yaml` (OpenCV
#'   `%YAML:1.0`), `Gyr` and `Acc` blocks with `avg-axis`, `x-axis`,
#'   `y-axis`, `z-axis` (`gyr_n`, `gyr_w`, `acc_n`, `acc_w`), readable by
#'   [read_imu_utils_yaml()];
#' * `"vins"`: the four VINS-Mono / VINS-Fusion keys `acc_n`, `gyr_n`,
#'   `acc_w`, `gyr_w` (to paste into its config);
#' * `"openvins"`: OpenVINS' `kalibr_imu_chain.yaml` (an `imu0` block with
#'   Kalibr's four keys, `rostopic`, `update_rate`), readable by
#'   [read_kalibr_yaml()];
#' * `"matlab"`: a MATLAB script creating `gyro = gyroparams(...)` and
#'   `accel = accelparams(...)` with per-axis `[x y z]` values.
#' For Kalibr's own `imu.yaml` use [write_kalibr_yaml()]. Every file states
#' its conventions in comments; text copied from the record is quoted.
#'
#' @inheritParams tool_params
#' @param file Path of the file to write (replaced whole, or left as it
#'   was when writing fails).
#' @param name For imu_utils: the `name` entry; `NULL` for the record's.
#' @param rostopic For OpenVINS: the `rostopic` entry.
#' @return `file`, invisibly, with the [tool_params()] table in attribute
#'   `values`.
#' @seealso [conventions].
#' @export
#' @examples
#' \donttest{
#' set.seed(1)
#' m <- cbind(gyro_x = rnorm(2e4) * 1e-3, gyro_y = rnorm(2e4) * 1e-3,
#'            gyro_z = rnorm(2e4) * 1e-3)
#' a <- analyze_imu(imu_record(m, freq = 100, units = rep("rad/s", 3)),
#'                  refine = FALSE, progress = FALSE)
#' f <- tempfile(fileext = ".yaml")
#' write_tool_params(a, "imu_utils", f)
#' cat(readLines(f), sep = "\n")
#' }
write_tool_params <- function(x, tool, file, axis = "max", freq = NULL,
                              noise_type = "double-sided", name = NULL,
                              rostopic = "/imu0") {
  check_present(missing(x), "x", "an imu_analysis or an avfit")
  check_present(missing(tool), "tool", "the name of a tool")
  check_present(missing(file), "file", "the path of the file to write")
  tool <- check_choice(tool, setdiff(tool_names, "kalibr"), "tool")
  file <- check_output_path(file)
  for (a in c("name", "rostopic")) {
    v <- get(a)
    if (!is.null(v) && (!is.character(v) || length(v) != 1L || is.na(v))) {
      abort("`", a, "` must be a single string, not ", describe_type(v), ".",
            class = "argument")
    }
  }
  tp <- tool_params(x, tool, axis = axis, freq = freq, noise_type = noise_type)
  if (inherits(x, "avfit")) x <- fit_analysis(x)
  freq <- freq %||% x$freq
  head <- c(sprintf("written by allanvar %s from %s; conventions: ?allanvar::conventions",
                    utils::packageVersion("allanvar"), comment_text(x$name)),
            unit_warning_lines(x),
            unique(paste0(tp$key, " = ", tp$formula)),
            "verdicts (measured: the model agrees with the data over the taus the value rests on):",
            unique(sprintf("  %s %s: %s", tp$axis, tp$key, comment_text(tp$note))))
  num <- function(v) if (is.finite(v)) sprintf("%.10e", v) else ".nan"
  out <- switch(tool,
    imu_utils = {
      blk <- function(s, pre, unit) {
        d <- tp[tp$sensor == s, , drop = FALSE]
        if (!nrow(d)) return(NULL)
        axes <- unique(d$axis)
        lab <- ifelse(axes == "avg", "avg-axis",
                      paste0(axis_letter(axes), "-axis"))
        c(paste0(if (s == "gyro") "Gyr" else "Acc", ":"),
          sprintf("   unit: \" %s\"", unit),
          unlist(lapply(seq_along(axes), function(i) {
            v <- d[d$axis == axes[i], ]
            c(sprintf("   %s:", lab[i]),
              sprintf("      %s: %s", v$key, vapply(v$value, num, "")))
          })))
      }
      c("%YAML:1.0", "---", paste0("# ", head), "type: \"IMU\"",
        paste0("name: ", yaml_quote(name %||% x$name)),
        blk("gyro", "gyr", "rad/s"), blk("accel", "acc", "m/s^2"))
    },
    vins = c("%YAML:1.0", paste0("# ", head),
             "# IMU noise: per-sample standard deviations (discrete time)",
             sprintf("%s: %s   # [%s] %s%s", tp$key, vapply(tp$value, num, ""),
                     tp$unit, tp$formula, file_note(tp))),
    openvins = c("%YAML:1.0", "", paste0("# ", head), "imu0:",
                 sprintf("  %s: %s   # [%s] %s%s", tp$key,
                         vapply(tp$value, num, ""), tp$unit, tp$formula,
                         file_note(tp)),
                 "  model: calibrated",
                 paste0("  rostopic: ", yaml_quote(rostopic)),
                 "  time_offset: 0.0",
                 sprintf("  update_rate: %s", format(freq %||% NA_real_, nsmall = 1))),
    matlab = {
      mat <- function(s, fun) {
        d <- tp[tp$sensor == s, , drop = FALSE]
        if (!nrow(d)) return(NULL)
        args <- vapply(unique(d$key), function(k) {
          v <- d$value[d$key == k]
          v[!is.finite(v)] <- 0
          # gyroparams takes a scalar or one value per axis of three
          if (length(v) != 3L) v <- max(v)
          sprintf("'%s', [%s]", k, paste(sprintf("%.10g", v), collapse = " "))
        }, "")
        if (noise_type == "single-sided") args <- c(args, "'NoiseType', 'single-sided'")
        c(sprintf("%% %s axes: %s", s, comment_text(paste(unique(d$axis), collapse = ", "))),
          sprintf("%s = %s(%s);", if (s == "gyro") "gyro" else "accel", fun,
                  paste(args, collapse = ", ...\n    ")))
      }
      c(paste0("% ", head), mat("gyro", "gyroparams"), mat("accel", "accelparams"))
    })
  write_atomic(file, function(path) writeLines(out, path))
  invisible(structure(file, values = tp))
}

# x, y, z from channel names ending in _x/_y/_z (else 1, 2, 3, ...).
axis_letter <- function(ch) {
  l <- sub(".*[_.]([xyzXYZ])$", "\\1", ch)
  ifelse(nchar(l) == 1L, tolower(l), as.character(seq_along(ch)))
}

# "; UPPER BOUND: ..." after a value whose reading is not measured.
file_note <- function(tp) {
  ifelse(tp$verdict == "measured", "",
         paste0("; ", toupper(verdict_label(tp$verdict))))
}
