# The closed loop's entry point: avrefine(), its argument checks and print
# method. The loop runs as named stages over one state (R/refine-stages.R,
# R/refine-state.R); a candidate's trial is in R/refine-screen.R, the
# refits in R/refine-refits.R, the rules in R/refine-rules.R and the raw
# diagnostics in R/refine-diagnostics.R. The residual signatures
# (signatures.R), the tracing to candidates (trace.R) and the raw-data
# evidence (evidence.R) come from their own files; every fact about an
# effect comes from the catalogue.

#' Close the loop: find what a noise model misses and add it
#'
#' Starting from a fitted noise model (typically the datasheet model
#' `terms = c("N", "B", "K")`), repeatedly:
#' 1. finds structure in the standardized residuals (a localized bump, an
#'    oscillation with nulls, a run at the short- or long-tau end, a slope)
#'    and its tau range;
#' 2. traces it to the effects whose Allan-deviation signature matches
#'    (a Gauss-Markov bump peaks at \eqn{\tau = 1.893 T_c}; a sinusoid's
#'    first peak is at \eqn{0.371/f_0} with nulls at \eqn{k/f_0};
#'    quantization grows with slope \eqn{-1} at short tau; a ramp with slope
#'    \eqn{+1} and rate random walk with \eqn{+1/2} at long tau; flicker is
#'    flat) and reads initial parameters from it; when the raw series is
#'    given, looks for the same effect in the data (a periodogram line at
#'    \eqn{f_0}, an exponential autocorrelation with \eqn{T_c}, an LSB grid
#'    and a lag-1 autocorrelation near \eqn{-1/2}, a linear trend);
#' 3. adds each candidate effect, refits with [avfit()], and keeps the best
#'    one only if it pays by the information criterion (a decrease of at
#'    least `min_gain`) and lowers \eqn{\chi^2} per degree of freedom by at
#'    least 10 percent;
#' 4. repeats until nothing pays or `max_steps` effects were added;
#' 5. judges each effect it added again on the final model: one whose
#'    removal raises the criterion by less than `min_gain` leaves it (a
#'    greedy step can take an effect that the model does without once a
#'    later one describes the same part of the curve). The two instances
#'    of a split are judged together; effects whose values the raw data
#'    measure (a periodogram line's frequency, a measured band's spectrum)
#'    and the filter are not judged by the curve alone. One that the
#'    refits after its step moved to where it stands in for a series effect
#'    left in the data (the rule that refuses such a candidate) leaves too,
#'    whatever it gains; an effect its removal sizes off what the raw data
#'    measure is then held there.
#'
#' The rules of acceptance:
#' * Candidates are compared by the criterion, not gated by a residual
#'   threshold: with no residual signature left, every candidate is still
#'   tried (the screening pass; everything free only for a further
#'   Gauss-Markov process beside one the model holds, whose one-term
#'   compromise held would keep a second from paying).
#' * An effect the raw data contradict is never accepted, nor an instance
#'   the catalogue declares not valid on this curve (a Gauss-Markov process
#'   with \eqn{T_c} below 2 samples is the sensor's filter; a sinusoid outside
#'   the band the curve can see, \eqn{1/\tau_{max}} to
#'   \eqn{1/(2\tau_{min})}, or above Nyquist). Both are listed in
#'   `$refine$rejected`.
#'   A Gauss-Markov process of a few samples must also keep its
#'   correlation at lag 2, as a filter of a sample or two does not.
#'   Conversely the sensor filter's two-pole form (`filter:ar2`) must be
#'   seen beyond lag 1: beside the model's other terms, its own steps of
#'   the raw autocovariance at lags 2-3 must improve their fit by the
#'   chi-square's 0.999 point and leave at most a quarter of the misfit.
#' * An effect whose raw-data check neither confirms nor contradicts it (a
#'   Gauss-Markov whose fitted \eqn{T_c} is 2-3 times the one the ACF of
#'   block means reads) must lower the criterion by `2 * min_gain` on the
#'   curve alone: a marginal gain there moves with whatever reshapes the
#'   rest of the curve (listed in `$refine$rejected` otherwise).
#' * An effect may replace a term (the catalogue's `replaces`): the filter
#'   term replaces `N`, whose value it carries as its DC level.
#' * A sinusoid proposed by a periodogram line keeps the line's frequency
#'   (the periodogram measures it far better than the curve) and is matched
#'   to lines within the periodogram's resolution. Raw-data checks of the
#'   other effects see the series with the significant lines removed. Its
#'   check confirms it when the line carries the amplitude the curve fits,
#'   within a factor 3 either way (far weaker on the curve: undecided).
#' * A further line of a harmonic set whose stronger lines the model holds
#'   adds no new source: confirmed by the raw data, it is kept unless it
#'   costs the criterion more than `min_gain` (the worth of that support);
#'   otherwise the criterion must prefer it. Where the line holds one
#'   frequency over the whole record (its least-squares sinusoid carries at
#'   least 0.8 of the periodogram line's amplitude, as a square wave's
#'   harmonics do and an axis's wandering lines do not), its amplitude is
#'   held at the periodogram's too: on the curve a further harmonic takes
#'   the power of the set's lines not yet in the model, and of a resonance
#'   beside them.
#' * What no catalogue effect explains is reported in `$unexplained`, not
#'   papered over; a reading whose tau range meets such a run is not
#'   "measured" (a bound or not determined, its `why` naming the run).
#'   When a run at the short-tau end stays unexplained, the model is
#'   refitted from the first tau after it (a message says so and
#'   `$refine$tau_range` records it), so that points the model cannot
#'   describe do not drive `N` to 0 or bend the long-tau terms.
#' * Without raw data, `$refine$unconfirmed` lists the accepted effects that
#'   could not be confirmed.
#' * With raw data, the series' non-stationary effects (steps, warm-up,
#'   spikes) are read first by [detect_series_effects()],
#'   kept in `$series`, and removed from the data only when named in
#'   `remove`.
#'
#' For speed, candidates are first screened with the nonlinear parameters
#' already in the model (`tc`, `f0`) held at their current values, and the
#' winner is refitted with all of them free (where that refit breaks an
#' effect accepted earlier, with each earlier term's values freed alone,
#' the best taken; the values the last step held are freed so in one last
#' refit, and those that stay held are marked "held" in the report); only
#' when screening finds nothing are the candidates tried again with
#' everything free. Every refit
#' starts from the current model's nonlinear estimates and uses its
#' settings (`bias_correct`, `correlation`, `control`, and its EDF), given
#' to [avfit()] explicitly; arguments in `...` override them.
#'
#' A refit that fails (an error, or no degrees of freedom left) does not
#' stop the loop: it is recorded as a condition of class
#' `allanvar_error_refit` (the original condition in its `parent`) in
#' `$refine$failures`, with the step and the candidate; warnings raised by
#' refits are recorded there too.
#'
#' Every candidate kind in `candidates` that is not already in the model
#' (gm and sinusoid may repeat) is refitted at each step; the residual
#' signature and the raw data supply the initial values, the tau range and
#' the evidence. Candidates traced from a signature (or proposed by the raw
#' data) are tried first, the others only when none of those pays. Among
#' the candidates that pay, the one with the lowest criterion wins, where
#' raw-data support counts as a gain of `min_gain`. A candidate the raw data
#' contradict is not accepted (see `$refine$rejected`), so `confirmed` is
#' never `FALSE` for a step of this loop.
#'
#' When nothing pays, the forms of a family (the sensor filter's) are
#' chosen again on the current model, compared on the curve without the
#' sharp lines the model does not hold yet (their frequencies and
#' amplitudes are the periodogram's and the record's: a first-order
#' low-pass mimics the bumps of a square wave's harmonics not yet in);
#' when none pays alone and the model is
#' still far from the curve (\eqn{\chi^2} per degree of freedom above 4),
#' each trial of that step the raw data refused at values it pins is
#' refitted beside each other form, everything free, and the best such pair
#' enters when it pays, the trial is confirmed and the new form is not
#' contradicted (a first-order low-pass taken for the bump of a line can
#' carry half a resonance, which the raw data then refuse at the power the
#' curve gives it).
#'
#' The greedy order can lock in the weaker of two explanations (a short
#' Gauss-Markov term taken at the first step for the bump of a line the
#' periodogram shows plainly). When the loop ends far from the curve
#' (\eqn{\chi^2} per degree of freedom above 4) after taking values the raw
#' data measure (a line's frequency, a band's spectrum) at steps behind
#' effects that measured nothing, or after refusing such values because they
#' would move an earlier effect to values the raw data contradict, it runs
#' once more from the start with those values taken first,
#' by the same rules, and keeps the run with the lower criterion (with a
#' message; `$refine$revisit` compares the two).
#'
#' @param fit An [avfit()] result.
#' @param data Optional raw rate series (numeric vector or `ts`) at the
#'   fit's sampling frequency, used to confirm effects from the data itself.
#' @param candidates Effects that may be added: terms of the catalogue
#'   ([av_terms()]); default all of them.
#' @param max_steps Maximum number of effects to add. A further line of a
#'   harmonic set already in the model is not counted (at most 10 of
#'   those): it adds no new source; nor is a step that only chooses a
#'   family's form again (the filter's, at most 2 of those): it adds no
#'   effect.
#' @param criterion `"BIC"` (default) or `"AIC"`.
#' @param min_gain Minimum decrease of the criterion for an effect to be
#'   kept (10 is "very strong" evidence on the BIC scale; adjacent taus of
#'   an overlapping Allan variance are correlated, so small gains are
#'   not trusted).
#' @param level Strength, in standard deviations, a residual run must reach
#'   to count as structure.
#' @param remove Series effects to take out of `data` before the loop (kinds
#'   of the catalogue's series components); never done unless asked.
#' @param series `NULL`, or the [detect_series_effects()] result that produced
#'   `data` (its cleaned series `series$x`), when that pass has already been
#'   run (as [analyze_imu()] does when asked to `remove` effects before the
#'   curve): it is kept in `$series` instead of running the pass again.
#'   Give `remove` or `series`, not both.
#' @param ... Passed to [avfit()] on each refit.
#' @return The refined `avfit` object. Its `steps` data frame has one row
#'   per accepted step with columns `effect` (as named in [avsim()]),
#'   `label` (the coefficient prefix, e.g. `gm1`), `tau_from`, `tau_to`
#'   (the tau range of the residual signature, s), `params` (the added
#'   effect's fitted parameters), `evidence` (the residual signature and the
#'   raw-data evidence), `confirmed` (`TRUE`/`FALSE` when the raw data
#'   support/contradict the effect, `NA` when not given or not decidable),
#'   `chi2_before`, `chi2_after` (\eqn{\chi^2} per degree of freedom),
#'   `rms_before`, `rms_after` (RMS relative ADEV error, percent),
#'   `crit_before`, `crit_after` (the criterion). `refine` holds the
#'   arguments, the raw-data diagnostics ([avdiagnose()]) and the
#'   signatures left when the loop stopped and `failures` (a data frame
#'   `step`, `effect`, `stage`, `message`, with the conditions in the list
#'   column `condition`), `rejected` (step, effect, params, reason; an
#'   instance the final model holds at amplitude 0, or does without (point
#'   5 above), is left out and listed here, its step's `label` then reads
#'   `"left:"` and the old label and its `evidence` says why; one
#'   the final model sizes far off what the raw data measure, a sinusoid
#'   below a third or above 3 times its periodogram line's amplitude or a
#'   resonance more than twice as narrow or as wide as its spectral band
#'   (held at the band's centre and width), is
#'   first held at the raw data's value (fixed in `layout`) when that
#'   costs the criterion less than `min_gain` and no effect loses its
#'   raw-data support, and its step's `evidence` says so),
#'   `series_duplicates` (the rejected terms that would have described a
#'   series effect of this run again, which was left in the data: step,
#'   effect, params, `series_kind`, `ratio` = the AV that series effect
#'   adds over the term's own AV, at `tau`, `how`: `"share"` when that
#'   ratio is 1 or more, `"refit"` when the term no longer pays on the
#'   curve with the effect's excess taken out (by `2 * min_gain` for a
#'   term the raw data leave undecided); the readings of such a run
#'   carry that series effect's bias, see [series_reading_bias()]),
#'   `unconfirmed` (labels), `tau_range` (NULL or the automatic range),
#'   `revisit` (NULL, or when the greedy order was revisited a data frame
#'   `order`, `terms`, `chi2`, `criterion`, `kept`, one row per run),
#'   `alternatives` (NULL, or the effects the raw data confirm that the
#'   final model lacks though the curve prefers it with them, by less
#'   than `min_gain` when the steps ended: a data frame `effect`, `label`,
#'   `params`, `gain` (the criterion's fall with it, beside the final
#'   model), `evidence`, `chi2`; at most 3), `alternative_coefs` (their
#'   models' coefficients; a reading one of them reads 25% or more lower
#'   is an upper bound, higher not determined, with the reason in the
#'   readings' `why`) and `removed`. `unexplained` is a data frame (kind, tau_from, tau_to,
#'   strength in sigma, size = largest ADEV error inside in percent,
#'   description) and `series` the series pass (or NULL) without its
#'   cleaned series `x` (the result does not carry a copy of the data). The object keeps
#'   class `avfit`
#'   (with `avrefine` in front, whose print method lists the steps), so
#'   every avfit method applies.
#' @seealso [avfit()], [avdiagnose()], [avsim()]
#' @export
#' @examples
#' # White noise plus a Gauss-Markov process, fitted as white noise only:
#' x <- avsim(3e4, 100, N = 0.01, gm = list(sigma = 0.01, tc = 1), seed = 1)
#' fit <- avfit(allan(x, 100, taus = 5), terms = "N")
#' ref <- avrefine(fit, candidates = c("gm", "K"), max_steps = 1)
#' ref$steps[, c("effect", "params", "chi2_before", "chi2_after")]
avrefine <- function(fit, data = NULL, candidates = effect_kinds(),
                     max_steps = 8, criterion = "BIC", min_gain = 10,
                     level = 3.5, remove = character(), series = NULL, ...) {
  check_present(missing(fit), "fit", "an avfit() result")
  args <- check_refine_args(fit, data, candidates, max_steps, criterion,
                            min_gain, level, remove, series)
  st <- new_refine_state(fit, args, refit_settings(fit, list(...)))
  # the refits share the basis columns they build (R/coef.R)
  call_store_open(basis_store)
  on.exit(call_store_close(basis_store, "slots"), add = TRUE)
  # and each refit is made once (R/refine-refits.R)
  call_store_open(refit_memo)
  on.exit(call_store_close(refit_memo, "entries"), add = TRUE)
  # the stages in order (R/refine-stages.R), each taking and returning the state
  for (stage in refine_stages()) st <- validate_refine_state(stage(st))
  st$result
}

