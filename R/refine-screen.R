# One candidate trial of a step: the refit with the candidate added, the
# rules it must pass (it pays by the criterion and chi2, explains something,
# is a valid instance, is not contradicted by the raw data, leaves the
# effects accepted earlier as the raw data confirmed them), the free and
# held refits that may rescue a screened instance, and its score.

# Returns list(st, cand): the state (failures and rejections recorded) and
# the candidate (NULL when the trial does not pay or is rejected).
# `nl_now`: the current model's free nonlinear values.
screen_trial <- function(st, tr, nl_now) {
  cur <- st$current
  hold_now <- st$hold
  c0 <- st$c0
  min_gain <- st$args$min_gain
  # A further line of a harmonic set the model holds (its stronger lines,
  # `after`, are in it) is no new source: the periodogram found it at the
  # set's frequency. Its confirmation by the raw data counts as a gain of
  # min_gain, as it does for any candidate: the curve must not lose more
  # than that (on a measured accelerometer its own 3rd harmonic of 0.56 Hz,
  # a periodogram line at p = 2e-38, gained -2.9 alone and +1.7 beside an
  # added line: it came and went with unrelated effects).
  set_line <- continues_set(tr)
  need <- if (set_line) -min_gain else min_gain
  crit <- function(f) refine_crit(st, f)
  crit_s <- function(f) refine_crit_held(st, f, length(hold_now))
  # Parameters the raw data measure better than the curve (a line's
  # frequency from the periodogram) are pinned there (a value the model
  # already pins never reaches here: fresh_pinned_trials()).
  pin <- pin_values(cur$terms, tr$effect, tr$pin[[1L]])
  # the instances the new one replaces leave; the held values of the
  # others follow their labels
  tm <- model_terms(cur$terms, tr$effect, c(tr$init[[1L]], tr$pin[[1L]]), cur)
  hold_now <- relabel_values(hold_now, cur$terms, tm)
  nl_now <- relabel_values(nl_now, cur$terms, tm)
  settings <- st$settings
  settings$fixed <- relabel_values(settings$fixed, cur$terms, tm, keep_gone = TRUE)
  r <- refit_with(cur, c(tm), tr$effect,
                  tr$init[[1L]], settings, hold = c(hold_now, pin),
                  good_enough = function(f) crit_s(f) < c0 - min_gain)
  st$failures <- record_conditions(st$failures, r$conditions, st$step, tr$effect)
  new <- r$fit
  if (is.null(new)) return(list(st = st, cand = NULL))
  c1 <- crit_s(new)
  # (a set's line whose amplitude the raw data pin may also raise chi2:
  # the terms fitted before it took its power on the curve; the criterion
  # bounds what that costs)
  amp_pinned <- set_line && pins_amp(tr)
  pays <- is.finite(c1) && c1 < c0 - need &&
    (new$chi2 < (if (set_line) 1 else 0.9) * cur$chi2 || amp_pinned)
  # Held where the terms before it took its power, such a line is refitted
  # once with the others free (its pinned values kept) before it is
  # refused (a square wave's 5th harmonic beside an axis's resonance and
  # filter)
  if (!pays && amp_pinned && length(hold_now)) {
    r <- refit_from(st, cur, new, settings, pin, "free refit of a pinned line",
                    tr$effect)
    st <- r$st
    if (!is.null(r$fit) && is.finite(crit(r$fit)) && crit(r$fit) < c0 - need) {
      new <- r$fit
      c1 <- crit(new)
      pays <- TRUE
    }
  }
  # A further instance of another process than the model's instances of
  # its entry (the catalogue's `apart`: a GM an order slower than the one
  # there), confirmed by the raw data, counts the confirmation as
  # min_gain: the curve must gain. (Held at a compromise between the two,
  # the first leaves the second less than min_gain: unit 1 accel_y + a 6 s
  # GM read one GM at 9.3 s and left out the axis's own of 211 s.)
  if (!pays && !set_line && is.finite(c1) && c1 < c0 && new$chi2 < cur$chi2 &&
      apart_confirmed(st, new, new_label(cur$terms, tr$effect))) {
    pays <- TRUE
  }
  if (!pays) {
    # raw-data values that do not pay alone may pay beside a family form
    # the raw data refused alone (family_pairs())
    if (length(pin)) st$unpaid <- add_refused(st$unpaid, tr)
    # one the curve prefers by less than min_gain may be an alternative
    # description of the final model (stage_alternatives())
    if (!set_line && is.finite(c1) && c1 < c0) {
      lab <- new_label(cur$terms, tr$effect)
      st$short_trials[[length(st$short_trials) + 1L]] <- list(
        trial = tr, gain = c0 - c1,
        par = instance_params(stats::coef(new), new$layout, lab))
    }
    return(list(st = st, cand = NULL))
  }
  lab <- new_label(cur$terms, tr$effect)
  # An added term that explains (almost) nothing anywhere is a refit
  # artefact, not an effect (a set's further line is the periodogram's).
  # Screened with the model's values held, a term can take less than its
  # share (a measured accelerometer's 9.9 Hz resonance, 1% of its
  # variance, at 1.2% of the AV beside a held filter, 2.7% free, was left
  # out behind a square wave's 13 harmonics): it is refitted once with
  # everything free first.
  # (a free refit, from the screen's values with the pins held, pays as a
  # screened instance must)
  free_pays <- function(f) {
    !is.null(f) && is.finite(crit(f)) && crit(f) < c0 - min_gain && f$chi2 < 0.9 * cur$chi2
  }
  freed <- FALSE
  if (!set_line && max_share(new, lab, settings$fixed) < 0.02) {
    if (!length(hold_now)) return(list(st = st, cand = NULL))
    r <- refit_from(st, cur, new, settings, pin, "free refit of a screen that explains little",
                    tr$effect)
    st <- r$st
    free <- r$fit
    if (!free_pays(free) || max_share(free, lab, settings$fixed) < 0.02) return(list(st = st, cand = NULL))
    new <- free
    c1 <- crit(free)
    freed <- TRUE
  }
  tau <- cur$data$tau
  jd <- judge_instance(st, new, tr$effect, lab, tau)
  # A screened instance (others held) that fails is refitted once with
  # everything free before it is rejected: held at the one-term
  # compromise, a second GM lands at the wrong Tc. (One freed above is
  # that refit already.)
  if (!is.null(jd$why) && length(hold_now) && !freed) {
    r <- refit_from(st, cur, new, settings, pin, "free refit of a rejected screen",
                    tr$effect)
    st <- r$st
    free <- r$fit
    if (free_pays(free)) {
      jf <- judge_instance(st, free, tr$effect, lab, tau)
      if (is.null(jf$why)) {
        new <- free
        c1 <- crit(free)
        jd <- jf
      }
    }
  }
  # A family's form the raw data contradict at the shape the curve gives it
  # is refitted once with its shape held where the raw data measure it
  # (the family's start: the filter's lag-1 excess), everything else free:
  # at m = 1 a line near Nyquist and the filter's dip trade on the curve
  # alone (unit 2 gyro_z + a 44.6 Hz line: the moving average at L 2.39
  # and 1.47, each refused, the loop ended at chi2/dof 106 without a
  # filter, N -7%; held at the raw 1.14, chi2/dof 1.9 and N as without the
  # line). The held shape is pinned as raw values are, and freed when the
  # loop ends if the raw data then accept it (stage_release()).
  if (!is.null(jd$why) && isFALSE(jd$ev$support) && !length(pin)) {
    rs <- raw_shape(st, cur$terms, tr$effect)
    if (length(rs)) {
      r <- refit_from(st, cur, new, settings, rs,
                      "refit at the raw data's shape", tr$effect)
      st <- r$st
      g <- r$fit
      if (free_pays(g) && max_share(g, lab, settings$fixed) >= 0.02) {
        jg <- judge_instance(st, g, tr$effect, lab, tau)
        if (is.null(jg$why)) {
          new <- g
          c1 <- crit(g)
          jd <- jg
          pin <- rs
          tr$release_late <- TRUE
        }
      }
    }
  }
  # A refit that moves effects accepted earlier to values the raw data
  # contradict is tried once more with those effects' nonlinear values held
  # where they were accepted, and an instance's amplitudes too when the raw
  # data pinned its shape and confirm the new effect (the rest free): the
  # new effect is judged beside the earlier ones as the raw data confirmed
  # them, charged for the held values as a screen is.
  if (isTRUE(jd$moved)) {
    broken <- earlier_broken(st, new)
    # (a measured band, its spectrum pinned, is moved by its scale alone: a
    # 0.54 Hz line 1.4 x the white sd was refused beside one, chi2/dof
    # 6831), for a new effect the raw data confirm (a long-tau GM they
    # leave undecided gets no such help)
    vals <- nl_now
    if (isTRUE(jd$ev$support) && any(!broken %in% sub("\\.[^.]*$", "", names(nl_now)))) {
      amp <- stats::coef(cur)[cur$layout$role != "nonlinear"]
      vals <- c(vals, relabel_values(amp, cur$terms, tm))
    }
    keep <- vals[vapply(names(vals), function(nm) {
      any(startsWith(nm, paste0(broken, "."))) || nm %in% broken
    }, NA)]
    if (length(keep)) {
      r <- refit_from(st, cur, new, settings, c(keep, pin),
                      "refit with earlier effects held", tr$effect)
      st <- r$st
      held <- r$fit
      c_held <- if (is.null(held)) Inf else refine_crit_held(st, held, length(keep))
      if (is.finite(c_held) && c_held < c0 - min_gain &&
          held$chi2 < 0.9 * cur$chi2 && max_share(held, lab, settings$fixed) >= 0.02) {
        jh <- judge_instance(st, held, tr$effect, lab, tau)
        if (is.null(jh$why)) {
          new <- held
          c1 <- c_held
          jd <- jh
        }
      }
    }
  }
  if (!is.null(jd$why)) {
    st$rejected <- add_rejected(st$rejected, st$step, tr$effect, jd$par, jd$why)
    # raw-data values the raw data then contradict: family_pairs() may try
    # them beside another form of the model's family, as it may values
    # that move an earlier effect (a square wave's harmonic pinned at its
    # line beside a first-order low-pass that had taken its power)
    if (length(pin) && (isFALSE(jd$ev$support) || isTRUE(jd$moved))) {
      st$refused <- add_refused(st$refused, tr)
    }
    # a form of a family the model lacks, fitted alone to what another
    # effect also shapes: family_pairs() may add it beside that effect
    kind <- split_term(tr$effect)$kind
    if (!length(pin) && isFALSE(jd$ev$support) && !is.null(effect_entry(kind)$family) &&
        !kind %in% split_term(cur$terms)$kind) {
      st$refused_forms <- union(st$refused_forms, kind)
    }
    # raw-data values an earlier effect keeps out: a revisit takes them first
    if (isTRUE(jd$moved) && length(pin)) st$blocked[[length(st$blocked) + 1L]] <- unlist(pin)
    if (!is.null(jd$dup)) {
      st$duplicates <- rbind(st$duplicates, cbind(
        data.frame(step = as.integer(st$step), effect = tr$effect,
                   params = format_params(jd$par, tr$effect), stringsAsFactors = FALSE),
        jd$dup))
    }
    return(list(st = st, cand = NULL))
  }
  # Pinned values the entry lets the curve refine (`release`): the
  # instance that passed is refitted with them and the model's values free
  # (held, a resonance released beside a filter at its one-term compromise
  # runs off to a tone), searched from there only, and kept when its
  # criterion is lower and it still passes (a band's centre read from the
  # Welch spectrum 0.2% off costs the curve's criterion more than the
  # raw-data check minds).
  if (length(pin) && isTRUE(tr$release)) {
    rel <- refit_with(cur, c(tm), tr$effect, tr$pin[[1L]], settings, local = TRUE)
    st$failures <- record_conditions(st$failures, rel$conditions, st$step, tr$effect)
    f <- rel$fit
    if (!is.null(f) && is.finite(crit(f)) && crit(f) < c1 && max_share(f, lab, settings$fixed) >= 0.02) {
      jr <- judge_instance(st, f, tr$effect, lab, tau)
      if (is.null(jr$why)) {
        new <- f
        c1 <- crit(f)
        jd <- jr
        pin <- NULL
      }
    }
  }
  sp <- split_trial(st, tr, tm, jd, lab, settings, pin, c1)
  st <- sp$st
  if (!is.null(sp$fit)) {
    new <- sp$fit
    c1 <- sp$crit
    jd <- sp$jd
  }
  # (a set's further line the raw data do not confirm needs the curve to
  # prefer it, as before its confirmation counted)
  why <- if (!set_line) {
    unconfirmed_marginal(tr$effect, jd$ev, c0 - c1, min_gain, st$raw)
  } else if (!isTRUE(jd$ev$support) && !(c1 < c0)) {
    paste("a further line of a held harmonic set that the raw data do not",
          "confirm and the curve does not prefer")
  }
  if (!is.null(why)) {
    st$rejected <- add_rejected(st$rejected, st$step, tr$effect, jd$par, why)
    return(list(st = st, cand = NULL))
  }
  # raw-data support counts as a gain of min_gain
  adj <- c1 - min_gain * isTRUE(jd$ev$support)
  list(st = st, cand = list(fit = new, crit = c1, adj = adj, trial = tr, label = lab,
                            params = jd$par, ev = jd$ev, pin = pin,
                            fixed = settings$fixed, also = jd$also))
}

