# The non-stationary effects of a raw series through one pass: every
# "series" entry of the catalogue detects its instances, the Allan deviation
# is computed with and without them, and the series is corrected only for
# the kinds the user names. series.R names no effect: the entries, their
# order and their columns come from the catalogue (R/effect-series.R).

#' Non-stationary effects of a rate series: find, measure, remove on request
#'
#' Runs the detectors of the catalogue's series effects ([av_terms()] rows
#' with `component == "series"`) over a raw rate series, in catalogue
#' order: isolated spikes (additive outliers of the series' own AR model;
#' their size the excess over a 7-sample running median), an exponential
#' warm-up, bias steps (multi-scale changepoints of the Allan differences,
#' standardised by the series' own
#' Allan variance so that red noise is not read as steps) and transients
#' (two steps of opposite sign and similar size less than 120 s apart).
#' Each detector sees the series with the instances found before it taken
#' out (a spike does not disturb the step search), and with its sharp
#' spectral lines taken out (a line that holds one frequency over the whole
#' record: its least-squares sinusoid, which carries at least 0.8 of the
#' line's periodogram amplitude; a periodic disturbance is no step, and
#' what it leaves in window means hid a step of z 6.6). Spikes and the
#' warm-up are then read again with the other kinds found taken out (a
#' step's first sample is an outlier of the AR model until the step is
#' removed; a step at a warm-up's start bends the exponential), and
#' where that changed what they found, the steps and transients are
#' read again beside them (at most two such rounds). A step within five
#' time constants of a warm-up is then judged beside it by the warm-up's
#' likelihood (the block means with and without the step each fitting
#' their noise model by maximum likelihood, the warm-up's time constant
#' refitted) and kept when it adds z above 5, as its `evidence` says;
#' where one is dropped the warm-up is read again. Thresholds are
#' Bonferroni over the record and never below 5 (warm-up) or 6 (spikes,
#' steps) standard deviations. A spike is an additive outlier of the
#' series' own AR model (its filter, lines and colour), so that a line or a
#' filter does not hide it; where that model's statistic has heavy tails
#' (a non-Gaussian body, as on many accelerometers), the level is the
#' Bonferroni quantile of a Student t fitted to its body: outliers that
#' belong to the noise's own tail are not spikes. The warm-up's time constant is fitted by
#' generalised least squares under the series' own noise model (white,
#' random walk and Gauss-Markov components from its Allan variance), and a
#' warm-up is named by a likelihood ratio in which the series with and
#' without it each fit their own noise model (a random walk's excursion is
#' not a warm-up); up to two exponentials are named. Each time constant's
#' 95% interval, from the profile likelihood (the noise refitted at each
#' time constant), is given in the row's `evidence`.
#'
#' The Allan deviation of the series as given is compared with that of the
#' series with every effect found taken out, on the octave grid of
#' [allan()]: the error the uncorrected effects make at each tau. The
#' series is corrected only for the kinds named in `remove`, never
#' silently; what was removed is listed.
#'
#' @param x Rate series: numeric vector or `ts`.
#' @param freq Sampling frequency in Hz (taken from `x` when it is a `ts`
#'   and `freq` is missing).
#' @param remove The kinds of effect to take out of the series: none (the
#'   default: report only), kinds among `kinds`, e.g. `c("spikes",
#'   "steps")`, or `"all"` (every kind found).
#' @param ... Must be empty.
#' @param kinds The kinds to look for; default every series effect of the
#'   catalogue (`"spikes"`, `"warmup"`, `"steps"`, `"transients"`). Kinds
#'   named in `remove` are always looked for.
#' @return An object of class `series_effects`: a list with
#'   * `table`: one row per instance found, columns `kind`, `index` (first
#'     sample affected), `time` (s from the first sample), `size` (rate
#'     unit: the spike's excess over its neighbours, the step's level after
#'     minus before, the warm-up's offset at the first sample, the
#'     transient's offset while it lasts), `tc` (s, time constant of a
#'     warm-up), `duration` (s, of a transient), `z` (detection statistic in
#'     noise standard deviations), `removed` (logical) and `evidence` (text);
#'     `NA` where a kind has no such quantity;
#'   * `adev`: columns `tau`, `before` (Allan deviation of `x` as given),
#'     `after` (with every effect found taken out) and `change` (`before /
#'     after - 1`, the error the uncorrected effects make);
#'   * `adev_kinds`: the same per kind found (columns `kind`, `tau`,
#'     `before`, `after`, `change`: only that kind taken out);
#'   * `x`: the series with the `removed` kinds taken out (the input
#'     unchanged when nothing was removed; a `ts` when `x` was);
#'   * `removed`: the kinds removed; `kinds`, `freq` and `n`;
#'   * `reading_bias`: [series_reading_bias()] at its default taus: per
#'     kind left in, the relative change of N, B and K it causes (e.g.
#'     what genuine outliers left in do to N).
#' @seealso [avrefine()] (its `remove` argument), [avdiagnose()]
#' @export
#' @examples
#' set.seed(1)
#' x <- rnorm(1e5, sd = 0.1) + cumsum(rnorm(1e5, sd = 1e-4))
#' x[60001:1e5] <- x[60001:1e5] + 0.05        # a bias step at 600 s
#' x[c(1000, 42000)] <- x[c(1000, 42000)] + 2  # two spikes
#' se <- detect_series_effects(x, 100, remove = "spikes")
#' se
#' se$table[, c("kind", "time", "size", "z", "removed")]
detect_series_effects <- function(x, freq, remove = character(), ..., kinds = NULL) {
  check_dots_empty(...)
  check_present(missing(x), "x", "a rate series")
  was_ts <- stats::is.ts(x)
  if (missing(freq)) {
    if (!was_ts) check_present(TRUE, "freq", "the sampling frequency in Hz")
    freq <- stats::frequency(x)
  }
  freq <- check_freq(freq)
  if (was_ts && abs(stats::frequency(x) - freq) > 1e-6 * freq) {
    abort("`x` is a ts at ", format(stats::frequency(x)), " Hz but `freq` is ",
          format(freq), " Hz.", class = "argument")
  }
  start <- if (was_ts) stats::start(x) else NULL
  x <- check_values(x, min_n = 256L, arg = "x")
  all_kinds <- effect_kinds("series")
  kinds <- if (is.null(kinds)) all_kinds else check_series_kinds(kinds, "kinds", all_kinds)
  remove <- check_series_kinds(remove, "remove", c(all_kinds, "all"))
  if ("all" %in% remove) remove <- all_kinds
  kinds <- intersect(all_kinds, c(kinds, remove))
  table <- detect_series(x, freq, kinds)
  table$removed <- table$kind %in% remove
  removed <- intersect(all_kinds, unique(table$kind[table$removed]))
  y <- remove_series(x, freq, table[table$removed, , drop = FALSE])
  if (was_ts) y <- stats::ts(y, start = start, frequency = freq)
  adev <- series_adev(x, freq, table)
  out <- structure(list(table = table, adev = adev$all, adev_kinds = adev$kinds,
                        x = y, removed = removed, kinds = kinds, freq = freq,
                        n = length(x)),
                   class = "series_effects")
  out$reading_bias <- series_reading_bias(out)
  out
}

