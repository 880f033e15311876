#' Analyse IMU recordings axis by axis
#'
#' For every channel (axis) of one or more recordings: the Allan deviation
#' curve on one tau grid ([allan()]), a noise-model fit ([avfit()] with
#' `terms`), the closed-loop refinement ([avrefine()], when `refine = TRUE`),
#' the datasheet readings N, B, K and the guidance on record length
#' ([imu_guidance()]). Axes are never averaged (see `average` in
#' [datasheet()]).
#'
#' Channels are analysed in parallel with [future.apply::future_lapply()],
#' so the call runs on whatever [future::plan()] is set (sequential by
#' default, `multisession`, a cluster, ...), with `future.seed = TRUE`:
#' results do not depend on the plan.
#'
#' Readings (the `method` column says which rule gave each number): N is
#' the fitted white-noise coefficient, the -1/2 line's value at tau = 1 s;
#' Gauss-Markov terms the refinement added with Tc < 0.1 s are white noise
#' at tau >= 1 s (their AV tends to 2 sigma^2 Tc / tau) and are folded in,
#' N = sqrt(N^2 + sum 2 sigma^2 Tc). K is the fitted rate random walk (the
#' +1/2 line's value at tau = 3 s) and B the fitted bias instability,
#' reported with the tau where it is read: the minimum of the fitted Allan
#' deviation (the flat region), or without a fit the minimum of the
#' measured one among the taus with at least 10 degrees of freedom.
#' A term the fit lacks or sets to 0 (for K: or whose standard error
#' exceeds it) is read by the IEEE 952 slope lines
#' instead: N and K from the tangent lines of slope -1/2 and +1/2,
#' B = min ADEV / 0.664; with no +1/2 region, K is given as the upper bound
#' min over tau of upper(tau) sqrt(3 / tau) (see [imu_guidance()]).
#'
#' @param x An [imu_record()] (from [read_imu()]), a list of them, or a
#'   character vector of file paths (read with [read_imu()] and `read_args`).
#' @param taus,type Passed to [allan()]: the tau grid (the same for every
#'   channel of a record) and the estimator.
#' @param terms Terms to fit, passed to [avfit()].
#' @param refine Run [avrefine()] on each fit to identify effects the model
#'   misses (logical).
#' @param segment Which gap-free segment to use: `"longest"` (default),
#'   `"each"` (every segment analysed as its own record) or a number.
#' @param channels Optional channel names to analyse (default: all).
#' @param progress Report progress, one message per axis. Default: on in
#'   interactive sessions unless `options(allanvar.progress = FALSE)`.
#' @param read_args A list of arguments for [read_imu()] when `x` holds
#'   file paths.
#' @param ... Further arguments passed to [avfit()].
#' @return For one recording, an object of class `"imu_analysis"`: a list
#'   with `name`, `freq`, `n` (samples used), `duration` (s), `record` (the
#'   record's `problems`, `segments`, `units`, `file`), `channels` (one entry
#'   per axis: `channel`, `sensor`, `unit`, `curve` (the [allan()] result),
#'   `fit` (the [avfit()]/[avrefine()] result or `NULL`), `fit_error`,
#'   `coef` (SI), `readings` (data frame `term`, `value`, `unit`, `tau`,
#'   `method`) and `guidance`), and `datasheet` ([datasheet()]). For
#'   several recordings, a list of those, of class `"imu_analysis_list"`.
#' @seealso [plot.imu_analysis()], [datasheet()], [write_kalibr_yaml()],
#'   [filter_params()], [allanvar_cli()].
#' @export
#' @examples
#' \donttest{
#' set.seed(1)
#' m <- cbind(gyro_x = rnorm(1e4, sd = 0.01), accel_x = rnorm(1e4, sd = 0.002))
#' r <- imu_record(m, freq = 100)
#' a <- analyze_imu(r, refine = FALSE, progress = FALSE)
#' a
#' }
analyze_imu <- function(x, taus = "octave", type = "overlapping",
                        terms = c("N", "B", "K"), refine = TRUE,
                        segment = "longest", channels = NULL,
                        progress = interactive() &&
                          isTRUE(getOption("allanvar.progress", TRUE)),
                        read_args = list(), ...) {
  check_present(missing(x), "x", "an imu_record, a list of them or file paths")
  if (!is.logical(refine) || length(refine) != 1L || is.na(refine)) {
    abort("`refine` must be TRUE or FALSE, not ", format_value(refine), ".")
  }
  if (!is.logical(progress) || length(progress) != 1L || is.na(progress)) {
    abort("`progress` must be TRUE or FALSE, not ", format_value(progress), ".")
  }
  records <- as_record_list(x, read_args)
  records <- split_segments(records, segment)
  single <- length(records) == 1L

  # One job per (record, channel): the unit of parallel work.
  jobs <- list()
  for (i in seq_along(records)) {
    r <- records[[i]]
    ch <- colnames(r$data)
    if (!is.null(channels)) {
      miss <- setdiff(channels, ch)
      if (length(miss)) {
        abort("`channels`: ", paste(miss, collapse = ", "), " not in ",
              r$name, " (", paste(ch, collapse = ", "), ").")
      }
      ch <- channels
    }
    for (chn in ch) {
      jobs[[length(jobs) + 1L]] <- list(
        record = i, name = r$name, channel = chn, sensor = r$sensors[[chn]],
        unit = r$si_units[[chn]], x = r$data[, chn], freq = r$freq)
    }
  }
  n_jobs <- length(jobs)
  for (k in seq_along(jobs)) jobs[[k]]$label <- sprintf("[%d/%d] %s: %s", k,
                                                        n_jobs, jobs[[k]]$name,
                                                        jobs[[k]]$channel)
  opts <- list(taus = taus, type = type, terms = terms, refine = refine,
               progress = progress, fit_args = list(...))
  # One future per axis: axes differ in cost (the refinement), so this
  # balances the workers, and progress arrives as each axis finishes.
  results <- future.apply::future_lapply(jobs, analyze_channel, opts = opts,
                                         future.seed = TRUE,
                                         future.scheduling = Inf)

  out <- lapply(seq_along(records), function(i) {
    r <- records[[i]]
    res <- results[vapply(jobs, function(j) j$record == i, logical(1))]
    names(res) <- vapply(res, function(z) z$channel, "")
    a <- list(name = r$name, freq = r$freq, n = nrow(r$data),
              duration = nrow(r$data) / r$freq,
              record = list(file = r$file, problems = r$problems,
                            segments = r$segments, units = r$units,
                            sampling = r$sampling),
              channels = res, call = match.call())
    class(a) <- "imu_analysis"
    a$datasheet <- datasheet(a)
    g <- imu_guidance(a)
    if (nrow(g)) {
      msg <- paste0(r$name, ": the record is short for some readings:\n",
                    paste0("  - ", g$channel, ": ", g$message, collapse = "\n"))
      warning(structure(class = c("allanvar_guidance", "warning", "condition"),
                        list(message = msg, call = NULL)))
    }
    a
  })
  if (single) return(out[[1L]])
  names(out) <- vapply(out, function(a) a$name, "")
  class(out) <- "imu_analysis_list"
  out
}

