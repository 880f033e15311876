# The state one avrefine() call passes from stage to stage
# (R/refine-stages.R): the arguments, the refit settings, the raw-data
# diagnostics, the current model, the accepted steps, the failures and
# rejections, and the flow of the step loop. Every stage takes a state and
# returns it; nothing is changed out of sight.

# `args`: the checked arguments (check_refine_args()); `settings`: what
# every refit uses.
new_refine_state <- function(fit, args, settings) {
  validate_refine_state(structure(list(
    fit = fit,                 # the fit the loop started from
    args = args,               # candidates, max_steps, criterion, min_gain,
                               # level, remove, data, series, freq
    settings = settings,       # refit settings (refit_settings())
    settings0 = settings,      # the same at the start (the user's fixed values)
    data = args$data,          # the raw series the loop sees (NULL: curve only)
    series = NULL,             # the series pass (detect_series_effects()) or NULL
    raw = NULL,                # refine_diagnostics() of `data`, or NULL
    current = fit,             # the model so far
    steps = list(),            # accepted steps of this call (step_row())
    failures = new_failures(),
    rejected = new_rejected(),
    duplicates = new_duplicates(), # terms rejected as a series effect again
    sig = NULL,                # residual signatures of the current model
    step = 0L,                 # the step being taken
    trials = NULL,             # that step's candidate trials
    best = NULL,               # the candidate that paid best
    hold = numeric(0),         # nonlinear values held while it was screened
    c0 = NA_real_,             # the criterion before the step
    flow = "go",               # "go", "next" (on to the next step), "stop"
    settled = NULL,            # the model the families were last chosen on, unchanged
    reform = FALSE,            # a family form predates an effect the raw data pinned and confirmed
    only_sets = FALSE,         # budget spent: only further lines of held harmonic sets
    start = NULL,              # the model the steps started from
    pins = list(),             # per accepted step, the raw-data values it pinned
    release_late = character(), # pinned values an entry frees at the end (stage_release())
    taken_with = integer(),    # per accepted step, the step it was taken with (a split's), or NA
    blocked = list(),          # raw-data values of trials an earlier effect kept out
    refused = list(),          # this step's trials the raw data refused (family_pairs())
    unpaid = list(),           # this step's raw-pinned trials that did not pay alone
    refused_forms = character(), # family kinds absent from the model whose forms the raw data refused this step
    seeds = list(),            # pinned value sets a revisit takes first (stage_revisit())
    until = NULL,              # a revisit stops on reaching these terms (sorted)
    revisit = NULL,            # what the revisit compared, or NULL
    short_trials = list(),     # the last screening's trials that gained under min_gain
    alternatives = NULL,       # stage_alternatives()'s alternatives to the final model, or NULL
    remaining = NULL,          # signatures left when the loop stopped
    unexplained = NULL,
    tau_range = NULL,
    result = NULL), class = "refine_state"))
}

validate_refine_state <- function(st) {
  ok <- inherits(st, "refine_state") && inherits(st$current, "avfit") &&
    is.list(st$steps) && is.data.frame(st$failures) && is.data.frame(st$rejected) &&
    st$flow %in% c("go", "next", "stop") &&
    (is.null(st$raw) || inherits(st$raw, "refine_diagnostics"))
  if (!ok) abort("Malformed state of the loop.", class = "internal")
  st
}

# The settings every refit uses, explicitly: the fit's own, overridden by
# the arguments in `dots`.
refit_settings <- function(fit, dots) {
  out <- utils::modifyList(
    list(bias_correct = !isFALSE(fit$bias_correct),
         correlation = isTRUE(fit$correlation),
         control = fit$control %||% avfit_control()),
    dots)
  # candidates are judged on the points' own scatter: a model-error term
  # would hide the departures they are meant to explain
  out$control <- check_control(out$control)
  out$control$model_error <- FALSE
  out
}

# The criterion of a fit, and the penalty of one parameter on its scale.
refine_crit <- function(st, f) {
  if (st$args$criterion == "BIC") stats::BIC(f) else stats::AIC(f)
}
refine_penalty <- function(st) {
  if (st$args$criterion == "BIC") log(st$current$nobs) else 2
}
# The criterion of a fit that holds `held` of the model's values, on the
# all-free scale: each held value charged one parameter's penalty.
refine_crit_held <- function(st, f, held) {
  refine_crit(st, f) + refine_penalty(st) * held
}

# A refit for the state: the conditions it raised are recorded as failures
# of (`step`, `effect`). Returns list(st, fit).
state_refit <- function(st, args, stage, effect, step = st$step) {
  r <- try_refit(args, stage)
  st$failures <- record_conditions(st$failures, r$conditions, step, effect)
  list(st = st, fit = r$fit)
}

# The labels of the effects accepted earlier in this call that a refit `f`
# leaves invalid or contradicted by the raw data (a resonance whose tc runs
# off to a pure tone no longer matches its band).
earlier_broken <- function(st, f) {
  out <- character()
  freq <- st$args$freq
  for (s in st$steps) {
    if (!any(startsWith(names(stats::coef(f)), paste0(s$label, ".")))) next
    par <- instance_params(stats::coef(f), f$layout, s$label)
    if (!is.null(inadmissible(s$effect, par, f$data$tau, freq))) {
      out <- c(out, s$label)
      next
    }
    ev <- raw_evidence(s$effect, as.list(par), st$raw, diag_series(st$raw), freq, f, s$label)
    if (isFALSE(ev$support)) out <- c(out, s$label)
  }
  out
}

earlier_hold <- function(st, f) !length(earlier_broken(st, f))

# ---- rejections -------------------------------------------------------------

new_rejected <- function() {
  data.frame(step = integer(), effect = character(), params = character(),
             reason = character(), stringsAsFactors = FALSE)
}

# Terms rejected because they describe a series effect of the same run
# again (series_duplicate(), series_pays_without()): the series kind, the
# share of the term's AV that effect adds, the tau it was read at and how
# the rule decided ("share", or "refit": no gain without the excess).
new_duplicates <- function() {
  data.frame(step = integer(), effect = character(), params = character(),
             series_kind = character(), ratio = numeric(), tau = numeric(),
             how = character(), stringsAsFactors = FALSE)
}

add_rejected <- function(rejected, step, effect, par, reason) {
  rbind(rejected, data.frame(step = as.integer(step), effect = effect,
                             params = format_params(par, effect),
                             reason = reason, stringsAsFactors = FALSE))
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

# The conditions of try_refit() (list(condition, stage) each), in order.
record_conditions <- function(failures, conditions, step, effect) {
  for (cn in conditions) failures <- add_failure(failures, cn$condition, step, effect, cn$stage)
  failures
}
