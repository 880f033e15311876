# The report's figures: each one drawn by base graphics (the package's own
# plot methods where one exists, so the page and plot() agree) into an
# inline SVG (svglite), with what is drawn thinned to what a page can show;
# what is computed is never thinned.

# An inline <svg> of the drawing `expr` (width, height in inches), or a note
# saying why it could not be drawn: one failed figure does not lose the page.
report_svg <- function(expr, width = 7, height = 4.5, alt = "") {
  drawn <- tryCatch({
    s <- svglite::svgstring(width = width, height = height, pointsize = 11,
                            standalone = FALSE)
    ok <- FALSE
    on.exit(if (!ok) grDevices::dev.off(), add = TRUE)
    # plot.avfit()'s error bars shorter than a pixel warn; nothing is lost
    withCallingHandlers(force(expr), warning = function(w) {
      if (grepl("zero-length arrow", conditionMessage(w), fixed = TRUE)) {
        invokeRestart("muffleWarning")
      }
    })
    grDevices::dev.off()
    ok <- TRUE
    s()
  }, error = function(e) e)
  if (inherits(drawn, "error")) {
    return(htmltools::tags$p(class = "plot-failed",
                             "Figure not drawn: ", conditionMessage(drawn)))
  }
  htmltools::tags$figure(class = "plot", role = "img", `aria-label` = alt,
                         htmltools::HTML(as.character(drawn)))
}

# Min and max of `y` in `bins` equal runs of samples: the envelope a thinned
# trace keeps (a spike stays visible however far the series is thinned).
thin_envelope <- function(t, y, bins = 1500L) {
  n <- length(y)
  if (n <= 2L * bins) return(list(t = t, y = y))
  m <- n %/% bins
  k <- m * bins
  y <- y[seq_len(k)]
  dim(y) <- c(m, bins)
  # one row per block; max.col() finds each row's extremes in C
  y <- t(y)
  rows <- seq_len(bins)
  lo <- y[cbind(rows, max.col(-y, ties.method = "first"))]
  hi <- y[cbind(rows, max.col(y, ties.method = "first"))]
  tt <- t[seq(1L, k, by = m)]
  list(t = rep(tt, each = 2L), y = as.vector(rbind(lo, hi)))
}


# A spectrum thinned on log-spaced frequency bins, keeping each bin's
# largest value (a line keeps its height).
thin_spectrum <- function(f, p, bins = 600L) {
  ok <- f > 0 & is.finite(p) & p > 0
  f <- f[ok]
  p <- p[ok]
  if (length(f) <= bins) return(list(f = f, p = p))
  edges <- exp(seq(log(min(f)), log(max(f)) * (1 + 1e-12), length.out = bins + 1L))
  b <- findInterval(f, edges, all.inside = TRUE)
  i <- unlist(lapply(split(seq_along(p), b), function(j) j[which.max(p[j])]),
              use.names = FALSE)
  list(f = f[i], p = p[i])
}

# The Welch periodogram of a raw axis with frequencies marked (lines) and
# bands shaded; `mark` / `band` in Hz.
plot_periodogram <- function(psd, mark = numeric(), band = NULL, unit = "u",
                             main = "Periodogram (raw series)") {
  th <- thin_spectrum(psd$f, psd$psd)
  graphics::plot(th$f, th$p, type = "l", log = "xy", col = "grey25",
                 xlab = "frequency [Hz]",
                 ylab = sprintf("PSD [(%s)^2/Hz]", unit), main = main)
  graphics::grid(equilogs = FALSE, col = "grey88")
  if (!is.null(band) && all(is.finite(band))) {
    u <- graphics::par("usr")
    graphics::rect(band[1L], 10^u[3L], band[2L], 10^u[4L], border = NA,
                   col = grDevices::adjustcolor("#d95f02", 0.18))
  }
  mark <- mark[is.finite(mark) & mark > 0]
  if (length(mark)) {
    graphics::abline(v = mark, col = "#d95f02", lwd = 1.5, lty = 2)
    graphics::mtext(sprintf("%.4g Hz", mark), side = 3, at = mark, line = 0.1,
                    cex = 0.75, col = "#d95f02")
  }
}

# ACF of block means of a raw axis beside the exponential a process with
# correlation time `tc` gives (exp(-lag m / (freq tc))).
plot_block_acf <- function(x, freq, tc, main = "ACF of block means") {
  m <- acf_block_size(tc, freq)
  b <- block_means(x, m)
  if (length(b) < 40L) {
    graphics::plot.new()
    graphics::title(main = main)
    graphics::text(0.5, 0.5, "too few blocks for an ACF")
    return(invisible())
  }
  r <- acf_lags(detrend_linear(b), min(length(b) - 2L, acf_max_lag))[-1L]
  lag <- seq_along(r) * m / freq
  graphics::plot(lag, r, type = "h", lwd = 2, col = "grey35",
                 ylim = range(c(r, 0, 1)), xlab = "lag [s]", ylab = "ACF",
                 main = sprintf("%s (blocks of %g s)", main, m / freq))
  graphics::abline(h = 0, col = "grey60")
  tt <- seq(0, max(lag), length.out = 200)
  graphics::lines(tt, r[1L] * exp(-(tt - lag[1L]) / tc), col = "#1b9e77", lwd = 2)
  graphics::legend("topright", bty = "n", cex = 0.8, lwd = c(2, 2),
                   col = c("grey35", "#1b9e77"),
                   legend = c("block means", sprintf("exp(-lag / %.3g s)", tc)))
}

