# The datasheet readings of one axis: for every catalogue entry with a
# `reading` (white noise N, bias instability B, rate random walk K), its
# value from the fit or, failing that, from the IEEE 952 slope lines or as
# an upper bound, in typed columns. The datasheet, the exports, the plots
# and the guidance read these columns, never the display text (`method`).

#' Readings of one axis (internal)
#'
#' One row per reading, in catalogue order, with columns
#' * `term` the coefficient ("N"), `role` ("white", "flicker",
#'   "random_walk"), `value` (SI), `unit`, `tau` (s) where it is read;
#' * `source`: `"fit"` (the fitted coefficient, with any folded terms),
#'   `"slope"` (the IEEE 952 line of the term's slope through the curve),
#'   `"bound"` (an upper bound: the region of the term was not reached) or
#'   `"none"`;
#' * `is_bound` (TRUE for an upper bound), `folded` (labels of the fitted
#'   instances folded into the value, comma-separated, "" for none);
#' * `slope` (the ADEV slope of the reading's line) and `adev` (the ADEV at
#'   `tau` on that line, where plots put the marker);
#' * `method`, the same facts as display text;
#' * the verdict columns of R/verdicts.R: `verdict` ("measured",
#'   "upper_bound", "lower_bound", "not_determined"), `why`, `tau_lo`,
#'   `tau_hi` (the taus the reading rests on), `biased_by` (series effects
#'   left in that change it), `bias_change`, `removed` (kinds taken out).
#' `series`: the axis' series pass (detect_series_effects()) or NULL.
#' `unexplained`: the runs the loop left unexplained (avrefine()'s
#' `$unexplained`, taus as the curve's) or NULL; a reading resting on one is
#' not measured (R/verdicts.R). `alternatives`: model_alternatives() of the
#' fit, or NULL (mark_model_choice()).
#' @noRd
channel_readings <- function(curve, coef, sensor, se = NULL, fitted = NULL,
                             series = NULL, unexplained = NULL, alternatives = NULL) {
  tau <- curve$tau
  adev <- curve$adev
  ok <- is.finite(adev) & adev > 0
  # The flat minimum is looked for where the curve is reliable (edf >= 10).
  rel <- if (is.null(curve$edf)) ok else ok & !is.na(curve$edf) & curve$edf >= 10
  if (!any(rel)) rel <- ok
  tau_min <- curve$tau[rel][which.min(adev[rel])]
  # With a fit, the minimum is read where the fitted model is flattest.
  if (!is.null(fitted) && !is.null(fitted$fitted) && any(is.finite(fitted$fitted))) {
    tau_min <- fitted$tau[which.min(fitted$fitted)]
  }
  lay <- if (length(coef)) check_coef(coef) else NULL
  rows <- lapply(entries_with("reading"), function(e) {
    reading_row(e, lay, coef, se, curve, ok, rel, tau_min, sensor)
  })
  out <- do.call(rbind, rows)
  rownames(out) <- NULL
  out <- mark_series_bias(reading_verdicts(out, curve, lay, ok, rel, unexplained),
                          series)
  mark_model_choice(out, alternatives, curve, ok, rel, tau_min, sensor)
}

# The readings of a dead axis: one row per reading, no value, `reason` as
# the method.
dead_readings <- function(sensor, reason) {
  rows <- lapply(entries_with("reading"), function(e) {
    spec <- e$reading
    data.frame(term = spec$symbol, value = NA_real_,
               unit = si_unit(sensor, spec$unit),
               tau = if (is.finite(spec$tau)) spec$tau else NA_real_,
               method = reason, source = "none", is_bound = FALSE, folded = "",
               role = spec$role, slope = spec$slope, adev = NA_real_,
               verdict = "not_determined", why = reason,
               tau_lo = NA_real_, tau_hi = NA_real_, biased_by = "",
               bias_change = NA_real_, removed = "", stringsAsFactors = FALSE)
  })
  out <- do.call(rbind, rows)
  rownames(out) <- NULL
  out
}

