# The effect catalogue: one entry per effect of the noise model, holding
# every fact about it. The fit, the simulator, the closed loop (tracing,
# raw-data evidence), the readings, the exports and the plots ask the
# catalogue; no other file switches on effect kinds. Adding an effect is one
# call to register_effect() (the built-in entries live in R/effect-*.R).
#
# An entry is a list built by new_effect(); its fields:
#   name        kind name, letters only ("N", "gm"); the word used in `terms`
#   title       a few words
#   component   "av": a stationary (or stationary-increment) term whose
#                 expected AV adds to the model, fitted by avfit();
#               "series": a deterministic non-stationary effect (a step, a
#                 warm-up, outliers) detected and corrected in the series
#                 rather than added to the AV
#   params      data frame from effect_param(): name, role ("amp" or
#                 "nonlinear"), unit, meaning, profile ("smooth" or
#                 "oscillatory": how the AV varies with a nonlinear
#                 parameter, which sets the search grid), print_unit,
#                 hidden (a measured value left out of step summaries)
#   repeatable  may appear several times in a model (gm1, gm2, ...)
#   variants    NULL, or a function(variant) returning the fields that
#                 replace the entry's for that variant (NULL when the variant
#                 is unknown): a family of filters, a harmonic set with a
#                 variable number of components. Written "kind:variant" in
#                 `terms` and "kind<i>_<variant>" in coefficient labels.
#   slope, psd_alpha, formula, signature   descriptive facts (av_terms())
#   basis(tau, tau0, nl)   AV per squared amplitude; a vector, or a matrix
#                 with one column per amplitude parameter; tau0 = NULL gives
#                 the continuous IEEE 952 form
#   psd(f, nl)  two-sided IEEE rate PSD per squared amplitude, or NULL
#   acf(h, tau0, nl)  autocovariance of the sampled rate per squared
#                 amplitude at lag h samples, or NULL (not stationary)
#   sim(n, tau0, amp, nl)  n rate samples (amp: named amplitudes)
#   sim_check(par, freq, arg)  extra checks of avsim() arguments, or NULL
#   edf_alpha(tau, tau0, nl)  power-law exponent used for the EDF at each
#                 tau; NA marks a deterministic term (no estimation variance)
#   nl_range(tau, freq)  named list of c(lo, hi): where each nonlinear
#                 parameter's grid is laid (the search's first look)
#   nl_bounds(tau, freq)  named list of c(lo, hi): the hard limits of each
#                 nonlinear parameter, what the curve and the record can see
#                 (no search step, start or refit leaves them); NULL: the
#                 nl_range
#   trace(ctx)  from a residual signature (see trace.R) to list(init =
#                 start values, score = how well it matches), or NULL
#   propose(raw, tau, sig)  candidates read from the raw-data diagnostics
#                 (each may `pin` parameters the raw data measure better,
#                 and name `after`: pinned values that must be in the model
#                 first, the stronger lines of its harmonic set;
#                 `release` TRUE: the pinned values are a start the curve
#                 may refine: a pinned trial that passes is refitted with
#                 them free, searched from there, and the better kept;
#                 `release_late` TRUE: they stay pinned until the loop ends and
#                 are freed then, beside the rest, by stage_release())
#                 alone: a list of list(init, tau_from, tau_to, note, score)
#   evidence(par, raw, x, freq)  list(text, support = TRUE/FALSE/NA): what
#                 the raw series says about a fitted instance
#   model_evidence(ev, fit, label, raw, freq)  NULL, or evidence() read
#                 again beside the other terms of the model `fit` that holds
#                 the instance `label` (what the raw series shows of a shape
#                 only the whole model predicts): the list evidence() gives
#   raw_hold(par, raw)  NULL, or for an instance the curve sizes far off
#                 what the raw data measure: list(values (named parameter
#                 values the raw data measure, to hold it at), note)
#   peak_tau(par)  characteristic tau of an instance (where its residual
#                 signature sits), or NULL
#   reading     NULL, or how the entry is read off a curve for a datasheet:
#                 list(symbol, role, tau, slope, anchor, unit, bound,
#                 resolve, pch, legend, slope_method) (see readings.R)
#   fold        NULL, or list(into = role, when(par), amount(par), note):
#                 an instance that shows as part of another reading (a GM
#                 with Tc well below 1 s is white noise at tau >= 1 s)
#   discrete(par, dt, units, opts)  rows of a discrete-time filter model
#                 (kalman_params()), or NULL
#   describe(values)  datasheet text for the instances of this kind added by
#                 the loop (values: data frame, one row per instance)
#   detect(x, freq), remove(x, freq, par)  for "series" components
#   detect_again  TRUE: a "series" entry whose detector, run before the
#                 later kinds are out, takes their edges for its own (an
#                 outlier detector, a step's first sample) or whose
#                 shape they bend (a warm-up beside a step): it reads the
#                 series again with the other kinds' instances removed
#   judge(x, freq, table)  a "series" entry's judge of its instances beside
#                 the others found (`x`: the series as the pass read it,
#                 nothing removed; `table`: every instance found): the
#                 rows of its own kind that stand. Where it drops any,
#                 the detect_again kinds read the series again without them
#   known_av(raw, fit, tau, tau0)  the AV, at `tau`, of the instances of
#                 this entry the raw data measure exactly (every parameter)
#                 and `fit` does not hold yet (a square wave's sharp
#                 harmonics), or NULL: a family's form is chosen on the
#                 curve without it during the steps
#   unheld(raw, fit)  NULL, or the same instances as a list of list(values
#                 (every parameter, named), at (where they sit, Hz)), the
#                 strongest first: stage_absorbed() adds those that sit in
#                 the reach of an instance that `absorbs` them
#   absorbs(par, raw)  NULL, or for an instance whose shape on the curve
#                 can take the power of an unheld one in its reach (a
#                 band, a line on it): list(lo, hi (Hz), start (named
#                 nonlinear values the raw data read for it, without what
#                 it took), what (a few words))
#   known_acov(raw, fit, h, tau0)  the same instances' autocovariance at
#                 lags `h` (samples), or NULL: the short-lag shape checks
#                 compare the raw series with the model and them (a line
#                 near Nyquist not yet in the model swings the raw
#                 autocovariance at every lag)
#   replaces    kinds this entry takes the place of when the loop adds it
#                 (the filter replaces N: its DC level is the white level)
#   replaces_instance  NULL (every instance of those kinds goes), or
#                 function(par, kind, old) -> TRUE when the instance `old`
#                 (its values) is the thing the new one (`par`: its pinned
#                 and start values) describes (a measured band replaces the
#                 resonance at the same band, not one elsewhere)
#   proposed_only  TRUE when the loop tries the entry only where the raw
#                 data propose it (its parameters are measured, not
#                 searched: a tabulated band spectrum)
#   statespace(amp, nl, tau0)  the term's part of a linear Gaussian
#                 state-space model of the sampled rate (avmle()): a list
#                 with any of R (measurement-noise variance), and per state
#                 T (transition coefficient), Q (innovation variance), P0
#                 (start variance, Inf for a diffuse start); NULL when the
#                 term has none
#   admissible(par, tau, freq)  NULL when a fitted instance is a valid
#                 instance of this effect on this curve, else the reason it
#                 is not (a sub-sample GM is a filter; a sinusoid outside
#                 the band the curve can see)
#   diagnose    NULL, or what the entry reads from the raw series once per
#                 avrefine() call (R/refine-diagnostics.R): list(part (its
#                 name in the diagnostics), reads ("raw" or "clean": the
#                 series with the other parts' clean() applied), needs
#                 (parts made first), make(x, freq, dg), clean(x, freq, part)
#                 (the series without what the part describes) or NULL)
#   family      NULL, or for an entry with variants that describe one thing
#                 in different forms (the sensor filter's families), which
#                 the loop chooses among again on the final model:
#                 list(variants (the first is the bare kind's), start(raw,
#                 variant): start values read from the raw diagnostics)
#   exact_edf(amp, nl, tau0)  NULL, or how the term enters the exact EDF of
#                 the model's AV estimates (src/avfit.cpp): a list of parts
#                 list(shape, coef, phi) of its structure function, shape one
#                 of "linear" (coef * l), "cubic" (-coef (l^3 - l) / 6),
#                 "step" (2 coef for l > 0), "ar1" (coef = sigma^2, phi)
#   apart(par, others)  NULL, or for a repeatable entry TRUE when the
#                 instance `par` (its values) describes a process other than
#                 the model's instances of the entry (`others`: a list of
#                 their values) that the curve sees too weakly to size it
#                 against them: its raw-data confirmation then counts as
#                 min_gain, as a harmonic set's line's does (a GM an order
#                 slower than the model's, which had taken a compromise
#                 between the two on the curve)
#   noise_lookalike  TRUE for a "series" kind that a stationary noise
#                 term's own excursions can produce (a Gauss-Markov
#                 term's slow swings are transients to the series pass): a
#                 term is then not judged on the curve with that kind's
#                 excess taken out (series_pays_without())

