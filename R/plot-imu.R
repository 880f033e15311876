# Plots of an IMU analysis: per sensor, the Allan deviation of every axis,
# the fitted model and the readings' markers, drawn from the typed reading
# columns (value, tau, slope, adev, verdict) and the catalogue's marker
# and legend for each reading; the legend beside the plot (R/plot-legend.R).

#' Plot the Allan deviation of an IMU analysis
#'
#' One panel per sensor (gyroscope, accelerometer): the Allan deviation of
#' every axis with its confidence band, the fitted model (dashed), and
#' markers where the datasheet values were read: N on the -1/2 line at
#' tau = 1 s (circle), B at the flat minimum, plotted at 0.664 B (triangle),
#' K on the +1/2 line at tau = 3 s (square). A reading the data support only
#' as a bound is drawn open with an arrow pointing the way the sensor's value
#' may lie; one not determined is not drawn (see the readings' `verdict`).
#' The legend, beside the plot so that it never covers data, explains
#' colours and markers; axes are labelled with units.
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
  uw <- unit_warnings(x)
  for (s in sensors) {
    plot_sensor(x, s, units, ...)
    # failed unit checks are said on the plot too
    if (nrow(uw)) {
      graphics::mtext("WARNING: the units failed their checks (see the datasheet)",
                      side = 3, line = 0.3, col = "red", cex = 0.8)
    }
  }
  invisible(x)
}

# Readings a plot draws: finite values that are measured or a bound (a
# bound is drawn open, with an arrow pointing the way the truth may lie).
drawn_readings <- function(rd) {
  rd[is.finite(rd$value) & is.finite(rd$adev) & rd$verdict != "not_determined", ,
     drop = FALSE]
}

# The legend entries of the readings drawn on some axis: one per (term,
# verdict), in catalogue order.
reading_legend <- function(chans, specs) {
  drawn <- do.call(rbind, lapply(chans, function(cc)
    drawn_readings(cc$readings)[c("term", "verdict")]))
  out <- list()
  for (r in specs) {
    v <- unique(drawn$verdict[drawn$term == r$symbol])
    for (w in intersect(verdict_levels, v)) {
      out[[length(out) + 1L]] <- list(
        symbol = r$symbol, slope = r$slope, pch = r$pch,
        bg = if (w == "measured") "grey60" else "white",
        legend = if (w == "measured") r$legend
                 else paste0(r$symbol, ": ", verdict_label(w), " (open marker)"))
    }
  }
  out
}

plot_sensor <- function(x, s, units, ...) {
  chans <- Filter(function(cc) cc$sensor == s, x$channels)
  u <- if (units == "SI") si_unit(s, "rate") else if (s == "gyro") "deg/h" else "ug"
  k <- convert_units(1, si_unit(s, "rate"), u)
  cols <- grDevices::hcl.colors(max(3L, length(chans)), "Dark 3")[seq_along(chans)]
  specs <- lapply(entries_with("reading"), function(e) e$reading)
  pch_of <- stats::setNames(vapply(specs, function(r) r$pch, 0),
                            vapply(specs, function(r) r$symbol, ""))
  # The legend lists only the markers and lines drawn on some axis.
  shown <- reading_legend(chans, specs)
  slopes <- unique(vapply(Filter(function(r) r$slope != 0, shown), function(r)
    if (r$slope > 0) sprintf("+%g", r$slope) else sprintf("%g", r$slope), ""))
  slopes <- gsub("0.5", "1/2", slopes, fixed = TRUE)
  has_fit <- any(vapply(chans, function(cc) !is.null(cc$fit$data$fitted), FALSE))
  n_read <- length(shown)
  line_lab <- if (length(slopes)) paste(paste(slopes, collapse = " and "),
                                        if (length(slopes) > 1L) "lines" else "line")
  leg <- list(legend = c(vapply(chans, function(cc) cc$channel, ""),
                         if (has_fit) "fitted model", line_lab,
                         vapply(shown, function(r) r$legend, "")),
              col = c(cols, rep("black", has_fit + length(line_lab) + n_read)),
              lty = c(rep(1, length(chans)), if (has_fit) 2,
                      if (length(line_lab)) 3, rep(NA, n_read)),
              pch = c(rep(20, length(chans)), if (has_fit) NA,
                      if (length(line_lab)) NA,
                      vapply(shown, function(r) r$pch, 0)),
              pt.bg = c(rep(NA, length(chans) + has_fit + length(line_lab)),
                        vapply(shown, function(r) r$bg, "")))
  op <- reserve_legend(leg, cex = 0.75)
  on.exit(graphics::par(op))
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
    for (j in seq_len(nrow(rd))) draw_reading(rd[j, ], cv, rng_x, k, cols[i], pch_of)
  }
  drawn <- legend_beside(leg, cex = 0.75)
  invisible(list(legend = leg$legend, rect = drawn$rect, usr = graphics::par("usr")))
}

# One reading: its line (dotted) and marker; a bound open, with an arrow
# towards where the sensor's value may lie.
draw_reading <- function(r, cv, rng_x, k, col, pch_of) {
  # the reading's line: ADEV = adev (tau / tau_read)^slope
  if (r$slope != 0) {
    graphics::lines(rng_x, r$adev * (rng_x / r$tau)^r$slope * k, col = col, lty = 3)
  }
  # a flat reading taken from the data's minimum is marked on the data
  # (the reading's tau is the fitted model's flattest point)
  tau_mark <- r$tau
  if (r$slope == 0 && identical(r$source, "slope")) {
    near <- which.min(abs(log(cv$adev) - log(r$adev)))
    if (length(near)) tau_mark <- cv$tau[near]
  }
  y <- r$adev * k
  if (r$verdict %in% c("upper_bound", "lower_bound")) {
    to <- if (r$verdict == "upper_bound") y / 1.6 else y * 1.6
    graphics::arrows(tau_mark, y, tau_mark, to, length = 0.06, col = col, lwd = 1.5)
  }
  graphics::points(tau_mark, y, pch = pch_of[[r$term]],
                   bg = if (r$verdict == "measured") col else "white", col = col,
                   cex = 1.4)
}

# Number of interior local maxima of v (an oscillating curve has many).
n_peaks <- function(v) {
  v <- v[is.finite(v)]
  if (length(v) < 3L) return(0L)
  d <- diff(v)
  sum(d[-length(d)] > 0 & d[-1L] <= 0)
}

# Units of fit coefficients ("u*sqrt(s)", "u", "1", "s") with u replaced by
# the fit's rate unit when it is known.
unit_label <- function(units, fit) {
  u <- fit_unit(fit)
  if (is.null(u)) return(units)
  out <- gsub("\\bu\\b", paste0("(", u, ")"), units, perl = TRUE)
  out[units == "u"] <- u
  out
}

#' @export
plot.imu_analysis_list <- function(x, ...) {
  for (a in x) plot(a, ...)
  invisible(x)
}
