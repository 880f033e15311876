#' Plot an Allan deviation curve with error bars
#'
#' The log-log plot of 'allanvar' 1.1: Allan standard deviation against
#' cluster time, with error bars of \eqn{\pm} `error` times the deviation
#' ([gplots::plotCI()]), the curve, axes at decades, an orange log grid and
#' the original title. Works on the output of [avar()], [avarn()] and
#' [avari()] (and on [allan()] results, whose `tau` and `avar` columns are
#' used, and its confidence limits `lower` and `upper` drawn as the bars).
#' A bar whose lower end would fall at or below zero (an `error` of 1 or
#' more) cannot be drawn on log axes: it is drawn down to the lowest
#' positive end of the other bars (a tenth of the curve's minimum when there
#' is none).
#'
#' Lines can be added afterwards (for example with [graphics::abline()]) in
#' the plot's log coordinates, as in `demo(allanvar)`. Graphical parameters
#' set with [graphics::par()] are left as they were.
#'
#' @param avdf A data frame with numeric columns `time`, `av` and `error`.
#' @return `avdf`, invisibly.
#' @seealso [avar()], [avarn()], [avari()].
#' @export
#' @examples
#' data(gyroz)
#' av <- avar(gyroz, frequency(gyroz))
#' plotav(av)
plotav <- function(avdf) {
  check_present(missing(avdf), "avdf", "the data frame returned by avar(), avarn() or avari()")
  curve <- plotav_columns(avdf)
  adev <- sqrt(curve$av)
  # plotCI() hands `log` on to points(), which warns that it is not a
  # graphical parameter; the warning says nothing about the user's data.
  withCallingHandlers(
    gplots::plotCI(x = curve$time, y = adev, uiw = curve$uiw, liw = curve$liw,
                   gap = 0, lty = 1, xaxt = "n", yaxt = "n", col = "blue",
                   log = "xy", lwd = 1, xlab = "", ylab = ""),
    warning = function(w) {
      # (a row without an interval has a bar of zero length: nothing to draw)
      if (grepl("\"log\" is not a graphical parameter", conditionMessage(w),
                fixed = TRUE) ||
          grepl("zero-length arrow", conditionMessage(w), fixed = TRUE)) {
        invokeRestart("muffleWarning")
      }
    })
  graphics::lines(curve$time, adev, col = "blue")
  graphics::axis(1, c(0.001, 0.01, 0.1, 0, 1, 10, 100, 1000, 10000))
  graphics::axis(2, c(0.000001, 0.00001, 0.0001, 0.001, 0.01, 0.1, 0, 1, 10,
                      100, 1000))
  graphics::grid(equilogs = TRUE, lwd = 1, col = "orange")
  graphics::title(main = "Allan variance Analysis",
                  xlab = "Cluster Times (Sec)",
                  ylab = "Allan Standard Deviation")
  invisible(avdf)
}

# time, av and error of a compatibility data frame (or of an allan() result).
plotav_columns <- function(avdf) {
  if (!is.data.frame(avdf) && !is.list(avdf)) {
    abort("`avdf` must be the data frame returned by avar(), avarn() or ",
          "avari(), not ", describe_type(avdf), ".", class = "argument")
  }
  limits <- NULL
  if (all(c("tau", "avar", "upper", "adev") %in% names(avdf))) {
    # allan(): asymmetric chi-square limits, drawn as they are
    limits <- list(lower = avdf$lower %||% avdf$adev, upper = avdf$upper)
    avdf <- list(time = avdf$tau, av = avdf$avar,
                 error = (avdf$upper - avdf$adev) / avdf$adev)
  }
  missing_cols <- setdiff(c("time", "av", "error"), names(avdf))
  if (length(missing_cols)) {
    abort("`avdf` must have columns `time`, `av` and `error`; it lacks ",
          paste0("`", missing_cols, "`", collapse = ", "), ".", class = "argument")
  }
  cols <- list(time = avdf$time, av = avdf$av, error = avdf$error)
  for (nm in names(cols)) {
    x <- cols[[nm]]
    if (!is.numeric(x) || is.factor(x)) {
      abort("`avdf$", nm, "` must be numeric, not ", describe_type(x), ".", class = "argument")
    }
  }
  lens <- lengths(cols)
  if (lens[[1L]] < 1L || any(lens != lens[[1L]])) {
    abort("`avdf` must have at least one row and columns of equal length.",
          class = "argument")
  }
  ok <- is.finite(cols$time) & cols$time > 0 & is.finite(cols$av) & cols$av > 0
  if (!any(ok)) {
    abort("`avdf` has no row with positive, finite `time` and `av` to plot ",
          "on log axes.", class = "argument")
  }
  out <- lapply(cols, `[`, ok)
  adev <- sqrt(out$av)
  if (is.null(limits)) {
    out$uiw <- adev * out$error
    out$liw <- out$uiw
  } else {
    out$uiw <- limits$upper[ok] - adev
    out$liw <- adev - limits$lower[ok]
  }
  # NA or negative widths (no confidence interval): no bar
  out$uiw[!is.finite(out$uiw) | out$uiw < 0] <- 0
  out$liw[!is.finite(out$liw) | out$liw < 0] <- 0
  # a lower end at or below zero has no place on a log axis
  low <- adev - out$liw
  bad <- low <= 0
  if (any(bad)) {
    floor <- if (any(!bad)) min(low[!bad]) else min(adev) / 10
    out$liw[bad] <- adev[bad] - floor
  }
  out
}
