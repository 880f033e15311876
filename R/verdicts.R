# The verdict of every reading, from the data: measured only where the
# final model agrees with the curve, within the points' confidence limits
# (jointly at 95% over the range), over the taus the reading rests on; otherwise a bound (which side, why) or
# not determined (why). Series effects left in mark the readings they
# change. The datasheet, the exports, the plots, the CLI, the report and the
# guidance read these columns (verdict, why, tau_lo, tau_hi, biased_by,
# bias_change, removed), never decide a verdict of their own.

# Relative tolerance added to the points' confidence limits when the model
# is compared with the curve: the intervals of short-tau points are a few
# tenths of a percent wide, finer than any filter needs; a model within 2%
# of such a point agrees with it for every use of the reading.
verdict_tolerance <- 0.02

# A series effect left in that changes a reading by this much marks it; by
# `bias_bound` or more the reading is no longer a measurement of the sensor
# but an upper bound (every effect left in adds to the Allan variance).
bias_mark <- 0.05
bias_bound <- 0.25

verdict_levels <- c("measured", "upper_bound", "lower_bound", "not_determined")

# Verdict display: "measured", "upper bound", ...; in a sentence ("is an
# upper bound").
verdict_label <- function(v) gsub("_", " ", v, fixed = TRUE)
# The verdict of a mean of axes: measured only where every axis is; an
# upper bound where every axis is one; otherwise not determined.
mean_verdict <- function(v) {
  if (all(v == "measured")) "measured"
  else if (all(v == "upper_bound")) "upper_bound"
  else "not_determined"
}

verdict_phrase <- function(v) {
  ifelse(v == "upper_bound", "an upper bound",
         ifelse(v == "lower_bound", "a lower bound", verdict_label(v)))
}

# The verdict columns of readings `rd` (one row per reading) from `curve`
# (tau, adev, lower, upper, edf, m) and the model's layout `lay`; `ok` the
# usable points, `rel` the reliable ones (EDF >= 10); `unexplained` the
# fit's runs no catalogue effect explains (avrefine()'s $unexplained, in
# the curve's taus) or NULL.
reading_verdicts <- function(rd, curve, lay, ok, rel, unexplained = NULL) {
  ctx <- list(curve = curve, ok = ok, rel = rel,
              model = verdict_model(curve, lay),
              limits = !is.null(curve$lower) && !is.null(curve$upper))
  v <- lapply(seq_len(nrow(rd)), function(i) {
    judge_unexplained(rd[i, ], judge_reading(rd[i, ], ctx), unexplained, ctx)
  })
  rd$verdict <- vapply(v, `[[`, "", "verdict")
  rd$why <- vapply(v, `[[`, "", "why")
  rd$tau_lo <- vapply(v, `[[`, 0, "lo")
  rd$tau_hi <- vapply(v, `[[`, 0, "hi")
  rd$is_bound <- rd$verdict %in% c("upper_bound", "lower_bound")
  rd
}

# The final model's Allan variance at the curve's taus (NULL without one).
verdict_model <- function(curve, lay) {
  if (is.null(lay) || !nrow(lay)) return(NULL)
  tau <- curve$tau
  tau0 <- if (!is.null(curve$m) && is.finite(curve$m[1L]) && curve$m[1L] > 0)
    tau[1L] / curve$m[1L] else NULL
  comp <- tryCatch(model_components(tau, tau0, lay), error = function(e) NULL)
  if (is.null(comp) || !all(is.finite(comp))) return(NULL)
  rowSums(comp)
}

verdict <- function(v, why = "", lo = NA_real_, hi = NA_real_) {
  list(verdict = v, why = why, lo = lo, hi = hi)
}

# The share of the model `model` (AV at `tau`) that reading r's term makes.
reading_share <- function(r, tau, model) {
  r$value^2 * reading_entry(r$role)$basis(tau, NULL, NULL) / model
}

