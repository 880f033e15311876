#' Write a Kalibr imu.yaml from an IMU analysis
#'
#' Writes the four noise parameters Kalibr (and VINS, OpenVINS, ...) read
#' from `imu.yaml`, with their continuous-time units in comments:
#' * `gyroscope_noise_density`: gyroscope N, rad/s/sqrt(Hz) (= rad/sqrt(s));
#' * `gyroscope_random_walk`: gyroscope K, rad/s^2/sqrt(Hz);
#' * `accelerometer_noise_density`: accelerometer N, m/s^2/sqrt(Hz);
#' * `accelerometer_random_walk`: accelerometer K, m/s^3/sqrt(Hz);
#' * `update_rate`: the sampling rate in Hz, which Kalibr uses to discretize
#'   (sigma_d = N / sqrt(dt), sigma_bd = K * sqrt(dt); see [kalman_params()]).
#'
#' Kalibr takes one number per sensor, so by default the worst (largest)
#' axis is written (`axis = "max"`); the per-axis values and the axis used
#' are listed in comments. Each value's comment carries the verdict of its
#' reading (MEASURED, UPPER BOUND, LOWER BOUND, NOT DETERMINED, with why;
#' see [analyze_imu()]): e.g. when K could not be read (the +1/2 region was
#' not reached), the value written is the upper bound from the longest tau
#' (see [imu_guidance()]). Failed unit checks of the record are repeated as
#' WARNING lines at the top. Kalibr's documentation
#' advises inflating the values for real use; `inflate` multiplies all four
#' (default 1, stated in the file).
#'
#' @param x An `imu_analysis` ([analyze_imu()]), an [avfit()] of a curve of
#'   known unit and rate, or a named list or vector
#'   with `gyroscope_noise_density`, `gyroscope_random_walk`,
#'   `accelerometer_noise_density`, `accelerometer_random_walk` (SI) and
#'   `update_rate` (Hz).
#' @param file Path of the yaml file to write.
#' @param axis `"max"` (worst axis, default) or `"mean"` of the axes.
#' @param rostopic The `rostopic` entry.
#' @param inflate A factor applied to the four noise values (>= 1).
#' @return `file`, invisibly; the values written are in attribute `values`.
#' @export
#' @examples
#' f <- tempfile(fileext = ".yaml")
#' write_kalibr_yaml(list(gyroscope_noise_density = 1.7e-4,
#'                        gyroscope_random_walk = 2e-5,
#'                        accelerometer_noise_density = 2e-3,
#'                        accelerometer_random_walk = 3e-3,
#'                        update_rate = 200), f)
#' cat(readLines(f), sep = "\n")
write_kalibr_yaml <- function(x, file = "imu.yaml", axis = "max",
                              rostopic = "/imu0", inflate = 1) {
  check_present(missing(x), "x", "an imu_analysis or the four noise values")
  axis <- check_choice(axis, c("max", "mean"), "axis")
  inflate <- check_number(inflate, "inflate", lo = 1)
  if (!is.character(rostopic) || length(rostopic) != 1L || is.na(rostopic)) {
    abort("`rostopic` must be a single string, not ", describe_type(rostopic),
          ".", class = "argument")
  }
  file <- check_output_path(file)
  if (inherits(x, "avfit")) {
    # a fit of a curve alone, read as one axis (in SI when its unit is known)
    x <- fit_analysis(x)
    if (is.null(x$freq) || all(is.na(x$channels[[1L]]$sensor))) {
      abort("`x`: an avfit needs its sampling rate (`freq`) and the unit of ",
            "its curve to be written as a Kalibr imu.yaml.", class = "argument")
    }
  }
  keys <- c("accelerometer_noise_density", "accelerometer_random_walk",
            "gyroscope_noise_density", "gyroscope_random_walk")
  notes <- stats::setNames(rep("", 4L), keys)
  header <- character()
  if (inherits(x, "imu_analysis")) {
    check_analysis(x)
    vals <- numeric()
    for (k in keys) {
      sensor <- if (startsWith(k, "gyro")) "gyro" else "accel"
      # Kalibr's noise density is the white-noise reading, its random walk
      # the rate-random-walk reading.
      role <- if (endsWith(k, "noise_density")) "white" else "random_walk"
      rows <- lapply(Filter(function(cc) cc$sensor == sensor, x$channels),
                     function(cc) {
                       r <- reading_of(cc$readings, role)
                       data.frame(axis = cc$channel, value = r$value,
                                  verdict = r$verdict,
                                  note = verdict_note(r$verdict, r$why, r$biased_by,
                                                      r$bias_change),
                                  stringsAsFactors = FALSE)
                     })
      if (!length(rows)) {
        vals[k] <- NA_real_
        next
      }
      rows <- do.call(rbind, rows)
      header <- c(header, sprintf("#   %-28s %s", k, comment_text(paste(sprintf(
        "%s = %s", rows$axis, ifelse(is.na(rows$value), "NA (dead axis)",
                                     sprintf("%.4e (%s)", rows$value,
                                             verdict_label(rows$verdict)))),
        collapse = ", "))))
      # dead axes carry no value and take no part in the max or the mean
      rows <- rows[is.finite(rows$value), , drop = FALSE]
      if (!nrow(rows)) {
        vals[k] <- NA_real_
        dead <- vapply(Filter(function(cc) identical(cc$sensor, sensor), x$channels),
                       function(cc) !is.null(cc$dead), FALSE)
        notes[k] <- if (all(dead)) "every axis dead" else "not read on any axis"
        next
      }
      if (axis == "max") {
        i <- which.max(rows$value)
        vals[k] <- rows$value[i]
        notes[k] <- sprintf("worst axis (%s); %s", rows$axis[i], rows$note[i])
      } else {
        vals[k] <- mean(rows$value)
        notes[k] <- if (all(rows$verdict == "measured")) "mean of the axes; MEASURED"
          else paste0("mean of the axes; NOT all MEASURED: ",
                      paste0(rows$axis, " ", rows$note, collapse = "; "))
      }
    }
    # A measured sensor needs both of its values: a yaml with one of them
    # missing (a record too short for any reading) is refused, not written.
    for (ks in list(keys[1:2], keys[3:4])) {
      v <- vals[ks]
      if (anyNA(v) && !all(is.na(v))) {
        miss <- ks[is.na(v)]
        abort("`x`: ", paste(miss, collapse = ", "), " could not be read from ",
              "the analysis (", paste(notes[miss][nzchar(notes[miss])], collapse = "; "),
              if (any(nzchar(notes[miss]))) "; ",
              "see imu_guidance(): the record may be too short); nothing written.",
              class = "argument")
      }
    }
    rate <- x$freq
    src <- sprintf("# Source: %s, %d samples at %.6g Hz (%.3g h), Allan deviation per axis.",
                   comment_text(x$name), x$n, x$freq, x$duration / 3600)
    header <- c(src, paste0("# ", unit_warning_lines(x)),
                "# MEASURED: the model agrees with the data over the taus the value rests on;",
                "# otherwise the value is a bound or not determined, and the comment says why.",
                paste0("# Kalibr takes one value per sensor; written: ",
                            if (axis == "max") "the worst (largest) axis."
                            else "the mean of the axes.",
                            " Per axis:"), header)
  } else if (is.list(x) || is.numeric(x)) {
    x <- as.list(x)
    miss <- setdiff(c(keys, "update_rate"), names(x))
    if (length(miss)) {
      abort("`x` lacks ", paste(miss, collapse = ", "), ".", class = "argument")
    }
    vals <- vapply(keys, function(k) check_number(x[[k]], k, lo = 0), 0)
    rate <- check_freq(x[["update_rate"]], "update_rate")
  } else {
    abort("`x` must be an imu_analysis or a named list of the noise values, not ",
          describe_type(x), ".", class = "argument")
  }
  vals <- vals * inflate
  units <- c(accelerometer_noise_density = "m/s^2/sqrt(Hz)",
             accelerometer_random_walk = "m/s^3/sqrt(Hz)",
             gyroscope_noise_density = "rad/s/sqrt(Hz)",
             gyroscope_random_walk = "rad/s^2/sqrt(Hz)")
  what <- c(accelerometer_noise_density = "white noise N, continuous time",
            accelerometer_random_walk = "bias random walk K, continuous time",
            gyroscope_noise_density = "white noise N, continuous time",
            gyroscope_random_walk = "bias random walk K, continuous time")
  line <- function(k) {
    sprintf("%-28s %-14s # [%s] %s%s", paste0(k, ":"), sprintf("%.6e", vals[[k]]),
            units[[k]], what[[k]],
            if (nzchar(notes[[k]])) paste0("; ", comment_text(notes[[k]])) else "")
  }
  # A sensor the record does not hold is left out (with a comment), never
  # written as .nan: Kalibr and OpenVINS would read that as a number.
  block <- function(title, sensor, ks) {
    if (all(is.na(vals[ks]))) {
      return(c(paste0("#", title), sprintf(
        "# (%s: %s not written)",
        if (any(notes[ks] == "every axis dead")) paste("every", sensor, "axis is dead")
        else paste("no", sensor, "channel in the record"),
        paste(ks, collapse = ", "))))
    }
    c(paste0("#", title), vapply(ks, line, ""))
  }
  out <- c(
    sprintf("# Kalibr IMU noise model, written by allanvar %s on %s.",
            utils::packageVersion("allanvar"), format(Sys.Date())),
    "# Noise densities and random walks are continuous-time IEEE 952 coefficients in SI;",
    "# Kalibr discretizes them with update_rate: sigma_d = N / sqrt(dt), sigma_bd = K * sqrt(dt).",
    if (inflate != 1) sprintf("# All four values multiplied by inflate = %g.", inflate),
    header,
    "",
    block("Accelerometers", "accelerometer",
          c("accelerometer_noise_density", "accelerometer_random_walk")),
    "",
    block("Gyroscopes", "gyroscope",
          c("gyroscope_noise_density", "gyroscope_random_walk")),
    "",
    sprintf("%-28s %-14s # the IMU ROS topic", "rostopic:", yaml_quote(rostopic)),
    sprintf("%-28s %-14s # [Hz] sampling rate, used by Kalibr to discretize",
            "update_rate:", format(rate, nsmall = 1))
  )
  write_atomic(file, function(path) writeLines(out, path))
  invisible(structure(file, values = c(vals, update_rate = rate)))
}

