# The loop's rules: which terms a step adds and replaces, which instances
# are valid, the candidate trials of a step, where an accepted effect's
# signature sits, and the row it adds to the steps.

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
# (the filter replaces N) leave; with the entry's `replaces_instance`, only
# the instances it names (a measured band replaces the resonance at that
# band), judged on the current model `fit` against the new instance's
# known values `par`.
model_terms <- function(terms, effect, par = NULL, fit = NULL) {
  sp <- split_term(effect)
  e <- effect_entry(sp$kind, sp$variant)
  kinds <- split_term(terms)$kind
  gone <- kinds %in% e$replaces
  if (any(gone) && !is.null(e$replaces_instance)) {
    labs <- term_labels(terms)
    for (i in which(gone)) {
      old <- if (is.null(fit)) list() else
        as.list(instance_params(stats::coef(fit), fit$layout, labs[i]))
      gone[i] <- isTRUE(e$replaces_instance(as.list(par), kinds[i], old))
    }
  }
  structure(c(terms[!gone], effect), gone = gone)
}

# Values named by the labels of `terms` (held values "resonance2.fr"),
# renamed for `new_terms` = model_terms(terms, ...): a replaced instance
# leaves (its values are dropped) and the later instances of its kind move
# down a number (instances of a kind keep their order). `keep_gone`: the
# values of the instances that left stay, under names no term has (pinned
# values: a value pinned once is not proposed again).
relabel_values <- function(v, terms, new_terms, keep_gone = FALSE) {
  gone <- attr(new_terms, "gone")
  if (!length(v) || !any(gone)) return(v)
  map <- label_map(terms, gone)
  lab <- sub("\\.[^.]*$", "", names(v))
  par <- sub("^.*\\.", "", names(v))
  ok <- lab %in% names(map)
  out <- v[ok]
  # bare coefficients ("N") are their own label
  bare <- !grepl(".", names(v)[ok], fixed = TRUE)
  names(out) <- ifelse(bare, map[lab[ok]], paste0(map[lab[ok]], ".", par[ok]))
  if (keep_gone && any(!ok)) {
    out <- c(out, stats::setNames(v[!ok], paste0("left:", names(v)[!ok])))
  }
  out
}

# The labels of `terms` that stay when the instances `gone` (logical, one
# per term) leave, named by their labels before: labels number the
# instances of one kind in order (term_labels() sorts the kinds), so the
# j-th kept instance of a kind takes its kind's j-th label.
label_map <- function(terms, gone) {
  kinds <- split_term(terms)$kind
  map <- character()
  for (k in unique(kinds[!gone])) {
    i <- which(kinds == k)
    map[term_labels(terms[i])[!gone[i]]] <- term_labels(terms[i][!gone[i]])
  }
  map
}

# Kinds that may still be added next to `present`: repeatable ones or those
# absent, and never one that a present term replaced (kind by kind; an
# entry that replaces instance by instance leaves the others addable).
addable_kind <- function(kind, present) {
  pk <- split_term(present)$kind
  replaced <- unlist(lapply(unique(pk), function(k) {
    e <- effect_entry(k)
    if (is.null(e$replaces_instance)) e$replaces
  }))
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
        score = 0, release = FALSE, release_late = FALSE, traced = FALSE, stringsAsFactors = FALSE)
      r$init <- list(list())
      r$pin <- list(NULL)
      r$after <- list(NULL)
      rows[[length(rows) + 1L]] <- r
    }
  }
  if (!length(rows)) return(data.frame())
  # every row in one column order (the traced rows carry more columns)
  do.call(rbind, lapply(rows, function(r) r[, c("effect", "tau_from", "tau_to",
                                                "signature", "score", "release", "release_late",
                                                "init", "pin", "after", "traced")]))
}

# The trials whose `after` values (a proposal's prerequisites: the stronger
# lines of its harmonic set) are all pinned in the model already (`fixed`).
# A set is entered strongest first, so a weak harmonic is not fitted before
# a stronger one and left to absorb it on the curve.
ready_trials <- function(trials, fixed) {
  if (!nrow(trials) || is.null(trials$after)) return(trials)
  ok <- vapply(trials$after, function(a) all(same_values(a, fixed)), NA)
  trials[ok, , drop = FALSE]
}