# One reading's verdict.
judge_reading <- function(r, ctx) {
  e <- reading_entry(r$role)
  tau <- ctx$curve$tau
  ok <- ctx$ok
  if (r$source == "none" || !is.finite(r$value)) {
    return(verdict("not_determined", paste0(
      "no ", r$term, " could be read from the curve",
      if (grepl("fit .* = 0", r$method)) " (the fit set it to 0)")))
  }
  if (r$source == "bound") {
    return(verdict("upper_bound", sprintf(
      "the %+g/2 region is not reached: %s is at most what the curve allows",
      2 * e$reading$slope, r$term), min(tau[ok]), max(tau[ok])))
  }
  flat <- identical(e$reading$anchor, "min")
  if (r$source == "slope" || is.null(ctx$model)) {
    return(judge_slope_reading(r, flat, ctx))
  }
  model <- ctx$model
  if (flat) {
    madev <- sqrt(model)
    at <- which(ok)[which.min(madev[ok])]
    span <- ok & madev <= 1.1 * madev[at]
    j <- which(ctx$rel)
    if (!length(j) || tau[at] >= tau[j[length(j)]]) {
      w <- which(span)
      return(verdict("upper_bound", paste0(
        "the model's minimum lies at or beyond the longest reliable tau ",
        "(EDF >= 10): the flat minimum is not reached"), min(tau[w]), max(tau[w])))
    }
  } else {
    share <- reading_share(r, tau, model)
    span <- ok & is.finite(share) & share >= 0.5
  }
  if (!any(span)) {
    return(verdict("upper_bound", sprintf(paste0(
      "the %s term never makes half of the model within the curve's taus: ",
      "%s is at most this"), r$term, r$term)))
  }
  judge_span(r, e, span, sqrt(model), ctx)
}

# A reading from a slope line (no model): the line touches the curve where
# it is read; a flat minimum at the longest reliable tau is not reached.
judge_slope_reading <- function(r, flat, ctx) {
  tau <- ctx$curve$tau
  if (!flat) return(verdict("measured", "", r$tau, r$tau))
  j <- which(ctx$rel)
  at <- j[which.min(ctx$curve$adev[j])]
  if (at == j[length(j)]) {
    return(verdict("upper_bound", paste0(
      "the Allan deviation still falls at the longest reliable tau ",
      "(EDF >= 10): the flat minimum is not reached"), tau[at], tau[at]))
  }
  verdict("measured", "", tau[at], tau[at])
}

# A measured reading whose range [lo, hi] overlaps a run the loop left
# unexplained is not measured: the run test over consecutive points sees
# structure the pointwise limits let pass. A run where the curve stays within
# `verdict_tolerance` of the model (a significant 0.5% wiggle at short tau,
# where the points' limits are finest) does not count, as in judge_span().
# Where the reading's term makes most of the model over the overlap, the run
# is attributed to it: the curve above the model there makes the reading a
# lower bound (the data show more variance than the term gives), below it an
# upper bound (every term adds variance, so the term is at most what the
# model gives). Where other terms make most of the model, or the runs
# disagree, it is not determined.
judge_unexplained <- function(r, v, unexplained, ctx) {
  if (v$verdict != "measured" || !NROW(unexplained) ||
      !is.finite(v$lo) || !is.finite(v$hi)) return(v)
  u <- unexplained[is.finite(unexplained$tau_from) & is.finite(unexplained$tau_to) &
                     unexplained$tau_from <= v$hi & unexplained$tau_to >= v$lo, ,
                   drop = FALSE]
  side <- vapply(seq_len(nrow(u)), function(i) {
    run_side(r, max(u$tau_from[i], v$lo), min(u$tau_to[i], v$hi), ctx)
  }, 0)
  u <- u[!is.na(side), , drop = FALSE]
  side <- side[!is.na(side)]
  if (!nrow(u)) return(v)
  runs <- paste(ifelse(u$tau_from == u$tau_to, paste0(format_num(u$tau_from), " s"),
                       sprintf("%s-%s s", format_num(u$tau_from), format_num(u$tau_to))),
                collapse = ", ")
  head <- sprintf("%s at tau %s %s in its range (see $unexplained)",
                  if (nrow(u) > 1L) "unexplained runs" else "an unexplained run",
                  runs, if (nrow(u) > 1L) "lie" else "lies")
  term <- r$term
  if (all(side == 1)) {
    return(verdict("lower_bound", sprintf(paste0(
      "%s: the curve lies above the model there, where %s makes most of it: ",
      "%s is at least this"), head, term, term), v$lo, v$hi))
  }
  if (all(side == -1)) {
    return(verdict("upper_bound", sprintf(paste0(
      "%s: the curve lies below the model there, where %s makes most of it: ",
      "%s is at most this"), head, term, term), v$lo, v$hi))
  }
  verdict("not_determined", paste0(head, if (any(side == 0))
    ": other terms make most of the model there"
    else ": the curve lies above the model at one and below it at another"),
    v$lo, v$hi)
}

