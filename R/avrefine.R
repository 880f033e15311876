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
#' For speed, candidates are first screened with the nonlinear parameters
#' already in the model (`tc`, `f0`) held at their current values, and the
#' winner is refitted with all of them free; only when screening finds
#' nothing are the candidates tried again with everything free. A sinusoid
#' whose frequency the raw periodogram resolves is also tried with `f0`
#' held at the periodogram value (one parameter fewer), and such a
#' frequency stays held in later steps.
#'
#' Every candidate kind in `candidates` that is not already in the model
#' (gm and sinusoid may repeat) is refitted at each step; the residual
#' signature and the raw data supply the initial values, the tau range and
#' the evidence. Candidates traced from a signature (or proposed by the raw
#' data) are tried first, the others only when none of those pays. Among
#' the candidates that pay, the one with the lowest criterion wins, where
#' raw-data support counts as a gain of `min_gain` and a contradiction as a
#' loss of `min_gain` (so an effect the raw data contradict must lower the
#' criterion by twice `min_gain`). An accepted effect that the raw data
#' contradict is kept (it pays on the curve) but flagged
#' `confirmed = FALSE`.
#'
#' @param fit An [avfit()] result.
#' @param data Optional raw rate series (numeric vector or `ts`) at the
#'   fit's sampling frequency, used to confirm effects from the data itself.
#' @param candidates Effects that may be added: any of `"Q"`, `"N"`, `"B"`,
#'   `"K"`, `"R"`, `"gm"`, `"sinusoid"`.
#' @param max_steps Maximum number of effects to add.
#' @param criterion `"BIC"` (default) or `"AIC"`.
#' @param min_gain Minimum decrease of the criterion for an effect to be
#'   kept (10 is "very strong" evidence on the BIC scale; adjacent taus of
#'   an overlapping Allan variance are correlated, so small gains are
#'   not trusted).
#' @param level Strength, in standard deviations, a residual run must reach
#'   to count as structure.
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
#'   signatures left when the loop stopped. The object keeps class `avfit`
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
avrefine <- function(fit, data = NULL,
                     candidates = c("Q", "N", "B", "K", "R", "gm", "sinusoid"),
                     max_steps = 5, criterion = "BIC", min_gain = 10,
                     level = 3.5, ...) {
  check_present(missing(fit), "fit", "an avfit() result")
  if (!inherits(fit, "avfit")) {
    abort("`fit` must be an avfit() result, not ", describe_type(fit), ".")
  }
  kinds <- c("Q", "N", "B", "K", "R", "gm", "sinusoid")
  if (!is.character(candidates) || !length(candidates) || anyNA(candidates) ||
      !all(candidates %in% kinds)) {
    abort("`candidates` must name effects among ", paste(kinds, collapse = ", "),
          ", not ", if (is.character(candidates))
            paste(encodeString(setdiff(candidates, kinds), quote = '"'), collapse = ", ")
          else describe_type(candidates), ".")
  }
  candidates <- unique(candidates)
  max_steps <- check_number(max_steps, "max_steps", 0, 50, integer = TRUE)
  if (!is.character(criterion) || length(criterion) != 1L ||
      !criterion %in% c("BIC", "AIC")) {
    abort("`criterion` must be \"BIC\" or \"AIC\", not ", format_value(criterion), ".")
  }
  min_gain <- check_number(min_gain, "min_gain", 0)
  level <- check_number(level, "level", 0, open = TRUE)
  freq <- fit$freq
  raw <- NULL
  if (!is.null(data)) {
    if (stats::is.ts(data) && !is.null(freq) &&
        abs(stats::frequency(data) - freq) > 1e-6 * freq) {
      abort("`data` is a ts at ", stats::frequency(data), " Hz but the fit is at ",
            freq, " Hz; give the raw series the curve was computed from.")
    }
    if (is.null(freq)) {
      abort("`data` needs the fit's sampling frequency, but `fit$freq` is NULL.")
    }
    data <- check_values(data, min_n = 256L, arg = "data")
    raw <- avdiagnose(data, freq)
  }
  crit <- function(f) if (criterion == "BIC") stats::BIC(f) else stats::AIC(f)

  steps <- list()
  current <- fit
  # Sinusoid frequencies taken from the raw periodogram stay held.
  known <- numeric(0)
  sig <- NULL
  for (step in seq_len(max_steps)) {
    tau <- current$data$tau
    z <- stats::residuals(current)
    sig <- residual_signatures(tau, z, level = level)
    if (!nrow(sig)) break
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
    pen <- if (criterion == "BIC") log(current$nobs) else 2
    crit_s <- function(f) crit(f) + pen * (length(hold_now) - length(known))
    best <- NULL
    # When screening finds nothing, the candidates are tried once more with
    # all nonlinear parameters free (slower, but catches effects that only
    # pay once the others may move). Traced candidates first; the others
    # only when none of those pays.
    holds <- if (length(nl_now) > length(known)) list(nl_now, known) else list(known)
    passes <- list()
    for (h in holds) {
      passes[[length(passes) + 1L]] <- list(hold = h, tier = which(trials$traced))
      passes[[length(passes) + 1L]] <- list(hold = h, tier = which(!trials$traced))
    }
    for (pass in passes) {
      hold_now <- pass$hold
      tier <- pass$tier
      for (i in tier) {
        tr <- trials[i, ]
        init <- tr$init[[1L]]
        new <- refit_with(current, c(current$terms, tr$effect), tr$effect, init, ...,
                          hold = hold_now,
                          good_enough = function(f) crit_s(f) < c0 - min_gain)
        if (tr$effect == "sinusoid" && isTRUE(tr$from_raw)) {
          alt <- refit_fixed_f0(current, c(current$terms, tr$effect), init$f0, ...,
                                hold = hold_now)
          if (!is.null(alt) && (is.null(new) || crit_s(alt) < crit_s(new))) new <- alt
        }
        if (is.null(new)) next
        c1 <- crit_s(new)
        pays <- is.finite(c1) && c1 < c0 - min_gain &&
          new$chi2 < 0.9 * current$chi2
        if (!pays) next
        lab <- new_label(current$terms, tr$effect)
        # An added term that explains (almost) nothing anywhere is a refit
        # artefact, not an effect.
        if (max_share(new, lab) < 0.02) next
        par <- effect_params(new, lab)
        ev <- raw_evidence(tr$effect, as.list(par), raw, data, freq)
        # Raw-data support or contradiction weighs min_gain criterion units;
        # an effect the raw data contradict must pay twice the margin.
        adj <- c1 - min_gain * (isTRUE(ev$support) - isFALSE(ev$support))
        if (isFALSE(ev$support) && !(adj < c0 - min_gain)) next
        cand <- list(fit = new, crit = c1, adj = adj, trial = tr, label = lab,
                     params = par, ev = ev)
        if (is.null(best) || adj < best$adj) best <- cand
      }
      if (!is.null(best)) break
    }
    if (is.null(best)) break
    # Refit the winner with the held nonlinear parameters free again (the new
    # one starts where screening put it).
    if (length(hold_now) > length(known)) {
      lay <- best$fit$layout
      start <- stats::coef(best$fit)[lay$role == "nonlinear"]
      f0_held <- lay$name[lay$fixed & lay$param == "f0" & lay$label == best$label]
      hold <- c(known, stats::coef(best$fit)[f0_held])
      start <- start[!names(start) %in% names(hold)]
      args <- c(list(av = current, terms = best$fit$terms, start = start), list(...))
      if (length(hold)) args$fixed <- c(args$fixed, hold)
      full <- tryCatch(suppressWarnings(do.call(avfit, args)), error = function(e) NULL)
      if (!is.null(full) && is.finite(full$chi2) && crit(full) <= best$crit + 1e-6) {
        best$fit <- full
        best$crit <- crit(full)
        best$params <- effect_params(full, best$label)
      }
    }
    tr <- best$trial
    lay <- best$fit$layout
    f0_held <- lay$name[lay$fixed & lay$param == "f0" & lay$label == best$label]
    if (length(f0_held)) known <- c(known, stats::coef(best$fit)[f0_held])
    # Describe the effect where the fitted term actually sits, which may
    # differ from where the trial started.
    loc <- locate_signature(sig, best$fit, best$label, tr)
    tr$tau_from <- loc$tau_from
    tr$tau_to <- loc$tau_to
    evidence <- loc$text
    if (nzchar(best$ev$text)) {
      evidence <- paste0(evidence, "; raw data: ", best$ev$text,
                         if (isFALSE(best$ev$support)) " (NOT supported by the raw data)")
    }
    steps[[length(steps) + 1L]] <- data.frame(
      effect = tr$effect, label = best$label,
      tau_from = tr$tau_from, tau_to = tr$tau_to,
      params = paste0(format_params(best$params, tr$effect),
                      if (length(f0_held)) " (f0 from the periodogram)"),
      evidence = evidence, confirmed = best$ev$support,
      chi2_before = current$chi2, chi2_after = best$fit$chi2,
      rms_before = current$rms, rms_after = best$fit$rms,
      crit_before = c0, crit_after = best$crit,
      stringsAsFactors = FALSE)
    current <- best$fit
  }
  old <- fit$steps
  new_steps <- if (length(steps)) do.call(rbind, steps) else empty_steps()
  if (is.data.frame(old) && nrow(old)) {
    new_steps <- merge_steps(old, new_steps)
  }
  rownames(new_steps) <- NULL
  current$steps <- new_steps
  current$refine <- list(candidates = candidates, criterion = criterion,
                         min_gain = min_gain, level = level, diagnostics = raw,
                         remaining = sig, start_terms = fit$terms)
  class(current) <- unique(c("avrefine", class(current)))
  current
}