# `x`: a character vector of kinds among `allowed` (character() allowed).
check_series_kinds <- function(x, arg, allowed) {
  if (is.null(x)) x <- character()
  if (!is.character(x) || anyNA(x) || !all(x %in% allowed)) {
    abort("`", arg, "` must name series effects among ",
          paste0("\"", allowed, "\"", collapse = ", "), "; not ",
          if (is.character(x) && !anyNA(x))
            paste(encodeString(setdiff(x, allowed), quote = '"'), collapse = ", ")
          else describe_type(x), ".", class = "argument")
  }
  unique(x)
}

# The columns of the table, whatever was found.
series_columns <- c("kind", "index", "time", "size", "tc", "duration", "z",
                    "removed", "evidence")

# Every kind's instances, in catalogue order, each detector seeing the
# series with its sharp lines and the instances found before it removed.
# The entries marked detect_again then read the series again with every
# other kind's instances out (found or not the first time: a warm-up and a
# step at its start hide each other), and when that changed what they
# found, the kinds after them are read again beside it (at most twice).
# Last, the entries with a judge weigh their instances beside the rest (a
# step beside a warm-up, by the warm-up's likelihood).
detect_series <- function(x, freq, kinds) {
  # detectors that read the same thing of the same series compute it once
  series_pass_open()
  on.exit(series_pass_close(), add = TRUE)
  base <- without_sharp_lines(x, freq)
  as_part <- function(d, k) {
    if (is.null(d)) d <- data.frame()
    d$kind <- rep(k, NROW(d))
    for (cl in setdiff(series_columns, names(d))) d[[cl]] <- rep(NA, NROW(d))
    d[series_columns]
  }
  kinds <- intersect(effect_kinds("series"), kinds)
  again <- kinds[vapply(kinds, function(k) isTRUE(effect_entry(k)$detect_again), TRUE)]
  # the pass in catalogue order; the kinds in `held` keep their instances
  # (an empty table: none)
  pass <- function(held) {
    work <- base
    parts <- list()
    for (k in kinds) {
      e <- effect_entry(k)
      d <- if (k %in% names(held)) held[[k]] else as_part(e$detect(work, freq), k)
      if (!NROW(d)) next
      work <- e$remove(work, freq, d)
      parts[[k]] <- d
    }
    parts
  }
  # every other kind's instances in `parts`, one table (NULL: none)
  others_of <- function(parts, k) {
    o <- parts[names(parts) != k]
    if (length(o)) do.call(rbind, unname(o))
  }
  # kind k read on the series with `others` taken out
  detect_beside <- function(k, others) {
    as_part(effect_entry(k)$detect(remove_series(base, freq, others), freq), k)
  }
  parts <- pass(list())
  held <- list()
  read_beside <- list()          # what each kind was last read beside
  for (round in 1:2) {
    changed <- FALSE
    for (k in again) {
      others <- others_of(parts, k)
      if (is.null(others)) next
      if (identical(others, read_beside[[k]])) next
      read_beside[[k]] <- others
      d <- detect_beside(k, others)
      before <- parts[[k]]
      if (NROW(d) || NROW(before)) changed <- changed || !identical(d, before)
      held[[k]] <- d
      parts[[k]] <- if (NROW(d)) d
    }
    if (!changed) break
    parts <- pass(held)
  }
  # each entry's judge of its instances beside the others; where one drops
  # any, the detect_again kinds read the series again without them
  judged <- FALSE
  for (k in kinds[vapply(kinds, function(k) is.function(effect_entry(k)$judge), TRUE)]) {
    if (is.null(parts[[k]])) next
    d <- effect_entry(k)$judge(base, freq, do.call(rbind, unname(parts)))
    judged <- judged || NROW(d) < NROW(parts[[k]])
    held[[k]] <- d
    parts[[k]] <- if (NROW(d)) d
  }
  if (judged) {
    for (k in again) {
      others <- others_of(parts, k)
      if (!is.null(others)) held[[k]] <- detect_beside(k, others)
    }
    parts <- pass(held)
  }
  out <- if (length(parts)) do.call(rbind, parts) else
    data.frame(kind = character(), index = integer(), time = numeric(),
               size = numeric(), tc = numeric(), duration = numeric(),
               z = numeric(), removed = logical(), evidence = character(),
               stringsAsFactors = FALSE)
  out$kind <- as.character(out$kind)
  out$index <- as.integer(out$index)
  for (cl in c("time", "size", "tc", "duration", "z")) out[[cl]] <- as.double(out[[cl]])
  out$removed <- rep(FALSE, nrow(out))
  out$evidence <- as.character(out$evidence)
  rownames(out) <- NULL
  out
}