# Over the curve's points in [from, to]: NA when the curve stays within
# `verdict_tolerance` of the model there; else +1 when it lies above the
# model (on average, in log) and the reading's term makes at least half of
# the model, -1 when below, 0 when the term does not make most of it (or
# the points or the model are missing).
run_side <- function(r, from, to, ctx) {
  cv <- ctx$curve
  w <- which(ctx$ok & cv$tau >= from & cv$tau <= to)
  if (is.null(ctx$model) || !length(w)) return(0)
  model <- ctx$model[w]
  ratio <- cv$adev[w] / sqrt(model)
  if (all(is.finite(ratio)) && max(abs(ratio - 1)) <= verdict_tolerance) return(NA_real_)
  share <- reading_share(r, cv$tau[w], model)
  if (!all(is.finite(share)) || mean(share) < 0.5) return(0)
  d <- mean(log(ratio))
  if (!is.finite(d) || d == 0) 0 else sign(d)
}

# Model ADEV `m` against the curve's limits over the points in `span`. A
# range with no reliable point (EDF >= 10) measures nothing: the reading is
# then an upper bound when the reliable points allow it (its term alone
# stays under their upper limits), else not determined.
judge_span <- function(r, e, span, m, ctx) {
  term <- r$term
  cv <- ctx$curve
  tau <- cv$tau
  lo <- min(tau[span])
  hi <- max(tau[span])
  if (!any(span & ctx$rel) && any(ctx$rel) && !is.null(cv$upper)) {
    j <- which(ctx$rel & is.finite(cv$upper))
    reach <- format_num(max(tau[ctx$rel]))
    allowed <- min(cv$upper[j] / sqrt(e$basis(tau[j], NULL, NULL)))
    if (length(j) && is.finite(allowed) && r$value <= allowed) {
      return(verdict("upper_bound", sprintf(paste0(
        "its range (%s-%s s) lies beyond the reliable taus (EDF >= 10 up to %s s): ",
        "%s is at most what the reliable points allow"), format_num(lo), format_num(hi),
        reach, term), lo, hi))
    }
    return(verdict("not_determined", sprintf(
      "its range (%s-%s s) lies beyond the reliable taus (EDF >= 10 up to %s s)",
      format_num(lo), format_num(hi), reach), lo, hi))
  }
  if (!ctx$limits) {
    return(verdict("not_determined",
                   "the curve has no confidence limits to check the model against", lo, hi))
  }
  w <- which(span & is.finite(cv$lower) & is.finite(cv$upper))
  if (!length(w)) {
    return(verdict("not_determined", "no point with confidence limits in its range", lo, hi))
  }
  lim <- joint_limits(cv, w)
  m <- m[w]
  above <- m > lim$upper * (1 + verdict_tolerance)
  below <- m < lim$lower * (1 - verdict_tolerance)
  rng <- sprintf("%s-%s s", format_num(lo), format_num(hi))
  if (!any(above | below)) return(verdict("measured", "", lo, hi))
  if (!any(below)) {
    f <- max(m[above] / cv$adev[w][above])
    return(verdict("upper_bound", sprintf(paste0(
      "the model lies above the curve's confidence limits over %s (up to %.2gx): ",
      "%s is at most this"), rng, f, term), lo, hi))
  }
  if (!any(above)) {
    f <- max(cv$adev[w][below] / m[below])
    return(verdict("lower_bound", sprintf(paste0(
      "the model lies below the curve's confidence limits over %s (by up to %.2gx): ",
      "%s is at least this"), rng, f, term), lo, hi))
  }
  verdict("not_determined", sprintf(
    "the model leaves the curve's confidence limits on both sides over %s", rng), lo, hi)
}