# The trial's model `new` refitted from its own nonlinear values with
# `hold` held (the current model's settings): list(st, fit).
refit_from <- function(st, cur, new, settings, hold, what, effect) {
  args <- refit_args(cur, new$terms, settings,
                     start = stats::coef(new)[new$layout$role == "nonlinear"],
                     hold = hold)
  state_refit(st, args, what, effect)
}

# One instance over two processes: the raw data read the instance's value
# a factor 2-3 away (undecided; a 20 s GM beside an axis's own 170 s one
# becomes one GM at 42 s, its block means' ACF reading 20 s). The entry's
# evidence then says where the two would sit (`split`: start values of
# two instances), and the pair is refitted with everything free. It
# enters in this step, in place of the one, when it pays, each instance is
# valid and confirmed by the raw data, and its criterion, with that
# support counted as a gain of min_gain, is below the one's. Returns
# list(st, fit, crit, jd); `fit` NULL when the one stays.
split_trial <- function(st, tr, tm, jd, lab, settings, pin, c1) {
  starts <- jd$ev$split
  out <- list(st = st, fit = NULL)
  if (length(starts) != 2L || !is.na(jd$ev$support %||% NA) ||
      !isTRUE(effect_entry(split_term(tr$effect)$kind)$repeatable)) {
    return(out)
  }
  cur <- st$current
  tm2 <- c(tm, tr$effect)
  lab2 <- new_label(tm, tr$effect)
  sv <- c(pin_values(tm[-length(tm)], tr$effect, starts[[1L]]),
          stats::setNames(unlist(starts[[2L]]),
                          paste0(lab2, ".", names(starts[[2L]]))))
  args <- refit_args(cur, tm2, settings, start = sv, hold = pin)
  r <- state_refit(st, args, "split in two", tr$effect)
  out$st <- r$st
  f <- r$fit
  crit <- refine_crit(st, f %||% cur)
  if (is.null(f) || !is.finite(crit) || crit >= st$c0 - st$args$min_gain ||
      f$chi2 >= 0.9 * cur$chi2 || crit - st$args$min_gain >= c1) {
    return(out)
  }
  tau <- cur$data$tau
  j1 <- judge_instance(out$st, f, tr$effect, lab, tau)
  j2 <- judge_instance(out$st, f, tr$effect, lab2, tau)
  if (!is.null(j1$why) || !is.null(j2$why) || !isTRUE(j1$ev$support) ||
      !isTRUE(j2$ev$support) || min(max_share(f, lab, settings$fixed), max_share(f, lab2, settings$fixed)) < 0.02) {
    return(out)
  }
  j1$ev$text <- sprintf("%s; split in two, %s with %s (%s): %s", j1$ev$text, lab, lab2,
                        format_params(j2$par, tr$effect), j2$ev$text)
  j1$also <- list(label = lab2, par = j2$par, ev = j2$ev)
  list(st = out$st, fit = f, crit = crit, jd = j1)
}