#' @export
print.avrefine <- function(x, ...) {
  NextMethod()
  cat("\n")
  print_steps(x)
  invisible(x)
}

empty_steps <- function() {
  data.frame(effect = character(), label = character(), tau_from = numeric(),
             tau_to = numeric(), params = character(), evidence = character(),
             confirmed = logical(), chi2_before = numeric(), chi2_after = numeric(),
             rms_before = numeric(), rms_after = numeric(), crit_before = numeric(),
             crit_after = numeric(), stringsAsFactors = FALSE)
}

merge_steps <- function(old, new) {
  cols <- union(names(old), names(new))
  fill <- function(d) {
    for (cl in setdiff(cols, names(d))) d[[cl]] <- rep(NA, nrow(d))
    d[cols]
  }
  rbind(fill(old), fill(new))
}

# One trial per candidate kind: the best-scoring traced start, or a generic
# start when no signature points at that kind (the refit then decides).
candidate_trials <- function(traced, present, candidates, sig) {
  kinds <- candidates[!(candidates %in% c("Q", "N", "B", "K", "R") &
                          candidates %in% present)]
  rows <- list()
  strongest <- sig[which.max(abs(sig$strength)), ]
  for (k in kinds) {
    t <- traced[traced$effect == k, , drop = FALSE]
    if (nrow(t)) {
      # gm and sinusoid: try up to two distinct starts (signature and raw data).
      take <- if (k %in% c("gm", "sinusoid")) seq_len(min(2L, nrow(t))) else 1L
      t$traced <- rep(TRUE, nrow(t))
      rows[[length(rows) + 1L]] <- t[take, , drop = FALSE]
    } else {
      rows[[length(rows) + 1L]] <- data.frame(
        effect = k, tau_from = strongest$tau_from, tau_to = strongest$tau_to,
        signature = paste0(strongest$description, " (no signature specific to ", k, ")"),
        score = 0, from_raw = FALSE, traced = FALSE, stringsAsFactors = FALSE)
      rows[[length(rows)]]$init <- list(list())
    }
  }
  if (!length(rows)) return(data.frame())
  do.call(rbind, rows)
}

