# Cluster-size grids for allan(). A curve is computed at cluster sizes m
# (tau = m / freq); every estimator has a largest m with at least one term.

# The estimator table defined once in src/types.h (name, code, d,
# overlapping, modified) for the Allan-family types of the sums kernel, read
# from C++ on first use (the catalogue of statistics joins every type's row
# to its entry: R/stat-catalogue.R).
allan_type_table <- local({
  table <- NULL
  function() {
    if (is.null(table)) table <<- allan_type_table_cpp()
    table
  }
})

# The C++ kernels' code for each type.
allan_type_code <- function(type) stat_entry(type)$code

# The options the sums kernel reads (src/opts-allan.h), built once per call.
allan_opts <- function(type, rate, octave = FALSE,
                       threads = allanvar_threads(), sums = TRUE) {
  rules <- noise_id_rules(type = type)
  list(type = allan_type_code(type), rate = isTRUE(rate),
       octave = isTRUE(octave), threads = as.integer(threads),
       acf_min = rules$acf_min, b1_rw_own = rules$b1_rw_own,
       rn_stable32 = rules$rn_stable32, rn_check_wfm = rules$rn_check_wfm,
       sums = isTRUE(sums))
}

# The noise-identification rules (src/noise_id.h) for `type`:
#  * "default": Stable32's (B1 with N = the statistic's number of terms),
#    except where Monte Carlo coverage or SP 1065's published values reject
#    them: the lag-1 ACF from 64 points, not 30 (from 30, flicker PM's 68%
#    coverage falls to 0.55 for TOTDEV at N/m = 32); for the total type
#    random walk told from flicker FM by B1 with its own count (b1_rw_own);
#    R(n) over all five types (rn_stable32 FALSE); R(n) may turn B1's white
#    FM into white PM (from 4 averaged frequencies) or flicker PM (from 8),
#    except for the total type (rn_check_wfm; src/noise_id.h). The ACF
#    threshold moves none of the limits compared with Stable32
#    (tools/check-stable32*.R); the R(n) check moves 2 of 753 (GPS OADEV and
#    OHDEV at AF 8192, where Stable32 reads white FM and R(n) flicker PM);
#  * "stable32": Stable32's rules throughout, for comparisons with it;
#  * "coverage": allanvar's rules before (random walk told by B1's own count
#    for every type).
noise_id_rules <- function(rule = getOption("allanvar.noise_id", "default"),
                           type = "overlapping") {
  known <- c("default", "stable32", "coverage")
  if (!(is.character(rule) && length(rule) == 1L && rule %in% known)) {
    abort("`options(allanvar.noise_id)` must be one of ",
          paste0("\"", known, "\"", collapse = ", "), "; not ",
          paste(format(rule), collapse = " "), ".", class = "option")
  }
  # the type-dependent switches (b1_rw_own, rn_check_wfm) are the
  # statistic's (its catalogue entry's `noise_id`)
  c(list(acf_min = if (rule == "stable32") 30L else 64L,
         rn_stable32 = rule == "stable32"),
    stat_entry(type)$noise_id(rule))
}

# Largest cluster size with at least one term, for L phase points (L = N + 1
# for rate input, N for integrated input): the statistic's entry.
allan_max_m <- function(type, L) stat_entry(type)$max_m(L)

# Number of terms (squared differences) of each estimator at cluster size m.
allan_nterms <- function(type, m, L) stat_entry(type)$nterms(m, L)

# The cluster sizes m (sorted, unique, as doubles) requested by `taus`.
allan_taus <- function(taus, freq, maxm) {
  if (maxm < 1) return(numeric(0))
  if (is.character(taus)) {
    if (length(taus) != 1L || is.na(taus) ||
        !taus %in% c("octave", "decade", "all")) {
      abort("`taus` must be \"octave\", \"decade\", \"all\", a number of ",
            "points per decade, or a numeric vector of tau in seconds; not ",
            format_value(taus), ".")
    }
    m <- switch(taus,
      octave = 2^(0:floor(log2(maxm) + 1e-9)),
      decade = {
        k <- 0:floor(log10(maxm) + 1e-9)
        sort(as.vector(outer(c(1, 2, 4), 10^k)))
      },
      all = as.double(seq_len(maxm))
    )
    return(if (taus == "all") m else as.double(m[m <= maxm]))
  }
  if (!is.numeric(taus) || is.factor(taus) || length(taus) == 0L ||
      anyNA(taus) || any(!is.finite(taus)) || any(taus <= 0)) {
    abort("`taus` must be \"octave\", \"decade\", \"all\", a number of ",
          "points per decade, or a numeric vector of positive tau in seconds; ",
          "not ", describe_type(taus), ".")
  }
  if (length(taus) == 1L && !inherits(taus, "AsIs")) {
    if (taus != round(taus) || taus > 1000) {
      abort("A single number in `taus` is the number of points per decade ",
            "and must be a whole number in [1, 1000], not ", format(taus),
            ". Wrap a single tau in seconds in I(), e.g. taus = I(10).")
    }
    m <- unique(round(10^seq(0, log10(maxm), by = 1 / taus)))
    return(as.double(m[m >= 1 & m <= maxm]))
  }
  m <- round(as.double(taus) * freq)
  bad <- m < 1 | m > maxm
  if (any(bad)) {
    warn(sum(bad), " of the requested tau values lie outside [",
         format(1 / freq), ", ", format(maxm / freq),
         "] s (cluster sizes 1..", maxm, ") and were dropped.",
         class = "taus_dropped")
  }
  sort(unique(m[!bad]))
}