.catalogue <- new.env(parent = emptyenv())

# The entries, in their canonical order (the order of the coefficients).
catalogue <- function() {
  if (is.null(.catalogue$entries)) {
    .catalogue$entries <- list()
    for (e in builtin_effects()) register_effect(e)
  }
  .catalogue$entries
}

builtin_effects <- function() {
  list(effect_quantization(), effect_white(), effect_flicker(),
       effect_random_walk(), effect_ramp(), effect_gauss_markov(),
       effect_sinusoid(), effect_filter(), effect_resonance(), effect_band(),
       # series effects, in the order detect_series_effects() detects them
       effect_spike(), effect_warmup(), effect_bias_step(), effect_transient())
}

#' Register an effect in the catalogue (internal)
#'
#' `entry` is built by [new_effect()]; it is validated and appended (or,
#' with `replace = TRUE`, replaces the entry of the same name). Returns the
#' validated entry invisibly. `unregister_effect()` removes one.
#' @noRd
register_effect <- function(entry, replace = FALSE) {
  entry <- validate_effect(entry)
  entries <- catalogue()
  if (entry$name %in% names(entries) && !replace) {
    abort("The catalogue already has an effect \"", entry$name,
          "\"; use replace = TRUE.", class = "catalogue")
  }
  entries[[entry$name]] <- entry
  .catalogue$entries <- entries
  .catalogue$layouts <- NULL
  invisible(entry)
}

