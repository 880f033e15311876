# The closed loop: screen candidate effects, refit the winner, record the
# step. The residual signatures (signatures.R), the tracing to candidates
# (trace.R) and the raw-data evidence (evidence.R) come from their own
# files; every fact about an effect comes from the catalogue.

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
#' 4. repeats until nothing pays or `max_steps` effects were added.
#'
#' The rules of acceptance (issue 9):
#' * Candidates are compared by the criterion, not gated by a residual
#'   threshold: with no residual signature left, every candidate is still
#'   tried (screening pass only).
#' * An effect the raw data contradict is never accepted, nor an instance
#'   the catalogue declares not valid on this curve (a Gauss-Markov process
#'   with \eqn{T_c} below 2 samples is the sensor's filter; a sinusoid outside
#'   the band the curve can see, \eqn{1/\tau_{max}} to
#'   \eqn{1/(2\tau_{min})}, or above Nyquist). Both are listed in
#'   `$refine$rejected`.
#' * An effect may replace a term (the catalogue's `replaces`): the filter
#'   term replaces `N`, whose value it carries as its DC level.
#' * A sinusoid proposed by a periodogram line keeps the line's frequency
#'   (the periodogram measures it far better than the curve) and is matched
#'   to lines within the periodogram's resolution. Raw-data checks of the
#'   other effects see the series with the significant lines removed.
#' * What no catalogue effect explains is reported in `$unexplained`, not
#'   papered over. When a run at the short-tau end stays unexplained, the
#'   model is refitted from the first tau after it (a message says so and
#'   `$refine$tau_range` records it), so that points the model cannot
#'   describe do not drive `N` to 0 or bend the long-tau terms.
#' * Without raw data, `$refine$unconfirmed` lists the accepted effects that
#'   could not be confirmed.
#' * With raw data, the series' non-stationary effects (steps, warm-up,
#'   spikes) are read first by [series_effects()],
#'   kept in `$series`, and removed from the data only when named in
#'   `remove`.
#'
#' For speed, candidates are first screened with the nonlinear parameters
#' already in the model (`tc`, `f0`) held at their current values, and the
#' winner is refitted with all of them free; only when screening finds
#' nothing are the candidates tried again with everything free. Every refit
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
#' @param fit An [avfit()] result.
#' @param data Optional raw rate series (numeric vector or `ts`) at the
#'   fit's sampling frequency, used to confirm effects from the data itself.
#' @param candidates Effects that may be added: terms of the catalogue
#'   ([av_terms()]); default all of them.
#' @param max_steps Maximum number of effects to add.
#' @param criterion `"BIC"` (default) or `"AIC"`.
#' @param min_gain Minimum decrease of the criterion for an effect to be
#'   kept (10 is "very strong" evidence on the BIC scale; adjacent taus of
#'   an overlapping Allan variance are correlated, so small gains are
#'   not trusted).
#' @param level Strength, in standard deviations, a residual run must reach
#'   to count as structure.
#' @param remove Series effects to take out of `data` before the loop (kinds
#'   of the catalogue's series components); never done unless asked.
#' @param series `NULL`, or the [series_effects()] result that produced
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
#'   column `condition`), `rejected` (step, effect, params, reason),
#'   `unconfirmed` (labels), `tau_range` (NULL or the automatic range) and
#'   `removed`. `unexplained` is a data frame (kind, tau_from, tau_to,
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
                     max_steps = 5, criterion = "BIC", min_gain = 10,
                     level = 3.5, remove = character(), series = NULL, ...) {
  check_present(missing(fit), "fit", "an avfit() result")
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
      abort("`series` must be a series_effects() result or NULL, not ",
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
  raw <- NULL
  ser <- NULL
  if (!is.null(data)) {
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
    # Non-stationary effects (steps, warm-up, spikes) are read from the
    # series first (R/series.R); what the user asks to remove is taken out
    # of the data the loop then sees.
    if (is.null(series)) {
      ser <- series_effects(data, freq, remove = remove)
      if (length(ser$removed)) data <- ser$x
    } else {
      # the caller's pass: `data` must be the series it left
      if (!isTRUE(all.equal(series$freq, freq)) ||
          !identical(as.numeric(series$x), data)) {
        abort("`data` must be `series$x` at the fit's sampling frequency: the ",
              "series the given series_effects() pass left.", class = "argument")
      }
      ser <- series
    }
    raw <- avdiagnose(data, freq)
    # Bins of a broad band (a resonance) are not lines: they are not
    # proposed or matched as sinusoids. The bands themselves propose and
    # confirm a resonance.
    raw$bands <- find_bands(data, freq)
    # each band's own spectrum (the measured-band effect's proposal)
    raw$band_spectra <- Filter(Negate(is.null), lapply(seq_len(nrow(raw$bands)), function(j) {
      measure_band(data, freq, raw$bands[j, ])
    }))
    raw$lines <- lines_outside_bands(raw$lines, raw$bands)
  }
  # The series the raw-data checks of an effect see: the data with the
  # significant periodogram lines taken out and the broad bands brought
  # down to their background (a sinusoid disturbs the ACF that confirms a
  # Gauss-Markov process, a resonance the short-lag ACF that confirms the
  # filter; the line and band checks read the raw periodogram, not this
  # series). Its short-lag ACF (filter_evidence()) proposes the filter.
  clean <- NULL
  if (!is.null(data)) {
    clean <- if (nrow(raw$lines)) remove_lines(data, freq, raw$lines$f0) else data
    clean <- remove_bands(clean, freq, raw$bands)
    raw$filter <- filter_evidence(clean, freq)
    # Statistics of `clean` that the checks of many candidates share (the
    # block-mean ACF of each block size), computed once per call.
    raw$cache <- new.env(parent = emptyenv())
  }
  evidence_series <- function(effect) clean
  rejected <- new_rejected()
  # The settings every refit uses, explicitly: the fit's own, overridden by
  # the arguments in `...`.
  settings <- utils::modifyList(
    list(bias_correct = !isFALSE(fit$bias_correct),
         correlation = isTRUE(fit$correlation),
         control = fit$control %||% avfit_control()),
    list(...))
  crit <- function(f) if (criterion == "BIC") stats::BIC(f) else stats::AIC(f)
  failures <- new_failures()

  steps <- list()
  current <- fit
  sig <- NULL
  # A refit that frees the parameters of the effects accepted earlier must
  # leave each of them valid and not contradicted by the raw data (a
  # resonance whose tc runs off to a pure tone no longer matches its band).
  # (earlier_broken(): the labels of those that do not hold)
  earlier_broken <- function(f) {
    out <- character()
    for (st in steps) {
      if (!any(startsWith(names(stats::coef(f)), paste0(st$label, ".")))) next
      par <- instance_params(stats::coef(f), f$layout, st$label)
      if (!is.null(inadmissible(st$effect, par, f$data$tau, freq))) {
        out <- c(out, st$label)
        next
      }
      ev <- raw_evidence(st$effect, as.list(par), raw, evidence_series(st$effect), freq)
      if (isFALSE(ev$support)) out <- c(out, st$label)
    }
    out
  }
  earlier_hold <- function(f) !length(earlier_broken(f))
  # The filter's family was chosen against the model of the step it entered
  # at; the effects added since can change which family describes the
  # short-tau end (a first-order low-pass chosen before the 0.55 Hz line ran
  # to its Nyquist bound). So it is chosen again on the final model: each
  # other family refitted with everything free; the criterion chooses, and
  # the new family must be admissible and not contradicted by the raw data,
  # nor move an effect accepted earlier to values the raw data contradict.
  # When no candidate pays, the loop asks this once more and goes on after
  # a change (the effects that pay may differ under the new family).
  rechoose_filter <- function() {
    fi <- grep("^filter", current$terms, value = TRUE)
    if (length(fi) == 1L && length(steps)) {
      rest <- current$terms[current$terms != fi]
      old_lab <- term_labels(current$terms)[current$terms == fi]
      nl_cur <- stats::coef(current)[current$layout$role == "nonlinear"]
      swap <- NULL
      for (v in setdiff(c("filter", "filter:lp1", "filter:lp2"), fi)) {
        lab <- new_label(rest, v)
        st <- raw$filter$start[[if (v == "filter") "ma" else sub("^filter:", "", v)]]
        start <- c(nl_cur[!startsWith(names(nl_cur), paste0(old_lab, "."))],
                   if (length(st)) stats::setNames(unlist(st), paste0(lab, ".", names(st))))
        start <- start[names(start) %in% coef_layout(c(rest, v))$name]
        args <- refit_args(current, c(rest, v), settings, start = start)
        g <- try_refit(args, function(cnd, stage) {
          failures <<- add_failure(failures, cnd, length(steps) + 1L, v, stage)
        }, "filter family chosen again")
        if (is.null(g) || !is.finite(crit(g)) ||
            crit(g) >= min(crit(current), swap$crit %||% Inf) - min_gain) next
        par <- instance_params(stats::coef(g), g$layout, lab)
        if (!is.null(inadmissible(v, par, g$data$tau, freq))) next
        ev <- raw_evidence(v, as.list(par), raw, evidence_series(v), freq)
        if (isFALSE(ev$support) || !earlier_hold(g)) next
        swap <- list(fit = g, crit = crit(g), effect = v, label = lab, par = par, ev = ev)
      }
      if (!is.null(swap)) {
        loc <- locate_signature(sig, swap$fit, swap$label)
        evidence <- paste0("the filter family chosen again on the final model (was ",
                           fi, "); ", loc$text)
        if (nzchar(swap$ev$text)) evidence <- paste0(evidence, "; raw data: ", swap$ev$text)
        steps[[length(steps) + 1L]] <<- step_row(
          swap$effect, swap$label, loc, swap$par, evidence, swap$ev$support,
          current, swap$fit, crit(current), swap$crit)
        current <<- swap$fit
        return(TRUE)
      }
    }
    FALSE
  }
  for (step in seq_len(max_steps)) {
    tau <- current$data$tau
    z <- stats::residuals(current)
    sig <- residual_signatures(tau, z, level = level)
    # No residual threshold gates the search: with no signature every
    # candidate is still asked, and only the criterion decides (two GMs a
    # decade apart leave no run reaching `level` for the second one).
    traced <- trace_candidates(tau, current$data$avar, current$data$fitted, sig,
                               present = current$terms, candidates = candidates,
                               raw = raw)
    trials <- candidate_trials(traced, current$terms, candidates, sig)
    if (!nrow(trials)) break
    c0 <- crit(current)
    # Screening: the model's existing nonlinear parameters are held at their
    # current values while candidates are compared (one 1-D profile each);
    # the winner is then refitted with everything free. The criterion of a
    # screened fit is put on the all-free scale by charging the held ones.
    nl_now <- stats::coef(current)[current$layout$role == "nonlinear"]
    nl_now <- nl_now[!names(nl_now) %in% names(settings$fixed)]
    pen <- if (criterion == "BIC") log(current$nobs) else 2
    crit_s <- function(f) crit(f) + pen * length(hold_now)
    best <- NULL
    # When screening finds nothing, the candidates are tried once more with
    # all nonlinear parameters free (slower, but catches effects that only
    # pay once the others may move). Traced candidates first; the others
    # only when none of those pays.
    # (Without any residual signature, only the screening pass is run.)
    holds <- if (length(nl_now) && nrow(sig)) list(nl_now, numeric(0))
      else if (length(nl_now)) list(nl_now) else list(numeric(0))
    passes <- list()
    for (h in holds) {
      passes[[length(passes) + 1L]] <- list(hold = h, tier = which(trials$traced))
      passes[[length(passes) + 1L]] <- list(hold = h, tier = which(!trials$traced))
    }
    for (pass in passes) {
      hold_now <- pass$hold
      for (i in pass$tier) {
        tr <- trials[i, ]
        # Parameters the raw data measure better than the curve (a line's
        # frequency from the periodogram) are pinned there.
        pin <- pin_values(current$terms, tr$effect, tr$pin[[1L]])
        # a value already pinned in the model (that line is in it) is not
        # proposed twice
        if (length(pin) && any(vapply(pin, function(v) any(abs(settings$fixed - v) <=
              1e-9 * abs(v)), logical(1)))) next
        new <- refit_with(current, model_terms(current$terms, tr$effect), tr$effect,
                          tr$init[[1L]], settings, hold = c(hold_now, pin),
                          good_enough = function(f) crit_s(f) < c0 - min_gain,
                          record = function(cnd, stage) {
                            failures <<- add_failure(failures, cnd, step,
                                                     tr$effect, stage)
                          })
        if (is.null(new)) next
        c1 <- crit_s(new)
        pays <- is.finite(c1) && c1 < c0 - min_gain &&
          new$chi2 < 0.9 * current$chi2
        if (!pays) next
        lab <- new_label(current$terms, tr$effect)
        # An added term that explains (almost) nothing anywhere is a refit
        # artefact, not an effect.
        if (max_share(new, lab) < 0.02) next
        # An instance that is not a valid instance of its effect on this
        # curve (a sub-sample GM, a sinusoid the curve cannot see) is never
        # accepted, however well it bends the curve; nor one the raw data
        # contradict. A screened instance (others held) that fails is
        # refitted once with everything free before it is rejected: held
        # at the one-term compromise, a second GM lands at the wrong Tc.
        judge <- function(f) {
          par <- instance_params(stats::coef(f), f$layout, lab)
          why <- inadmissible(tr$effect, par, tau, freq)
          ev <- if (is.null(why)) raw_evidence(tr$effect, as.list(par), raw,
                                               evidence_series(tr$effect), freq)
          if (is.null(why) && isFALSE(ev$support)) {
            why <- paste("contradicted by the raw data:", ev$text)
          }
          moved <- FALSE
          if (is.null(why) && !earlier_hold(f)) {
            why <- "moves an effect accepted earlier to values the raw data contradict"
            moved <- TRUE
          }
          list(par = par, why = why, ev = ev, moved = moved)
        }
        jd <- judge(new)
        if (!is.null(jd$why) && length(hold_now)) {
          args <- refit_args(current, new$terms, settings,
                             start = stats::coef(new)[new$layout$role == "nonlinear"],
                             hold = pin)
          free <- try_refit(args, function(cnd, stage) {
            failures <<- add_failure(failures, cnd, step, tr$effect, stage)
          }, "free refit of a rejected screen")
          if (!is.null(free) && is.finite(crit(free)) && crit(free) < c0 - min_gain &&
              free$chi2 < 0.9 * current$chi2) {
            jf <- judge(free)
            if (is.null(jf$why)) {
              new <- free
              c1 <- crit(free)
              jd <- jf
            }
          }
        }
        # A refit that moves effects accepted earlier to values the raw data
        # contradict is tried once more with those effects' nonlinear values
        # held where they were accepted (the rest free): the new effect is
        # judged beside the earlier ones as the raw data confirmed them,
        # charged for the held values as a screen is.
        if (isTRUE(jd$moved)) {
          broken <- earlier_broken(new)
          keep <- nl_now[vapply(names(nl_now), function(nm) {
            any(startsWith(nm, paste0(broken, ".")))
          }, NA)]
          if (length(keep)) {
            args <- refit_args(current, new$terms, settings,
                               start = stats::coef(new)[new$layout$role == "nonlinear"],
                               hold = c(keep, pin))
            held <- try_refit(args, function(cnd, stage) {
              failures <<- add_failure(failures, cnd, step, tr$effect, stage)
            }, "refit with earlier effects held")
            c_held <- if (is.null(held)) Inf else crit(held) + pen * length(keep)
            if (is.finite(c_held) && c_held < c0 - min_gain &&
                held$chi2 < 0.9 * current$chi2 && max_share(held, lab) >= 0.02) {
              jh <- judge(held)
              if (is.null(jh$why)) {
                new <- held
                c1 <- c_held
                jd <- jh
              }
            }
          }
        }
        par <- jd$par
        ev <- jd$ev
        if (!is.null(jd$why)) {
          rejected <- add_rejected(rejected, step, tr$effect, par, jd$why)
          next
        }
        adj <- c1 - min_gain * isTRUE(ev$support)
        cand <- list(fit = new, crit = c1, adj = adj, trial = tr, label = lab,
                     params = par, ev = ev, pin = pin)
        if (is.null(best) || adj < best$adj) best <- cand
      }
      if (!is.null(best)) break
    }
    if (is.null(best)) {
      if (rechoose_filter()) next
      break
    }
    if (length(best$pin)) settings$fixed <- c(settings$fixed, best$pin)
    # Refit the winner with the held nonlinear parameters free again (the new
    # one starts where screening put it).
    if (length(hold_now)) {
      lay <- best$fit$layout
      args <- refit_args(current, best$fit$terms, settings,
                         start = stats::coef(best$fit)[lay$role == "nonlinear"])
      full <- try_refit(args, function(cnd, stage) {
        failures <<- add_failure(failures, cnd, step, best$trial$effect, stage)
      }, "refit of the winner")
      if (!is.null(full) && crit(full) <= best$crit + 1e-6) {
        # the evidence is read again at the values the free refit gives;
        # a refit the raw data contradict is not taken
        p2 <- instance_params(stats::coef(full), full$layout, best$label)
        ev2 <- raw_evidence(best$trial$effect, as.list(p2), raw,
                            evidence_series(best$trial$effect), freq)
        if (!isFALSE(ev2$support) &&
            is.null(inadmissible(best$trial$effect, p2, tau, freq)) &&
            earlier_hold(full)) {
          best$fit <- full
          best$crit <- crit(full)
          best$params <- p2
          best$ev <- ev2
        }
      }
    }
    tr <- best$trial
    # Describe the effect where the fitted term actually sits, which may
    # differ from where the trial started.
    loc <- locate_signature(sig, best$fit, best$label)
    evidence <- loc$text
    if (nzchar(best$ev$text)) {
      evidence <- paste0(evidence, "; raw data: ", best$ev$text,
                         if (isFALSE(best$ev$support)) " (NOT supported by the raw data)")
    }
    steps[[length(steps) + 1L]] <- step_row(
      tr$effect, best$label, loc, best$params, evidence, best$ev$support,
      current, best$fit, c0, best$crit)
    current <- best$fit
  }
  # the loop may have ended on a step that chose the family again
  rechoose_filter()
  all_steps <- Reduce(bind_steps, steps, fit$steps)
  # What is left: residual structure no catalogue effect explained.
  sig <- residual_signatures(current$data$tau, stats::residuals(current), level = level)
  unexplained <- unexplained_table(sig, current)
  # Short tau cannot hijack the fit: when the model still cannot describe a
  # run of first points, they are left out of the fit (an automatic tau
  # range, with a message) so that they do not drive N to 0 or bend the
  # long-tau terms; the run stays listed as unexplained.
  tau_range <- NULL
  short <- unexplained[unexplained$kind == "short_end", , drop = FALSE]
  if (nrow(short)) {
    tau_all <- current$data$tau
    keep_from <- min(tau_all[tau_all > short$tau_to[1L]], Inf)
    if (sum(tau_all >= keep_from) >= length(current$coefficients) + 3L) {
      args <- refit_args(current, current$terms, settings,
                         start = stats::coef(current)[current$layout$role == "nonlinear"])
      args$tau_range <- c(keep_from, Inf)
      rec <- function(cnd, stage) {
        failures <<- add_failure(failures, cnd, length(steps) + 1L, "tau_range", stage)
      }
      trimmed <- try_refit(args, rec, "refit without the first points")
      # without the first points a free nonlinear parameter may run off to
      # values the raw data contradict (a resonance's tc to a pure tone);
      # then the effects keep the nonlinear values the full curve gave them
      # and only the amplitudes are refitted
      if (is.null(trimmed) || !earlier_hold(trimmed)) {
        nl <- stats::coef(current)[current$layout$role == "nonlinear"]
        nl <- nl[!names(nl) %in% names(settings$fixed)]
        if (length(nl)) {
          args_h <- refit_args(current, current$terms, settings, hold = nl)
          args_h$tau_range <- c(keep_from, Inf)
          trimmed <- try_refit(args_h, rec, "refit without the first points, nonlinear held")
        }
      }
      if (!is.null(trimmed) && earlier_hold(trimmed)) {
        tau_range <- c(keep_from, max(tau_all))
        message(sprintf(paste(
          "avrefine(): no catalogue effect describes the first points (tau %s-%s s);",
          "the model is fitted from tau = %s s on (see $unexplained)."),
          format_num(short$tau_from[1L]), format_num(short$tau_to[1L]),
          format_num(keep_from)))
        current <- trimmed
      }
    }
  }
  current$steps <- all_steps
  current$unexplained <- unexplained
  # Curve only: the accepted effects the raw data could not confirm.
  new_steps_df <- all_steps[seq_len(nrow(all_steps)) > NROW(fit$steps), , drop = FALSE]
  unconfirmed <- if (is.null(data)) new_steps_df$label else character()
  current$series <- series_kept(ser)
  if (!is.null(raw)) raw$cache <- NULL
  current$refine <- list(candidates = candidates, criterion = criterion,
                         min_gain = min_gain, level = level, diagnostics = raw,
                         remaining = sig, start_terms = fit$terms,
                         failures = failures, rejected = rejected,
                         unconfirmed = unconfirmed, tau_range = tau_range,
                         removed = if (is.null(ser)) character() else ser$removed)
  class(current) <- unique(c("avrefine", class(current)))
  validate_avfit(current)
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

# ---- refits -----------------------------------------------------------------

# The arguments of a refit of `fit` with `terms`: the settings, start values
# (given ones first, then the fit's nonlinear estimates) and held values.
refit_args <- function(fit, terms, settings, start = NULL, hold = NULL) {
  args <- c(list(av = fit, terms = terms), settings)
  names_new <- coef_layout(terms)$name
  st <- c(settings$start, start)
  prev <- stats::coef(fit)[fit$layout$role == "nonlinear"]
  prev <- prev[names(prev) %in% names_new & !names(prev) %in% names(st)]
  st <- c(st, prev)
  args$start <- if (length(st)) st else NULL
  if (length(hold)) args$fixed <- c(settings$fixed, hold)
  # values pinned for a term the new model no longer has (a replaced one)
  if (length(args$fixed)) args$fixed <- args$fixed[names(args$fixed) %in% names_new]
  if (!length(args$fixed)) args$fixed <- NULL
  if (length(args$fixed)) {
    args$fixed <- args$fixed[!duplicated(names(args$fixed))]
    if (length(args$start)) {
      args$start <- args$start[!names(args$start) %in% names(args$fixed)]
      if (!length(args$start)) args$start <- NULL
    }
  }
  args
}

# Run one refit; a failure is recorded through `record(condition, stage)`
# and gives NULL, as does a fit with no degrees of freedom left. Warnings
# are recorded and muffled.
try_refit <- function(args, record, stage) {
  res <- withCallingHandlers(
    tryCatch(do.call(avfit, args), error = function(e) {
      record(e, stage)
      NULL
    }),
    warning = function(w) {
      record(w, stage)
      invokeRestart("muffleWarning")
    })
  if (!is.null(res) && !is.finite(res$chi2)) {
    record(simpleCondition("no degrees of freedom left for chi2"), stage)
    return(NULL)
  }
  res
}

# Refit the curve with one more term. avfit() profiles the nonlinear
# parameters on its own grid; when the tracing gives a start value for the
# new term's nonlinear parameters the refit is also tried from there, and
# the better of the two is kept. NULL when both fail.
refit_with <- function(fit, terms, effect, init, settings, hold = NULL,
                       good_enough = NULL, record) {
  one <- function(start, stage) {
    try_refit(refit_args(fit, terms, settings, start = start, hold = hold),
              record, stage)
  }
  best <- one(NULL, "screen")
  if (!is.null(best) && !is.null(good_enough) && good_enough(best)) return(best)
  lab <- new_label(fit$terms, effect)
  sp <- split_term(effect)
  e <- effect_entry(sp$kind, sp$variant)
  nl <- e$params$name[e$params$role == "nonlinear"]
  ok <- vapply(nl, function(p) {
    v <- init[[p]]
    is.numeric(v) && length(v) == 1L && is.finite(v) && v > 0
  }, logical(1))
  if (any(ok)) {
    st <- unlist(init[nl[ok]])
    names(st) <- coef_names(e, lab)[match(nl[ok], e$params$name)]
    alt <- one(st, "screen from the traced start")
    if (!is.null(alt) && (is.null(best) || alt$objective < best$objective)) best <- alt
  }
  best
}

# ---- rules ------------------------------------------------------------------

# A trial's pinned values (named by parameter) as coefficients of the term
# `effect` would get next to `terms`.
pin_values <- function(terms, effect, pin) {
  if (!length(pin)) return(NULL)
  sp <- split_term(effect)
  e <- effect_entry(sp$kind, sp$variant)
  lab <- new_label(terms, effect)
  pin <- unlist(pin)
  j <- match(names(pin), e$params$name)
  out <- pin[!is.na(j)]
  names(out) <- coef_names(e, lab)[j[!is.na(j)]]
  out
}

# The model after adding `effect`: the kinds the effect's entry replaces
# (the filter replaces N) leave.
model_terms <- function(terms, effect) {
  sp <- split_term(effect)
  gone <- effect_entry(sp$kind, sp$variant)$replaces
  c(terms[!split_term(terms)$kind %in% gone], effect)
}

# Kinds that may still be added next to `present`: repeatable ones or those
# absent, and never one that a present term replaced.
addable_kind <- function(kind, present) {
  pk <- split_term(present)$kind
  replaced <- unlist(lapply(unique(pk), function(k) effect_entry(k)$replaces))
  e <- effect_entry(kind)
  !kind %in% replaced && (e$repeatable || !kind %in% pk)
}

# NULL when a fitted instance is valid on this curve, else the reason.
inadmissible <- function(effect, par, tau, freq) {
  sp <- split_term(effect)
  e <- effect_entry(sp$kind, sp$variant)
  if (is.null(e$admissible)) return(NULL)
  e$admissible(as.list(par), tau, freq)
}

new_rejected <- function() {
  data.frame(step = integer(), effect = character(), params = character(),
             reason = character(), stringsAsFactors = FALSE)
}

add_rejected <- function(rejected, step, effect, par, reason) {
  rbind(rejected, data.frame(step = as.integer(step), effect = effect,
                             params = format_params(par, effect),
                             reason = reason, stringsAsFactors = FALSE))
}

# The residual structure left after the loop, as a table: kind, tau range,
# strength (sigma) and size (largest relative ADEV error inside, percent).
unexplained_table <- function(sig, fit) {
  s <- sig[sig$kind != "oscillation", , drop = FALSE]
  tau <- fit$data$tau
  err <- 100 * abs(sqrt(fit$data$avar / fit$data$fitted) - 1)
  size <- vapply(seq_len(nrow(s)), function(i) {
    inr <- tau >= s$tau_from[i] & tau <= s$tau_to[i]
    if (any(inr)) max(err[inr]) else NA_real_
  }, 0)
  data.frame(kind = s$kind, tau_from = s$tau_from, tau_to = s$tau_to,
             strength = abs(s$strength), size = size,
             description = s$description, stringsAsFactors = FALSE)
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

# ---- failures ---------------------------------------------------------------

new_failures <- function() {
  out <- data.frame(step = integer(), effect = character(), stage = character(),
                    message = character(), stringsAsFactors = FALSE)
  out$condition <- list()
  out
}

# Record a refit's condition as an allanvar_error_refit (or, for a warning,
# allanvar_warning_refit) condition whose parent is the original.
add_failure <- function(failures, cnd, step, effect, stage) {
  is_warning <- inherits(cnd, "warning")
  msg <- sprintf("refit with %s (%s) %s: %s", effect, stage,
                 if (is_warning) "warned" else "failed", conditionMessage(cnd))
  cls <- if (is_warning) {
    c("allanvar_warning_refit", "allanvar_warning", "warning", "condition")
  } else {
    c("allanvar_error_refit", "allanvar_error", "error", "condition")
  }
  rec <- structure(list(message = msg, call = NULL, parent = cnd, step = step,
                        effect = effect, stage = stage), class = cls)
  row <- data.frame(step = as.integer(step), effect = effect, stage = stage,
                    message = msg, stringsAsFactors = FALSE)
  row$condition <- list(rec)
  rbind(failures, row)
}

# ---- trials and steps ---------------------------------------------------------

# One trial per candidate kind: the best-scoring traced start (two for kinds
# with nonlinear parameters), or a generic start when no signature points
# at that kind (the refit then decides).
candidate_trials <- function(traced, present, candidates, sig) {
  kinds <- candidates[vapply(candidates, addable_kind, logical(1), present = present)]
  rows <- list()
  strongest <- if (nrow(sig)) sig[which.max(abs(sig$strength)), ] else
    data.frame(tau_from = NA_real_, tau_to = NA_real_,
               description = "no residual signature", stringsAsFactors = FALSE)
  for (k in kinds) {
    t <- if (nrow(traced)) traced[split_term(traced$effect)$kind == k, , drop = FALSE]
      else traced
    if (nrow(t)) {
      nonlinear <- any(effect_entry(k)$params$role == "nonlinear")
      take <- if (nonlinear) seq_len(min(2L, nrow(t))) else 1L
      # every raw-data proposal that pins a value (each periodogram line)
      # is tried, not only the two best-scoring starts; so is the best
      # start of every variant proposed (each filter family the raw data
      # support): the criterion chooses among them
      pinned <- which(lengths(t$pin) > 0L)
      take <- union(union(take, pinned), which(!duplicated(t$effect)))
      t$traced <- rep(TRUE, nrow(t))
      rows[[length(rows) + 1L]] <- t[take, , drop = FALSE]
    } else if (!isTRUE(effect_entry(k)$proposed_only)) {
      r <- data.frame(
        effect = k, tau_from = strongest$tau_from, tau_to = strongest$tau_to,
        signature = paste0(strongest$description, " (no signature specific to ", k, ")"),
        score = 0, traced = FALSE, stringsAsFactors = FALSE)
      r$init <- list(list())
      r$pin <- list(NULL)
      rows[[length(rows) + 1L]] <- r[, c("effect", "tau_from", "tau_to", "signature",
                                         "score", "init", "pin", "traced")]
    }
  }
  if (!length(rows)) return(data.frame())
  do.call(rbind, lapply(rows, function(r) r[, c("effect", "tau_from", "tau_to",
                                                "signature", "score", "init",
                                                "pin", "traced")]))
}

# The residual signature that matches an accepted term: the one whose tau
# range holds (or lies nearest, within a factor 3) the term's characteristic
# tau (the catalogue's peak_tau, otherwise the tau where the term's share of
# the model is largest). Without one, the tau range is where the term
# carries over a quarter of the model AV.
locate_signature <- function(sig, fit, label) {
  tau <- fit$data$tau
  comp <- fit$components
  share <- comp[, label] / rowSums(comp)
  e <- effect_entry(parse_labels(label)$kind, parse_labels(label)$variant)
  par <- instance_params(stats::coef(fit), fit$layout, label)
  tchar <- if (!is.null(e$peak_tau)) e$peak_tau(par)
    else if (all(is.na(share))) NA_real_ else tau[which.max(share)]
  big <- which(share > 0.25)
  range <- if (length(big)) range(tau[big]) else range(tau)
  s <- sig[sig$kind != "slope" & sig$kind != "oscillation", , drop = FALSE]
  if (is.finite(tchar) && nrow(s)) {
    dist <- ifelse(tchar < s$tau_from, log(s$tau_from / tchar),
                   ifelse(tchar > s$tau_to, log(tchar / s$tau_to), 0))
    dist <- dist - 0.01 * (s$sign > 0)       # prefer a positive run on ties
    j <- which.min(dist)
    if (dist[j] < log(3)) {
      return(list(tau_from = s$tau_from[j], tau_to = s$tau_to[j],
                  text = s$description[j]))
    }
  }
  list(tau_from = range[1L], tau_to = range[2L],
       text = sprintf("no residual signature near tau = %s s (the term carries >25%% of the model AV over tau %s-%s s)",
                      format_num(tchar), format_num(range[1L]), format_num(range[2L])))
}

# Largest share of the model AV carried by one term instance over the taus.
max_share <- function(fit, label) {
  comp <- fit$components
  if (!label %in% colnames(comp)) return(1)
  max(comp[, label] / rowSums(comp))
}

# One accepted step: the effect, where its signature sits (`loc`), its
# parameters, the evidence, and the fit before and after it.
step_row <- function(effect, label, loc, par, evidence, confirmed, before,
                     after, crit_before, crit_after) {
  new_steps(effect = effect, label = label,
            tau_from = loc$tau_from, tau_to = loc$tau_to,
            params = format_params(par, effect),
            evidence = evidence, confirmed = confirmed,
            chi2_before = before$chi2, chi2_after = after$chi2,
            rms_before = before$rms, rms_after = after$rms,
            crit_before = crit_before, crit_after = crit_after)
}