# Refit the curve with one more term. avfit() profiles the nonlinear
# parameters on its own grid; when the tracing gives a starting Tc or f0 the
# refit is also tried from there, and the better of the two is kept. NULL
# when both fail.
refit_with <- function(fit, terms, effect, init, ..., hold = NULL,
                       good_enough = NULL) {
  one <- function(start) {
    args <- c(list(av = fit, terms = terms), list(...))
    if (length(start)) args$start <- c(args$start, start)
    if (length(hold)) args$fixed <- c(args$fixed, hold)
    res <- tryCatch(suppressWarnings(do.call(avfit, args)),
                    error = function(e) NULL)
    if (is.null(res) || !is.finite(res$chi2)) NULL else res
  }
  best <- one(NULL)
  if (!is.null(best) && !is.null(good_enough) && good_enough(best)) return(best)
  lab <- new_label(fit$terms, effect)
  nl <- c(gm = "tc", sinusoid = "f0")[effect]
  if (!is.na(nl) && is.finite(init[[nl]] %||% NA_real_) && init[[nl]] > 0) {
    st <- stats::setNames(init[[nl]], paste0(lab, ".", nl))
    alt <- one(st)
    if (!is.null(alt) && (is.null(best) || alt$objective < best$objective)) best <- alt
  }
  best
}

# A sinusoid whose line the raw periodogram resolves: its f0 is known far
# better from the data than from the curve, so also try it held fixed there.
refit_fixed_f0 <- function(fit, terms, f0, ..., hold = NULL) {
  lab <- new_label(fit$terms, "sinusoid")
  args <- c(list(av = fit, terms = terms), list(...))
  args$fixed <- c(args$fixed, hold, stats::setNames(f0, paste0(lab, ".f0")))
  res <- tryCatch(suppressWarnings(do.call(avfit, args)), error = function(e) NULL)
  if (is.null(res) || !is.finite(res$chi2)) NULL else res
}