# Limits of the curve's points `w` that hold jointly at `verdict_level`
# (Bonferroni over the points of the range): 68% limits point by point
# would reject a true model somewhere in most ranges of five or more
# points. From each point's EDF (chi-square); the curve's own limits where
# it has no EDF.
verdict_level <- 0.95
joint_limits <- function(cv, w) {
  lower <- cv$lower[w]
  upper <- cv$upper[w]
  edf <- if (is.null(cv$edf)) rep(NA_real_, length(w)) else cv$edf[w]
  ok <- is.finite(edf) & edf > 0
  if (any(ok)) {
    a <- (1 - verdict_level) / length(w)
    lower[ok] <- cv$adev[w][ok] * sqrt(edf[ok] / stats::qchisq(1 - a / 2, edf[ok]))
    upper[ok] <- cv$adev[w][ok] * sqrt(edf[ok] / stats::qchisq(a / 2, edf[ok]))
  }
  list(lower = lower, upper = upper)
}

# Series effects (a detect_series_effects() pass) and the readings: each
# reading a kind left in changes by `bias_mark` or more is marked
# (`biased_by`, `bias_change`: the relative change of the Allan deviation
# with the kind left in, at the tau of the reading's range where its term
# weighs most: the short end for a falling line, the long end for a rising
# one, the middle of a flat minimum). By `bias_bound` or more the reading
# no longer measures the sensor: a measured one becomes an upper bound,
# a lower bound (of the curve with the effect in) not determined.
# `removed`: the kinds taken out before the curve (the readings are the
# corrected ones).
mark_series_bias <- function(rd, pass) {
  n <- nrow(rd)
  rd$biased_by <- rep("", n)
  rd$bias_change <- rep(NA_real_, n)
  rd$removed <- rep(if (is.null(pass) || !length(pass$removed)) ""
                    else paste(pass$removed, collapse = ","), n)
  if (is.null(pass) || !nrow(pass$table)) return(rd)
  left <- unique(pass$table$kind[!pass$table$removed])
  ak <- pass$adev_kinds
  for (i in seq_len(n)) {
    if (!is.finite(rd$value[i])) next
    lo <- rd$tau_lo[i]
    hi <- rd$tau_hi[i]
    if (!is.finite(lo) || !is.finite(hi)) lo <- hi <- rd$tau[i]
    at <- if (rd$slope[i] < 0) lo else if (rd$slope[i] > 0) hi else sqrt(lo * hi)
    ch <- vapply(left, function(k) {
      d <- ak[ak$kind == k & ak$before > 0 & ak$after > 0, , drop = FALSE]
      if (nrow(d) < 2L) return(NA_real_)
      exp(stats::approx(log(d$tau), log(d$before / d$after), log(at), rule = 2)$y) - 1
    }, 0)
    ch <- ch[is.finite(ch) & abs(ch) >= bias_mark]
    if (!length(ch)) next
    ch <- ch[order(-abs(ch))]
    k <- names(ch)[1L]
    rd$biased_by[i] <- paste(names(ch), collapse = ",")
    rd$bias_change[i] <- ch[[1L]]
    if (ch[[1L]] < bias_bound) next
    note <- sprintf(paste0("%s left in the series raise the Allan deviation at %s s by ",
                           "%+.0f%%; remove = \"%s\" corrects it"),
                    k, format_num(at), 100 * ch[[1L]], k)
    rd$why[i] <- switch(rd$verdict[i],
      measured = paste0(note, ": ", rd$term[i], " is at most this"),
      lower_bound = paste0(note, ": ", rd$term[i], " of the sensor is not determined"),
      paste0(rd$why[i], "; ", note))
    rd$verdict[i] <- switch(rd$verdict[i], measured = "upper_bound",
                            lower_bound = "not_determined", rd$verdict[i])
  }
  rd$is_bound <- rd$verdict %in% c("upper_bound", "lower_bound")
  rd
}