# TRUE when the instance `label` of `f` is, by its entry's `apart`, another
# process than each of the model's other instances of its entry, and the
# raw data confirm it there (support, not undecided).
apart_confirmed <- function(st, f, label) {
  effect <- f$terms[match(label, term_labels(f$terms))]
  sp <- split_term(effect)
  e <- effect_entry(sp$kind, sp$variant)
  if (is.null(e$apart)) return(FALSE)
  lay <- f$layout
  cf <- stats::coef(f)
  others <- setdiff(unique(lay$label[lay$kind == e$name]), label)
  if (!length(others)) return(FALSE)
  par <- as.list(instance_params(cf, lay, label))
  vals <- lapply(others, function(l) as.list(instance_params(cf, lay, l)))
  if (!isTRUE(e$apart(par, vals))) return(FALSE)
  jd <- judge_instance(st, f, effect, label, f$data$tau)
  is.null(jd$why) && isTRUE(jd$ev$support)
}

# The criterion gain the instances `label` of `f` (one, or a group that
# entered together) must bring to stay: min_gain, or any gain for one
# apart_confirmed() or beside which another is (without the faster of
# such a pair the slower one returns to the compromise between the two).
instance_need <- function(st, f, label) {
  if (length(label) != 1L) return(st$args$min_gain)
  lay <- f$layout
  same <- unique(lay$label[lay$kind == lay$kind[match(label, lay$label)]])
  for (l in same) {
    if (apart_confirmed(st, f, l)) return(0)
  }
  st$args$min_gain
}

