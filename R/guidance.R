#' Is the record long enough? Guidance per axis
#'
#' Checks, for every axis of an analysis, whether the record resolves what
#' was asked and, when not, how long a record would be needed. The rules:
#' * **reliable range**: a tau is reliable when its Allan variance rests on
#'   at least 10 equivalent degrees of freedom (`edf` from [allan()]);
#'   `tau_rel` is the largest such tau. Taus beyond it are flagged ("a
#'   handful of terms").
#' * **K** (rate random walk, the +1/2 region): call `tau_x` the tau where
#'   the +1/2 line meets the rest of the model, i.e. where
#'   K^2 tau / 3 = N^2 / tau + (2 ln 2 / pi) B^2. K is read within the
#'   reliable range when `tau_rel >= 3 tau_x`. When it is not, and the record
#'   does not already give K to 25% by the exact bound, the record
#'   needed is the one whose exact Cramer-Rao bound gives K to 25% (relative
#'   standard deviation; [av_plan()] on the fitted model when all its terms
#'   have a state-space form: N, K, Gauss-Markov). Where the planner cannot
#'   run (no N, or a B, Q or other term without a state-space form in the
#'   model), the scaling `T * 3 tau_x / tau_rel` is given. When no +1/2
#'   region is seen at all, K is bounded by min over tau of upper(tau) *
#'   sqrt(3 / tau) and the record needed to resolve a K that large is given
#'   (smaller K need longer records).
#' * **B**: the flat minimum must lie inside the reliable range, at
#'   `tau_B <= tau_rel / 3`; otherwise the curve may still fall and B is an
#'   upper bound; a record at least `T * 3 tau_B / tau_rel` long is needed.
#' * **N**: a -1/2 region (or a fitted N) must exist.
#' * **any fitted term that is no reading** (a Gauss-Markov term, a line, a
#'   band) is reported when the fit does not determine each of its values
#'   within a factor 2 at 95% (1.96 standard errors of the log): the rule
#'   of the `verdict` column of [kalman_params()], over the values the fit
#'   estimated (a line's frequency held at the periodogram's is not judged
#'   here; there a held value makes the term not determined).
#' * **non-stationary effects** of the raw series (spikes/outliers, bias
#'   steps, warm-up, transients; [detect_series_effects()], run by [avrefine()]
#'   when it has the data, so by [analyze_imu()] with `refine = TRUE` or
#'   `remove`) that were left in the series: one line per kind with the
#'   count, the first times, the largest size in noise standard deviations,
#'   the change they make to the Allan deviation, and how to remove them.
#'
#' * **every reading whose verdict is not "measured"** (see [analyze_imu()],
#'   readings): the verdict and why.
#'
#' [analyze_imu()] runs these checks; printing the analysis lists them after
#' the datasheet.
#'
#' @param x An `imu_analysis` ([analyze_imu()]), or an [avfit()] of a curve
#'   alone (for example another tool's curve, [read_allan_variance_ros_curve()]), read as
#'   one axis.
#' @param unit For an `avfit`: the rate unit of the fitted curve (`"rad/s"`,
#'   `"deg/s"`, `"m/s^2"`, ...; see [av_units()]); `NULL` takes the unit the
#'   curve carried (curves of other tools are SI), else values stay in the
#'   input's unit.
#' @return A data frame with columns `record`, `channel`, `message` (empty
#'   when every check passes).
#' @export
#' @examples
#' \donttest{
#' set.seed(1)
#' m <- cbind(gyro_x = rnorm(5000, sd = 0.01))
#' a <- suppressWarnings(analyze_imu(imu_record(m, freq = 100),
#'                                   refine = FALSE, progress = FALSE))
#' imu_guidance(a)
#' }
imu_guidance <- function(x, unit = NULL) {
  if (inherits(x, "imu_analysis")) {
    rows <- lapply(x$channels, function(ch) {
      if (!length(ch$guidance)) return(NULL)
      data.frame(record = x$name, channel = ch$channel, message = ch$guidance,
                 stringsAsFactors = FALSE)
    })
    rows <- rows[!vapply(rows, is.null, logical(1))]
    if (!length(rows)) {
      return(data.frame(record = character(), channel = character(),
                        message = character()))
    }
    out <- do.call(rbind, rows)
    rownames(out) <- NULL
    return(out)
  }
  if (inherits(x, "imu_analysis_list")) {
    out <- do.call(rbind, lapply(x, imu_guidance))
    rownames(out) <- NULL
    return(out)
  }
  if (inherits(x, "avfit")) {
    return(imu_guidance(fit_analysis(x, unit = unit)))
  }
  if (is.list(x) && !is.null(x$curve) && !is.null(x$readings)) {
    return(channel_guidance(x))
  }
  abort("`x` must be an imu_analysis or an avfit, not ", describe_type(x), ".",
        class = "argument")
}