# Proposals that pin a value the model holds already (a periodogram line
# in it) are dropped, and of the rest at most `max_pinned_trials` per entry
# are kept, in the order the entry proposed them (strongest first): an
# axis's own weaker line beyond the fifth strongest (below a square wave's
# harmonics) is reached once the stronger ones are in the model, and a
# step screens a bounded number of them.
max_pinned_trials <- 5L
fresh_pinned_trials <- function(trials, fixed) {
  if (!nrow(trials) || is.null(trials$pin)) return(trials)
  held <- vapply(trials$pin, function(p) any(same_values(p, fixed)), NA)
  trials <- trials[!held, , drop = FALSE]
  pinned <- lengths(trials$pin) > 0L
  rank <- stats::ave(seq_len(nrow(trials)), trials$effect, pinned, FUN = seq_along)
  trials[!pinned | rank <= max_pinned_trials, , drop = FALSE]
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
  # (a term that never carries a quarter of the model, a weak line beside
  # a band, is placed where its share is largest)
  top <- if (all(is.na(share))) NA_integer_ else which.max(share)
  range <- if (length(big)) range(tau[big]) else if (!is.na(top)) tau[c(top, top)] else range(tau)
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
  text <- if (length(big) || is.na(top)) {
    sprintf("no residual signature near tau = %s s (the term carries >25%% of the model AV over tau %s-%s s)",
            format_num(tchar), format_num(range[1L]), format_num(range[2L]))
  } else {
    sprintf("no residual signature near tau = %s s (the term carries at most %s%% of the model AV, at tau = %s s)",
            format_num(tchar), format_num(100 * share[top], 2), format_num(tau[top]))
  }
  list(tau_from = range[1L], tau_to = range[2L], text = text)
}

# Largest share of the model AV carried by one term instance over the
# taus, beside the instances other than it whose values are all `fixed`
# (measured by the raw data, a sharp line at its record amplitude): their
# AV is known, not the curve's to share out (a measured accelerometer's
# 9.8 Hz resonance, 1% of the variance, confirmed by its band and
# lowering chi2 by a third, carried 1.8% of the model AV beside an added
# 9.13 Hz line pinned there, and was taken for a refit artefact).
max_share <- function(fit, label, fixed = NULL) {
  comp <- fit$components
  if (!label %in% colnames(comp)) return(1)
  lay <- fit$layout
  others <- setdiff(colnames(comp), label)
  measured <- others[vapply(others, function(l) {
    nm <- lay$name[lay$label == l]
    length(nm) > 0L && all(nm %in% names(fixed))
  }, NA)]
  max(comp[, label] / rowSums(comp[, setdiff(colnames(comp), measured), drop = FALSE]))
}

# One accepted step: the effect, where its signature sits (`loc`), its
# parameters, the evidence, and the fit before and after it.
step_row <- function(effect, label, loc, par, evidence, confirmed, before,
                     after, crit_before, crit_after) {
  out <- new_steps(effect = effect, label = label,
                   tau_from = loc$tau_from, tau_to = loc$tau_to,
                   params = format_params(par, effect),
                   evidence = evidence, confirmed = confirmed,
                   chi2_before = before$chi2, chi2_after = after$chi2,
                   rms_before = before$rms, rms_after = after$rms,
                   crit_before = crit_before, crit_after = crit_after)
  # the values it was taken at (final_stand_in() reads how far they moved)
  attr(out, "values") <- par
  out
}

# ---- terms that describe a series effect again --------------------------------

# A model term that stands in for a series effect the same run found and
# left in the data (a Gauss-Markov term describing an unremoved warm-up, a
# slow term describing a bias step): where the term dominates the model
# (of the taus where it holds at least half the fitted AV, the one where
# its own AV is largest: a GM's peak), the AV that series effect adds to
# the curve (ADEV^2 with it minus without it, from the series pass) is at
# least `share` of the term's own AV: with the series effect taken out, the
# term would have nothing left to describe there. (A part only, 0.68 on a
# measured accelerometer whose 20 s GM sits beside six 17-60 s transients,
# does not make the term a duplicate: a GM's own excursions are transients
# to the series pass.) Returns NULL, or a one-row data frame: the series
# kind, that ratio and the tau it was read at.
series_duplicate <- function(series, fit, label, share = 1) {
  if (is.null(series) || !NROW(series$table) || !NROW(series$adev_kinds)) return(NULL)
  comp <- fit$components
  if (!label %in% colnames(comp)) return(NULL)
  tab <- series$table
  left <- unique(tab$kind[!tab$removed])
  tau <- fit$data$tau
  j <- term_peak(comp, label)
  own <- comp[j, label]
  if (!(own > 0)) return(NULL)
  out <- NULL
  for (k in left) {
    a <- series$adev_kinds[series$adev_kinds$kind == k, , drop = FALSE]
    ex <- a$before^2 - a$after^2
    ok <- is.finite(ex) & a$tau > 0
    if (sum(ok) < 2L || tau[j] < min(a$tau[ok]) || tau[j] > max(a$tau[ok])) next
    at <- stats::approx(log(a$tau[ok]), ex[ok], log(tau[j]))$y
    r <- at / own
    if (is.finite(r) && r >= share && (is.null(out) || r > out$ratio)) {
      out <- data.frame(series_kind = k, ratio = r, tau = tau[j], how = "share",
                        stringsAsFactors = FALSE)
    }
  }
  out
}