# An instance that is not a valid instance of its effect on this curve (a
# sub-sample GM, a sinusoid the curve cannot see) is never accepted, however
# well it bends the curve; nor one the raw data contradict, nor one whose
# refit moves an effect accepted earlier to values the raw data contradict.
# Returns list(par, why (NULL when it holds), ev, moved).
judge_instance <- function(st, f, effect, label, tau) {
  freq <- st$args$freq
  par <- instance_params(stats::coef(f), f$layout, label)
  why <- inadmissible(effect, par, tau, freq)
  ev <- if (is.null(why)) raw_evidence(effect, as.list(par), st$raw,
                                       diag_series(st$raw), freq, f, label)
  if (is.null(why) && isFALSE(ev$support)) {
    why <- paste("contradicted by the raw data:", ev$text)
  }
  # a term standing in for a series effect this run found and left in the
  # data describes one thing twice (remove it in the series instead)
  dup <- if (is.null(why)) series_stand_in(st, f, label, effect, par, ev)
  if (!is.null(dup)) why <- series_stand_in_text(dup)
  moved <- FALSE
  if (is.null(why) && !earlier_hold(st, f)) {
    why <- "moves an effect accepted earlier to values the raw data contradict"
    moved <- TRUE
  }
  list(par = par, why = why, ev = ev, moved = moved, dup = dup)
}

# A family's form (the sensor filter's moving average, first- or
# second-order low-pass) was chosen against the model of the step it
# entered at; the effects added since can change which form describes the
# curve (a first-order low-pass chosen before the 0.55 Hz line ran to its
# Nyquist bound). So it is chosen again: each other variant of the entry's
# `family` refitted with everything free, started from the raw data's
# values; the criterion chooses, and the new form must be admissible and
# not contradicted by the raw data, nor move an effect accepted earlier to
# values the raw data contradict. Returns list(st, swapped).
rechoose_families <- function(st, known = FALSE) {
  if (!length(st$steps)) return(list(st = st, swapped = FALSE))
  for (e in entries_with("family")) {
    ff <- family_forms(st, e)
    if (is.null(ff)) next
    cur <- st$current
    fi <- ff$current
    rest <- ff$rest
    stage <- paste(e$name, "family chosen again")
    swap <- NULL
    near <- list()
    # During the steps the forms are compared on the curve without what the
    # raw data measure exactly and the model does not hold yet (known_av
    # fields: a square wave's sharp harmonics): a first-order low-pass
    # mimics the bumps of the harmonics not yet in, beats the moving
    # average there, and then keeps them and the axis's resonance out.
    cv <- if (known) curve_without_known(st, cur)
    crit_of <- function(st, g) {
      if (is.null(cv)) return(list(st = st, crit = refine_crit(st, g)))
      args <- refit_args(g, g$terms, st$settings)
      args$av <- cv
      r <- state_refit(st, args, paste(stage, "without the known lines"), e$name,
                       length(st$steps) + 1L)
      list(st = r$st, crit = if (is.null(r$fit)) Inf else refine_crit(r$st, r$fit))
    }
    k <- crit_of(st, cur)
    st <- k$st
    c_cur <- k$crit
    for (fm in ff$forms) {
      v <- fm$term
      lab <- fm$label
      start <- fm$start[names(fm$start) %in% coef_layout(c(rest, v))$name]
      args <- refit_args(cur, c(rest, v), st$settings, start = start)
      r <- state_refit(st, args, stage, v, length(st$steps) + 1L)
      st <- r$st
      g <- r$fit
      if (is.null(g) || !is.finite(refine_crit(st, g))) next
      k <- crit_of(st, g)
      st <- k$st
      c_g <- k$crit
      if (!is.finite(c_g)) next
      if (c_g >= min(c_cur, swap$crit %||% Inf) - st$args$min_gain) {
        # a form the curve cannot tell from the current one
        if (c_g < c_cur + st$args$min_gain) {
          near[[length(near) + 1L]] <- list(fit = g, effect = v, label = lab)
        }
        next
      }
      fj <- judge_form(st, g, v, lab)
      if (is.null(fj)) next
      swap <- list(fit = g, crit = c_g, effect = v, label = lab,
                   par = fj$par, ev = fj$ev,
                   note = if (!is.null(cv)) "; chosen on the curve without the sharp lines not yet in the model")
    }
    if (is.null(swap) && length(near)) swap <- acov_choice(st, cur, near)
    if (!is.null(swap)) {
      loc <- locate_signature(st$sig, swap$fit, swap$label)
      evidence <- paste0("the ", e$name, " family chosen again on the final model (was ",
                         fi, "); ", loc$text, swap$note %||% "")
      if (nzchar(swap$ev$text)) evidence <- paste0(evidence, "; raw data: ", swap$ev$text)
      st$steps[[length(st$steps) + 1L]] <- step_row(
        swap$effect, swap$label, loc, swap$par, evidence, swap$ev$support,
        cur, swap$fit, refine_crit(st, cur), refine_crit(st, swap$fit))
      st$current <- swap$fit
      return(list(st = st, swapped = TRUE))
    }
  }
  list(st = st, swapped = FALSE)
}