# The series with the instances in `table` removed, in catalogue order.
remove_series <- function(x, freq, table) {
  for (k in intersect(effect_kinds("series"), unique(table$kind))) {
    x <- effect_entry(k)$remove(x, freq, table[table$kind == k, , drop = FALSE])
  }
  x
}

# The shapes of the instances a series pass found and left in the data,
# as block means of m samples, one column each (each entry's remove() on a
# series of zeros): what a raw-data check fits beside its own regressor (a
# ramp's trend is read beyond an unremoved warm-up or step, which a line
# would otherwise take). An instance that moves no block mean by 1% of its
# own largest sample (a spike) cannot bend such a check and is left out.
# Returns function(m) for linear_trend()'s `beside`, or NULL.
series_shapes <- function(series, n, freq) {
  tab <- series$table
  if (is.null(tab) || !NROW(tab)) return(NULL)
  tab <- tab[!tab$removed, , drop = FALSE]
  if (!nrow(tab)) return(NULL)
  function(m) {
    # (one series of zeros for all: each remove() modifies its own copy)
    zero <- numeric(n)
    cols <- lapply(seq_len(nrow(tab)), function(i) {
      # remove() from zeros gives minus the shape: its block means and
      # largest size negated (exact; 0 - v keeps a zero mean +0, as the
      # shape's own), two passes over n samples fewer
      neg <- remove_series(zero, freq, tab[i, , drop = FALSE])
      b <- 0 - block_means(neg, m)
      top <- max(-min(neg), max(neg))
      if (top > 0 && diff(range(b)) >= 0.01 * top) b
    })
    cols <- cols[!vapply(cols, is.null, NA)]
    if (length(cols)) do.call(cbind, cols)
  }
}

