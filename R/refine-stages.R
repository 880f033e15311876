# The closed loop as named stages. avrefine() runs refine_stages() in
# order on one state (R/refine-state.R); the `steps` stage runs
# step_stages() once per step until a stage stops it. A new ability is one
# more stage (or step stage) here: it takes the state and returns it.

refine_stages <- function() {
  list(prepare = stage_prepare,      # series pass, raw-data diagnostics
       steps = stage_steps,          # add effects, one step at a time
       rechoose = stage_rechoose,    # families chosen again on the final model
       revisit = stage_revisit,      # raw-data values first, if the greedy order failed
       redescribe = stage_redescribe, # one thing described by another entry
       remaining = stage_remaining,  # residual structure no effect explains
       trim = stage_trim,            # leave out a short end nothing describes
       release = stage_release,      # values the last screening held, freed
       hold = stage_hold,            # instances the curve sizes off the raw data's
       absorbed = stage_absorbed,    # lines a band took on the curve, at the raw data's values
       prune = stage_prune,          # instances the final model holds at 0 leave
       reconsider = stage_reconsider, # instances the final model does without leave
       alternatives = stage_alternatives, # confirmed effects left out below min_gain
       assemble = stage_assemble)    # the refined avfit object
}

step_stages <- function() {
  list(trace = step_trace,           # signatures -> candidate trials
       reform = step_reform,         # a family form chosen before a raw-data effect, again
       screen = step_screen,         # each trial refitted, judged, scored
       settle = step_settle,         # none paid: choose families again or stop
       refit = step_refit_winner,    # the winner with everything free
       record = step_record)         # the accepted step
}

# ---- stages -------------------------------------------------------------------

# Non-stationary effects (steps, warm-up, spikes) are read from the series
# first (R/series.R); what the user asks to remove is taken out of the data
# the loop then sees. Then the raw-data diagnostics, once per call.
stage_prepare <- function(st) {
  # the loop weighs points by their own scatter (refit_settings()): a fit
  # given with a model-error term starts it refitted without one
  if (isTRUE(st$current$model_error > 0)) {
    r <- try_refit(refit_args(st$current, st$current$terms, st$settings), "prepare")
    if (!is.null(r$fit)) st$current <- r$fit
  }
  if (is.null(st$data)) return(st)
  a <- st$args
  if (is.null(a$series)) {
    st$series <- detect_series_effects(st$data, a$freq, remove = a$remove)
    if (length(st$series$removed)) st$data <- st$series$x
  } else {
    st$series <- a$series
  }
  # a trend is a ramp only beyond what the series pass found and left in
  # the data (a warm-up or a step projects onto a line)
  st$raw <- refine_diagnostics(st$data, a$freq,
                               beside = series_shapes(st$series, length(st$data), a$freq))
  st
}

# A step that adds a further line of a harmonic set the model already holds
# (the trial's prerequisites, `after`, are that set's stronger lines) adds
# no new source: it does not spend the `max_steps` budget (at most
# `max_set_steps` such steps in a call). Once the budget is spent, steps go
# on with those trials alone, so an axis's own effects cannot starve a set
# of its harmonics.
max_set_steps <- 10L
max_rechosen <- 2L

stage_steps <- function(st) {
  budget <- st$args$max_steps
  st$start <- st$start %||% st$current
  if (budget < 1L) return(st)
  step <- 0L
  free <- 0L
  # a step that only chose a family again (step_settle()) adds no effect:
  # it leaves the budget alone (at most max_rechosen of them, each of which
  # must lower the criterion by min_gain)
  rechosen <- 0L
  st$only_sets <- FALSE
  repeat {
    if (step - free - rechosen >= budget) {
      if (free >= max_set_steps) break
      st$only_sets <- TRUE
    }
    step <- step + 1L
    st$step <- step
    st$flow <- "go"
    for (s in step_stages()) {
      st <- s(st)
      if (st$flow != "go") break
    }
    if (st$flow == "stop") break
    # a revisit that has reached the greedy run's terms ends as it did
    if (!is.null(st$until) && identical(sort(st$current$terms), st$until)) break
    if (st$flow == "next" && rechosen < max_rechosen) {
      rechosen <- rechosen + 1L
    } else if (st$flow == "go" && free < max_set_steps && continues_set(st$best$trial)) {
      free <- free + 1L
    } else if (st$only_sets) {
      break
    }
  }
  st$only_sets <- FALSE
  st
}

# Does model `f` hold an instance of a family entry (forms chosen again)?
holds_family <- function(f) {
  any(split_term(f$terms)$kind %in% vapply(entries_with("family"), `[[`, "", "name"))
}

continues_set <- function(trial) {
  !is.null(trial) && !is.null(trial$after) && length(unlist(trial$after)) > 0L
}

# Does a trial pin an amplitude of its effect (the raw data measure it)?
pins_amp <- function(trial) {
  tk <- split_term(trial$effect)
  p <- effect_entry(tk$kind, tk$variant)$params
  any(names(trial$pin[[1L]]) %in% p$name[p$role == "amp"])
}

# The loop may have ended on a step that chose a family again. A loop that
# ended because nothing paid has just chosen them on this same model
# (step_settle()): that is not done twice.
stage_rechoose <- function(st) {
  if (identical(st$settled, st$current)) return(st)
  rechoose_families(st)$st
}

# On the model the loop keeps (after a revisit: a greedy order that ended
# far from the curve is first run again with the raw data's values first),
# a thing of the raw data described by one entry may be described again by
# another (rechoose_descriptions()), the family's form chosen beside it.
stage_redescribe <- function(st) {
  if (is.null(st$data) || !length(st$steps)) return(st)
  r <- rechoose_descriptions(st)
  if (r$swapped) rechoose_families(r$st)$st else r$st
}