# Alternative descriptions of the record (avrefine()'s $refine$alternatives: an
# effect the raw data confirm that the final model lacks because the curve
# gains less than min_gain with it) and the readings: one that the
# alternative's model reads `bias_bound` or more lower no longer measures
# the sensor but bounds it from above (its term took what the left-out
# effect describes); one it reads that much higher is not determined.
# `alternatives`: model_alternatives(); the other arguments as
# channel_readings() makes them.
mark_model_choice <- function(rd, alternatives, curve, ok, rel, tau_min, sensor) {
  if (!length(alternatives)) return(rd)
  entries <- entries_with("reading")
  for (a in alternatives) {
    lay <- check_coef(a$coef)
    alt <- vapply(entries, function(e) {
      reading_row(e, lay, a$coef, NULL, curve, ok, rel, tau_min, sensor)$value
    }, 0)
    what <- effect_entry(split_term(a$effect)$kind)$title
    gained <- if (a$gain < a$min_gain) {
      sprintf("the curve gains only %s with it, under min_gain %s", format_num(a$gain),
              format_num(a$min_gain))
    } else {
      sprintf("the steps ended below min_gain %s, though the final model gains %s with it",
              format_num(a$min_gain), format_num(a$gain))
    }
    for (i in seq_len(nrow(rd))) {
      v <- rd$value[i]
      w <- alt[i]
      if (!rd$verdict[i] %in% c("measured", "lower_bound") || !is.finite(v) ||
          !is.finite(w) || v <= 0) next
      change <- w / v - 1
      if (abs(change) < bias_bound) next
      note <- sprintf(paste("a %s (%s) that the raw data confirm (%s) is not in the model:",
                            "%s; with it %s reads %s (%+.0f%%)"),
                      what, a$params, a$evidence, gained, rd$term[i], format_num(w),
                      100 * change)
      down <- change < 0 && rd$verdict[i] == "measured"
      rd$why[i] <- if (down) paste0(note, ": ", rd$term[i], " is at most this")
        else if (nzchar(rd$why[i])) paste0(rd$why[i], "; ", note) else note
      rd$verdict[i] <- if (down) "upper_bound" else "not_determined"
    }
  }
  rd$is_bound <- rd$verdict %in% c("upper_bound", "lower_bound")
  rd
}

# The alternatives of a refined fit (its $refine$alternatives) for
# mark_model_choice(), their amplitudes scaled by `k` as the readings'
# coefficients are; NULL when there are none.
model_alternatives <- function(fit, k = 1) {
  r <- if (is.null(fit)) NULL else fit$refine
  nr <- r$alternatives
  cf <- r$alternative_coefs
  if (!NROW(nr) || length(cf) != nrow(nr)) return(NULL)
  lapply(seq_len(nrow(nr)), function(i) {
    co <- cf[[i]]
    if (k != 1) {
      lay <- check_coef(co)
      co <- co * ifelse(lay$role[match(names(co), lay$name)] == "amp", k, 1)
    }
    list(coef = co, effect = nr$effect[i], params = nr$params[i], gain = nr$gain[i],
         evidence = nr$evidence[i], min_gain = r$min_gain)
  })
}

# One line for a file's comment or a summary: the verdict and what marks it.
verdict_note <- function(verdict, why = "", biased_by = "", bias_change = NA_real_) {
  out <- toupper(verdict_label(verdict))
  if (verdict != "measured" && nzchar(why)) out <- paste0(out, ": ", why)
  if (nzchar(biased_by) && is.finite(bias_change) && verdict == "measured") {
    out <- sprintf("%s; %s left in change it by %+.0f%% (remove = \"%s\")", out,
                   biased_by, 100 * bias_change, strsplit(biased_by, ",")[[1L]][1L])
  }
  out
}