channel_guidance <- function(ch) {
  cv <- ch$curve
  # A curve read from another tool may come without its record length.
  T <- if (length(ch$n) == 1L && length(ch$freq) == 1L) ch$n / ch$freq else NA_real_
  msg <- character()
  hours <- function(s) {
    if (!is.finite(s)) "? (the record length is not known)" else if (s >= 3600) sprintf("%.3g h", s / 3600)
    else sprintf("%.4g s", s)
  }
  edf <- cv$edf
  rel <- if (is.null(edf) || all(is.na(edf))) {
    if (is.finite(T)) cv$tau <= T / 10 else rep(TRUE, length(cv$tau))
  } else {
    !is.na(edf) & edf >= 10
  }
  if (!any(rel)) {
    return(sprintf("no tau has 10 degrees of freedom: the record (%s) is too short for any reading.",
                   hours(T)))
  }
  tau_rel <- max(cv$tau[rel])
  few <- cv$tau > tau_rel
  if (any(few)) {
    msg <- c(msg, sprintf(
      "the %d largest tau (%s to %s) rest on fewer than 10 degrees of freedom (edf down to %.2g): do not read terms from them alone.",
      sum(few), hours(min(cv$tau[few])), hours(max(cv$tau[few])),
      if (is.null(edf)) NA else min(edf[few], na.rm = TRUE)))
  }
  rd <- ch$readings
  white <- reading_of(rd, "white")
  flat <- reading_of(rd, "flicker")
  walk <- reading_of(rd, "random_walk")
  N <- white$value
  B <- flat$value
  K <- walk$value
  n2 <- if (isTRUE(is.finite(N))) N^2 else 0
  b2 <- if (isTRUE(is.finite(B))) B^2 else 0
  need <- function(tau) T * 3 * tau / tau_rel
  # readings whose record-length note below already says why they are not
  # measured (their verdict line is not repeated)
  said <- character()
  if (identical(walk$source, "bound")) {
    tx <- tau_cross(n2, b2, K)
    said <- c(said, walk$term)
    msg <- c(msg, sprintf(
      "the +1/2 (rate random walk) region is never reached up to tau = %s: K <= %.3g %s only; resolving a K that large needs a record of at least %s (this one is %s), a smaller K a longer one.",
      hours(tau_rel), K, walk$unit, hours(need_k(ch, white, walk, tx, need)), hours(T)))
  } else if (isTRUE(is.finite(K) && K > 0)) {
    tx <- tau_cross(n2, b2, K)
    nk <- need_k(ch, white, walk, tx, need)
    # the exact bound says when this record already gives K to 25%
    if (tau_rel < 3 * tx && !isTRUE(nk <= T)) {
      said <- c(said, walk$term)
      msg <- c(msg, sprintf(
        "K = %.3g %s is read beyond the reliable range: the +1/2 line meets the rest at tau = %s, so tau up to %s (a record of %s) is needed; this record is %s.",
        K, walk$unit, hours(tx), hours(3 * tx), hours(nk), hours(T)))
    }
  }
  tau_b <- flat$tau
  if (isTRUE(is.finite(tau_b) && tau_b > tau_rel / 3)) {
    said <- c(said, flat$term)
    msg <- c(msg, sprintf(
      "the Allan deviation minimum (tau = %s) is not inside the reliable range (up to %s / 3): B = %.3g %s may be an overestimate of the flat region; a record of at least %s is needed (this one is %s).",
      hours(tau_b), hours(tau_rel), B, flat$unit,
      hours(need(tau_b)), hours(T)))
  }
  if (!isTRUE(is.finite(N))) {
    msg <- c(msg, "no -1/2 (white noise) region found: N not read; a higher sampling rate shows more of the short-tau region.")
  }
  # Every other reading the data do not support as measured, with why.
  judged <- rd[rd$verdict != "measured" & rd$source %in% c("fit", "slope") &
                 nzchar(rd$why) & !rd$term %in% said, , drop = FALSE]
  msg <- c(msg, sprintf("%s = %.3g %s is %s: %s.", judged$term, judged$value,
                        judged$unit, verdict_phrase(judged$verdict), judged$why))
  # Every fitted term that is no reading, by the rule of kalman_params()'
  # verdicts (its values within a factor 2 at 95%)
  nd <- undetermined_own_terms(ch, rd)
  msg <- c(msg, sprintf("term %s is %s from this record: %s.", names(nd),
                        verdict_phrase(vapply(nd, `[[`, "", "verdict")),
                        vapply(nd, `[[`, "", "why")))
  msg <- c(msg, series_guidance(if (!is.null(ch$series)) ch$series else ch$fit$series,
                                hours))
  if (!is.null(ch$fit_error)) {
    msg <- c(msg, paste0("fit not used (", ch$fit_error,
                         "): values read from the slope lines."))
  }
  msg
}