# A greedy order can lock in the weaker explanation: an effect taken early
# for a bump that a periodogram line explains (a GM of tc 0.025 s for a
# 1.7 Hz line) keeps its place, and the line, added later, cannot move it
# (or is refused because it would move it). When the loop ends far from
# the curve (chi2/dof above `revisit_chi2`) after taking values measured
# on the raw data (a line's frequency) at steps behind effects that
# measured nothing, or refusing such values for moving an earlier effect,
# it is run once more from the start with those values taken first, by the
# same rules; the run with the lower criterion is kept and
# `$refine$revisit` says what was compared. So are the instances the raw
# data measure that an instance of the model took on the curve
# (absorbed_seeds(): a resonance taken at step 2 for a 9.9 Hz band and a
# 8.46 Hz line beside it on a measured accelerometer; the line, refused
# after it, and the axis's own GM and lines, refused beside it, ended the
# loop at chi2/dof 211 with N +5%).
revisit_chi2 <- 4

stage_revisit <- function(st) {
  if (is.null(st$data) || !length(st$steps) || !(st$current$chi2 > revisit_chi2)) {
    return(st)
  }
  late <- late_pins(st)
  blocked <- unique(st$blocked)
  blocked <- blocked[!vapply(blocked, function(b) {
    any(vapply(st$pins, function(p) length(p) > 0L && all(same_values(b, p)), NA))
  }, NA)]
  absorbed <- absorbed_seeds(st)
  if (!length(late) && !length(blocked) && !length(absorbed)) return(st)
  # a fresh state on what stage_prepare() made: the series, its diagnostics
  # and the model the steps started from
  s2 <- new_refine_state(st$fit, st$args, st$settings0)
  s2$data <- st$data
  s2$series <- st$series
  s2$raw <- st$raw
  s2$start <- s2$current <- st$start
  s2$seeds <- c(st$pins[late], blocked, lapply(absorbed, `[[`, "values"))
  s2$until <- sort(st$current$terms)
  s2 <- stage_rechoose(stage_steps(s2))
  s2$seeds <- list()
  s2$until <- NULL
  c1 <- refine_crit(st, st$current)
  c2 <- refine_crit(s2, s2$current)
  taken <- is.finite(c2) && c2 < c1 - st$args$min_gain
  rv <- data.frame(
    order = c("greedy", "raw-data values first"),
    terms = c(paste(st$current$terms, collapse = " + "),
              paste(s2$current$terms, collapse = " + ")),
    chi2 = c(st$current$chi2, s2$current$chi2), criterion = c(c1, c2),
    kept = c(!taken, taken), stringsAsFactors = FALSE)
  first <- c(vapply(st$steps[late], function(s) sprintf("%s (%s)", s$effect, s$params), ""),
             if (length(blocked)) sprintf("%d trial(s) an earlier effect kept out", length(blocked)),
             vapply(absorbed, function(a) sprintf("%s at the raw data's values (in the reach of %s)",
                                                  a$effect, a$what), ""))
  message(sprintf(paste(
    "avrefine(): the greedy order ended at chi2/dof %s; taking %s first gave %s:",
    "%s kept."), format_num(st$current$chi2), paste(first, collapse = ", "),
    format_num(s2$current$chi2), if (taken) "that run is" else "the greedy run is"))
  out <- if (taken) s2 else st
  out$revisit <- rv
  out
}

# The accepted steps that pinned values measured on the raw data (a line's
# frequency, a band's spectrum) behind a step that pinned nothing, whose
# values the final model still holds: their indices, in the order taken.
late_pins <- function(st) {
  pinned <- lengths(st$pins) > 0L
  first_free <- match(FALSE, pinned)
  if (is.na(first_free)) return(integer(0))
  held <- st$settings$fixed
  late <- which(seq_along(st$pins) > first_free & pinned)
  late[vapply(st$pins[late], function(p) all(same_values(p, held)), NA)]
}

# Which of `values` occur among `among` (to 1e-9 relative)?
same_values <- function(values, among) {
  vapply(unlist(values), function(v) any(abs(among - v) <= 1e-9 * abs(v)), NA)
}

# The seed (in `seeds`, a list of pinned value sets) whose values trial
# `tr` pins, or 0.
seed_of <- function(tr, seeds) {
  p <- unlist(tr$pin)
  if (!length(p)) return(0L)
  for (j in seq_along(seeds)) {
    s <- unlist(seeds[[j]])
    if (length(s) && all(same_values(s, p))) return(j)
  }
  0L
}

# What is left: residual structure no catalogue effect explained.
stage_remaining <- function(st) {
  cur <- st$current
  st$remaining <- residual_signatures(cur$data$tau, stats::residuals(cur),
                                      level = st$args$level)
  st$unexplained <- unexplained_table(st$remaining, cur)
  st
}