# What a result keeps of a series pass: everything but the cleaned series
# `x` (a fit or an analysis must not carry a second copy of the data).
series_kept <- function(s) {
  if (!is.null(s)) s$x <- NULL
  s
}

# Allan deviation before and after taking out every instance found, and
# per kind, on allan()'s octave grid.
series_adev <- function(x, freq, table) {
  # only the deviations are read: no limits (ci = FALSE leaves adev as is)
  a <- allan(x, freq, ci = FALSE)
  one <- function(tab) {
    b <- if (nrow(tab)) allan(remove_series(x, freq, tab), freq, taus = I(a$tau),
                              ci = FALSE)$adev
         else a$adev
    # a noiseless series: no change where both are 0, unknown where only
    # the corrected one is
    change <- ifelse(b > 0, a$adev / b - 1, ifelse(a$adev > 0, NA_real_, 0))
    data.frame(tau = a$tau, before = a$adev, after = b, change = change)
  }
  kinds <- unique(table$kind)
  all <- one(table)
  per <- lapply(kinds, function(k) {
    # one kind found: its rows are the whole table, its curve `all`
    d <- if (length(kinds) == 1L) all else one(table[table$kind == k, , drop = FALSE])
    cbind(kind = k, d, stringsAsFactors = FALSE)
  })
  list(all = all,
       kinds = if (length(per)) do.call(rbind, per) else
         data.frame(kind = character(), tau = numeric(), before = numeric(),
                    after = numeric(), change = numeric(),
                    stringsAsFactors = FALSE))
}

#' @export
print.series_effects <- function(x, ...) {
  tab <- x$table
  cat(sprintf("Series effects in %d samples at %s Hz (looked for: %s)\n", x$n,
              format(x$freq), paste(x$kinds, collapse = ", ")))
  if (!nrow(tab)) {
    cat("  none found\n")
    return(invisible(x))
  }
  for (k in unique(tab$kind)) {
    rows <- tab[tab$kind == k, , drop = FALSE]
    ch <- x$adev_kinds[x$adev_kinds$kind == k, , drop = FALSE]
    j <- which.max(abs(ch$change))
    cat(sprintf("  %s%s%s\n", effect_entry(k)$describe(rows),
                if (all(rows$removed)) " [removed]" else "",
                if (length(j)) sprintf("; ADEV %+.1f%% at tau = %s s when left in",
                                       100 * ch$change[j], format_num(ch$tau[j]))
                else "; nothing left without it"))
  }
  cat(if (length(x$removed)) paste0("  removed: ", paste(x$removed, collapse = ", "))
      else "  nothing removed (see `remove`)", "\n", sep = "")
  invisible(x)
}

