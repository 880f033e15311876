# Input normalisation for the fit: every kind of Allan variance curve the
# package accepts becomes one `av_curve` object.

#' One Allan variance curve from any input
#'
#' Turns the curves [avfit()] accepts into one object: the points (tau,
#' cluster size, Allan variance, EDF when known) and what the fit needs to
#' know about the record (sampling frequency, number of samples, phase
#' points, estimator).
#'
#' `av` may be
#' * the result of [allan()] (one channel, or choose one with `channel`);
#'   its `freq`, `N`, `type`, `input` and `edf` are used. Only the
#'   overlapping and standard (non-overlapping) estimators are accepted;
#' * the result of [avar()], [avarn()] or [avari()] (columns `time`, `av`,
#'   `error`); `freq` is required, `n` is recovered from the `error` column
#'   (\eqn{1/\sqrt{2(n/m - 1)}}) when not given. avar() and avarn() are
#'   non-overlapping estimators, so `type` defaults to `"non-overlapping"`
#'   for such a table; give `type = "overlapping"` for avari() output;
#' * a plain data frame with columns `tau` (s) and `avar`, and optionally
#'   `edf`, computed elsewhere; without `edf`, give `n` and `freq` (the
#'   estimator is taken as overlapping unless `type` says otherwise);
#' * a previous [avfit()] result: its whole curve (before `tau_range`),
#'   with the EDF the fit used; when that EDF was derived from the fit's
#'   model, it is recomputed from the fitted model at every point
#'   (`edf_source = "previous"`), so that fits of other models to this
#'   curve have comparable likelihoods (AIC, BIC). `n`, `freq`, `type` and
#'   `channel` cannot be given with a fit: they are the fit's.
#'
#' Points with a non-positive or non-finite tau, Allan variance or EDF are
#' dropped; without an EDF, so are points whose cluster size exceeds half
#' the record.
#'
#' @param av The Allan variance curve (see Details).
#' @param n Number of samples of the record (needed for the EDF when `av`
#'   has none).
#' @param freq Sampling frequency in Hz (needed for the exact discrete term
#'   forms and the EDF).
#' @param type Estimator that produced `av`: `"overlapping"` or
#'   `"non-overlapping"`; `NULL` (default) takes it from the input
#'   (allan()'s type; non-overlapping for avar()/avarn() tables; overlapping
#'   for a plain table).
#' @param channel For a multi-channel `allan()` result, the channel to use.
#' @return An object of class `"av_curve"`: a list with `data` (data frame
#'   `tau`, `m` (cluster size, NA without `freq`), `avar`, `edf` (NA when it
#'   is to be derived from the model)), `freq`, `n`, `L` (phase points: n + 1
#'   for rate input), `type`, `edf_source` (`"input"`, `"model"` or
#'   `"previous"`) and `source` (what `av` was).
#' @seealso [avfit()]
#' @export
#' @examples
#' x <- avsim(1e4, freq = 100, N = 0.01, seed = 1)
#' as_av_curve(allan(x, 100))
#' as_av_curve(avar(x, 100), freq = 100)
#' as_av_curve(data.frame(tau = c(0.01, 0.1, 1), avar = c(1, 0.1, 0.01)),
#'             n = 1e4, freq = 100)
as_av_curve <- function(av, n = NULL, freq = NULL, type = NULL, channel = NULL) {
  check_present(missing(av), "av", "an Allan variance curve")
  if (inherits(av, "av_curve")) return(av)
  if (inherits(av, "avfit")) {
    given <- c(n = !is.null(n), freq = !is.null(freq), type = !is.null(type),
               channel = !is.null(channel))
    if (any(given)) {
      abort("`", names(given)[given][1], "` cannot be given with a previous ",
            "fit: the fit's curve carries its own n, freq and type.",
            class = "argument")
    }
    return(curve_of_fit(av))
  }
  if (!is.null(freq)) freq <- check_freq(freq)
  if (!is.null(n)) n <- check_number(n, "n", lo = 2, integer = FALSE)
  edf <- NULL
  L <- NULL
  # A curve of several channels (allan() of a matrix, another tool's curve):
  # one channel is fitted, never a mixture of them.
  if (is.data.frame(av) && "channel" %in% names(av)) {
    chans <- unique(as.character(av$channel))
    if (is.null(channel)) {
      if (length(chans) > 1L) {
        abort("`av` holds ", length(chans), " channels (",
              paste(chans, collapse = ", "), "); choose one with `channel`.",
              class = "argument")
      }
      channel <- chans[1]
    }
    if (!is.character(channel) || length(channel) != 1L || !channel %in% chans) {
      abort("`channel` must be one of ", paste(chans, collapse = ", "), ".",
            class = "argument")
    }
    keep <- as.character(av$channel) == channel
    av <- av[keep, , drop = FALSE]
    if (anyDuplicated(av$tau[is.finite(av$tau)])) {
      abort("`av` repeats averaging times within channel \"", channel,
            "\": give one curve per channel.", class = "curve")
    }
  }
  if (inherits(av, "tool_curve") && is.null(freq) && !is.null(attr(av, "freq"))) {
    freq <- check_freq(attr(av, "freq"))
  }
  if (inherits(av, "allan")) {
    if (is.null(freq)) freq <- attr(av, "freq")
    if (is.null(n)) n <- attr(av, "N")
    if (is.null(type) && !is.null(attr(av, "type"))) type <- attr(av, "type")
    if (identical(attr(av, "input"), "integrated") && !is.null(n)) L <- n
    tau <- av$tau
    avv <- av$avar
    if ("edf" %in% names(av)) edf <- av$edf
    source <- "allan"
  } else if (is.data.frame(av) && all(c("time", "av", "error") %in% names(av))) {
    if (is.null(freq)) {
      abort("`freq` is needed with an avar()/avarn()/avari() table: give the ",
            "sampling frequency in Hz.", class = "argument")
    }
    if (is.null(type)) type <- "non-overlapping"
    tau <- av$time
    avv <- av$av
    if (is.null(n)) {
      m <- round(tau * freq)
      nn <- m * (1 / (2 * av$error^2) + 1)
      nn <- nn[is.finite(nn)]
      if (!length(nn)) {
        abort("`n` is needed: it cannot be recovered from `av$error`.",
              class = "argument")
      }
      n <- round(stats::median(nn))
    }
    source <- "avar table"
  } else if (is.data.frame(av) && all(c("tau", "avar") %in% names(av))) {
    tau <- av$tau
    avv <- av$avar
    if ("edf" %in% names(av)) edf <- av$edf
    source <- "table"
  } else {
    abort("`av` must be an allan() result, an avar()/avarn()/avari() data ",
          "frame (columns time, av, error) or a data frame with columns tau ",
          "and avar, not ", describe_type(av),
          if (is.data.frame(av)) paste0(" with columns ",
                                         paste(names(av), collapse = ", ")),
          ".", class = "curve")
  }
  type <- normalize_type(if (is.null(type)) "overlapping" else type)
  if (!is.numeric(tau) || !is.numeric(avv)) {
    abort("`av`: the tau and Allan variance columns must be numeric.",
          class = "curve")
  }
  if (!is.null(edf) && (!is.numeric(edf) || all(is.na(edf)))) edf <- NULL
  if (is.null(edf) && (is.null(n) || is.null(freq))) {
    abort("`n` and `freq` are needed when `av` has no `edf` column: give the ",
          "number of samples and the sampling frequency in Hz.",
          class = "argument")
  }
  ok <- is.finite(tau) & tau > 0 & is.finite(avv) & avv > 0
  if (!is.null(edf)) ok <- ok & is.finite(edf) & edf >= 1
  if (!all(ok) && any(ok)) {
    # An estimate rests on at least one degree of freedom: an EDF below 1
    # (or none) makes its weight and bias correction meaningless.
    low <- !is.null(edf) & is.finite(edf) & edf < 1
    warn(sum(!ok), " of ", length(ok), " point(s) of `av` left out of the fit: ",
         "tau, variance and EDF must be finite and positive",
         if (any(low)) paste0(", the EDF at least 1 (down to ",
                              format(signif(min(edf[low]), 3)), " here)"),
         ".", class = "points_dropped")
  }
  m <- if (is.null(freq)) rep(NA_real_, length(tau)) else tau * freq
  if (is.null(edf) && !is.null(n)) ok <- ok & m <= n / 2
  data <- data.frame(tau = tau[ok], m = m[ok], avar = avv[ok],
                     edf = if (is.null(edf)) rep(NA_real_, sum(ok)) else edf[ok])
  data <- data[order(data$tau), , drop = FALSE]
  rownames(data) <- NULL
  if (nrow(data) < 1L) {
    abort("`av` has no usable points (positive tau and avar).", class = "curve")
  }
  out <- new_av_curve(data, freq = freq, n = n,
                      L = if (is.null(L) && !is.null(n)) n + 1 else L, type = type,
                      edf_source = if (is.null(edf)) "model" else "input",
                      source = source)
  # The rate unit a curve carries (other tools' curves, in SI), for the
  # datasheet of a curve-only fit (R/analysis-fit.R).
  u <- if (is.data.frame(av) && is.character(av$unit)) unique(av$unit) else NULL
  if (length(u) == 1L && !is.na(u)) out$unit <- u
  ch <- if (is.data.frame(av) && !is.null(av$channel)) unique(as.character(av$channel))
  if (length(ch) == 1L && !is.na(ch)) out$channel <- ch
  out
}