# Short tau cannot hijack the fit: when the model still cannot describe a
# run of first points, they are left out of the fit (an automatic tau
# range, with a message) so that they do not drive N to 0 or bend the
# long-tau terms; the run stays listed as unexplained.
stage_trim <- function(st) {
  u <- st$unexplained
  short <- u[u$kind == "short_end", , drop = FALSE]
  if (!nrow(short)) return(st)
  cur <- st$current
  tau_all <- cur$data$tau
  keep_from <- min(tau_all[tau_all > short$tau_to[1L]], Inf)
  if (sum(tau_all >= keep_from) < length(cur$coefficients) + 3L) return(st)
  step <- length(st$steps) + 1L
  args <- refit_args(cur, cur$terms, st$settings,
                     start = stats::coef(cur)[cur$layout$role == "nonlinear"])
  args$tau_range <- c(keep_from, Inf)
  r <- state_refit(st, args, "refit without the first points", "tau_range", step)
  st <- r$st
  trimmed <- r$fit
  # without the first points a free nonlinear parameter may run off to
  # values the raw data contradict (a resonance's tc to a pure tone); then
  # the effects keep the nonlinear values the full curve gave them and only
  # the amplitudes are refitted
  if (is.null(trimmed) || !earlier_hold(st, trimmed)) {
    nl <- stats::coef(cur)[cur$layout$role == "nonlinear"]
    nl <- nl[!names(nl) %in% names(st$settings$fixed)]
    if (length(nl)) {
      args_h <- refit_args(cur, cur$terms, st$settings, hold = nl)
      args_h$tau_range <- c(keep_from, Inf)
      r <- state_refit(st, args_h, "refit without the first points, nonlinear held",
                       "tau_range", step)
      st <- r$st
      trimmed <- r$fit
    }
  }
  if (!is.null(trimmed) && earlier_hold(st, trimmed)) {
    st$tau_range <- c(keep_from, max(tau_all))
    message(sprintf(paste(
      "avrefine(): no catalogue effect describes the first points (tau %s-%s s);",
      "the model is fitted from tau = %s s on (see $unexplained)."),
      format_num(short$tau_from[1L]), format_num(short$tau_to[1L]),
      format_num(keep_from)))
    st$current <- trimmed
  }
  st
}

# A step screens its candidates with the model's nonlinear values held and
# keeps them held when its free refit breaks an earlier effect; the last
# step's stay so in the model returned (a GM's tc held at 48.5 s, its
# interval of zero width). They are freed in one last refit, taken where
# it is no worse on the all-free scale and leaves every effect as the raw
# data had it; else they stay held, and the report says so. Values the
# raw data pinned (a line's frequency) stay pinned, but for those an entry
# frees only now (`release_late`: two resonances of one run), freed with
# them at the cost of their parameters.
stage_release <- function(st) {
  cur <- st$current
  held <- held_values(cur, st$settings)
  pinned <- st$settings$fixed
  to_free <- intersect(intersect(st$release_late, names(pinned)), cur$layout$name)
  if (!length(held) && !length(to_free)) return(st)
  nl <- stats::coef(cur)[cur$layout$role == "nonlinear"]
  limit <- refine_crit_held(st, cur, length(held)) + 1e-6
  st$settings$fixed <- pinned[!names(pinned) %in% to_free]
  held <- c(held, stats::coef(cur)[to_free])
  # a refit's values still held, less the pinned ones it left pinned (never
  # charged: the raw data measure them)
  charged <- function(f) {
    lay <- f$layout
    sum(lay$fixed & lay$role == "nonlinear" & !lay$name %in% names(pinned))
  }
  taken <- function(st, f, still) {
    if (is.null(f)) return(NULL)
    crit <- refine_crit_held(st, f, charged(f))
    if (crit <= limit && earlier_hold(st, f)) list(fit = f, crit = crit)
  }
  r <- free_held(st, cur$terms, nl, held, taken, "refit with the held values free",
                 "release", length(st$steps) + 1L,
                 tau_range = if (!is.null(st$tau_range)) c(st$tau_range[1L], Inf))
  st <- r$st
  # the values freed here that the refit taken left held (all of them, when
  # none was taken) stay pinned
  kept <- if (is.null(r$won)) to_free else
    intersect(to_free, r$won$fit$layout$name[r$won$fit$layout$fixed])
  st$settings$fixed <- c(st$settings$fixed, pinned[kept])
  if (!is.null(r$won)) st$current <- r$won$fit
  st
}

# An instance this call added that the final model sizes far off what
# the raw data measure (the catalogue's raw_hold(): a line the curve put
# at a fraction of its periodogram amplitude, or at 0, or at many times
# it) is held at the raw
# data's values. The curve cannot tell lines 0.1 Hz apart: on measured
# accelerometers an axis's 1.60 Hz line went to 0 in one run and kept its
# amplitude in the next, once its 1.70 Hz neighbour had entered and taken
# their power, and the description of the axis flipped with it. Holding
# some moves the power among the others (a square wave's 5th and 7th
# harmonics held, its 9th went to 0 and its 11th took 14 x its line), so
# what the refit sizes off its raw values is held too, at most three
# rounds. Taken when the criterion rises less than `min_gain` (the values
# held are measured, not charged) and no effect loses its raw-data
# support.
stage_hold <- function(st) {
  if (is.null(st$raw)) return(st)
  cur <- st$current
  settings <- st$settings
  step <- length(st$steps) + 1L
  notes <- character()
  f <- cur
  for (round in 1:3) {
    h <- raw_holds(st, f, settings$fixed)
    if (!length(h$values)) break
    notes <- c(notes, h$notes[!names(h$notes) %in% names(notes)])
    settings$fixed <- c(settings$fixed, h$values)
    start <- stats::coef(f)[f$layout$role == "nonlinear"]
    start <- start[!names(start) %in% names(settings$fixed)]
    r <- state_refit(st, refit_args(f, f$terms, settings, start = start),
                     "refit with values held at the raw data's", "hold", step)
    st <- r$st
    f <- r$fit
    if (is.null(f)) return(st)
  }
  if (!length(notes) || !taken_at_raw_values(st, f, cur)) return(st)
  st <- note_at_end(st, notes)
  st$settings <- settings
  st$current <- f
  st
}