# The curve of `fit` less the AV the catalogue's known_av fields give (what
# the raw data measure exactly and `fit` does not hold), each point kept at
# 10% at least; NULL when there is none.
curve_without_known <- function(st, fit) {
  if (is.null(st$raw) || is.null(st$args$freq)) return(NULL)
  cv <- curve_of_fit(fit)
  known <- 0
  for (e in entries_with("known_av")) {
    k <- e$known_av(st$raw, fit, cv$data$tau, 1 / st$args$freq)
    if (!is.null(k)) known <- known + k
  }
  if (!any(known > 0)) return(NULL)
  cv$data$avar <- pmax(cv$data$avar - known, 0.1 * cv$data$avar)
  cv
}

# The autocovariance at lags `h` (samples) of what the raw data measure
# exactly and `fit` does not hold (the catalogue's known_acov fields: the
# sharp lines not in the model yet); 0 where there is none.
unheld_acov <- function(raw, fit, h, tau0) {
  out <- numeric(length(h))
  for (e in entries_with("known_acov")) {
    k <- e$known_acov(raw, fit, h, tau0)
    if (!is.null(k)) out <- out + k
  }
  out
}

# Forms the curve cannot tell apart (criteria within min_gain: beside a
# resonance a moving average and a first-order low-pass of the same lag-1
# excess differ by about 1) are told apart by the raw series' short-lag
# autocovariance steps (acov_steps()), which the whole model predicts
# (model_acov()): when the current model's steps are off at the 0.1% level
# of chi-square (3 dof) and a form's sum of squared z is lower by more than
# that level, the form whose steps fit best is taken, if valid, not
# contradicted and the earlier effects hold.
# Returns the swap (as rechoose_families() keeps it) or NULL.
acov_choice <- function(st, cur, near) {
  level <- stats::qchisq(0.999, 3L)
  m0 <- acov_misfit(st, cur)
  if (!is.finite(m0) || m0 <= level) return(NULL)
  best <- NULL
  for (nf in near) {
    m <- acov_misfit(st, nf$fit)
    if (!is.finite(m) || m >= m0 - level || m >= (best$misfit %||% Inf)) next
    fj <- judge_form(st, nf$fit, nf$effect, nf$label)
    if (is.null(fj)) next
    best <- list(fit = nf$fit, crit = refine_crit(st, nf$fit), effect = nf$effect,
                 label = nf$label, par = fj$par, ev = fj$ev, misfit = m,
                 note = sprintf(paste0("; the raw short-lag autocovariance steps (lags 1-3)",
                                       " fit it, chi-square %s against %s"),
                                format_num(m), format_num(m0)))
  }
  best
}

# Sum of squared z of the raw series' short-lag autocovariance steps against
# those model `f` implies (NA without the raw series); the raw steps are
# read once per call.
acov_misfit <- function(st, f) {
  if (is.null(st$data) || is.null(st$args$freq)) return(NA_real_)
  raw <- diag_acov_steps(st$raw) %||% acov_steps(st$data)
  h <- seq_len(length(raw$d) + 1L)
  tau0 <- 1 / st$args$freq
  md <- -diff(model_acov(f$layout, stats::coef(f), h, tau0) + unheld_acov(st$raw, f, h, tau0))
  sum(((raw$d - md) / raw$se)^2)
}

# Two entries may describe one thing of the raw data (a band of the
# spectrum as measured, or as a resonance whose AR(2) carries the skirt
# beyond the band's run); the one screened first was chosen beside the
# others held at values fitted without the rest (a measured band taken at
# step 1, a first-order low-pass then fitted to its missing skirt: N +20%).
# So each raw-data proposal that an instance of the model took the place
# of (that instance's entry `replaces` the proposal's kind there) is
# refitted in its place with everything free (values the entry releases are
# a start, the others are held) and taken when it pays by min_gain, is
# valid, not contradicted, and the earlier effects hold. Returns list(st,
# swapped).
rechoose_descriptions <- function(st) {
  cur <- st$current
  if (!length(st$steps) || is.null(st$raw)) return(list(st = st, swapped = FALSE))
  c0 <- refine_crit(st, cur)
  tau <- cur$data$tau
  best <- NULL
  near <- list()
  for (e in entries_with("propose")) {
    for (p in e$propose(st$raw, tau, st$sig)) {
      eff <- p$effect %||% e$name
      gone <- described_by(cur, e$name, c(p$init, p$pin))
      if (!any(gone)) next
      tm <- structure(c(cur$terms[!gone], eff), gone = gone)
      before <- tm[-length(tm)]
      lab <- new_label(before, eff)
      hold <- if (!isTRUE(p$release)) pin_values(before, eff, p$pin)
      start <- pin_values(before, eff, c(p$init[!names(p$init) %in% names(hold)],
                                         if (isTRUE(p$release)) p$pin))
      start <- start[!duplicated(names(start), fromLast = TRUE)]
      settings <- st$settings
      settings$fixed <- relabel_values(settings$fixed, cur$terms, tm, keep_gone = TRUE)
      # as the model holds it, and beside each other form of its families
      # (a form fitted to what the old description missed may be
      # contradicted once the new one carries it)
      sets <- lapply(form_choices(st), function(fm) {
        list(terms = with_form(tm, fm), start = fm$start, form = fm)
      })
      for (ts in sets) {
        sv <- c(start, ts$start)
        sv <- sv[!duplicated(names(sv)) & names(sv) %in% coef_layout(ts$terms)$name]
        args <- refit_args(cur, ts$terms, settings, start = sv, hold = hold)
        r <- state_refit(st, args, "a description chosen again", eff, length(st$steps) + 1L)
        st <- r$st
        f <- r$fit
        if (is.null(f) || !is.finite(refine_crit(st, f)) ||
            f$chi2 >= cur$chi2 || max_share(f, lab, settings$fixed) < 0.02) next
        c_f <- refine_crit(st, f)
        pays <- c_f < min(c0, best$crit %||% Inf) - st$args$min_gain
        # one the curve cannot tell from the model: the raw short-lag
        # autocovariance may (below)
        if (!pays && c_f >= c0 + st$args$min_gain) next
        jd <- judge_instance(st, f, eff, lab, tau)
        if (!is.null(jd$why)) next
        if (!is.null(ts$form) && is.null(judge_form(st, f, ts$form$term, ts$form$label))) next
        cand <- list(fit = f, crit = c_f, effect = eff, label = lab,
                     par = jd$par, ev = jd$ev, fixed = c(settings$fixed, hold),
                     gone = cur$terms[attr(tm, "gone")], form = ts$form$term)
        if (pays) best <- cand else near[[length(near) + 1L]] <- cand
      }
    }
  }
  if (is.null(best) && length(near)) best <- acov_description(st, cur, near)
  if (is.null(best)) return(list(st = st, swapped = FALSE))
  loc <- locate_signature(st$sig, best$fit, best$label)
  evidence <- paste0(best$label, " in place of the ", paste(best$gone, collapse = ", "),
                     " (one thing of the raw data described again",
                     if (!is.null(best$form)) paste0(", beside ", best$form), "); ", loc$text,
                     if (nzchar(best$ev$text)) paste0("; raw data: ", best$ev$text))
  st$steps[[length(st$steps) + 1L]] <- step_row(
    best$effect, best$label, loc, best$par, evidence, best$ev$support,
    cur, best$fit, c0, best$crit)
  st$pins[length(st$steps)] <- list(numeric(0))
  st$settings$fixed <- best$fixed
  st$current <- best$fit
  list(st = st, swapped = TRUE)
}