# The record (s) that gives K to 25% by the exact Cramer-Rao bound
# (av_plan() on the fitted model, N and K taken from the readings); the
# scaling of the reliable range where the model has a term without a
# state-space form (B, Q, ...) or no N.
need_k <- function(ch, white, walk, tx, need) {
  set <- c(white$value, walk$value)
  names(set) <- c(white$term, walk$term)
  rd <- ch$readings
  others <- rd$value[!rd$term %in% names(set)]
  s <- if (length(set) == 2L && all(is.finite(set) & set > 0) && length(ch$freq) == 1L &&
           !any(is.finite(others) & others > 0)) {
    plan_record_length(ch$coef %||% numeric(), ch$freq, set, walk$term, 0.25)
  } else NA_real_
  if (is.finite(s)) s else need(tx)
}

# One line per kind of non-stationary effect (spikes, steps, ...) found in
# the raw series and left in it: how many, where, how large, what it does
# to the Allan deviation, and how to take it out. The words come from the
# catalogue entry.
series_guidance <- function(se, hours) {
  if (is.null(se) || !NROW(se$table)) return(character())
  tab <- se$table[!se$table$removed, , drop = FALSE]
  # a kind that changes the Allan deviation by less than 1% anywhere
  # changes no reading: not worth a line
  ak <- se$adev_kinds
  matters <- vapply(unique(tab$kind), function(kind) {
    ch <- ak$change[ak$kind == kind]
    any(is.finite(ch) & abs(ch) >= 0.01)
  }, logical(1))
  tab <- tab[tab$kind %in% unique(tab$kind)[matters], , drop = FALSE]
  vapply(unique(tab$kind), function(kind) {
    k <- tab[tab$kind == kind, , drop = FALSE]
    at <- paste0(vapply(utils::head(k$time, 3L), hours, ""), collapse = ", ")
    if (nrow(k) > 3L) at <- paste0(at, ", ...")
    ch <- se$adev_kinds[se$adev_kinds$kind == kind, , drop = FALSE]
    worst <- if (nrow(ch) && any(is.finite(ch$change)))
      which.max(abs(replace(ch$change, !is.finite(ch$change), 0))) else NA_integer_
    effect <- if (is.na(worst)) "" else sprintf(
      "; left in, they change the Allan deviation by up to %+.0f%% (at tau = %s)",
      100 * ch$change[worst], hours(ch$tau[worst]))
    z <- abs(k$z[is.finite(k$z)])
    size <- if (length(z)) sprintf("; up to %.3g standard deviations", max(z)) else ""
    sprintf("%d x %s in the raw series (at %s%s)%s: take them out with remove = \"%s\" (command line: --remove %s).",
            nrow(k), effect_entry(kind)$title, at, size, effect, kind, kind)
  }, "", USE.NAMES = FALSE)
}

# tau where K^2 tau / 3 = N^2 / tau + (2 ln2 / pi) B^2 (positive root).
tau_cross <- function(n2, b2, K) {
  a <- K^2 / 3
  c0 <- 2 * log(2) / pi * b2
  (c0 + sqrt(c0^2 + 4 * a * n2)) / (2 * a)
}

# The guidance as printed: one line per message, the axes that share it
# named together.
guidance_lines <- function(g) {
  g <- g[nzchar(g$message), , drop = FALSE]
  if (!nrow(g)) return(character())
  msgs <- unique(g$message)
  vapply(msgs, function(m) paste0(paste(unique(g$channel[g$message == m]), collapse = ", "),
                                  ": ", m), "", USE.NAMES = FALSE)
}