# A refit `f` of the model `cur` with values held at the raw data's
# (measured, not charged) is taken when its criterion rises less than
# `min_gain` and it leaves no effect contradicted by the raw data that
# `cur` did not (stage_hold(), stage_absorbed()).
taken_at_raw_values <- function(st, f, cur) {
  refine_crit(st, f) <= refine_crit(st, cur) + st$args$min_gain &&
    all(earlier_broken(st, f) %in% earlier_broken(st, cur))
}

# Each step whose label `notes` names gets that note at the end of its
# evidence ("; at the end, ...").
note_at_end <- function(st, notes) {
  st$steps <- lapply(st$steps, function(s) {
    if (s$label[1L] %in% names(notes)) {
      s$evidence <- paste0(s$evidence, "; at the end, ", notes[[s$label[1L]]])
    }
    s
  })
  st
}

# The values the raw data measure for the instances `labels` (those this
# call added) that fit `f` sizes off them (raw_hold_values()), less those
# `fixed` already holds: list(values (named by coefficient), notes (named
# by label)).
raw_holds <- function(st, f, fixed, labels = added_labels(st)) {
  lay <- f$layout
  cf <- stats::coef(f)
  labs <- term_labels(f$terms)
  values <- numeric()
  notes <- character()
  for (l in intersect(labels, labs)) {
    h <- raw_hold_values(f$terms[match(l, labs)], as.list(instance_params(cf, lay, l)), st$raw)
    if (is.null(h)) next
    v <- stats::setNames(h$values, paste0(l, ".", names(h$values)))
    v <- v[names(v) %in% lay$name & !names(v) %in% names(fixed)]
    if (!length(v)) next
    values <- c(values, v)
    notes[[l]] <- h$note
  }
  list(values = values, notes = notes)
}

# The label of each step's instance, in step order.
step_labels <- function(st) vapply(st$steps, function(s) s$label[1L], "")

# The labels of the instances this call added, one per step, in order.
added_labels <- function(st) unique(step_labels(st))

# An instance this call added that the final model holds at amplitude 0
# (and stage_hold() could not hold at what the raw data measure)
# describes nothing: it leaves the model, refitted without it (taken when
# no worse by the criterion), and is listed in $refine$rejected.
stage_prune <- function(st) {
  cur <- st$current
  lay <- cur$layout
  cf <- stats::coef(cur)
  added <- added_labels(st)
  dead <- vapply(added, function(l) {
    a <- lay$label == l & lay$role == "amp"
    any(a) && all(cf[lay$name[a]] == 0)
  }, NA)
  dead <- added[dead]
  if (!length(dead)) return(st)
  step <- length(st$steps) + 1L
  w <- refit_without(st, cur, dead, "refit without the instances at 0", "prune", step)
  st <- w$st
  if (is.null(w$fit) || !(refine_crit(st, w$fit) <= refine_crit(st, cur) + 1e-6)) return(st)
  leave_model(st, w, dead, step, "at amplitude 0 in the final model: left out",
              "amplitude 0 in the final model")
}

# Each instance this call added is judged again on the final model, by
# the rule that took it: one whose removal raises the criterion by less
# than `min_gain` leaves the model (the least needed first, then the others
# again). A greedy step can take an effect while the model still lacks
# another that then describes the same part of the curve better (a GM
# taken at the step before a band's resonance entered); the order of the
# steps must not decide the description. Nor may the refits after its
# step move an instance to where it stands in for a series effect left in
# the data (a measured accelerometer's GM taken at 13 s beside a 19 s ACF,
# at 35 s in the final model: what the steps found in the series add
# there, the rule its entry would have failed): such an instance leaves
# too, whatever it gains (final_stand_in()). Instances whose values the raw
# data measure (a periodogram line's frequency, a harmonic set's further
# lines kept at a cost to the curve; the curve cannot tell two lines 0.1 Hz
# apart and would drop one run's and keep another's) and entries that
# replace a term (the filter) are not judged again by the curve, except an
# entry that can take others' power on the curve (`absorbs`: a resonance
# pinned at its band; a measured accelerometer's weak 8.17 Hz band, taken
# before a sawtooth's 7.8 and 8.58 Hz harmonics, gained 4 in the final
# model and stayed, an effect the run without the sawtooth left out); a
# removal that leaves an earlier effect contradicted by the raw data is not
# taken.
stage_reconsider <- function(st) {
  before <- st$current
  for (round in seq_along(st$steps)) {
    cur <- st$current
    groups <- judged_again(st, cur)
    if (!length(groups)) break
    c_cur <- refine_crit_held(st, cur, length(held_values(cur, st$settings)))
    broken <- earlier_broken(st, cur)
    step <- length(st$steps) + 1L
    best <- NULL
    for (l in groups) {
      w <- refit_without(st, cur, l, "refit without one instance", "reconsider", step)
      st <- w$st
      if (is.null(w$fit)) next
      holds <- all(broken_without(st, w) %in% broken)
      gain <- refine_crit(st, w$fit) - c_cur
      if (holds && gain < instance_need(st, cur, l)) {
        if (is.null(best) || gain < best$gain) best <- list(w = w, label = l, gain = gain)
        next
      }
      dup <- final_stand_in(st, cur, l, w)
      if (is.null(dup)) next
      # the instances its removal leaves sized off the raw data's values
      # are held there (stage_hold()'s rule)
      if (!holds) {
        w <- hold_broken(st, w, step)
        st <- w$st
        if (is.null(w$fit) || !all(broken_without(st, w) %in% broken)) next
        gain <- refine_crit(st, w$fit) - c_cur
      }
      if (is.null(best) || gain < best$gain) best <- list(w = w, label = l, gain = gain, dup = dup)
    }
    if (is.null(best)) break
    why <- if (!is.null(best$dup)) {
      series_stand_in_text(best$dup$dup)
    } else {
      sprintf("the final model does without it (the criterion %s by %s without it, under min_gain %s)",
              if (best$gain < 0) "falls" else "rises", format_num(abs(best$gain)),
              format_num(st$args$min_gain))
    }
    # (the notes are under the refit's labels, the steps under the model's)
    if (length(best$w$notes)) {
      map <- label_map(best$w$from$terms, attr(best$w$terms, "gone"))
      notes <- best$w$notes
      names(notes) <- names(map)[match(names(notes), map)]
      st <- note_at_end(st, notes)
    }
    if (!is.null(best$dup)) {
      st$duplicates <- rbind(st$duplicates, cbind(
        data.frame(step = as.integer(step), effect = best$dup$effect,
                   params = format_params(best$dup$par, best$dup$effect),
                   stringsAsFactors = FALSE),
        best$dup$dup))
    }
    st <- leave_model(st, best$w, best$label, step, why, why)
  }
  if (!identical(st$current, before)) st <- stage_remaining(st)
  st
}

