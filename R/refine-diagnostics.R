# The raw-data diagnostics of one avrefine() call: one classed object with
# a fixed structure, built once per call from avdiagnose() and the parts
# the catalogue entries declare in their `diagnose` field; every entry's
# propose() and evidence() read it through the accessors below.
#
# Structure (class "refine_diagnostics"):
#   base    the avdiagnose() object of the raw series (lines, ACF, grid,
#           trend, noise id)
#   parts   named list: one part per entry with a `diagnose` field (the
#           sinusoid's lines outside the bands, the resonance's bands, the
#           measured band's spectra, the filter's short-lag ACF), in the
#           order they were made
#   series  the series the raw-data checks of an effect see: the raw series
#           with each part's `clean()` applied in catalogue order (the
#           lines taken out, the bands brought to their background)
#   cache   an environment for statistics of `series` that many candidate
#           checks share (the block-mean ACF of each block size, its
#           variance), the raw series' Welch PSD the parts share
#           (raw_welch()), and the raw series itself (`data`) for its
#           short-lag autocovariance steps (diag_acov_steps())
#
# An entry's `diagnose` field: list(part, reads = "raw" or "clean", needs
# (parts made first), make(x, freq, dg) -> the part, clean(x, freq, part)
# -> the series without what the part describes, or NULL).

new_refine_diagnostics <- function(base, parts, series, cache = new.env(parent = emptyenv())) {
  validate_refine_diagnostics(structure(
    list(base = base, parts = parts, series = series, cache = cache),
    class = "refine_diagnostics"))
}

validate_refine_diagnostics <- function(dg) {
  ok <- inherits(dg, "refine_diagnostics") && inherits(dg$base, "avdiagnose") &&
    is.list(dg$parts) && (!length(dg$parts) || !is.null(names(dg$parts))) &&
    is.numeric(dg$series) && is.environment(dg$cache) &&
    identical(names(dg), c("base", "parts", "series", "cache"))
  if (!ok) {
    abort("Malformed raw-data diagnostics of the loop.", class = "internal")
  }
  dg
}

# The entries' diagnose fields, each after the parts it needs (catalogue
# order otherwise).
diagnose_order <- function() {
  todo <- lapply(entries_with("diagnose"), `[[`, "diagnose")
  out <- list()
  while (length(todo)) {
    made <- vapply(out, `[[`, "", "part")
    ready <- which(vapply(todo, function(d) all(d$needs %in% made), NA))
    if (!length(ready)) {
      abort("The catalogue's diagnose fields need parts no entry makes.",
            class = "catalogue")
    }
    out[[length(out) + 1L]] <- todo[[ready[1L]]]
    todo <- todo[-ready[1L]]
  }
  out
}

# Assemble the diagnostics of raw series `x`: avdiagnose() (its trend read
# beyond the shapes `beside`, linear_trend()'s), then the parts read from
# the raw series, the cleaned series, then the parts read from it.
refine_diagnostics <- function(x, freq, beside = NULL) {
  dg <- new_refine_diagnostics(diagnose_record(x, freq, beside = beside), list(), x)
  steps <- diagnose_order()
  for (d in steps) {
    if (identical(d$reads, "raw")) dg$parts[[d$part]] <- d$make(x, freq, dg)
  }
  # cleaning follows the catalogue's order (lines before bands)
  clean <- x
  for (e in entries_with("diagnose")) {
    d <- e$diagnose
    if (!is.null(d$clean) && !is.null(dg$parts[[d$part]])) {
      clean <- d$clean(clean, freq, dg$parts[[d$part]])
    }
  }
  dg$series <- clean
  assign("data", x, envir = dg$cache)
  for (d in steps) {
    if (identical(d$reads, "clean")) dg$parts[[d$part]] <- d$make(clean, freq, dg)
  }
  validate_refine_diagnostics(dg)
}

# ---- accessors ----------------------------------------------------------------
# They read a refine_diagnostics object or a bare avdiagnose() (its fields
# only; the parts an entry then needs are NULL and it reads them itself).

# A part made by an entry's diagnose field (NULL when absent); "lines"
# falls back to avdiagnose()'s own.
diag_part <- function(dg, part) {
  if (inherits(dg, "refine_diagnostics")) {
    return(dg$parts[[part]] %||% dg$base[[part]])
  }
  if (inherits(dg, "avdiagnose")) return(dg[[part]])
  NULL
}

# A field of avdiagnose(): freq, n, acf1, acf1_z, noise_id, grid, trend,
# lines.
diag_value <- function(dg, field) {
  if (inherits(dg, "refine_diagnostics")) return(dg$base[[field]])
  if (inherits(dg, "avdiagnose")) return(dg[[field]])
  NULL
}

# The call's store for statistics of the checked series (NULL outside a
# loop).
diag_cache <- function(dg) {
  if (inherits(dg, "refine_diagnostics")) dg$cache else NULL
}

# The variance of `x`, kept in the call's store when `x` is the series the
# checks see (every candidate's evidence reads it).
diag_var <- function(dg, x) {
  cache <- diag_cache(dg)
  if (is.null(cache) || !identical(x, diag_series(dg))) return(stats::var(x))
  if (is.null(cache$var)) cache$var <- stats::var(x)
  cache$var
}

# centred_welch() of the raw series for the parts that read it (the bands
# and the measured bands' spectra), made once per call and segment length:
# returns a function(x, freq, seg) for their `welch` argument.
raw_welch <- function(dg) {
  cache <- diag_cache(dg)
  function(x, freq, seg) {
    key <- paste0("raw_welch.", seg)
    hit <- if (!is.null(cache)) cache[[key]]
    if (!is.null(hit) && identical(hit$x, x) && identical(hit$freq, freq)) return(hit$w)
    w <- centred_welch(x, freq, seg)
    if (!is.null(cache)) cache[[key]] <- list(x = x, freq = freq, w = w)
    w
  }
}

# The short-lag autocovariance steps of the raw series (acov_steps()),
# made once per call; NULL without it.
diag_acov_steps <- function(dg) {
  cache <- diag_cache(dg)
  if (is.null(cache) || is.null(cache$data)) return(NULL)
  if (is.null(cache$acov_steps)) cache$acov_steps <- acov_steps(cache$data)
  cache$acov_steps
}

# The series the raw-data checks see.
diag_series <- function(dg) {
  if (inherits(dg, "refine_diagnostics")) dg$series else NULL
}

# The diagnostics with the series effects of `table` (rows of a series
# pass's table) taken out of the checked series, its parts as they are and
# a store of its own; made once per call and set of effects.
diag_without <- function(dg, table, freq) {
  key <- paste0("without.", paste(table$kind, table$index, collapse = ","))
  hit <- dg$cache[[key]]
  if (!is.null(hit)) return(hit)
  out <- new_refine_diagnostics(dg$base, dg$parts, remove_series(dg$series, freq, table))
  dg$cache[[key]] <- out
  out
}

# The diagnostics as the result reports them (`$refine$diagnostics`): the
# avdiagnose() list with each part in place of, or after, its fields.
diag_report <- function(dg) {
  if (is.null(dg)) return(NULL)
  out <- dg$base
  for (p in names(dg$parts)) out[[p]] <- dg$parts[[p]]
  out
}