new_av_curve <- function(data, freq, n, L, type, edf_source, source,
                         corr = NULL) {
  structure(list(data = data, freq = freq, n = n, L = L, type = type,
                 edf_source = edf_source, source = source, corr = corr),
            class = "av_curve")
}

# The curve a fit was made to (all its points, before tau_range), with the
# EDF it used: when that came from the model, from the fitted model.
curve_of_fit <- function(fit) {
  d <- fit$input
  if (!inherits(d, "av_curve")) {
    # a fit saved by an earlier version: its input is a plain list
    d <- new_av_curve(d$data, d$freq, d$n, if (is.null(d$n)) NULL else d$n + 1,
                      d$type, d$edf_source, "avfit")
  }
  if (identical(fit$edf_source, "model") || identical(d$edf_source, "model")) {
    tau0 <- if (is.null(d$freq)) NULL else 1 / d$freq
    d$data$edf <- edf_fit_model(d$data$m, d$n, d$type, d$data$tau, tau0,
                                fit$layout, d$L)
    d$edf_source <- "previous"
  }
  d$source <- "avfit"
  d
}

normalize_type <- function(type) {
  if (!is.character(type) || length(type) != 1L || is.na(type)) {
    abort("`type` must be \"overlapping\" or \"non-overlapping\", not ",
          describe_type(type), ".", class = "argument")
  }
  t <- tolower(type)
  if (t %in% c("overlapping", "oavar", "oadev")) return("overlapping")
  if (t %in% c("non-overlapping", "nonoverlapping", "standard", "avar", "adev"))
    return("non-overlapping")
  abort("`type` must be \"overlapping\" or \"non-overlapping\" (avfit fits the ",
        "Allan variance), not ", encodeString(type, quote = '"'), ".",
        class = "argument")
}

#' @export
print.av_curve <- function(x, ...) {
  d <- x$data
  cat(sprintf("<av_curve> %d points, tau %s to %s s, %s estimator (from %s)\n",
              nrow(d), format(signif(min(d$tau), 3)), format(signif(max(d$tau), 3)),
              x$type, x$source))
  cat(sprintf("n = %s, freq = %s Hz; EDF %s\n",
              if (is.null(x$n)) "unknown" else format(x$n, big.mark = ","),
              if (is.null(x$freq)) "unknown" else format(x$freq),
              switch(x$edf_source, input = "given with the curve",
                     model = "to be derived from the model",
                     previous = "from a previous fit's model")))
  invisible(x)
}