# stage_reconsider()'s series rule: a single instance `l` of the final
# model `cur` that stands in for a series effect left in the data, judged
# against `w`, the model refitted without it (series_stand_in()). Only an
# instance whose nonlinear values moved by more than half again since its
# step is judged again: at the values it was taken at it passed that rule,
# and near its bar the other effects' refits alone tip it either way (a
# measured accelerometer's own 84 s GM, unmoved, gained 8.7 and 26 in two
# rounds against the 20 it needs, and 24 in the run without the added
# square wave). NULL or list(effect, par, dup).
final_stand_in <- function(st, cur, l, w) {
  if (length(l) != 1L || is.null(st$series)) return(NULL)
  effect <- cur$terms[match(l, term_labels(cur$terms))]
  par <- instance_params(stats::coef(cur), cur$layout, l)
  k <- match(l, step_labels(st))
  if (!is.na(k) && !values_moved(effect, attr(st$steps[[k]], "values"), par)) return(NULL)
  ev <- raw_evidence(effect, as.list(par), st$raw, diag_series(st$raw), st$args$freq,
                     cur, l)
  dup <- series_stand_in(st, cur, l, effect, par, ev, without = w$fit,
                         without_settings = w$settings)
  if (is.null(dup)) NULL else list(effect = effect, par = par, dup = dup)
}

# Did the nonlinear values of an instance of `effect` move by more than a
# factor `by` from `then` (its values when taken; NULL: unknown, taken as
# moved) to `now`?
values_moved <- function(effect, then, now, by = 1.5) {
  if (is.null(then)) return(TRUE)
  sp <- split_term(effect)
  p <- effect_entry(sp$kind, sp$variant)$params
  nl <- intersect(intersect(p$name[p$role == "nonlinear"], names(then)), names(now))
  r <- abs(log(now[nl] / then[nl]))
  any(is.finite(r) & r > log(by))
}

# refit_without()'s model `w` refitted with the instances it leaves
# contradicted by the raw data held at the values the raw data measure
# (raw_holds(); a measured band the refit sized 5% over its power,
# beyond twice its uncertainty): `w` with fit, settings and `notes` (by
# label) of that refit, or with fit NULL when none can be held.
hold_broken <- function(st, w, step) {
  f <- w$fit
  h <- raw_holds(st, f, w$settings$fixed, earlier_broken(st, f))
  if (!length(h$values)) {
    w$fit <- NULL
    return(w)
  }
  settings <- w$settings
  settings$fixed <- c(settings$fixed, h$values)
  start <- stats::coef(f)[f$layout$role == "nonlinear"]
  start <- start[!names(start) %in% names(settings$fixed)]
  args <- refit_args(f, f$terms, settings, start = start)
  if (!is.null(st$tau_range)) args$tau_range <- c(st$tau_range[1L], Inf)
  r <- state_refit(st, args, "refit without one instance, values held at the raw data's",
                   "reconsider", step)
  w$st <- r$st
  w$fit <- r$fit
  w$settings <- settings
  w$notes <- h$notes
  w
}

# The instances earlier_broken() finds in refit_without()'s model `w`,
# under the labels they had before the drop (without gm1, the model's gm1 is
# the gm2 that was).
broken_without <- function(st, w) {
  now <- earlier_broken(st, w$fit)
  map <- label_map(w$from$terms, attr(w$terms, "gone"))
  names(map)[match(now, map)]
}

# The instances stage_reconsider() judges again, in groups that leave
# together (the two instances of a split, taken in one step, are judged as
# the step took them): added by this call, in the model, none of whose
# values the raw data measure (pinned: a periodogram line's frequency, a
# measured band's spectrum), not an entry that replaces a term.
judged_again <- function(st, cur) {
  lay <- cur$layout
  labs <- term_labels(cur$terms)
  measured <- lay$label[lay$name %in% names(st$settings$fixed)]
  kinds <- split_term(cur$terms)$kind
  # (an entry whose instances take others' power on the curve, `absorbs`,
  # is judged again where the raw data measure its values: at its step it
  # may have gained by lines the model did not hold yet)
  absorbing <- vapply(kinds, function(k) !is.null(effect_entry(k)$absorbs), NA)
  ok <- labs[(!labs %in% measured | absorbing) &
               vapply(kinds, function(k) !length(effect_entry(k)$replaces), NA)]
  rows <- step_labels(st)
  group <- vapply(seq_along(rows), function(i) {
    j <- if (i <= length(st$taken_with)) st$taken_with[i] else NA_integer_
    if (is.na(j)) i else j
  }, 0L)
  out <- lapply(unique(group[rows %in% labs]), function(g) unique(rows[group == g]))
  Filter(function(l) all(l %in% ok), out)
}