reading_row <- function(e, lay, coef, se, curve, ok, rel, tau_min, sensor) {
  spec <- e$reading
  sym <- spec$symbol
  value <- if (sym %in% names(coef)) unname(coef[[sym]]) else NA_real_
  method <- "fit"
  # Instances the catalogue folds into this reading (a GM with Tc well
  # below 1 s is white noise at tau >= 1 s: N^2 + 2 sigma^2 Tc).
  folded <- character()
  if (!is.null(lay)) {
    extra <- 0
    notes <- character()
    for (l in unique(lay$label)) {
      rows <- lay[lay$label == l, , drop = FALSE]
      f <- effect_entry(rows$kind[1L], rows$variant[1L])$fold
      if (is.null(f) || !identical(f$into, spec$role)) next
      par <- stats::setNames(rows$value, rows$param)
      if (!isTRUE(f$when(par))) next
      extra <- extra + f$amount(par)
      folded <- c(folded, l)
      notes <- union(notes, f$note %||% rows$kind[1L])
    }
    if (extra > 0) {
      value <- sqrt((if (is.finite(value)) value^2 else 0) + extra)
      method <- paste("fit +", paste(notes, collapse = " + "))
    } else {
      folded <- character()
    }
  }
  # A term the fit set to 0 is not read from it; nor one whose standard
  # error exceeds it when the reading must be resolved (then bounded).
  in_fit <- sym %in% names(coef)
  if (!is.finite(value) || value <= 0) value <- NA_real_
  if (isTRUE(spec$resolve) && !is.null(se) && sym %in% names(se) &&
      is.finite(value) && is.finite(se[[sym]]) && se[[sym]] > value) {
    value <- NA_real_
  }
  source <- if (is.finite(value)) "fit" else "none"
  if (!is.finite(value)) {
    # With a fit, a boundable term the fit lacks is not replaced by a slope
    # line: that slope may belong to something the model explains otherwise.
    if (!(isTRUE(spec$bound) && length(coef))) {
      value <- slope_reading(e, curve$tau[rel], curve$adev[rel])
      method <- spec$slope_method
      if (is.finite(value)) source <- "slope"
    }
    if (in_fit && !isTRUE(coef[[sym]] > 0)) method <- paste0(method, " (fit ", sym, " = 0)")
  }
  if (isTRUE(spec$bound) && (!is.finite(value) || value <= 0)) {
    # No region of the term: every term adds to the AV, so a^2 basis(tau) <=
    # AV(tau) at each tau; the upper confidence limit makes it conservative.
    up <- if (!is.null(curve$upper)) curve$upper[ok] else curve$adev[ok]
    up[!is.finite(up)] <- Inf
    value <- min(up / sqrt(e$basis(curve$tau[ok], NULL, NULL)))
    method <- spec$bound_method
    source <- "bound"
  }
  tau_read <- if (is.finite(spec$tau)) spec$tau else tau_min
  data.frame(term = sym, value = value, unit = si_unit(sensor, spec$unit),
             tau = tau_read, method = method, source = source,
             is_bound = source == "bound",
             folded = paste(folded, collapse = ","), role = spec$role,
             slope = spec$slope,
             adev = value * sqrt(e$basis(tau_read, NULL, NULL)),
             stringsAsFactors = FALSE)
}

# IEEE 952 slope-line reading of entry `e`: the local slope between
# successive taus; the line of the term's slope through the point whose
# slope is closest (within 1/4), read through the term's continuous basis.
# A flat term is read at the minimum.
slope_reading <- function(e, tau, adev) {
  spec <- e$reading
  if (identical(spec$anchor, "min")) {
    i <- which.min(adev)
    return(adev[i] / sqrt(e$basis(tau[i], NULL, NULL)))
  }
  if (length(tau) < 2L) return(NA_real_)
  s <- diff(log(adev)) / diff(log(tau))
  i <- which.min(abs(s - spec$slope))
  if (abs(s[i] - spec$slope) >= 0.25) return(NA_real_)
  j <- if (identical(spec$anchor, "last")) i + 1L else i
  adev[j] / sqrt(e$basis(tau[j], NULL, NULL))
}

fit_se <- function(fit) {
  if (is.null(fit)) return(NULL)
  se <- fit$se
  if (is.null(se) && !is.null(fit$vcov)) {
    se <- sqrt(pmax(diag(as.matrix(fit$vcov)), 0))
    names(se) <- names(fit$coefficients)
  }
  se
}

# The reading of `role` in a readings data frame (one row, or zero rows).
reading_of <- function(readings, role) {
  sym <- reading_symbol(role)
  readings[readings$term %in% sym, , drop = FALSE]
}

# Labels of the fitted instances the catalogue folds into a reading.
folded_labels <- function(coef) {
  if (!length(coef)) return(character())
  lay <- check_coef(coef)
  out <- character()
  for (l in unique(lay$label)) {
    rows <- lay[lay$label == l, , drop = FALSE]
    f <- effect_entry(rows$kind[1L], rows$variant[1L])$fold
    if (!is.null(f) && isTRUE(f$when(stats::setNames(rows$value, rows$param)))) {
      out <- c(out, l)
    }
  }
  out
}

# The coefficients without the instances in `folded` (by default those the
# catalogue folds into a reading), renumbered; only the instances of `kinds`
# when given.
unfolded_coef <- function(coef, folded = folded_labels(coef), kinds = NULL) {
  if (!length(coef)) return(numeric())
  lay <- check_coef(coef)
  keep <- !lay$label %in% folded
  if (!is.null(kinds)) keep <- keep & lay$kind %in% kinds
  lay <- lay[keep, , drop = FALSE]
  if (!nrow(lay)) return(numeric())
  stats::setNames(lay$value, coef_layout(layout_terms(lay))$name)
}