#' What the series effects left in do to the readings
#'
#' For each kind of series effect found and left in the series (not
#' removed), the relative change it makes to each reading (N, B, K): the
#' Allan deviation with the kind left in over that without it, minus 1, at
#' the tau where the reading is read (interpolated in log-log between the
#' pass's octave taus). A reading's coefficient scales with the Allan
#' deviation in its own region, so this is the change of the reading to
#' first order (a fit with the effect left in moves its coefficient by
#' about as much). The row `kind = "all"` takes every kind left in out
#' together.
#'
#' @param pass A [detect_series_effects()] result (also the `$series` of an
#'   [avrefine()] fit or of an analysis channel).
#' @param readings `NULL`, or readings with columns `term` and `tau` (s),
#'   e.g. an analysis channel's `$readings`: the taus where N, B and K are
#'   read. By default N at 1 s, B at the least Allan deviation without the
#'   effects, K at the longest tau of the pass.
#' @return A data.frame with columns `kind`, `term` ("N", "B", "K"), `tau`
#'   (s) and `bias_change` (relative change of the reading caused by
#'   leaving the kind in: 0.06 is +6%); no rows when nothing is left in.
#' @export
#' @examples
#' set.seed(1)
#' x <- rnorm(1e5, sd = 0.1)
#' x[sample.int(1e5, 200)] <- 3                  # 200 outliers
#' se <- detect_series_effects(x, 100)
#' series_reading_bias(se)
series_reading_bias <- function(pass, readings = NULL) {
  if (!inherits(pass, "series_effects")) {
    abort("`pass` must be a detect_series_effects() result, not ", describe_type(pass),
          ".", class = "argument")
  }
  out <- data.frame(kind = character(), term = character(), tau = numeric(),
                    bias_change = numeric(), stringsAsFactors = FALSE)
  tab <- pass$table
  left <- unique(tab$kind[!tab$removed])
  if (!length(left) || !NROW(pass$adev)) return(out)
  tau <- pass$adev$tau
  at <- c(N = 1, B = tau[which.min(pass$adev$after)], K = max(tau))
  if (!is.null(readings)) {
    if (!is.data.frame(readings) || !all(c("term", "tau") %in% names(readings))) {
      abort("`readings` must be a data frame with columns `term` and `tau`, or NULL.",
            class = "argument")
    }
    for (tm in names(at)) {
      v <- readings$tau[readings$term == tm]
      if (length(v) && is.finite(v[1L]) && v[1L] > 0) at[[tm]] <- v[1L]
    }
  }
  at <- pmin(pmax(at, min(tau)), max(tau))
  change_at <- function(before, after) {
    ok <- before > 0 & after > 0
    if (sum(ok) < 2L) return(rep(NA_real_, length(at)))
    exp(stats::approx(log(tau[ok]), log(before[ok] / after[ok]), log(at), rule = 2)$y) - 1
  }
  rows <- list()
  for (k in left) {
    # only this kind out, the rest as given: from the table of that kind
    ch <- pass$adev_kinds[pass$adev_kinds$kind == k, , drop = FALSE]
    if (!nrow(ch)) next
    rows[[k]] <- data.frame(kind = k, term = names(at), tau = unname(at),
                            bias_change = change_at(ch$before, ch$after),
                            stringsAsFactors = FALSE)
  }
  # every kind together, when the pass removed none (else `adev` compares
  # the raw series with one that lacks the removed kinds too)
  if (length(left) > 1L && !any(tab$removed)) {
    rows[["all"]] <- data.frame(kind = "all", term = names(at), tau = unname(at),
                                bias_change = change_at(pass$adev$before, pass$adev$after),
                                stringsAsFactors = FALSE)
  }
  out <- do.call(rbind, rows)
  rownames(out) <- NULL
  out
}