# A term that pays only for what a series effect left in adds to the curve
# (a Gauss-Markov term taking a warm-up's excess together with part of the
# axis's own long-tau level, which the share rule above does not reach):
# where the kinds left in add at least `min_share` of the term's AV at the
# tau it weighs most, the model with and without the term are refitted on
# the curve with those kinds' excess (ADEV^2 with minus without each, from
# the series pass) taken out; if the term no longer pays by the criterion
# there (by `gain`: twice min_gain for a term the raw data did not
# confirm, as unconfirmed_marginal() asks of the whole curve), it
# describes the series effect. Kinds a noise term's own
# excursions can produce (the entry's `noise_lookalike`: transients) are
# not taken out: a measured accelerometer's 20 s GM is also six transients
# to the series pass. Returns NULL or a one-row data
# frame like series_duplicate()'s (`ratio` the kinds' share at that tau).
series_pays_without <- function(st, new, label, gain = st$args$min_gain,
                                min_share = 0.1, effect = NULL, par = NULL, ev = NULL,
                                without = st$current, without_settings = st$settings) {
  series <- st$series
  if (is.null(series) || !NROW(series$table) || !NROW(series$adev_kinds)) return(NULL)
  left <- unique(series$table$kind[!series$table$removed])
  left <- left[!vapply(left, function(k) isTRUE(effect_entry(k)$noise_lookalike), NA)]
  comp <- new$components
  if (!length(left) || !label %in% colnames(comp)) return(NULL)
  # the components are at the fitted taus (a tau_range may leave some of
  # the curve out): the share is read there, the excess taken out of the
  # whole curve
  j <- term_peak(comp, label)
  # the term's AV there, read no higher than the curve's own: a term the
  # fit lets overshoot the few long-tau points (a rate ramp 14x above the
  # curve at its last tau, standing in for a warm-up's tail) does not
  # escape the check by its overshoot
  own <- min(comp[j, label], new$data$avar[j])
  at <- kind_excess(series$adev_kinds, left, new$data$tau[j])
  if (is.null(at) || !(own > 0) || sum(at) < min_share * own) return(NULL)
  # Support the raw data give only with the series effects in (a block
  # mean's ACF reads a bias step left in as slow correlation: a step at
  # 1571 s on a measured accelerometer read 139 s for a 241 s GM, without
  # it 88 s, undecided) does not count: the term must then pay as one
  # the raw data leave undecided, twice min_gain.
  if (isTRUE(ev$support) && !is.null(effect) && !is.null(st$raw)) {
    tab <- series$table
    raw2 <- diag_without(st$raw, tab[!tab$removed & tab$kind %in% left, , drop = FALSE],
                         st$args$freq)
    ev2 <- raw_evidence(effect, as.list(par), raw2, diag_series(raw2), st$args$freq)
    if (!isTRUE(ev2$support)) gain <- max(gain, 2 * st$args$min_gain)
  }
  cv <- curve_of_fit(new)
  # signed: a step against the axis's own wander lowers the long-tau
  # points (a measured accelerometer's 1310-2620 s points fell to a third),
  # a drop a GM's tail then describes; without the step they come back
  total <- rowSums(kind_excess(series$adev_kinds, left, cv$data$tau, signed = TRUE))
  # taken out to at most 90% of a point: the excess is an estimate too
  cv$data$avar <- pmax(cv$data$avar - total, 0.1 * cv$data$avar)
  refit_on <- function(fit, settings = st$settings) {
    args <- refit_args(fit, fit$terms, settings)
    args$av <- cv
    try_refit(args, "refit without the series effects")$fit
  }
  f_out <- refit_on(without, without_settings)
  f_in <- refit_on(new)
  if (is.null(f_out) || is.null(f_in)) return(NULL)
  if (refine_crit(st, f_in) < refine_crit(st, f_out) - gain) return(NULL)
  data.frame(series_kind = colnames(at)[which.max(at[1L, ])], ratio = sum(at) / own,
             tau = new$data$tau[j], how = "refit", stringsAsFactors = FALSE)
}