# The work for one axis; runs on a future worker, so it only uses its
# arguments and the package's namespace.
analyze_channel <- function(job, opts) {
  if (isTRUE(opts$progress)) message("allanvar: analysing ", job$label)
  curve <- allan(job$x, job$freq, taus = opts$taus, type = opts$type)
  fit <- NULL
  fit_error <- NULL
  fit <- tryCatch(
    do.call(avfit, c(list(curve, terms = opts$terms), opts$fit_args)),
    error = function(e) {
      fit_error <<- conditionMessage(e)
      NULL
    })
  if (!is.null(fit) && opts$refine) {
    # The raw series lets avrefine() confirm an effect in the data itself.
    fit <- tryCatch(avrefine(fit, data = job$x), error = function(e) {
      fit_error <<- paste("avrefine():", conditionMessage(e))
      fit
    })
  }
  coef <- if (is.null(fit)) numeric() else fit$coefficients
  readings <- channel_readings(curve, coef, job$sensor, se = fit_se(fit),
                               fitted = if (!is.null(fit)) fit$data)
  res <- list(channel = job$channel, sensor = job$sensor, unit = job$unit,
              freq = job$freq, n = length(job$x), curve = curve, fit = fit,
              fit_error = fit_error, coef = coef, readings = readings)
  res$guidance <- imu_guidance(res)
  res
}