# Descriptions the curve cannot tell from the model (criteria within
# min_gain) are told apart by the raw short-lag autocovariance steps, as
# forms are (acov_choice()): when the model's steps are off at the 0.1%
# level and a description's fit them better by more than that level, the
# best fitting one is taken. (A 44 Hz line added to a simulated sensor
# with a two-pole filter and a 9.8 Hz resonance: the line, not yet in the
# model at step 1, let a measured band take the resonance's place and a
# moving average the filter's; the steps were off at chi-square 139, N
# read 6.9% high.)
acov_description <- function(st, cur, near) {
  level <- stats::qchisq(0.999, 3L)
  m0 <- acov_misfit(st, cur)
  if (!is.finite(m0) || m0 <= level) return(NULL)
  m <- vapply(near, function(nd) acov_misfit(st, nd$fit), 0)
  ok <- is.finite(m) & m < m0 - level
  if (!any(ok)) return(NULL)
  j <- which(ok)[which.min(m[ok])]
  out <- near[[j]]
  out$ev$text <- paste0(out$ev$text, sprintf(paste0(
    "; the raw short-lag autocovariance steps (lags 1-3) fit it, chi-square %s",
    " against %s"), format_num(m[j]), format_num(m0)))
  out
}

# The instances of model `cur` that took the place of an instance of kind
# `kind` with values `par` (their entry `replaces` the kind, there).
described_by <- function(cur, kind, par) {
  labs <- term_labels(cur$terms)
  kinds <- split_term(cur$terms)$kind
  vapply(seq_along(cur$terms), function(i) {
    ei <- effect_entry(kinds[i])
    if (!kind %in% ei$replaces) return(FALSE)
    if (is.null(ei$replaces_instance)) return(TRUE)
    isTRUE(ei$replaces_instance(as.list(instance_params(stats::coef(cur), cur$layout, labs[i])),
                                kind, as.list(par)))
  }, NA)
}

# The other forms of family entry `e`'s one instance in the current model
# (NULL when it holds none, or several): each form's term, label and the
# start of its refit (the model's other nonlinear values, the form's own
# read from the raw data). With `absent = TRUE`, a model holding no
# instance gets every form, to add (`current` NULL).
family_forms <- function(st, e, absent = FALSE) {
  cur <- st$current
  fi <- cur$terms[split_term(cur$terms)$kind == e$name]
  if (length(fi) > 1L || (length(fi) == 0L && !absent) || (length(fi) == 1L && absent)) {
    return(NULL)
  }
  variants <- e$family$variants
  # the instances a form leaves (the form's old instance; an added one
  # takes the place of what its entry replaces: a filter, of N)
  out <- if (length(fi)) cur$terms == fi else
    attr(model_terms(cur$terms, family_term(e$name, variants, variants[1L])), "gone")
  rest <- cur$terms[!out]
  nl_rest <- stats::coef(cur)[cur$layout$role == "nonlinear"]
  for (lab in term_labels(cur$terms)[out]) {
    nl_rest <- nl_rest[!startsWith(names(nl_rest), paste0(lab, "."))]
  }
  forms <- lapply(seq_along(variants), function(j) {
    v <- family_term(e$name, variants, variants[j])
    if (length(fi) && v == fi) return(NULL)
    lab <- new_label(rest, v)
    s0 <- e$family$start(st$raw, variants[j])
    list(term = v, label = lab,
         start = c(nl_rest, if (length(s0)) stats::setNames(unlist(s0), paste0(lab, ".", names(s0)))))
  })
  list(current = if (length(fi)) fi, rest = rest, forms = Filter(Negate(is.null), forms))
}