# The current model refitted without the instances `dead` (labels), from
# its values, on its tau range: list(st, fit, settings, terms).
refit_without <- function(st, cur, dead, stage, effect, step) {
  lay <- cur$layout
  labs <- term_labels(cur$terms)
  gone <- labs %in% dead
  tm <- structure(cur$terms[!gone], gone = gone)
  settings <- st$settings
  settings$fixed <- relabel_values(settings$fixed, cur$terms, tm)
  start <- relabel_values(stats::coef(cur)[lay$role == "nonlinear"], cur$terms, tm)
  start <- start[!names(start) %in% names(settings$fixed)]
  args <- refit_args(cur, c(tm), settings, start = start)
  if (!is.null(st$tau_range)) args$tau_range <- c(st$tau_range[1L], Inf)
  r <- state_refit(st, args, stage, effect, step)
  list(st = r$st, fit = r$fit, settings = settings, terms = tm, from = cur)
}

# The model of refit_without() `w` taken: the instances `dead` listed in
# $refine$rejected (`reason`), the steps that added them labelled "left:"
# and their evidence saying why (`note`), the other steps under the labels
# the model now gives their instances.
leave_model <- function(st, w, dead, step, reason, note) {
  cur <- w$from
  cf <- stats::coef(cur)
  labs <- term_labels(cur$terms)
  for (l in dead) {
    st$rejected <- add_rejected(st$rejected, step, cur$terms[match(l, labs)],
                                instance_params(cf, cur$layout, l), reason)
  }
  map <- label_map(cur$terms, attr(w$terms, "gone"))
  st$steps <- lapply(st$steps, function(s) {
    if (s$label[1L] %in% dead) {
      s$label <- paste0("left:", s$label)
      s$evidence <- paste0(s$evidence, "; left out at the end: ", note)
    } else if (s$label[1L] %in% names(map)) {
      s$label <- unname(map[s$label])
    }
    s
  })
  st$settings <- w$settings
  st$current <- w$fit
  st
}

# Effects the raw data confirm that the final model lacks because the
# curve gained less than `min_gain` with them when the steps ended: a
# measured gyro's own 155 s GM, its block means' ACF at z 14.6, gained
# 9.94 and chi2/dof fell from 1.19 to 0.14; with it B reads 27% lower and
# K half. Those trials of the screening that ended the steps are refitted
# beside the final model from their values (the best `alternatives_max`
# by that gain); one the curve still prefers, a valid instance the raw
# data confirm, is an alternative description of the record. Listed in
# $refine$alternatives with its model's coefficients
# ($refine$alternative_coefs), whose readings mark the final model's
# (mark_model_choice()); the model is unchanged.
alternatives_max <- 3L
stage_alternatives <- function(st) {
  recs <- st$short_trials
  st$alternatives <- NULL
  if (is.null(st$raw) || !length(recs)) return(st)
  cur <- st$current
  c_cur <- refine_crit(st, cur)
  tau <- cur$data$tau
  recs <- recs[order(-vapply(recs, `[[`, 0, "gain"))]
  rows <- list()
  coefs <- list()
  seen <- character()
  for (rec in recs) {
    if (length(rows) >= alternatives_max) break
    tr <- rec$trial
    if (!addable_kind(split_term(tr$effect)$kind, cur$terms)) next
    key <- paste(tr$effect, format_params(rec$par, tr$effect))
    if (key %in% seen) next
    seen <- c(seen, key)
    tm <- model_terms(cur$terms, tr$effect, c(as.list(rec$par), tr$pin[[1L]]), cur)
    # (one that would replace a term of the model is a form, not an addition)
    if (any(attr(tm, "gone"))) next
    r <- refit_with(cur, c(tm), tr$effect, as.list(rec$par), st$settings,
                    hold = pin_values(cur$terms, tr$effect, tr$pin[[1L]]), local = TRUE)
    st$failures <- record_conditions(st$failures, r$conditions, length(st$steps) + 1L,
                                     tr$effect)
    f <- r$fit
    if (is.null(f)) next
    lab <- new_label(cur$terms, tr$effect)
    gain <- c_cur - refine_crit(st, f)
    if (!is.finite(gain) || gain <= 0 || max_share(f, lab, st$settings$fixed) < 0.02) next
    jd <- judge_instance(st, f, tr$effect, lab, tau)
    if (!is.null(jd$why) || !isTRUE(jd$ev$support)) next
    rows[[length(rows) + 1L]] <- data.frame(
      effect = tr$effect, label = lab, params = format_params(jd$par, tr$effect),
      gain = gain, evidence = jd$ev$text, chi2 = f$chi2, stringsAsFactors = FALSE)
    coefs[[length(coefs) + 1L]] <- stats::coef(f)
  }
  if (length(rows)) st$alternatives <- structure(do.call(rbind, rows), coefs = coefs)
  st
}