# avrefine()'s arguments checked once: a list of the clean values (`data`
# as a plain double vector, or NULL) and the fit's sampling frequency.
check_refine_args <- function(fit, data, candidates, max_steps, criterion,
                              min_gain, level, remove, series) {
  if (!inherits(fit, "avfit")) {
    abort("`fit` must be an avfit() result, not ", describe_type(fit), ".",
          class = "argument")
  }
  validate_avfit(fit, arg = "fit")
  kinds <- effect_kinds()
  if (!is.character(candidates) || !length(candidates) || anyNA(candidates) ||
      !all(candidates %in% kinds)) {
    abort("`candidates` must name effects among ", paste(kinds, collapse = ", "),
          ", not ", if (is.character(candidates))
            paste(encodeString(setdiff(candidates, kinds), quote = '"'), collapse = ", ")
          else describe_type(candidates), ".", class = "argument")
  }
  candidates <- unique(candidates)
  max_steps <- check_number(max_steps, "max_steps", 0, 50, integer = TRUE)
  if (!is.character(criterion) || length(criterion) != 1L ||
      !criterion %in% c("BIC", "AIC")) {
    abort("`criterion` must be \"BIC\" or \"AIC\", not ", format_value(criterion), ".",
          class = "argument")
  }
  min_gain <- check_number(min_gain, "min_gain", 0)
  level <- check_number(level, "level", 0, open = TRUE)
  freq <- fit$freq
  remove <- check_remove(remove)
  if (length(remove) && is.null(data)) {
    abort("`remove` needs the raw series: give `data`.", class = "argument")
  }
  if (!is.null(series)) {
    if (!inherits(series, "series_effects")) {
      abort("`series` must be a detect_series_effects() result or NULL, not ",
            describe_type(series), ".", class = "argument")
    }
    if (is.null(data)) {
      abort("`series` needs the series it produced: give `data = series$x`.",
            class = "argument")
    }
    if (length(remove)) {
      abort("Give `remove` or `series`, not both: `series` has already removed ",
            "what it was asked to.", class = "argument")
    }
  }
  if (!is.null(data)) data <- check_refine_data(data, freq, series)
  list(candidates = candidates, max_steps = max_steps, criterion = criterion,
       min_gain = min_gain, level = level, remove = remove, data = data,
       series = series, freq = freq)
}