# The shape the raw data measure for a family's form `effect` added to
# `terms` (the family's start, e.g. the moving average's L from the raw
# lag-1 excess), named for its new instance; NULL for other entries.
raw_shape <- function(st, terms, effect) {
  sp <- split_term(effect)
  e <- effect_entry(sp$kind, sp$variant)
  if (is.null(e$family) || is.null(st$raw)) return(NULL)
  v <- if (nzchar(sp$variant)) sp$variant else e$family$variants[1L]
  s0 <- e$family$start(st$raw, v)
  if (!length(s0)) return(NULL)
  pin_values(terms, effect, s0)
}

# The choices of the model's family forms: NULL (as they are) first, then
# each other form of each family, carrying the form it would replace
# (`current`).
form_choices <- function(st) {
  out <- list(NULL)
  for (fe in entries_with("family")) {
    ff <- family_forms(st, fe)
    if (!is.null(ff)) out <- c(out, lapply(ff$forms, function(fm) c(fm, list(current = ff$current))))
  }
  out
}

# Terms `tm` with form choice `fm` (form_choices()) in place of its current.
with_form <- function(tm, fm) {
  if (is.null(fm)) c(tm) else replace(c(tm), c(tm) == fm$current, fm$term)
}

# A family's form `v` (label `lab`) in refit `g`: valid on the curve, not
# contradicted by the raw data, and the effects accepted earlier hold.
# Returns list(par, ev), or NULL when it fails.
judge_form <- function(st, g, v, lab) {
  par <- instance_params(stats::coef(g), g$layout, lab)
  if (!is.null(inadmissible(v, par, g$data$tau, st$args$freq))) return(NULL)
  ev <- raw_evidence(v, as.list(par), st$raw, diag_series(st$raw), st$args$freq, g, lab)
  if (isFALSE(ev$support) || !earlier_hold(st, g)) return(NULL)
  list(par = par, ev = ev)
}

# Two things the raw data measure can each be refused alone where the
# other distorts the curve: a band at 7.9 Hz beside a resonance at 26 Hz
# that the model lacks both, the 26 Hz one alone fitted at half its
# measured power (the curve's short end carries both), the 7.9 Hz one
# alone raising chi2; together at their raw values they leave chi2/dof
# 1.8 of 1482. When nothing paid and the model is still far from the
# curve (chi2/dof above revisit_chi2), the trials refused this step at
# raw-data values, or that did not pay alone at them, are refitted two at
# a time at those values, the model's own values free. The best pair
# enters as this step's winner when it pays twice min_gain, lowers chi2,
# each instance is confirmed by the raw data and passes as any instance
# must (judge_instance()), and the effects accepted earlier hold. Values an
# entry releases stay pinned until the loop ends (stage_release()), as a
# resolved pair of one run's resonances does. Returns st, with st$best set
# when a pair won.
raw_pairs <- function(st) {
  cur <- st$current
  trials <- c(st$refused, st$unpaid)
  if (!(cur$chi2 > revisit_chi2) || length(trials) < 2L) return(st)
  c0 <- refine_crit(st, cur)
  min_gain <- st$args$min_gain
  tau <- cur$data$tau
  # the model's family forms as they are, and each other form in place of
  # its own (a second-order low-pass taken at 45 Hz for two bands the model
  # lacked holds their power: beside it the pair is refused)
  forms <- form_choices(st)
  for (pr in utils::combn(length(trials), 2L, simplify = FALSE)) {
    t1 <- trials[[pr[1L]]]
    t2 <- trials[[pr[2L]]]
    tm1 <- model_terms(cur$terms, t1$effect, c(t1$init[[1L]], t1$pin[[1L]]), cur)
    if (any(attr(tm1, "gone"))) next
    tm <- model_terms(c(tm1), t2$effect, c(t2$init[[1L]], t2$pin[[1L]]), cur)
    # a pair whose second describes the first again (a measured band over
    # the resonance it replaces) is no pair
    if (any(attr(tm, "gone"))) next
    lab1 <- new_label(cur$terms, t1$effect)
    lab2 <- new_label(c(tm1), t2$effect)
    pin <- c(pin_values(cur$terms, t1$effect, t1$pin[[1L]]),
             pin_values(c(tm1), t2$effect, t2$pin[[1L]]))
    start <- c(pin_values(cur$terms, t1$effect, t1$init[[1L]]),
               pin_values(c(tm1), t2$effect, t2$init[[1L]]))
    for (fm in forms) {
      terms <- with_form(tm, fm)
      sv <- c(start, fm$start)
      sv <- sv[!duplicated(names(sv)) & !names(sv) %in% names(pin) &
                 names(sv) %in% coef_layout(terms)$name]
      args <- refit_args(cur, terms, st$settings, start = sv, hold = pin)
      r <- state_refit(st, args, "two raw-data trials together", t1$effect)
      st <- r$st
      f <- r$fit
      # (the other forms are tried only for a pair that pays beside the
      # model's own and is refused there: the screen's cost stays small)
      c1 <- if (is.null(f)) NA_real_ else refine_crit(st, f)
      pays <- is.finite(c1) && c1 < c0 - 2 * min_gain && f$chi2 < 0.9 * cur$chi2
      if (!pays && is.null(fm)) break
      if (!pays) next
      if (c1 >= (st$best$crit %||% Inf) ||
          min(max_share(f, lab1, st$settings$fixed), max_share(f, lab2, st$settings$fixed)) < 0.02) next
      j1 <- judge_instance(st, f, t1$effect, lab1, tau)
      if (!is.null(j1$why) || !isTRUE(j1$ev$support)) next
      j2 <- judge_instance(st, f, t2$effect, lab2, tau)
      if (!is.null(j2$why) || !isTRUE(j2$ev$support)) next
      fj <- if (!is.null(fm)) judge_form(st, f, fm$term, fm$label)
      if (!is.null(fm) && is.null(fj)) next
      tr <- t1
      tr$release <- FALSE
      tr$release_late <- all(vapply(list(t1, t2), function(t) {
        isTRUE(t$release) || isTRUE(t$release_late)
      }, NA))
      note <- sprintf("%s and %s taken together (neither paid alone%s)", lab1, lab2,
                      if (is.null(fm)) "" else sprintf("; %s chosen again, was %s",
                                                        fm$term, fm$current))
      j1$ev$text <- paste0(j1$ev$text, "; ", note)
      st$best <- list(fit = f, crit = c1, adj = c1 - min_gain, trial = tr,
                      label = lab1, params = j1$par, ev = j1$ev, pin = pin,
                      fixed = st$settings$fixed,
                      also = list(effect = t2$effect, label = lab2, par = j2$par, ev = j2$ev,
                                  note = note),
                      extras = if (!is.null(fm)) {
                        list(list(effect = fm$term, label = fm$label, par = fj$par, ev = fj$ev,
                                  note = sprintf("chosen again (was %s) beside %s and %s",
                                                 fm$current, lab1, lab2)))
                      })
      if (is.null(fm)) break
    }
  }
  st
}