# N, B, K as a datasheet reads them: from the fit when it has them, else
# from the IEEE 952 slope lines.
channel_readings <- function(curve, coef, sensor, se = NULL, fitted = NULL) {
  tau <- curve$tau
  adev <- curve$adev
  ok <- is.finite(adev) & adev > 0
  # The flat minimum is looked for where the curve is reliable (edf >= 10).
  rel <- if (is.null(curve$edf)) ok else ok & !is.na(curve$edf) & curve$edf >= 10
  if (!any(rel)) rel <- ok
  lines <- slope_readings(curve$tau[rel], adev[rel])
  tau_b <- curve$tau[rel][which.min(adev[rel])]
  # With a fit, B is read where the fitted model is flattest (its minimum).
  if (!is.null(fitted) && !is.null(fitted$fitted) && any(is.finite(fitted$fitted))) {
    tau_b <- fitted$tau[which.min(fitted$fitted)]
  }
  tau <- tau[ok]
  adev <- adev[ok]
  get <- function(nm) if (nm %in% names(coef)) unname(coef[[nm]]) else NA_real_
  fitted <- c(N = get("N"), B = get("B"), K = get("K"))
  method <- c(N = "fit", B = "fit", K = "fit")
  # A Gauss-Markov term with Tc well below 1 s is white noise at every
  # tau >= 1 s (its AV tends to 2 sigma^2 Tc / tau): the datasheet N, the
  # -1/2 line at tau = 1 s, includes it.
  gm <- white_like_gm(coef)
  if (gm > 0) {
    fitted[["N"]] <- sqrt((if (is.finite(fitted[["N"]])) fitted[["N"]]^2 else 0) + gm)
    method[["N"]] <- "fit + white-like GM (Tc < 0.1 s)"
  }
  # A term the fit set to 0 is not read from it; nor a K whose standard
  # error exceeds it (not distinguishable from 0: bounded instead).
  fitted[!is.finite(fitted) | fitted <= 0] <- NA_real_
  if (!is.null(se) && "K" %in% names(se) && is.finite(fitted[["K"]]) &&
      is.finite(se[["K"]]) && se[["K"]] > fitted[["K"]]) {
    fitted[["K"]] <- NA_real_
  }
  value <- ifelse(is.na(fitted), lines$value, fitted)
  method <- ifelse(is.na(fitted), lines$method, method)
  # With a fit, a K it sets to 0 is not replaced by a +1/2 tangent: that
  # slope may belong to a bump the model explains otherwise.
  if (length(coef) && is.na(fitted[["K"]])) value[["K"]] <- NA_real_
  if ("B" %in% names(coef) && is.na(fitted[["B"]])) {
    method[["B"]] <- paste0(method[["B"]], " (fit B = 0)")
  }
  if (!is.finite(value[["K"]]) || value[["K"]] <= 0) {
    # No +1/2 region: every term adds to the AV, so K^2 tau / 3 <= AV(tau)
    # at each tau; the upper confidence limit makes the bound conservative.
    up <- if (!is.null(curve$upper)) curve$upper[ok] else adev
    up[!is.finite(up)] <- Inf
    value[["K"]] <- min(up * sqrt(3 / tau))
    method[["K"]] <- "upper bound (+1/2 region not reached)"
  }
  data.frame(term = c("N", "B", "K"), value = unname(value),
             unit = c(si_unit(sensor, "N"), si_unit(sensor, "rate"),
                      si_unit(sensor, "K")),
             tau = c(1, tau_b, 3), method = unname(method),
             stringsAsFactors = FALSE)
}

fit_se <- function(fit) {
  if (is.null(fit)) return(NULL)
  se <- fit$se
  if (is.null(se) && !is.null(fit$vcov)) {
    se <- sqrt(pmax(diag(as.matrix(fit$vcov)), 0))
    names(se) <- names(fit$coefficients)
  }
  se
}