unregister_effect <- function(name) {
  entries <- catalogue()
  if (!name %in% names(entries)) {
    abort("The catalogue has no effect \"", name, "\".", class = "catalogue")
  }
  if (name %in% vapply(builtin_effects(), `[[`, "", "name")) {
    abort("\"", name, "\" is a built-in effect and cannot be removed.",
          class = "catalogue")
  }
  .catalogue$entries <- entries[names(entries) != name]
  .catalogue$layouts <- NULL
  invisible(NULL)
}

# One parameter of an entry.
# `hidden`: a measured value carried for the entry's own use (a tabulated
# spectrum), left out of the step summaries.
effect_param <- function(name, role = c("amp", "nonlinear"), unit, meaning,
                         profile = NA_character_, print_unit = FALSE,
                         hidden = FALSE) {
  role <- role[1L]
  data.frame(name = name, role = role, unit = unit, meaning = meaning,
             profile = profile, print_unit = print_unit, hidden = hidden,
             stringsAsFactors = FALSE)
}

# An entry with every optional field present (NULL or NA when absent).
new_effect <- function(name, title, params, component = "av",
                       repeatable = FALSE, variants = NULL,
                       slope = NA_real_, psd_alpha = NA_real_,
                       formula = "", signature = "",
                       basis = NULL, psd = NULL, acf = NULL, sim = NULL,
                       sim_check = NULL, edf_alpha = NULL, nl_range = NULL,
                       nl_bounds = NULL,
                       trace = NULL, propose = NULL, evidence = NULL, raw_hold = NULL,
                       peak_tau = NULL, reading = NULL, fold = NULL,
                       discrete = NULL, describe = NULL, detect = NULL,
                       remove = NULL, replaces = character(),
                       replaces_instance = NULL, admissible = NULL, proposed_only = FALSE,
                       statespace = NULL, diagnose = NULL, family = NULL,
                       exact_edf = NULL, noise_lookalike = FALSE,
                       detect_again = FALSE, known_av = NULL, known_acov = NULL,
                       model_evidence = NULL, apart = NULL, unheld = NULL,
                       absorbs = NULL, judge = NULL) {
  list(name = name, title = title, params = params, component = component,
       repeatable = repeatable, variants = variants, slope = slope,
       psd_alpha = psd_alpha, formula = formula, signature = signature,
       basis = basis, psd = psd, acf = acf, sim = sim, sim_check = sim_check,
       edf_alpha = edf_alpha, nl_range = nl_range, nl_bounds = nl_bounds,
       trace = trace,
       propose = propose, evidence = evidence, raw_hold = raw_hold,
       peak_tau = peak_tau,
       reading = reading, fold = fold, discrete = discrete,
       describe = describe, detect = detect, remove = remove,
       replaces = replaces, replaces_instance = replaces_instance,
       admissible = admissible,
       proposed_only = proposed_only, statespace = statespace,
       diagnose = diagnose, family = family, exact_edf = exact_edf,
       noise_lookalike = noise_lookalike, detect_again = detect_again,
       known_av = known_av, known_acov = known_acov, model_evidence = model_evidence,
       apart = apart, unheld = unheld, absorbs = absorbs, judge = judge)
}