# A model term that is no reading (a Gauss-Markov term a filter takes from
# kalman_params()) is measured when the fit determines each of its values
# within a factor `term_factor` at 95% (1.96 standard errors of its log)
# and held none of them; otherwise not determined, with the widest
# interval. A record of a few thousand seconds often cannot tell a slow
# term's time constant to better than that (bench/gm-tc-information.R:
# the Cramer-Rao bound of log tc is 0.1-0.5 on the battery's GM cases).
# `free_only`: judge the values the fit estimated and pass over the held
# ones (a line's frequency or a band's shape read from the periodogram:
# held, but not for want of record); NULL when every value is held.
term_factor <- 2
term_verdict <- function(fit, label, free_only = FALSE) {
  lay <- if (is.null(fit)) NULL else fit$layout
  lay <- lay[lay$label == label, , drop = FALSE]
  if (!NROW(lay)) return(verdict("not_determined", "the term is not in the fit"))
  value <- unname(fit$coefficients[lay$name])
  se <- fit_se(fit)
  se <- if (is.null(se)) rep(NA_real_, nrow(lay)) else unname(se[lay$name])
  # seconds are the one unit a term's own values name (an amplitude is in
  # the curve's rate unit, which the fit does not carry)
  unit <- ifelse(lay$unit == "s", " s", "")
  held <- lay$fixed %in% TRUE | !is.finite(se) | se <= 0
  if (free_only) {
    if (all(held)) return(NULL)
    lay <- lay[!held, , drop = FALSE]
    value <- value[!held]
    se <- se[!held]
    unit <- unit[!held]
    held <- held[!held]
  }
  if (any(held)) {
    return(verdict("not_determined", sprintf(
      "%s held in the final fit: no standard error", paste(lay$param[held], collapse = ", "))))
  }
  zero <- !(is.finite(value) & value > 0)
  if (any(zero)) {
    return(verdict("not_determined", sprintf("%s at 0 in the fit", lay$param[zero][1L])))
  }
  half <- stats::qnorm(0.975) * se / value         # half-width of the log interval
  k <- which.max(half)
  lo <- value[k] * exp(-half[k])
  hi <- value[k] * exp(half[k])
  if (half[k] <= log(term_factor)) return(verdict("measured", "", lo, hi))
  verdict("not_determined", sprintf(
    "%s's 95%% interval %s-%s%s is wider than a factor %s either way of %s%s",
    lay$param[k], format_num(lo), format_num(hi), unit[k], format_num(term_factor),
    format_num(value[k]), unit[k]), lo, hi)
}

# The verdicts (term_verdict()) of a channel's fitted instances that are no
# reading: neither a reading's term nor folded into one. Named by their
# labels as unfolded_coef() numbers them, the names kalman_params() prints
# (a folded fast GM before a slow one makes the slow one "gm1" there,
# while the fit knows it as "gm2"). `free_only`: as term_verdict()'s (a
# term with every value held is left out).
own_term_verdicts <- function(fit, coef, rd, free_only = FALSE) {
  if (is.null(fit) || !length(coef)) return(list())
  folded <- unlist(strsplit(rd$folded[nzchar(rd$folded)], ",", fixed = TRUE))
  lay <- check_coef(coef)
  kept <- unique(lay$label[!lay$label %in% folded])
  shown <- unique(check_coef(unfolded_coef(coef, folded = folded))$label)
  own <- !shown %in% rd$term
  out <- lapply(kept[own], function(l) term_verdict(fit, l, free_only = free_only))
  names(out) <- shown[own]
  out[!vapply(out, is.null, NA)]
}

# Those of axis `ch` whose estimated values the record does not determine
# (own_term_verdicts() over the values the fit estimated: a value held at
# the raw data's reading is no want of record); the guidance and the
# datasheet say so.
undetermined_own_terms <- function(ch, rd) {
  tv <- own_term_verdicts(ch$fit, ch$coef, rd, free_only = TRUE)
  tv[vapply(tv, function(v) v$verdict != "measured", NA)]
}