# The short-lag ACF of the raw samples: a sensor's own filter shows as an
# excess over white noise (0 beyond lag 0).
plot_lag_acf <- function(x, main = "ACF of the raw samples") {
  r <- acf_lags(x, 10L)[-1L]
  z <- 2 / sqrt(length(x))
  graphics::barplot(r, names.arg = seq_along(r), col = "#7570b3", border = NA,
                    ylim = range(c(r, 0, z, -z)), xlab = "lag [samples]",
                    ylab = "ACF", main = main)
  graphics::abline(h = c(-z, z), lty = 2, col = "grey40")
  graphics::abline(h = 0)
  graphics::mtext(sprintf("lag-1 excess over white noise: %.3f", r[1L]),
                  side = 3, line = 0.1, cex = 0.8)
}

# The final model on the data with one step's added effect and its tau range.
plot_step <- function(fit, label, tau_from, tau_to, unit, main) {
  d <- fit$data
  tt <- exp(seq(log(min(d$tau)), log(max(d$tau)), length.out = 200))
  comp <- stats::predict(fit, tt, by_term = TRUE)
  lo <- sqrt(d$avar * d$edf / stats::qchisq(0.8415, d$edf))
  hi <- sqrt(d$avar * d$edf / stats::qchisq(0.1585, d$edf))
  tot <- sqrt(rowSums(comp))
  own <- grepl(paste0("^", label, "\\b"), colnames(comp)) |
    colnames(comp) == label
  yl <- range(c(lo, hi, tot), finite = TRUE)
  yl[1L] <- yl[1L] / 3
  graphics::plot(d$tau, sqrt(d$avar), log = "xy", pch = 19, cex = 0.6,
                 ylim = yl, xlab = "tau [s]",
                 ylab = sprintf("Allan deviation [%s]", unit), main = main)
  u <- graphics::par("usr")
  if (is.finite(tau_from) && is.finite(tau_to)) {
    graphics::rect(tau_from, 10^u[3L], tau_to, 10^u[4L], border = NA,
                   col = grDevices::adjustcolor("#e6ab02", 0.25))
  }
  ok <- is.finite(lo) & is.finite(hi) & hi > lo
  graphics::segments(d$tau[ok], lo[ok], d$tau[ok], hi[ok], col = "grey55")
  graphics::points(d$tau, sqrt(d$avar), pch = 19, cex = 0.6)
  graphics::lines(tt, tot, lwd = 2)
  if (any(own)) {
    v <- sqrt(rowSums(comp[, own, drop = FALSE]))
    v[v < yl[1L]] <- NA
    graphics::lines(tt, v, col = "#d95f02", lwd = 2, lty = 2)
  }
  graphics::legend("bottomleft", bty = "n", cex = 0.8,
                   legend = c("data (68% interval)", "final model",
                              paste("effect added:", label), "tau range of the residual"),
                   col = c("black", "black", "#d95f02", NA),
                   pch = c(19, NA, NA, 15), pt.cex = c(0.6, NA, NA, 2),
                   lty = c(NA, 1, 2, NA), lwd = c(NA, 2, 2, NA),
                   fill = c(NA, NA, NA, NA), border = NA)
}

# The rate of one axis on a time axis (thinned to its envelope), with the
# series effects marked where they were found.
plot_series_time <- function(x, freq, table, unit, main) {
  t <- (seq_along(x) - 1) / freq
  th <- thin_envelope(t, x)
  graphics::plot(th$t, th$y, type = "l", col = "grey45", xlab = "time [s]",
                 ylab = sprintf("rate [%s]", unit), main = main)
  series_marks(table)
}

# Series effects on an empty time axis (no raw series given).
plot_series_marks <- function(table, duration, main) {
  graphics::plot(NA, xlim = c(0, duration), ylim = c(0, 1), yaxt = "n",
                 xlab = "time [s]", ylab = "", main = main)
  series_marks(table)
}

series_marks <- function(table) {
  if (!NROW(table)) return(invisible())
  kinds <- unique(table$kind)
  cols <- stats::setNames(grDevices::hcl.colors(max(3L, length(kinds)), "Dark 3")[
    seq_along(kinds)], kinds)
  u <- graphics::par("usr")
  for (i in seq_len(nrow(table))) {
    r <- table[i, ]
    col <- cols[[r$kind]]
    dur <- if (is.finite(r$duration)) r$duration
           else if (is.finite(r$tc)) 3 * r$tc else 0
    if (dur > 0) {
      graphics::rect(r$time, u[3L], r$time + dur, u[4L], border = NA,
                     col = grDevices::adjustcolor(col, 0.2))
    }
    graphics::abline(v = r$time, col = col, lwd = 1.5, lty = 2)
  }
  graphics::legend("topright", bty = "n", cex = 0.8, lty = 2, lwd = 1.5,
                   col = cols, legend = names(cols))
}