validate_effect <- function(e) {
  bad <- function(...) abort("Effect entry ", encodeString(e$name %||% "?", quote = '"'),
                             ": ", ..., class = "catalogue")
  if (!is.list(e) || !is.character(e$name) || length(e$name) != 1L ||
      !grepl("^[A-Za-z]+$", e$name)) {
    abort("An effect entry needs a `name` made of letters only.",
          class = "catalogue")
  }
  if (!is.character(e$title) || length(e$title) != 1L) bad("`title` must be a string.")
  if (!identical(e$component, "av") && !identical(e$component, "series")) {
    bad("`component` must be \"av\" or \"series\".")
  }
  p <- e$params
  need <- c("name", "role", "unit", "meaning")
  if (!is.data.frame(p) || !all(need %in% names(p)) || !nrow(p)) {
    bad("`params` must be a data frame with columns ",
        paste(need, collapse = ", "), " (see effect_param()).")
  }
  if (is.null(p$profile)) p$profile <- NA_character_
  if (is.null(p$print_unit)) p$print_unit <- FALSE
  if (is.null(p$hidden)) p$hidden <- FALSE
  if (anyDuplicated(p$name) || !all(grepl("^[A-Za-z][A-Za-z0-9_]*$", p$name))) {
    bad("parameter names must be unique identifiers.")
  }
  if (!all(p$role %in% c("amp", "nonlinear"))) {
    bad("parameter roles must be \"amp\" or \"nonlinear\".")
  }
  e$params <- p
  fun_ok <- function(f) is.null(f) || is.function(f)
  for (f in c("basis", "psd", "acf", "sim", "sim_check", "edf_alpha",
              "nl_range", "nl_bounds", "trace", "propose", "evidence", "model_evidence",
              "raw_hold",
              "peak_tau",
              "discrete", "describe", "detect", "remove", "admissible",
              "statespace", "exact_edf", "apart", "unheld", "absorbs", "judge")) {
    if (!fun_ok(e[[f]])) bad("`", f, "` must be a function or NULL.")
  }
  if (!is.null(e$variants) && !is.function(e$variants)) {
    bad("`variants` must be a function(variant) or NULL.")
  }
  if (!isTRUE(e$noise_lookalike) && !isFALSE(e$noise_lookalike)) {
    bad("`noise_lookalike` must be TRUE or FALSE.")
  }
  if (!is.function(e$sim)) bad("`sim` (the simulator) is required.")
  if (identical(e$component, "av")) {
    if (!any(p$role == "amp")) bad("an AV term needs an amplitude parameter.")
    if (!is.function(e$basis)) bad("`basis` (the expected AV) is required.")
    if (!is.function(e$edf_alpha)) bad("`edf_alpha` is required.")
    if (any(p$role == "nonlinear") && !is.function(e$nl_range)) {
      bad("`nl_range` is required with nonlinear parameters.")
    }
    if (any(p$role == "nonlinear" & !p$profile %in% c("smooth", "oscillatory"))) {
      bad("nonlinear parameters need profile \"smooth\" or \"oscillatory\".")
    }
  } else if (!is.function(e$detect) || !is.function(e$remove)) {
    bad("a series effect needs `detect` and `remove`.")
  }
  if (!is.logical(e$repeatable) || length(e$repeatable) != 1L || is.na(e$repeatable)) {
    bad("`repeatable` must be TRUE or FALSE.")
  }
  if (!is.null(e$reading)) {
    rneed <- c("symbol", "role", "unit")
    if (!is.list(e$reading) || !all(rneed %in% names(e$reading))) {
      bad("`reading` needs ", paste(rneed, collapse = ", "), ".")
    }
  }
  if (!is.null(e$fold) && !all(c("into", "when", "amount") %in% names(e$fold))) {
    bad("`fold` needs into, when and amount.")
  }
  d <- e$diagnose
  if (!is.null(d) && !(is.list(d) && is.character(d$part) && length(d$part) == 1L &&
                       isTRUE(d$reads %in% c("raw", "clean")) &&
                       is.function(d$make) && (is.null(d$clean) || is.function(d$clean)) &&
                       is.character(d$needs %||% character()))) {
    bad("`diagnose` needs part, reads (\"raw\" or \"clean\") and make(), ",
        "optionally needs and clean().")
  }
  f <- e$family
  if (!is.null(f) && !(is.list(f) && is.character(f$variants) &&
                       length(f$variants) >= 2L && is.function(f$start))) {
    bad("`family` needs variants (at least two) and start().")
  }
  if (is.null(e$replaces)) e$replaces <- character()
  if (!is.character(e$replaces) || anyNA(e$replaces)) {
    bad("`replaces` must name effect kinds.")
  }
  if (!is.null(e$replaces_instance) && !is.function(e$replaces_instance)) {
    bad("`replaces_instance` must be NULL or a function(par, kind, old).")
  }
  if (is.null(e$describe)) e$describe <- function(values) e$name
  # Coefficients are written bare ("N") when the entry is a single
  # parameter named as the effect; otherwise "label.param" ("gm1.tc").
  e$bare <- !e$repeatable && is.null(e$variants) && nrow(p) == 1L &&
    p$name == e$name
  e
}