white_like_gm <- function(coef) {
  j <- 1L
  out <- 0
  while (paste0("gm", j, ".sigma") %in% names(coef)) {
    sig <- coef[[paste0("gm", j, ".sigma")]]
    tc <- coef[[paste0("gm", j, ".tc")]]
    if (is.finite(tc) && tc < 0.1) out <- out + 2 * sig^2 * tc
    j <- j + 1L
  }
  out
}

# IEEE 952 slope-line readings. The local slope between successive taus;
# the line of slope -1/2 (+1/2) through the point whose slope is closest.
slope_readings <- function(tau, adev) {
  b_val <- min(adev) / sqrt(2 * log(2) / pi)
  n_val <- NA_real_
  k_val <- NA_real_
  if (length(tau) >= 2L) {
    s <- diff(log(adev)) / diff(log(tau))
    i <- which.min(abs(s + 0.5))
    if (abs(s[i] + 0.5) < 0.25) n_val <- adev[i] * sqrt(tau[i])
    j <- which.min(abs(s - 0.5))
    if (abs(s[j] - 0.5) < 0.25) k_val <- adev[j + 1L] * sqrt(3 / tau[j + 1L])
  }
  list(value = c(N = n_val, B = b_val, K = k_val),
       method = c(N = "slope -1/2 line", B = "min ADEV / 0.664",
                  K = "slope +1/2 line"))
}

as_record_list <- function(x, read_args) {
  if (inherits(x, "imu_record")) return(list(x))
  if (is.character(x)) {
    if (!length(x)) abort("`x` is an empty character vector; give file paths.")
    return(lapply(x, function(f) do.call(read_imu, c(list(f), read_args))))
  }
  if (is.list(x) && length(x) && all(vapply(x, inherits, logical(1), "imu_record"))) {
    nm <- names(x)
    if (!is.null(nm)) for (i in seq_along(x)) if (nzchar(nm[i])) x[[i]]$name <- nm[i]
    return(unname(x))
  }
  abort("`x` must be an imu_record (see read_imu() and imu_record()), a list ",
        "of them, or file paths; not ", describe_type(x), ".")
}

split_segments <- function(records, segment) {
  out <- list()
  for (r in records) {
    if (identical(segment, "each") && nrow(r$segments) > 1L) {
      for (i in seq_len(nrow(r$segments))) {
        s <- r
        s$data <- record_segment(r, i)
        s$name <- sprintf("%s[segment %d]", r$name, i)
        s$segments <- r$segments[i, , drop = FALSE]
        out[[length(out) + 1L]] <- s
      }
    } else {
      seg <- if (identical(segment, "each")) "longest" else segment
      s <- r
      s$data <- record_segment(r, seg)
      out[[length(out) + 1L]] <- s
    }
  }
  nm <- vapply(out, function(r) r$name, "")
  if (anyDuplicated(nm)) {
    for (i in seq_along(out)) out[[i]]$name <- sprintf("%s#%d", nm[i], i)
  }
  out
}

#' @export
print.imu_analysis <- function(x, ...) {
  cat(sprintf("<imu_analysis> %s: %d channels, %d samples at %.6g Hz (%.3g h)\n",
              x$name, length(x$channels), x$n, x$freq, x$duration / 3600))
  if (nrow(x$record$problems)) {
    cat("record problems: ", paste(x$record$problems$type, collapse = ", "),
        " (see $record$problems)\n", sep = "")
  }
  print(x$datasheet)
  g <- unlist(lapply(x$channels, function(cc) if (length(cc$guidance))
    paste0(cc$channel, ": ", cc$guidance)))
  if (length(g)) {
    cat("\nGuidance:\n")
    cat(paste0("  - ", g, "\n"), sep = "")
  }
  invisible(x)
}

#' @export
print.imu_analysis_list <- function(x, ...) {
  cat(sprintf("<imu_analysis_list> %d recordings\n\n", length(x)))
  for (a in x) {
    print(a)
    cat("\n")
  }
  invisible(x)
}

