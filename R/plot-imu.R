# Plots of an IMU analysis: per sensor, the Allan deviation of every axis,
# the fitted model and the readings' markers, drawn from the typed reading
# columns (value, tau, slope, adev, is_bound) and the catalogue's marker
# and legend for each reading.

#' Plot the Allan deviation of an IMU analysis
#'
#' One panel per sensor (gyroscope, accelerometer): the Allan deviation of
#' every axis with its confidence band, the fitted model (dashed), and
#' markers where the datasheet values were read: N on the -1/2 line at
#' tau = 1 s (circle), B at the flat minimum, plotted at 0.664 B (triangle),
#' K on the +1/2 line at tau = 3 s (square; not drawn when K is only an
#' upper bound). A legend explains colours and markers; axes are labelled
#' with units.
#'
#' @param x An `imu_analysis` from [analyze_imu()].
#' @param sensor `NULL` for every sensor present, or `"gyro"` / `"accel"`.
#' @param units `"SI"` (default; rad/s, m/s^2) or `"datasheet"` (deg/h, ug).
#' @param ... Further graphical parameters passed to [graphics::plot()].
#' @return `x`, invisibly.
#' @export
#' @examples
#' \donttest{
#' set.seed(1)
#' m <- cbind(gyro_x = rnorm(2e4, sd = 0.01), gyro_y = rnorm(2e4, sd = 0.02))
#' a <- analyze_imu(imu_record(m, freq = 100), refine = FALSE, progress = FALSE)
#' plot(a)
#' }
plot.imu_analysis <- function(x, sensor = NULL, units = "SI", ...) {
  units <- check_choice(units, c("SI", "datasheet"), "units")
  sensors <- unique(vapply(x$channels, function(cc) cc$sensor, ""))
  if (!is.null(sensor)) sensors <- intersect(sensors, match_sensor(sensor))
  if (!length(sensors)) {
    abort("no ", sensor, " channels in this analysis.", class = "argument")
  }
  if (length(sensors) > 1L) {
    op <- graphics::par(mfrow = c(1L, length(sensors)))
    on.exit(graphics::par(op))
  }
  for (s in sensors) plot_sensor(x, s, units, ...)
  invisible(x)
}

# Readings a plot draws: finite values that are not mere bounds.
drawn_readings <- function(rd) {
  rd[is.finite(rd$value) & is.finite(rd$adev) & !rd$is_bound, , drop = FALSE]
}

plot_sensor <- function(x, s, units, ...) {
  chans <- Filter(function(cc) cc$sensor == s, x$channels)
  u <- if (units == "SI") si_unit(s, "rate") else if (s == "gyro") "deg/h" else "ug"
  k <- convert_units(1, si_unit(s, "rate"), u)
  cols <- grDevices::hcl.colors(max(3L, length(chans)), "Dark 3")[seq_along(chans)]
  rng_x <- range(unlist(lapply(chans, function(cc) cc$curve$tau)))
  rng_y <- range(unlist(lapply(chans, function(cc) {
    v <- c(cc$curve$adev, cc$curve$lower, cc$curve$upper,
           drawn_readings(cc$readings)$adev)
    v[is.finite(v) & v > 0]
  }))) * k
  graphics::plot(NA, xlim = rng_x, ylim = rng_y, log = "xy",
                 xlab = expression(tau ~ "[s]"),
                 ylab = sprintf("Allan deviation [%s]", u),
                 main = sprintf("%s: %s", x$name,
                                if (s == "gyro") "gyroscope" else "accelerometer"),
                 ...)
  graphics::grid(equilogs = FALSE, col = "grey85")
  specs <- lapply(entries_with("reading"), function(e) e$reading)
  pch_of <- stats::setNames(vapply(specs, function(r) r$pch, 0),
                            vapply(specs, function(r) r$symbol, ""))
  for (i in seq_along(chans)) {
    cv <- chans[[i]]$curve
    ok <- is.finite(cv$lower) & is.finite(cv$upper) & cv$lower > 0
    if (any(ok)) {
      graphics::segments(cv$tau[ok], cv$lower[ok] * k, cv$tau[ok],
                         cv$upper[ok] * k, col = grDevices::adjustcolor(cols[i], 0.5))
    }
    graphics::lines(cv$tau, cv$adev * k, col = cols[i], type = "o", pch = 20,
                    cex = 0.6)
    fit <- chans[[i]]$fit
    if (!is.null(fit) && !is.null(fit$data$fitted)) {
      graphics::lines(fit$data$tau, sqrt(fit$data$fitted) * k, col = cols[i],
                      lty = 2)
    }
    rd <- drawn_readings(chans[[i]]$readings)
    for (j in seq_len(nrow(rd))) {
      r <- rd[j, ]
      # the reading's line: ADEV = adev (tau / tau_read)^slope
      if (r$slope != 0) {
        graphics::lines(rng_x, r$adev * (rng_x / r$tau)^r$slope * k,
                        col = cols[i], lty = 3)
      }
      graphics::points(r$tau, r$adev * k, pch = pch_of[[r$term]], bg = cols[i],
                       cex = 1.4)
    }
  }
  n_read <- length(specs)
  graphics::legend("topright", bty = "n", cex = 0.75,
                   legend = c(vapply(chans, function(cc) cc$channel, ""),
                              "fitted model", "-1/2 and +1/2 lines",
                              vapply(specs, function(r) r$legend, "")),
                   col = c(cols, rep("black", 2L + n_read)),
                   lty = c(rep(1, length(chans)), 2, 3, rep(NA, n_read)),
                   pch = c(rep(20, length(chans)), NA, NA, unname(pch_of)),
                   pt.bg = "grey60")
}

#' @export
plot.imu_analysis_list <- function(x, ...) {
  for (a in x) plot(a, ...)
  invisible(x)
}