# ---- queries ----------------------------------------------------------------

# Kinds, in canonical order; by default those avfit() can fit.
effect_kinds <- function(component = "av") {
  cat <- catalogue()
  keep <- vapply(cat, function(e) e$component %in% component, logical(1))
  names(cat)[keep]
}

# The entry of `kind`, resolved for `variant` (NULL for none).
effect_entry <- function(kind, variant = NULL) {
  e <- catalogue()[[kind]]
  if (is.null(e)) {
    abort("Unknown noise term \"", kind, "\".", class = "model")
  }
  if (is.null(variant) || is.na(variant) || !nzchar(variant)) return(e)
  # a variant's entry is built from the kind's (a data frame of parameters
  # and closures per call) and the loop's refits ask for it thousands of
  # times: kept with the layouts, emptied with them when the catalogue
  # changes
  key <- paste0("\002", kind, ":", variant)
  hit <- .catalogue$layouts[[key]]
  if (!is.null(hit)) return(hit)
  out <- variant_entry(e, kind, variant)
  if (is.null(.catalogue$layouts)) .catalogue$layouts <- new.env(parent = emptyenv())
  assign(key, out, envir = .catalogue$layouts)
  out
}

variant_entry <- function(e, kind, variant) {
  if (is.null(e$variants)) {
    abort("The effect \"", kind, "\" has no variants; \"", kind, ":",
          variant, "\" is not a term.", class = "model")
  }
  over <- e$variants(variant)
  if (is.null(over)) {
    abort("The effect \"", kind, "\" has no variant \"", variant, "\".",
          class = "model")
  }
  e[names(over)] <- over
  e$variant <- variant
  e$bare <- FALSE
  validate_effect(e)
}

# The term naming variant `v` of a family whose variants are `variants`:
# the bare kind for the first, else "kind:variant".
family_term <- function(kind, variants, v) {
  if (identical(v, variants[1L])) kind else paste0(kind, ":", v)
}

# The hard limits of nonlinear parameter `param` of entry `e` on a curve
# over `tau` sampled at `freq` (NULL: unknown): c(lo, hi), never inverted.
effect_nl_bounds <- function(e, param, tau, freq) {
  b <- (e$nl_bounds %||% e$nl_range)(tau, freq)[[param]]
  sort(as.double(b))
}

# Entries whose `field` is not NULL, in canonical order.
entries_with <- function(field) {
  Filter(function(e) !is.null(e[[field]]), catalogue())
}

# The readings the catalogue defines (one per entry with a `reading`), in
# canonical order: data frame symbol, role, kind.
reading_entries <- function() {
  es <- entries_with("reading")
  data.frame(symbol = vapply(es, function(e) e$reading$symbol, ""),
             role = vapply(es, function(e) e$reading$role, ""),
             kind = vapply(es, `[[`, "", "name"), stringsAsFactors = FALSE,
             row.names = NULL)
}

# The entry that provides reading `role` ("white", "flicker", "random_walk").
reading_entry <- function(role) {
  for (e in entries_with("reading")) if (identical(e$reading$role, role)) return(e)
  NULL
}

# The datasheet model: the kinds that provide a reading (N, B, K).
datasheet_terms <- function() reading_entries()$kind

reading_symbol <- function(role) {
  e <- reading_entry(role)
  if (is.null(e)) NA_character_ else e$reading$symbol
}