# The residual signature that matches an accepted term: the one whose tau
# range holds (or lies nearest, within a factor 3) the term's characteristic
# tau (GM ADEV peak 1.893 Tc, sinusoid first peak 0.371 / f0, otherwise the
# tau where the term's share of the model is largest). Without one, the tau
# range is where the term carries over a quarter of the model AV.
locate_signature <- function(sig, fit, label, trial) {
  tau <- fit$data$tau
  comp <- tryCatch(av_model(tau, stats::coef(fit), freq = fit$freq, by_term = TRUE),
                   error = function(e) NULL)
  share <- if (!is.null(comp) && label %in% colnames(comp))
    comp[, label] / rowSums(comp) else rep(NA_real_, length(tau))
  cf <- stats::coef(fit)
  tchar <- if (startsWith(label, "gm")) gm_peak_ratio * cf[[paste0(label, ".tc")]]
    else if (startsWith(label, "sinusoid")) sin_peak_ratio / cf[[paste0(label, ".f0")]]
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
      txt <- s$description[j]
      if (isTRUE(trial$from_raw) && grepl("periodogram", trial$signature) &&
          startsWith(label, "sinusoid")) {
        f0 <- cf[[paste0(label, ".f0")]]
        lf <- trial$init[[1L]]$f0
        if (abs(f0 - lf) < 0.25 * lf) {
          txt <- paste0(txt, sprintf("; proposed by a periodogram line at %s Hz",
                                     format_num(lf)))
        }
      }
      return(list(tau_from = s$tau_from[j], tau_to = s$tau_to[j], text = txt))
    }
  }
  list(tau_from = range[1L], tau_to = range[2L],
       text = sprintf("no residual signature near tau = %s s (the term carries >25%% of the model AV over tau %s-%s s)",
                      format_num(tchar), format_num(range[1L]), format_num(range[2L])))
}

# Largest share of the model AV carried by one term instance over the taus.
max_share <- function(fit, label) {
  comp <- tryCatch(av_model(fit$data$tau, stats::coef(fit), freq = fit$freq,
                            by_term = TRUE), error = function(e) NULL)
  if (is.null(comp) || !label %in% colnames(comp)) return(1)
  max(comp[, label] / rowSums(comp))
}

# Label the new instance gets: "gm" -> "gm2" if one gm is already there.
new_label <- function(terms, effect) {
  if (effect %in% c("gm", "sinusoid")) paste0(effect, sum(terms == effect) + 1L)
  else effect
}

# Fitted parameters of one term instance as a named numeric vector
# (names without the label prefix: sigma, tc, amp, f0, or the kind).
effect_params <- function(fit, label) {
  cf <- stats::coef(fit)
  if (label %in% names(cf)) return(stats::setNames(cf[[label]], label))
  hit <- startsWith(names(cf), paste0(label, "."))
  stats::setNames(unname(cf[hit]), sub("^[^.]*\\.", "", names(cf)[hit]))
}

format_params <- function(par, effect) {
  units <- c(tc = " s", f0 = " Hz")
  nm <- names(par)
  txt <- vapply(seq_along(par), function(i) {
    u <- if (nm[i] %in% names(units)) units[[nm[i]]] else ""
    sprintf("%s=%s%s", nm[i], format(signif(par[[i]], 3)), u)
  }, character(1))
  paste(txt, collapse = ", ")
}

# Steps as text for print/summary of a refined fit.
format_steps <- function(steps) {
  if (is.null(steps) || !nrow(steps)) return(character(0))
  vapply(seq_len(nrow(steps)), function(i) {
    s <- steps[i, ]
    sprintf("%d. + %s (%s), tau %s-%s s: chi2/dof %.2f -> %.2f, RMS %.1f%% -> %.1f%%\n     evidence: %s",
            i, s$effect, s$params, format_num(s$tau_from), format_num(s$tau_to),
            s$chi2_before, s$chi2_after, s$rms_before, s$rms_after, s$evidence)
  }, character(1))
}

# Print the steps of a refined fit (after the avfit print).
print_steps <- function(x, ...) {
  txt <- format_steps(x$steps)
  if (length(txt)) {
    cat("Refinement steps (avrefine):\n")
    cat(txt, sep = "\n")
  } else if (!is.null(x$refine)) {
    cat("Refinement: nothing added (no effect paid by ", x$refine$criterion, ").\n",
        sep = "")
  }
  invisible(x)
}
