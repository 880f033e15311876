# The catalogue of statistics: one entry per statistic allan() computes,
# holding every fact allan() and its helpers need about it. allan(), the
# gap rule, the EDF and limits, print() and plot() ask the entry; no other
# file switches on statistic names. The C++ half is src/types.h (code,
# order of the difference, overlap, modified, unit, tau factor, whether a
# bias correction exists), read once through allan_type_table_cpp() and
# joined to the entries by name. The built-in entries are in
# R/stat-allan.R (the Allan family of the sums kernel) and
# R/stat-further.R (the statistics with kernels of their own).
#
# An entry is a list built by new_stat(); its fields:
#   name        the name allan(type = ) takes ("overlapping")
#   aliases     other names accepted for it (allantools': "oadev")
#   kernel      "sums": the Allan-family sums kernel (src/allan.cpp) with
#                 `divisor`; or function(ctx) for a statistic with a kernel
#                 of its own (ctx: v, freq, m, theo_row, rate, L, n, conf,
#                 debias, input, threads, theo), returning list(av, alpha, edf)
#                 and optionally n, adev, and `limits` (list(rows, lower,
#                 upper): intervals the kernel computed itself)
#   divisor(m)  the estimator's divisor per term (times the number of
#                 terms gives the variance's); "sums" kernels only
#   min_points  phase points a window needs for one term at m = 1
#                 (dynamic_allan()'s windows)
#   max_m(L)    largest cluster size with a term, for L phase points
#   nterms(m, L, theo_row)  terms behind each value (Stable32's "#")
#   taus(taus, freq, L, maxm)  the cluster sizes asked for: list(m,
#                 theo_row: rows at the Theo1 averaging time 0.75 m)
#   edf         name of the EDF rule (stat_edf_rules(), R/edf.R), or NA:
#                 no EDF and no limits
#   edf_fallback(m, n, L)  the EDF where the engine gives none (the number
#                 of terms; "total": NIST SP 1065 Table 7's white-FM value)
#   octave_pass whether the one-pass octave kernel of rate data computes
#                 the statistic at octave m (the standard type)
#   alpha_range the noise exponents the EDF rule admits (c(lo, hi))
#   exact_ci    whether rows at few averages take the exact generalized
#                 chi-square limits (R/ci-exact.R; from alpha_range's lo)
#   exact_form  NULL: the exact law from the stationary terms' covariance
#                 (src/gchisq.cpp, the Allan and Hadamard families); or the
#                 name of a function(m, L) giving the statistic's quadratic
#                 form in the phase, whose law is computed densely
#                 (R/ci-exact-forms.R: the total family, Theo1)
#   exact_id    "sums" kernels: the Allan-family statistic whose noise
#                 identification the exact rows rest on, or NA: the
#                 statistic's own
#   id_base     for kernel functions: the Allan-family statistic whose
#                 noise identification gives the type at each tau (NA:
#                 none, or the kernel's own)
#   noise_id(rule)  the rule-dependent identification switches of the sums
#                 kernel (b1_rw_own, rn_check_wfm; R/taus.R)
#   debias(alpha, m)  the noise-dependent bias factor (multiply the
#                 variance by it), or NULL where there is none
#   unbiased    whether `unbiased = TRUE` applies (a deviation with an EDF)
#   gaps        "sums": the gap kernel (src/allan.cpp allan_gap_sums_cpp);
#                 a function(x, freq, taus, input, conf, unbiased); or a
#                 string: why the statistic is not defined with gaps (the
#                 error message)
#   variance    whether the statistic is a variance (a deviation squared),
#                 so that sums and differences of it mean something (the
#                 three-cornered hat); FALSE for the time interval errors
#   theo        TheoBR's bias-factor options, the defaults of allan()'s
#                 `theo` (ladder, method, fast_above, fast_points;
#                 R/theo-fast.R), or NULL: `theo` does not apply
#   title       what the deviation column holds, for print()'s header
#   ylab        plot()'s y-axis label

.stat_catalogue <- new.env(parent = emptyenv())

# The entries by name, C++ fields joined, built on first use.
stat_catalogue <- function() {
  if (is.null(.stat_catalogue$entries)) {
    tab <- allan_type_table_cpp(TRUE)
    entries <- list()
    for (e in builtin_stats()) {
      e <- validate_stat(e)
      i <- match(e$name, tab$name)
      if (is.na(i)) {
        abort("Statistic \"", e$name, "\" has no row in src/types.h.",
              class = "catalogue")
      }
      e$code <- tab$code[i]
      e$d <- tab$d[i]
      e$overlapping <- tab$overlapping[i]
      e$modified <- tab$modified[i]
      e$unit <- tab$unit[i]
      e$tau_factor <- tab$tau_factor[i]
      e$has_debias <- tab$debias[i]
      entries[[e$name]] <- e
    }
    alias <- unlist(lapply(entries, `[[`, "aliases"))
    canon <- rep(names(entries), lengths(lapply(entries, `[[`, "aliases")))
    # in the order of allan_type_aliases (the documented order)
    o <- order(match(alias, names(allan_type_aliases)))
    .stat_catalogue$aliases <- stats::setNames(canon[o], alias[o])
    .stat_catalogue$entries <- entries
  }
  .stat_catalogue$entries
}