#' Discrete-time filter parameters from an IMU analysis
#'
#' Converts the continuous-time noise coefficients into the numbers a
#' discrete Kalman filter with step `dt` uses, with the convention written
#' next to each number:
#' * white noise N: `sigma_d = N / sqrt(dt)`, the standard deviation of each
#'   sample's white noise (rad/s or m/s^2);
#' * rate random walk K: `sigma_bd = K * sqrt(dt)`, the standard deviation
#'   of the bias increment per step, `b[k] = b[k-1] + sigma_bd * w[k]`;
#' * each Gauss-Markov term (sigma, Tc) fitted by [avfit()]/[avrefine()]
#'   (for an analysis, those with Tc < 0.1 s are already part of its N and
#'   are not repeated):
#'   `phi = exp(-dt / Tc)` and the driving-noise variance
#'   `q_d = sigma^2 * (1 - phi^2)`, for `x[k] = phi * x[k-1] + w[k]`,
#'   `Var(w[k]) = q_d` (so that the stationary variance is sigma^2);
#' * bias instability B (flicker noise) has no exact finite-state model;
#'   with `bias_instability = "gm"` it is approximated by one Gauss-Markov
#'   term whose Allan deviation peak (0.6174 sigma at tau = 1.893 Tc) sits
#'   on the flat minimum: `Tc = tau_B / 1.893`, `sigma = 0.664 B / 0.6174`,
#'   then `phi` and `q_d` as above. `"omit"` leaves it out.
#'
#' @param x An `imu_analysis` ([analyze_imu()]), an `avfit` object, or a
#'   named numeric vector of coefficients (`N`, `K`, `B`, `gm1.sigma`,
#'   `gm1.tc`, ..., in the rate unit, e.g. SI).
#' @param dt The filter step in seconds; default `1 / freq` of the analysis
#'   (required for a plain vector without `freq`).
#' @param bias_instability `"gm"` or `"omit"`, see above; `NULL` (default)
#'   for `"gm"`, the approximation the catalogue's flicker entry gives.
#' @param tau_B For a vector or `avfit`: the tau (s) of the flat minimum,
#'   used by `bias_instability = "gm"`.
#' @param unit For an `avfit`: the rate unit of the fitted curve (see
#'   [av_units()]); `NULL` for the unit the curve carried, if any.
#' @return A data frame with one row per parameter: `channel`, `sensor`,
#'   `term`, `parameter`, `value`, `unit`, `continuous` (the coefficient it
#'   comes from), `continuous_unit`, `dt` and `convention`; rows in the
#'   catalogue's order of the terms (N, B, K, then the Gauss-Markov terms).
#'   For an analysis also `verdict` and `why` (of the reading N, B or K the
#'   row comes from, see [analyze_imu()]; for a Gauss-Markov term,
#'   "measured" when the fit determines its sigma and Tc within a factor 2
#'   at 95% and held neither, else "not determined" with the widest
#'   interval: a record of a few thousand seconds often cannot tell a slow
#'   term's Tc better) and `warning` (failed unit checks of the axis).
#' @export
#' @examples
#' kalman_params(c(N = 1e-3, K = 1e-5, gm1.sigma = 2e-4, gm1.tc = 50), dt = 0.01)
kalman_params <- function(x, dt = NULL, bias_instability = NULL,
                          tau_B = NULL, unit = NULL) {
  check_present(missing(x), "x", "an imu_analysis, an avfit or coefficients")
  # how B may stand in a finite-state model: the catalogue's flicker entry
  # says (its approximation first, the default)
  approx <- reading_entry("flicker")$reading$approximations
  bias_instability <- check_choice(bias_instability %||% approx[1L], approx,
                                   "bias_instability")
  if (!is.null(tau_B)) tau_B <- check_number(tau_B, "tau_B", lo = 0, open = TRUE)
  if (!is.null(dt)) dt <- check_number(dt, "dt", lo = 0, open = TRUE)
  if (inherits(x, "avfit")) {
    # A fit (of a curve with or without raw data) is read like one axis of
    # an analysis: the same readings, in the fit's unit when known.
    x <- fit_analysis(x, unit = unit)
    if (is.null(dt) && is.null(x$freq)) {
      abort("`dt` is missing and the fit has no sampling rate; give the ",
            "filter step in seconds.", class = "missing_argument")
    }
  }
  if (inherits(x, "imu_analysis")) {
    check_analysis(x)
    if (is.null(dt)) dt <- 1 / x$freq
    uw <- unit_warnings(x)
    rows <- lapply(x$channels, function(ch) {
      rd <- ch$readings
      # the readings replace the fitted values; terms folded into a reading
      # are not repeated
      folded <- unlist(strsplit(rd$folded[nzchar(rd$folded)], ",", fixed = TRUE))
      cf <- unfolded_coef(ch$coef, folded = folded)
      cf <- cf[!names(cf) %in% rd$term]
      cf <- c(stats::setNames(rd$value, rd$term), cf)
      flat <- reading_of(rd, "flicker")
      d <- discrete_rows(cf, dt, ch$channel, ch$sensor, bias_instability,
                         tau_B %||% if (nrow(flat)) flat$tau else NA_real_,
                         bounds = rd$term[rd$is_bound])
      # each parameter carries the verdict of the reading it comes from;
      # a term that is no reading (a Gauss-Markov term), how well the fit
      # determines its values
      i <- match(d$term, rd$term)
      tv <- own_term_verdicts(ch$fit, ch$coef, rd)
      d$verdict <- ifelse(is.na(i), vapply(tv, `[[`, "", "verdict")[d$term], rd$verdict[i])
      d$why <- ifelse(is.na(i), vapply(tv, `[[`, "", "why")[d$term], rd$why[i])
      d$warning <- rep(channel_unit_warning(uw, ch$channel), nrow(d))
      d
    })
    out <- do.call(rbind, rows)
  } else {
    if (!is.numeric(x) || is.null(names(x)) || anyNA(names(x)) ||
        !all(nzchar(names(x)))) {
      abort("`x` must be an imu_analysis, an avfit or a named numeric vector ",
            "of coefficients, not ", describe_type(x), ".", class = "argument")
    }
    if (anyDuplicated(names(x))) {
      abort("`x` names a coefficient twice (",
            names(x)[anyDuplicated(names(x))], "); give each once.",
            class = "argument")
    }
    bad <- which(!is.finite(x) | x < 0)
    if (length(bad)) {
      abort("`x` must hold finite, non-negative coefficients; ",
            names(x)[bad[1L]], " = ", format(x[[bad[1L]]]), ".",
            class = "argument")
    }
    check_coef(x, "x")
    if (is.null(dt)) {
      abort("`dt` is missing; give the filter step in seconds.",
            class = "missing_argument")
    }
    sensor <- NA_character_
    if (!is.null(unit)) sensor <- lookup_unit(unit, "unit", kind = "rate")$sensor
    out <- discrete_rows(x, dt, "x", sensor, bias_instability,
                         if (is.null(tau_B)) NA_real_ else tau_B)
  }
  rownames(out) <- NULL
  out
}