# The trials of this step refused as contradicted by the raw data at
# values they pin, once each (a trial is screened held and free).
add_refused <- function(refused, tr) {
  key <- function(t) paste(t$effect, paste(signif(unlist(t$pin), 9), collapse = ","))
  if (any(vapply(refused, key, "") == key(tr))) return(refused)
  c(refused, list(tr))
}

# A family form taken early can absorb part of an effect the raw data
# measure (a first-order low-pass taken for the bump of a 3.7 Hz line then
# carries half of the axis's 9.8 Hz resonance: the curve asks the
# resonance for less power than its band holds, and the raw data refuse
# it). When nothing paid, no other form pays alone and the model is still
# far from the curve (chi2/dof above revisit_chi2), each trial refused this
# step at raw-data values, or that did not pay alone at them (a square
# wave's harmonic beside a first-order low-pass that took the bumps of the
# harmonics not yet in, and the axis's resonance), is refitted beside each
# other form of the family, everything free. Conversely, the forms of a
# family the model lacks, which the raw data refused alone (a moving
# average fitted without a 45.5 Hz line, whose bump at tau0 hides the
# average's dip, predicts too little lag-1 autocorrelation), are each
# refitted beside such trials (that line). The best pair enters as this
# step's winner when it pays, the trial is confirmed by the raw data, the
# new form is valid and not contradicted (confirmed, beside a trial that
# did not pay alone), and the effects accepted earlier hold. Returns st,
# with st$best set when a pair won.
family_pairs <- function(st) {
  cur <- st$current
  if (!(cur$chi2 > revisit_chi2)) return(st)
  c0 <- refine_crit(st, cur)
  min_gain <- st$args$min_gain
  tau <- cur$data$tau
  for (e in entries_with("family")) {
    ff <- family_forms(st, e)
    if (is.null(ff) && e$name %in% st$refused_forms) ff <- family_forms(st, e, absent = TRUE)
    trials <- c(st$refused, st$unpaid)
    if (is.null(ff) || !length(trials)) next
    fi <- ff$current
    rest <- ff$rest
    for (fm in ff$forms) {
      v <- fm$term
      vlab <- fm$label
      sv <- fm$start
      for (ti in seq_along(trials)) {
        tr <- trials[[ti]]
        # beside a trial that did not pay alone, the form must be confirmed
        # by the raw data, not merely left undecided (a second-order
        # low-pass at 45 Hz, nearly white, entered beside a weak line of 2.6
        # x its periodogram amplitude: N -10%)
        unpaid <- ti > length(st$refused)
        tm <- model_terms(c(rest, v), tr$effect, c(tr$init[[1L]], tr$pin[[1L]]), cur)
        before <- tm[-length(tm)]
        lab <- new_label(before, tr$effect)
        pin <- pin_values(before, tr$effect, tr$pin[[1L]])
        start <- c(sv, pin_values(before, tr$effect, tr$init[[1L]]))
        start <- start[names(start) %in% coef_layout(tm)$name]
        # values pinned before, under the labels of the new model
        settings <- st$settings
        settings$fixed <- relabel_values(settings$fixed, c(rest, v), tm, keep_gone = TRUE)
        args <- refit_args(cur, c(tm), settings, start = start, hold = pin)
        r <- state_refit(st, args, paste(e$name, if (is.null(fi)) "family added" else
                                           "family chosen again", "beside a trial"),
                         tr$effect)
        st <- r$st
        f <- r$fit
        if (is.null(f)) next
        c1 <- refine_crit(st, f)
        if (!is.finite(c1) || c1 >= c0 - min_gain || f$chi2 >= 0.9 * cur$chi2 ||
            c1 >= (st$best$crit %||% Inf) || max_share(f, lab, settings$fixed) < 0.02) next
        jd <- judge_instance(st, f, tr$effect, lab, tau)
        if (!is.null(jd$why) || !isTRUE(jd$ev$support)) next
        fj <- judge_form(st, f, v, vlab)
        if (is.null(fj) || (unpaid && !isTRUE(fj$ev$support))) next
        how <- if (is.null(fi)) sprintf("the %s family added", e$name) else
          sprintf("the %s family chosen again (was %s)", e$name, fi)
        jd$ev$text <- paste0(jd$ev$text, "; with ", how,
                             if (is.null(fi)) " beside it (neither paid alone)")
        st$best <- list(fit = f, crit = c1, adj = c1 - min_gain, trial = tr,
                        label = lab, params = jd$par, ev = jd$ev, pin = pin,
                        fixed = settings$fixed,
                        also = list(effect = v, label = vlab, par = fj$par, ev = fj$ev,
                                    note = paste(how, "beside", lab)))
      }
    }
  }
  st
}