builtin_stats <- function() {
  c(stats_allan_family(), stats_further())
}

# An entry with every optional field present.
new_stat <- function(name, title, ylab, max_m, nterms, kernel = "sums",
                     divisor = NULL, taus = stat_taus_grid, edf = NA_character_,
                     alpha_range = c(-2L, 2L), id_base = NA_character_,
                     noise_id = function(rule) list(), debias = NULL,
                     unbiased = !is.na(edf), gaps = "sums",
                     aliases = character(),
                     edf_fallback = function(m, n, L) n,
                     octave_pass = FALSE, min_points = 3L,
                     exact_ci = FALSE, exact_form = NULL,
                     exact_id = NA_character_, variance = TRUE,
                     theo = NULL) {
  list(name = name, title = title, ylab = ylab, max_m = max_m,
       nterms = nterms, kernel = kernel, divisor = divisor, taus = taus,
       edf = edf, alpha_range = as.integer(alpha_range), id_base = id_base,
       noise_id = noise_id, debias = debias, unbiased = unbiased, gaps = gaps,
       aliases = aliases, edf_fallback = edf_fallback,
       octave_pass = octave_pass, min_points = min_points,
       exact_ci = exact_ci, exact_form = exact_form, exact_id = exact_id,
       variance = variance, theo = theo)
}

validate_stat <- function(e) {
  bad <- function(...) abort("Statistic entry \"", e$name, "\": ", ...,
                             class = "catalogue")
  if (!is.character(e$name) || length(e$name) != 1L) {
    abort("A statistic entry needs a `name`.", class = "catalogue")
  }
  for (f in c("max_m", "nterms", "taus", "noise_id", "edf_fallback")) {
    if (!is.function(e[[f]])) bad("`", f, "` must be a function.")
  }
  if (!isTRUE(e$variance) && !isFALSE(e$variance)) {
    bad("`variance` must be TRUE or FALSE.")
  }
  if (!is.null(e$exact_form) && !(is.character(e$exact_form) &&
                                   length(e$exact_form) == 1L)) {
    bad("`exact_form` must be NULL or a function's name.")
  }
  if (!is.null(e$debias) && !is.function(e$debias)) {
    bad("`debias` must be a function or NULL.")
  }
  if (identical(e$kernel, "sums")) {
    if (!is.function(e$divisor)) bad("a \"sums\" kernel needs a `divisor`.")
  } else if (!is.function(e$kernel)) {
    bad("`kernel` must be \"sums\" or a function.")
  }
  if (!is.na(e$edf) && !e$edf %in% names(stat_edf_rules())) {
    bad("unknown EDF rule \"", e$edf, "\".")
  }
  if (!(identical(e$gaps, "sums") || is.function(e$gaps) ||
        is.character(e$gaps))) {
    bad("`gaps` must be \"sums\", a function or the reason it is refused.")
  }
  e
}

# The entry of a statistic (aliases resolved); NULL when there is none.
stat_entry <- function(type) {
  entries <- stat_catalogue()
  e <- entries[[type]]
  if (!is.null(e)) return(e)
  canon <- .stat_catalogue$aliases[type]
  if (is.na(canon)) NULL else entries[[canon]]
}

# Every name `type` accepts: the statistics in their documented order,
# then the aliases.
stat_names <- function() {
  stat_catalogue()
  c(names(.stat_catalogue$entries), names(.stat_catalogue$aliases))
}

# The canonical name of a statistic (aliases resolved).
stat_canonical <- function(type) stat_entry(type)$name

# The statistics of the sums kernel (the Allan family), in order.
stat_sums_names <- function() {
  e <- stat_catalogue()
  names(e)[vapply(e, function(s) identical(s$kernel, "sums"), TRUE)]
}

# Whether a statistic has confidence limits (an EDF rule).
stat_has_limits <- function(e) !is.na(e$edf)

# The default `taus` rule: the grid of allan_taus() (R/taus.R), no Theo rows.
stat_taus_grid <- function(taus, freq, L, maxm) {
  m <- allan_taus(taus, freq, maxm)
  list(m = m, theo_row = rep(FALSE, length(m)))
}