# The discrete-time rows of every instance in `cf` whose catalogue entry has
# a discrete-time model, in catalogue order. `bounds`: terms that are upper
# bounds.
discrete_rows <- function(cf, dt, channel, sensor, bi, tau_b, bounds = character()) {
  # for an unknown sensor, u is the input's rate unit
  unit <- function(kind) si_unit(sensor, kind)
  cf <- cf[is.finite(cf)]
  lay <- if (length(cf)) check_coef(cf) else NULL
  rows <- list()
  for (l in unique(lay$label)) {
    r <- lay[lay$label == l, , drop = FALSE]
    e <- effect_entry(r$kind[1L], r$variant[1L])
    if (is.null(e$discrete)) next
    par <- stats::setNames(r$value, r$param)
    rows[[length(rows) + 1L]] <- e$discrete(par, dt, unit, list(
      label = l, bias_instability = bi, tau_B = tau_b,
      bound = any(r$name %in% bounds)))
  }
  rows <- Filter(Negate(is.null), rows)
  if (!length(rows)) {
    return(data.frame(channel = character(), sensor = character(),
                      term = character(), parameter = character(),
                      value = numeric(), unit = character(),
                      continuous = numeric(), continuous_unit = character(),
                      dt = numeric(), convention = character()))
  }
  out <- do.call(rbind, rows)
  cbind(data.frame(channel = channel, sensor = sensor, stringsAsFactors = FALSE),
        out[c("term", "parameter", "value", "unit", "continuous",
              "continuous_unit")],
        dt = dt, convention = out$convention, stringsAsFactors = FALSE)
}
