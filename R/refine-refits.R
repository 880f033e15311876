# The loop's refits: the arguments of a refit (explicit settings, start and
# held values), one refit with its conditions kept, and the refit of a
# model with one more term from two starts.

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

# Run one refit. Returns list(fit, conditions): `fit` is NULL when the refit
# failed or has no degrees of freedom left; `conditions` lists, in the order
# they came, each error or (muffled) warning as list(condition, stage), for
# the caller to record (record_conditions()).
try_refit <- function(args, stage) {
  hit <- refit_memo_get(args)
  if (!is.null(hit)) {
    fit <- hit$fit
    if (!is.null(fit)) fit$call <- refit_call(args)
    return(list(fit = fit, conditions = lapply(hit$conditions, function(cd) {
      cd$stage <- stage
      cd
    })))
  }
  log <- new.env(parent = emptyenv())
  log$conditions <- list()
  keep <- function(cnd) {
    log$conditions[[length(log$conditions) + 1L]] <- list(condition = cnd, stage = stage)
  }
  res <- withCallingHandlers(
    tryCatch(refit_curve(args), error = function(e) {
      keep(e)
      NULL
    }),
    warning = function(w) {
      keep(w)
      invokeRestart("muffleWarning")
    })
  if (!is.null(res) && !is.finite(res$chi2)) {
    keep(simpleCondition("no degrees of freedom left for chi2"))
    res <- NULL
  }
  refit_memo_put(args, res, log$conditions)
  list(fit = res, conditions = log$conditions)
}

# The refits of one avrefine() call, each made once. A refit is a pure
# function of its arguments: the previous fit enters only through its
# curve, its EDF source and its layout (the EDF the curve gets from that
# model, curve_of_fit()), the rest are the terms, start and held values,
# tau range and settings. The loop asks for the same refit again (a
# candidate screened at the next step against an unchanged model, the
# free refit that repeats a screen): the first result is given, with its
# conditions replayed under the asking stage, so the failures recorded are
# those of a second run. avrefine() opens the memo for its call.
# Opened and closed with call_store_open() / call_store_close() (R/coef.R).
refit_memo <- new.env(parent = emptyenv())
refit_memo$depth <- 0L
refit_memo$entries <- list()

refit_key <- function(args) {
  av <- args$av
  list(input = av$input, edf_source = av$edf_source, layout = av$layout,
       rest = args[names(args) != "av"])
}

refit_memo_get <- function(args) {
  if (refit_memo$depth == 0L || !length(refit_memo$entries)) return(NULL)
  key <- refit_key(args)
  for (e in refit_memo$entries) if (identical(e$key, key)) return(e)
  NULL
}

refit_memo_put <- function(args, fit, conditions) {
  if (refit_memo$depth == 0L) return(invisible(NULL))
  refit_memo$entries[[length(refit_memo$entries) + 1L]] <- list(
    key = refit_key(args), fit = fit, conditions = conditions)
  invisible(NULL)
}

# avfit() with `args` (as do.call(avfit, args) calls it), without the
# covariance's costly part: the loop reads its refits' criterion, chi2 and
# shares, never their SEs; the fit it returns gets its full covariance at
# the end (complete_covariance(), stage_assemble()).
refit_curve <- function(args) {
  # an argument avfit() does not name exactly (a user's avrefine(...)) is
  # left to avfit() to match or refuse
  if (!all(names(args) %in% setdiff(names(formals(avfit)), "..."))) {
    return(do.call(avfit, args))
  }
  cl <- refit_call(args)
  a <- c(formals(avfit)[setdiff(names(formals(avfit)), c("av", "..."))], list(av = NULL))
  a[names(args)] <- args
  if (is.call(a$control)) a$control <- avfit_control()
  fit_curve(a$av, a$terms, a$n, a$freq, a$type, a$channel, a$start, a$fixed,
            a$tau_range, a$bias_correct, a$correlation, a$control, cl,
            covariance = FALSE)
}

# The call a fit made by do.call(avfit, args) records.
refit_call <- function(args) match.call(avfit, as.call(c(list(avfit), args)))

# Refit the curve with one more term. avfit() profiles the nonlinear
# parameters on its own grid; when the tracing gives a start value for the
# new term's nonlinear parameters the refit is also tried from there, and
# the better of the two is kept (`fit` NULL when both fail); a `local`
# trial is searched from its start only. Returns list(fit, conditions) as
# try_refit() does.
refit_with <- function(fit, terms, effect, init, settings, hold = NULL,
                       good_enough = NULL, local = FALSE) {
  one <- function(start, stage) {
    try_refit(refit_args(fit, terms, settings, start = start, hold = hold), stage)
  }
  lab <- new_label(fit$terms, effect)
  sp <- split_term(effect)
  e <- effect_entry(sp$kind, sp$variant)
  nl <- e$params$name[e$params$role == "nonlinear"]
  ok <- vapply(nl, function(p) {
    v <- init[[p]]
    is.numeric(v) && length(v) == 1L && is.finite(v) && v > 0
  }, logical(1))
  # a trial searched from its start only (`local`) skips the search over
  # the whole range, where it could only end far from what proposed it
  local <- local && all(ok)
  best <- NULL
  conditions <- list()
  if (!local) {
    first <- one(NULL, "screen")
    best <- first$fit
    conditions <- first$conditions
    if (!is.null(best) && !is.null(good_enough) && good_enough(best)) {
      return(list(fit = best, conditions = conditions))
    }
  }
  if (any(ok)) {
    st <- unlist(init[nl[ok]])
    names(st) <- coef_names(e, lab)[match(nl[ok], e$params$name)]
    alt <- one(st, "screen from the traced start")
    conditions <- c(conditions, alt$conditions)
    if (!is.null(alt$fit) && (is.null(best) || alt$fit$objective < best$objective)) {
      best <- alt$fit
    }
  }
  list(fit = best, conditions = conditions)
}

# The nonlinear values fit `f` holds that `settings` did not pin (the raw
# data's values): those screening held, named as `f` names them.
held_values <- function(f, settings) {
  lay <- f$layout
  held <- lay$fixed & lay$role == "nonlinear" & !lay$name %in% names(settings$fixed)
  stats::coef(f)[lay$name[held]]
}

# Refits of `terms` on the current model with the held values `hold` free
# (from `start`): all of them first; where `judge(st, fit, still)` refuses
# that (`still`: how many values the refit left held), each term's held
# values alone, the best `judge` takes (its `crit`). Everything free may
# trade two earlier terms against each other (a filter's shape against a
# measured band's power at the short taus, which the raw data refuse)
# where one held value alone was left behind (a GM's tc held at 48.5 s
# while the curve asks for 20-25 s). Returns list(st, won): `won` NULL or
# what `judge` returned.
free_held <- function(st, terms, start, hold, judge, stage, effect,
                      step = st$step, tau_range = NULL) {
  refit <- function(st, keep) {
    args <- refit_args(st$current, terms, st$settings, start = start, hold = keep)
    if (!is.null(tau_range)) args$tau_range <- tau_range
    state_refit(st, args, stage, effect, step)
  }
  r <- refit(st, NULL)
  st <- r$st
  won <- judge(st, r$fit, 0L)
  owners <- sub("[.][^.]*$", "", names(hold))
  if (is.null(won) && length(unique(owners)) > 1L) {
    for (k in unique(owners)) {
      r <- refit(st, hold[owners != k])
      st <- r$st
      one <- judge(st, r$fit, sum(owners != k))
      if (!is.null(one) && (is.null(won) || one$crit < won$crit)) won <- one
    }
  }
  list(st = st, won = won)
}