# The raw series of avrefine(): at the fit's sampling frequency, and the
# very series a given detect_series_effects() pass left.
check_refine_data <- function(data, freq, series) {
  if (stats::is.ts(data) && !is.null(freq) &&
      abs(stats::frequency(data) - freq) > 1e-6 * freq) {
    abort("`data` is a ts at ", stats::frequency(data), " Hz but the fit is at ",
          freq, " Hz; give the raw series the curve was computed from.",
          class = "argument")
  }
  if (is.null(freq)) {
    abort("`data` needs the fit's sampling frequency, but `fit$freq` is NULL.",
          class = "argument")
  }
  data <- check_values(data, min_n = 256L, arg = "data")
  check_diagnosable(data, "data")
  # the caller's pass: `data` must be the series it left
  if (!is.null(series) && (!isTRUE(all.equal(series$freq, freq)) ||
                           !identical(as.numeric(series$x), data))) {
    abort("`data` must be `series$x` at the fit's sampling frequency: the ",
          "series the given detect_series_effects() pass left.", class = "argument")
  }
  data
}

#' @export
print.avrefine <- function(x, ...) {
  NextMethod()
  cat("\n")
  print_steps(x)
  print_refine_notes(x)
  invisible(x)
}

# The loop's notes after the steps: what could not be confirmed, what is
# left unexplained, the automatic tau range, the series effects.
print_refine_notes <- function(x) {
  r <- x$refine
  if (length(r$unconfirmed)) {
    cat("Without raw data these effects could not be confirmed: ",
        paste(r$unconfirmed, collapse = ", "), ".\n", sep = "")
  }
  nr <- NROW(r$rejected)
  if (nr) {
    cat(nr, " candidate(s) rejected (contradicted by the raw data or not a valid ",
        "instance); see $refine$rejected.\n", sep = "")
  }
  al <- r$alternatives
  if (NROW(al)) {
    cat(sprintf(paste("Not in the model, though the raw data confirm it and the curve gains %s",
                      "with it (min_gain %s): %s (%s); see $refine$alternatives.\n"),
                format_num(al$gain), format_num(r$min_gain), al$effect, al$params), sep = "")
  }
  rv <- r$revisit
  if (NROW(rv)) {
    cat(sprintf(paste("The greedy order ended at chi2/dof %s; with the raw data's measured values",
                      "first, %s: the %s run is kept (see $refine$revisit).\n"),
                format_num(rv$chi2[1L]), format_num(rv$chi2[2L]),
                rv$order[rv$kept][1L]))
  }
  d <- unique(r$series_duplicates[c("effect", "series_kind")])
  if (NROW(d)) {
    cat(sprintf("Not added: %s would describe the %s left in the series (remove = \"%s\").\n",
                d$effect, d$series_kind, d$series_kind), sep = "")
  }
  u <- x$unexplained
  if (NROW(u)) {
    cat("Unexplained by any catalogue effect:\n")
    cat(sprintf("  tau %s-%s s: %s (ADEV off by up to %.1f%%)\n",
                format_num(u$tau_from), format_num(u$tau_to), u$description,
                u$size), sep = "")
  }
  if (!is.null(r$tau_range)) {
    cat(sprintf("Fitted from tau = %s s on: the first points are not described by any catalogue effect.\n",
                format_num(r$tau_range[1L])))
  }
  if (!is.null(x$series)) {
    nt <- NROW(x$series$table)
    cat(sprintf("Series effects (steps, warm-up, spikes): %d found%s.\n", nt,
                if (length(x$series$removed)) paste0(", removed: ",
                  paste(x$series$removed, collapse = ", ")) else ", none removed"))
  }
  invisible(x)
}

# `remove`: the series kinds to take out of the data (the catalogue's
# "series" components when it has them).
check_remove <- function(remove) {
  kinds <- effect_kinds("series")
  if (is.character(remove) && identical(remove, "all")) return(kinds)
  if (!is.character(remove) || anyNA(remove) ||
      (length(kinds) && !all(remove %in% kinds))) {
    abort("`remove` must name series effects",
          if (length(kinds)) paste0(" among ", paste0("\"", kinds, "\"", collapse = ", "),
                                    " (or \"all\")"),
          ", not ", if (is.character(remove))
            paste(encodeString(setdiff(remove, kinds), quote = '"'), collapse = ", ")
          else describe_type(remove), ".", class = "argument")
  }
  unique(remove)
}