#' Plot the Allan deviation of an IMU analysis
#'
#' One panel per sensor (gyroscope, accelerometer): the Allan deviation of
#' every axis with its confidence band, the fitted model (dashed), and
#' markers where the datasheet values were read: N on the -1/2 line at
#' tau = 1 s (circle), B at the flat minimum, plotted at 0.664 B (triangle),
#' K on the +1/2 line at tau = 3 s (square). A legend explains colours and
#' markers; axes are labelled with units.
#'
#' @param x An `imu_analysis` from [analyze_imu()].
#' @param sensor `NULL` for every sensor present, or `"gyro"` / `"accel"`.
#' @param units `"SI"` (rad/s, m/s^2) or `"datasheet"` (deg/h, ug).
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
plot.imu_analysis <- function(x, sensor = NULL, units = c("SI", "datasheet"), ...) {
  units <- match.arg(units)
  sensors <- unique(vapply(x$channels, function(cc) cc$sensor, ""))
  if (!is.null(sensor)) sensors <- intersect(sensors, match_sensor(sensor))
  if (!length(sensors)) abort("no ", sensor, " channels in this analysis.")
  if (length(sensors) > 1L) {
    op <- graphics::par(mfrow = c(1L, length(sensors)))
    on.exit(graphics::par(op))
  }
  for (s in sensors) plot_sensor(x, s, units, ...)
  invisible(x)
}

plot_sensor <- function(x, s, units, ...) {
  chans <- Filter(function(cc) cc$sensor == s, x$channels)
  u <- if (units == "SI") si_unit(s, "rate") else if (s == "gyro") "deg/h" else "ug"
  k <- convert_units(1, si_unit(s, "rate"), u)
  cols <- grDevices::hcl.colors(max(3L, length(chans)), "Dark 3")[seq_along(chans)]
  rng_x <- range(unlist(lapply(chans, function(cc) cc$curve$tau)))
  rng_y <- range(unlist(lapply(chans, function(cc) {
    v <- c(cc$curve$adev, cc$curve$lower, cc$curve$upper)
    rd <- cc$readings
    v <- c(v, rd$value[rd$term == "N"],
           rd$value[rd$term == "B"] * sqrt(2 * log(2) / pi))
    if (!grepl("upper bound", rd$method[rd$term == "K"])) {
      v <- c(v, rd$value[rd$term == "K"])
    }
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
    rd <- chans[[i]]$readings
    n <- rd$value[rd$term == "N"]
    b <- rd$value[rd$term == "B"]
    kk <- rd$value[rd$term == "K"]
    if (is.finite(n)) {
      graphics::lines(rng_x, n / sqrt(rng_x) * k, col = cols[i], lty = 3)
      graphics::points(1, n * k, pch = 21, bg = cols[i], cex = 1.4)
    }
    if (is.finite(b)) {
      graphics::points(rd$tau[rd$term == "B"], b * sqrt(2 * log(2) / pi) * k,
                       pch = 24, bg = cols[i], cex = 1.4)
    }
    if (is.finite(kk) && !grepl("upper bound", rd$method[rd$term == "K"])) {
      graphics::lines(rng_x, kk * sqrt(rng_x / 3) * k, col = cols[i], lty = 3)
      graphics::points(3, kk * k, pch = 22, bg = cols[i], cex = 1.4)
    }
  }
  graphics::legend("topright", bty = "n", cex = 0.75,
                   legend = c(vapply(chans, function(cc) cc$channel, ""),
                              "fitted model", "-1/2 and +1/2 lines",
                              "N: -1/2 line at tau = 1 s",
                              "B: flat minimum (ADEV = 0.664 B)",
                              "K: +1/2 line at tau = 3 s"),
                   col = c(cols, "black", "black", "black", "black", "black"),
                   lty = c(rep(1, length(chans)), 2, 3, NA, NA, NA),
                   pch = c(rep(20, length(chans)), NA, NA, 21, 24, 22),
                   pt.bg = "grey60")
}

#' @export
plot.imu_analysis_list <- function(x, ...) {
  for (a in x) plot(a, ...)
  invisible(x)
}
