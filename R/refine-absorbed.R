# The loop's stage for instances the raw data measure that the model's
# other instances took on the curve (stage_absorbed()).

# An instance the raw data measure exactly (a sharp periodogram line:
# its frequency, and its amplitude over the whole record) that the model
# does not hold, lying in the reach of an instance that can take its
# power on the curve (a resonance or a measured band: the catalogue's
# `absorbs`), is one the curve cannot tell from that instance's shape.
# Fitted while the line was not yet in the model, the band took its power
# and moved towards it; the line, screened beside the band held there,
# gained nothing (an AR(2) at 9.8 Hz with a line at 8.97 Hz: one
# resonance at 9.65 Hz, the line refused). Each such instance, strongest
# first, is added held at the raw data's values, the absorbing instance
# started again where the raw data read it without the line (and where
# it stands), the rest free. It is taken when the criterion rises less
# than `min_gain` (the values held are measured, not charged, as
# stage_hold() charges none), the raw data still confirm it and every
# earlier effect keeps its raw-data support. At most `max_absorbed`.
stage_absorbed <- function(st, max_absorbed = 4L) {
  each_absorbed(st, take_absorbed, max_absorbed)
}

# Every candidate of stage_absorbed() on the current model, strongest
# first (at most `max_absorbed`): the seeds a revisit takes first
# (stage_revisit()).
absorbed_seeds <- function(st, max_absorbed = 4L) {
  st$seen <- list()                # (on this copy of the state only)
  st <- each_absorbed(st, function(s, cand) {
    s$seen[[length(s$seen) + 1L]] <- cand
    s
  }, max_absorbed)
  st$seen
}

# `take(st, cand)` for each absorbed_candidate() in turn (on the model as
# `take` leaves it), each place once; the state `take` returns last.
each_absorbed <- function(st, take, max_absorbed) {
  if (is.null(st$raw)) return(st)
  tried <- numeric()
  for (round in seq_len(max_absorbed)) {
    cand <- absorbed_candidate(st, st$current, tried)
    if (is.null(cand)) break
    tried <- c(tried, cand$at)
    st <- take(st, cand)
  }
  st
}

# The strongest unheld instance (the catalogue's `unheld`) inside the
# reach of an instance of `fit` that `absorbs` it, not at a place in
# `tried`: list(effect, values, at, label (the absorbing instance), start
# (its nonlinear values to start from, named by coefficient), what), or
# NULL.
absorbed_candidate <- function(st, fit, tried) {
  labs <- term_labels(fit$terms)
  cf <- stats::coef(fit)
  reach <- list()
  for (i in seq_along(fit$terms)) {
    sp <- split_term(fit$terms[i])
    e <- effect_entry(sp$kind, sp$variant)
    if (!is.function(e$absorbs)) next
    a <- e$absorbs(as.list(instance_params(cf, fit$layout, labs[i])), st$raw)
    if (!is.null(a)) reach[[length(reach) + 1L]] <- c(a, list(label = labs[i]))
  }
  if (!length(reach)) return(NULL)
  for (e in entries_with("unheld")) {
    for (u in e$unheld(st$raw, fit) %||% list()) {
      if (any(abs(tried - u$at) <= 1e-9 * u$at)) next
      for (a in reach) {
        if (u$at < a$lo || u$at > a$hi) next
        start <- a$start
        if (length(start)) names(start) <- paste0(a$label, ".", names(start))
        return(list(effect = e$name, values = u$values, at = u$at, label = a$label,
                    start = start, what = a$what))
      }
    }
  }
  NULL
}

# The model with `cand` added at its raw values (absorbed_candidate()),
# refitted from the absorbing instance's raw read and from where it
# stands; the better taken when it passes stage_absorbed()'s rules.
take_absorbed <- function(st, cand) {
  cur <- st$current
  step <- length(st$steps) + 1L
  tm <- model_terms(cur$terms, cand$effect)
  lab <- new_label(cur$terms, cand$effect)
  pin <- stats::setNames(cand$values, paste0(lab, ".", names(cand$values)))
  settings <- st$settings
  settings$fixed <- c(settings$fixed, pin)
  nl <- stats::coef(cur)[cur$layout$role == "nonlinear"]
  nl <- nl[!names(nl) %in% names(settings$fixed)]
  moved <- nl
  again <- intersect(names(cand$start), names(moved))
  moved[again] <- cand$start[again]
  best <- NULL
  c1 <- Inf
  for (start in unique(list(moved, nl))) {
    args <- refit_args(cur, c(tm), settings, start = start)
    if (!is.null(st$tau_range)) args$tau_range <- c(st$tau_range[1L], Inf)
    r <- state_refit(st, args, "refit with an instance another took on the curve", cand$effect, step)
    st <- r$st
    c_r <- if (is.null(r$fit)) Inf else refine_crit(st, r$fit)
    if (is.finite(c_r) && c_r < c1) {
      best <- r$fit
      c1 <- c_r
    }
  }
  if (is.null(best)) return(st)
  c0 <- refine_crit(st, cur)
  par <- instance_params(stats::coef(best), best$layout, lab)
  ev <- raw_evidence(cand$effect, as.list(par), st$raw, diag_series(st$raw),
                     st$args$freq, best, lab)
  if (!isTRUE(ev$support) || !taken_at_raw_values(st, best, cur)) {
    st$rejected <- add_rejected(st$rejected, step, cand$effect, par, sprintf(
      "in the reach of %s: held at the raw data's values it %s",
      cand$what,
      if (!isTRUE(ev$support)) paste("is not confirmed by the raw data:", ev$text)
      else if (c1 > c0 + st$args$min_gain)
        sprintf("raises the criterion by %s, min_gain or more", format_num(c1 - c0))
      else "leaves an earlier effect contradicted by the raw data"))
    return(st)
  }
  # where it sits among the residual signatures of the model without it
  sig <- residual_signatures(cur$data$tau, stats::residuals(cur), level = st$args$level)
  loc <- locate_signature(sig, best, lab)
  evidence <- sprintf(paste0("%s; raw data: %s; added at the end at the raw data's values:",
                             " in the reach of %s, which had taken its power on the curve",
                             " (criterion %s)"),
                      loc$text, ev$text, cand$what,
                      if (c1 <= c0) sprintf("%s lower", format_num(c0 - c1))
                      else sprintf("%s higher, less than min_gain", format_num(c1 - c0)))
  st$steps[[length(st$steps) + 1L]] <- step_row(cand$effect, lab, loc, par, evidence,
                                                TRUE, cur, best, c0, c1)
  st$pins[length(st$steps)] <- list(pin)
  st$settings <- settings
  st$current <- best
  st
}