# Does instance `label` of model `f` (entry `effect`, values `par`, raw-data
# evidence `ev`) stand in for a series effect this run found and left in
# the data: by the share rule, or by paying only for what those effects
# add to the curve against the model `without` it (twice min_gain for a
# term the raw data leave undecided)? NULL or series_duplicate()'s row.
series_stand_in <- function(st, f, label, effect, par, ev, without = st$current,
                            without_settings = st$settings) {
  dup <- series_duplicate(st$series, f, label)
  if (!is.null(dup)) return(dup)
  need <- st$args$min_gain * (1 + rests_on_curve(effect, ev, st$raw))
  series_pays_without(st, f, label, gain = need, effect = effect, par = par, ev = ev,
                      without = without, without_settings = without_settings)
}

# Why such an instance is refused, for $refine$rejected.
series_stand_in_text <- function(dup) {
  if (dup$how == "share") {
    sprintf(paste("describes the %s found in the series (not removed): it adds",
                  "%s%% of this term's AV at tau %s s"), dup$series_kind,
            format_num(100 * dup$ratio), format_num(dup$tau))
  } else {
    sprintf(paste("pays only for the %s found in the series (not removed): with",
                  "its excess (%s%% of this term's AV at tau %s s) taken out of",
                  "the curve the term no longer pays"), dup$series_kind,
            format_num(100 * dup$ratio), format_num(dup$tau))
  }
}

# Where a term instance weighs most: of the taus where it holds at least
# half the model AV, the one of its largest AV (a GM's peak); else where
# its share is largest. A row index of the fit's components.
term_peak <- function(comp, label) {
  sh <- comp[, label] / rowSums(comp)
  if (any(sh >= 0.5)) which.max(comp[, label] * (sh >= 0.5)) else which.max(sh)
}

# The AV each kind left in adds at the taus `tau` (ADEV^2 with it minus
# without it, interpolated on log tau; 0 outside the pass's taus, and
# where taking it out raised the curve unless `signed`): a matrix, one
# column per kind, or NULL.
kind_excess <- function(adev_kinds, kinds, tau, signed = FALSE) {
  out <- NULL
  for (k in kinds) {
    a <- adev_kinds[adev_kinds$kind == k, , drop = FALSE]
    e <- a$before^2 - a$after^2
    ok <- is.finite(e) & a$tau > 0
    if (sum(ok) < 2L) next
    v <- stats::approx(log(a$tau[ok]), if (signed) e[ok] else pmax(e[ok], 0), log(tau))$y
    v[is.na(v)] <- 0
    out <- cbind(out, v)
    colnames(out)[ncol(out)] <- k
  }
  out
}

# Could the raw data have confirmed this instance (its entry has a check,
# the loop has the series) and did not decide (`ev$support` NA)?
rests_on_curve <- function(effect, ev, raw) {
  if (is.null(raw) || !is.na(ev$support %||% NA)) return(FALSE)
  sp <- split_term(effect)
  !is.null(effect_entry(sp$kind, sp$variant)$evidence)
}

# An effect whose raw-data check could have confirmed it and did not (an
# exponential ACF found, but at a Tc 2-3x from the fitted one) rests on the
# curve alone; a marginal gain there moves with anything that reshapes the
# curve's other end (a line fitted exactly at m = 1 freed the short-tau fit
# and tipped a 118 s GM over min_gain). On the scale where raw support
# counts as a gain of `min_gain`, such an effect must show the confirmed
# one's total, 2 min_gain, from the curve. Curve-only runs, and entries
# with no raw-data check, are judged by the curve as before.
unconfirmed_marginal <- function(effect, ev, gain, min_gain, raw) {
  if (!rests_on_curve(effect, ev, raw) || gain >= 2 * min_gain) return(NULL)
  sprintf(paste("the raw data do not confirm it (%s) and the curve alone gains",
                "%s, less than 2 min_gain"), ev$text, format_num(gain))
}