stage_assemble <- function(st) {
  fit <- st$fit
  out <- complete_covariance(st$current)
  all_steps <- Reduce(bind_steps, st$steps, fit$steps)
  out$steps <- all_steps
  out$unexplained <- st$unexplained
  # Curve only: the accepted effects the raw data could not confirm.
  new_steps_df <- all_steps[seq_len(nrow(all_steps)) > NROW(fit$steps), , drop = FALSE]
  unconfirmed <- if (is.null(st$data)) new_steps_df$label else character()
  out$series <- series_kept(st$series)
  a <- st$args
  out$refine <- list(candidates = a$candidates, criterion = a$criterion,
                     min_gain = a$min_gain, level = a$level,
                     diagnostics = diag_report(st$raw),
                     remaining = st$remaining, start_terms = fit$terms,
                     failures = st$failures, rejected = st$rejected,
                     series_duplicates = st$duplicates, revisit = st$revisit,
                     unconfirmed = unconfirmed, tau_range = st$tau_range,
                     alternatives = st$alternatives,
                     alternative_coefs = attr(st$alternatives, "coefs"),
                     removed = if (is.null(st$series)) character() else st$series$removed)
  class(out) <- unique(c("avrefine", class(out)))
  st$result <- validate_avfit(out)
  st
}

# ---- step stages ----------------------------------------------------------------

# No residual threshold gates the search: with no signature every candidate
# is still asked, and only the criterion decides (two GMs a decade apart
# leave no run reaching `level` for the second one).
step_trace <- function(st) {
  cur <- st$current
  st$refused <- list()
  st$unpaid <- list()
  st$refused_forms <- character()
  tau <- cur$data$tau
  st$sig <- residual_signatures(tau, stats::residuals(cur), level = st$args$level)
  traced <- trace_candidates(tau, cur$data$avar, cur$data$fitted, st$sig,
                             present = cur$terms, candidates = st$args$candidates,
                             raw = st$raw)
  st$trials <- fresh_pinned_trials(
    ready_trials(candidate_trials(traced, cur$terms, st$args$candidates, st$sig),
                 st$settings$fixed),
    st$settings$fixed)
  if (isTRUE(st$only_sets) && nrow(st$trials)) {
    keep <- vapply(seq_len(nrow(st$trials)), function(i) continues_set(st$trials[i, ]), NA)
    st$trials <- st$trials[keep, , drop = FALSE]
  }
  if (length(st$seeds) && nrow(st$trials)) {
    keep <- vapply(seq_len(nrow(st$trials)), function(i) seed_of(st$trials[i, ], st$seeds) > 0L, NA)
    if (any(keep)) st$trials <- st$trials[keep, , drop = FALSE] else st$seeds <- list()
  }
  if (!nrow(st$trials)) st$flow <- "stop"
  st
}

# A family's form chosen before an effect the raw data pinned and confirm
# (a line's frequency) may have been chosen for that effect's bump (a
# first-order low-pass taken for a 2.2 Hz line's bump beside a moving
# average's own: N +24%); once the effect is in, the form is chosen again,
# on the curve without the sharp lines the model does not hold yet (a set
# that effect opened, whose further lines a form would otherwise take in
# turn).
step_reform <- function(st) {
  if (!isTRUE(st$reform)) return(st)
  st$reform <- FALSE
  r <- rechoose_families(st, known = TRUE)
  st <- r$st
  if (r$swapped) st$flow <- "next"
  st
}

# Screening: the model's existing nonlinear parameters are held at their
# current values while candidates are compared (one 1-D profile each); the
# winner is then refitted with everything free. The criterion of a screened
# fit is put on the all-free scale by charging the held ones. When
# screening finds nothing, the candidates are tried once more with all
# nonlinear parameters free (slower, but catches effects that only pay
# once the others may move). Traced candidates first; the others only when
# none of those pays. (Without any residual signature, the free pass
# screens only a further instance of an entry the model holds: below.)
step_screen <- function(st) {
  st <- screen_trials(st)
  # a revisit's seeds that do not pay leave the step to every trial
  if (is.null(st$best) && length(st$seeds)) {
    st$seeds <- list()
    st <- step_trace(st)
    if (st$flow == "go") st <- screen_trials(st)
  }
  st
}

screen_trials <- function(st) {
  cur <- st$current
  st$c0 <- refine_crit(st, cur)
  st$best <- NULL
  st$short_trials <- list()
  nl_now <- stats::coef(cur)[cur$layout$role == "nonlinear"]
  nl_now <- nl_now[!names(nl_now) %in% names(st$settings$fixed)]
  holds <- if (length(nl_now)) list(nl_now, numeric(0)) else list(numeric(0))
  trials <- st$trials
  # Without a residual signature the free pass screens only a further
  # instance of a repeatable entry the model holds and that the curve
  # alone places (the raw data propose none: their values are never
  # pinned). Beside the first held at its one-term compromise, a second
  # GM of another time constant does not pay, and the terms the first
  # shares the curve with (B, K) leave no signature to trace it by.
  only_again <- length(nl_now) && !nrow(st$sig)
  if (only_again) {
    again <- vapply(trials$effect, function(k) {
      e <- effect_entry(split_term(k)$kind)
      isTRUE(e$repeatable) && is.null(e$propose) && e$name %in% split_term(cur$terms)$kind
    }, NA)
  }
  for (h in holds) {
    st$hold <- h
    for (tier in list(which(trials$traced), which(!trials$traced))) {
      if (only_again && !length(h)) tier <- tier[again[tier]]
      for (i in tier) {
        r <- screen_trial(st, trials[i, ], nl_now)
        st <- r$st
        if (!is.null(r$cand) && (is.null(st$best) || r$cand$adj < st$best$adj)) {
          st$best <- r$cand
        }
      }
      if (!is.null(st$best)) return(st)
    }
  }
  st
}

