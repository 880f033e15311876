# A fit of a curve alone (another tool's curve, an allan() result, a table)
# seen as a one-axis imu_analysis, so that datasheet(), imu_guidance(),
# kalman_params() and the exporters read it exactly as they read an axis of
# analyze_imu(): the same readings, in the fit's unit when it is known.

# The rate unit of a fit: `unit` when given, else the unit its curve carried
# (a tool_curve's `unit` column), else NULL (unknown: values stay in the
# input's unit u).
fit_unit <- function(fit, unit = NULL) {
  if (!is.null(unit)) {
    lookup_unit(unit, "unit", kind = "rate")
    return(normalize_unit(unit))
  }
  u <- fit$input$unit
  if (is.character(u) && length(u) == 1L && !is.na(u) &&
      normalize_unit(u) %in% unit_table()$unit[unit_table()$kind == "rate"]) {
    return(normalize_unit(u))
  }
  NULL
}

#' One-axis analysis of a fit (internal)
#'
#' `fit`: an avfit. `unit`: the rate unit of the curve fitted ("rad/s",
#' "deg/s", "m/s^2", "g", ...), or NULL for the unit the fit's curve
#' carried; when unknown, values are in the input's unit u and the sensor is
#' NA. Amplitudes are converted to SI; nonlinear parameters (Tc, f0) are not.
#' @noRd
fit_analysis <- function(fit, unit = NULL, name = NULL) {
  unit <- fit_unit(fit, unit)
  if (is.null(unit)) {
    sensor <- NA_character_
    k <- 1
  } else {
    u <- lookup_unit(unit, "unit", kind = "rate")
    sensor <- u$sensor
    k <- u$to_si
  }
  lay <- fit$layout
  scale <- ifelse(lay$role == "amp", k, 1)
  coef <- stats::setNames(lay$value * scale, lay$name)
  se <- stats::setNames(fit$se * scale, lay$name)
  d <- fit$input$data
  # The EDF of the points: the curve's own, else the fit's model EDF.
  edf <- d$edf
  if (all(is.na(edf))) edf <- fit$data$edf[match(d$tau, fit$data$tau)]
  adev <- sqrt(d$avar) * k
  lo <- hi <- rep(NA_real_, length(edf))
  ok <- is.finite(edf) & edf > 0
  lo[ok] <- adev[ok] * sqrt(edf[ok] / stats::qchisq(0.8415, edf[ok]))
  hi[ok] <- adev[ok] * sqrt(edf[ok] / stats::qchisq(0.1585, edf[ok]))
  curve <- data.frame(tau = d$tau, m = d$m, avar = adev^2, adev = adev,
                      lower = lo, upper = hi, edf = edf)
  fitted <- data.frame(tau = fit$data$tau, fitted = fit$data$fitted * k^2)
  label <- name %||% (fit$channel %||% (fit$input$channel %||% "fit"))
  readings <- channel_readings(curve, coef, sensor, se = se, fitted = fitted,
                               series = fit$series, unexplained = fit$unexplained,
                               alternatives = model_alternatives(fit, k))
  ch <- list(channel = label, sensor = sensor, unit = unit %||% "u",
             freq = fit$freq, n = fit$n, curve = curve, fit = fit,
             fit_error = NULL, fit_condition = NULL, coef = coef,
             readings = readings)
  ch$guidance <- channel_guidance(ch)
  n <- fit$n %||% NA_real_
  freq <- fit$freq
  a <- list(name = label, freq = freq, n = n,
            duration = if (is.null(freq)) NA_real_ else n / freq,
            record = list(file = NULL, problems = data.frame(type = character()),
                          segments = NULL, units = unit, sampling = NULL),
            channels = stats::setNames(list(ch), label), call = fit$call,
            unit = unit)
  class(a) <- c("imu_fit_analysis", "imu_analysis")
  a$datasheet <- datasheet(a)
  a
}