# Nothing paid: choose the families again on the current model; after a
# change the loop goes on (the effects that pay may differ); else a form
# may pay beside a trial the raw data refused (family_pairs()), else the
# loop stops.
step_settle <- function(st) {
  if (!is.null(st$best)) return(st)
  r <- rechoose_families(st, known = TRUE)
  st <- r$st
  # no form pays alone: one may pay beside a trial the old form kept out
  if (!r$swapped) {
    st <- family_pairs(st)
    if (!is.null(st$best)) return(st)
    # nor a trial alone: two the raw data measure may pay together
    st <- raw_pairs(st)
    if (!is.null(st$best)) return(st)
  }
  st$flow <- if (r$swapped) "next" else "stop"
  if (!r$swapped) st$settled <- st$current
  st
}

# Refit the winner with the held nonlinear parameters free again (the new
# one starts where screening put it); the evidence is read again at the
# values the free refit gives, and a refit the raw data contradict is not
# taken.
step_refit_winner <- function(st) {
  best <- st$best
  # the values pinned before, under the labels of the new model
  if (length(best$pin) || !identical(best$fixed, st$settings$fixed)) {
    st$settings$fixed <- c(best$fixed, best$pin)
  }
  if (!length(st$hold)) return(st)
  lay <- best$fit$layout
  start <- stats::coef(best$fit)[lay$role == "nonlinear"]
  effect <- best$trial$effect
  # a refit taken when it is no worse than the screened one (both on the
  # all-free scale: each value still held charged as screening charges
  # them), its evidence read again, and leaves every earlier effect as the
  # raw data had it
  taken <- function(st, full, held = 0L) {
    if (is.null(full)) return(NULL)
    crit <- refine_crit_held(st, full, held)
    if (crit > best$crit + 1e-6) return(NULL)
    p2 <- instance_params(stats::coef(full), full$layout, best$label)
    ev2 <- raw_evidence(effect, as.list(p2), st$raw, diag_series(st$raw), st$args$freq,
                        full, best$label)
    ok <- !isFALSE(ev2$support) &&
      is.null(unconfirmed_marginal(effect, ev2, st$c0 - crit, st$args$min_gain, st$raw)) &&
      is.null(inadmissible(effect, p2, st$current$data$tau, st$args$freq)) &&
      earlier_hold(st, full)
    if (ok) list(fit = full, crit = crit, params = p2, ev = ev2)
  }
  r <- free_held(st, best$fit$terms, start, held_values(best$fit, st$settings), taken,
                 "refit of the winner", effect)
  st <- r$st
  won <- r$won
  if (!is.null(won)) {
    st$best$fit <- won$fit
    st$best$crit <- won$crit
    st$best$params <- won$params
    st$best$ev <- won$ev
    if (!is.null(best$also)) {
      st$best$ev$text <- paste0(won$ev$text, "; ", best$also$note %||%
                                  paste("split in two with", best$also$label))
    }
  }
  st
}

# Describe the effect where the fitted term actually sits, which may differ
# from where the trial started.
step_record <- function(st) {
  best <- st$best
  loc <- locate_signature(st$sig, best$fit, best$label)
  evidence <- loc$text
  if (nzchar(best$ev$text)) {
    evidence <- paste0(evidence, "; raw data: ", best$ev$text,
                       if (isFALSE(best$ev$support)) " (NOT supported by the raw data)")
  }
  k <- if (length(st$seeds)) seed_of(best$trial, st$seeds) else 0L
  if (k > 0L) {
    evidence <- paste0(evidence, "; taken first on a revisit of the greedy order")
    st$seeds <- st$seeds[-k]
  }
  st$steps[[length(st$steps) + 1L]] <- step_row(
    best$trial$effect, best$label, loc, best$params, evidence, best$ev$support,
    st$current, best$fit, st$c0, best$crit)
  st$pins[length(st$steps)] <- list(unlist(best$pin) %||% numeric(0))
  # pinned values the entry frees only once the loop ends (stage_release())
  if (isTRUE(best$trial$release_late)) st$release_late <- c(st$release_late, names(unlist(best$pin)))
  if (length(best$pin) && isTRUE(best$ev$support) && holds_family(st$current)) {
    st$reform <- TRUE
  }
  # the second instance of a split (split_trial()): its own row, at the
  # values the final refit gave it (the step's gain is on the first row)
  # (and a form chosen again beside them: raw_pairs())
  first <- length(st$steps)
  for (also in c(if (!is.null(best$also)) list(best$also), best$extras)) {
    lab2 <- also$label
    effect2 <- also$effect %||% best$trial$effect
    par2 <- instance_params(stats::coef(best$fit), best$fit$layout, lab2)
    loc2 <- locate_signature(st$sig, best$fit, lab2)
    ev2 <- raw_evidence(effect2, as.list(par2), st$raw,
                        diag_series(st$raw), st$args$freq, best$fit, lab2)
    st$steps[[length(st$steps) + 1L]] <- step_row(
      effect2, lab2, loc2, par2,
      paste0(loc2$text, "; ", also$note %||%
               paste0("split from ", best$label, "'s one-term compromise"),
             if (nzchar(ev2$text)) paste0("; raw data: ", ev2$text)),
      ev2$support, best$fit, best$fit, best$crit, best$crit)
    st$pins[length(st$steps)] <- list(numeric(0))
    st$taken_with[length(st$steps)] <- first
  }
  st$current <- best$fit
  st
}
