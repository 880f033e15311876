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
#' * `method`, the same facts as display text.
#' @noRd
channel_readings <- function(curve, coef, sensor, se = NULL, fitted = NULL) {
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
  out <- reading_verdicts(out, curve, lay, ok, rel)
  out$biased_by <- rep("", nrow(out))
  out$bias_change <- rep(NA_real_, nrow(out))
  out
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
               bias_change = NA_real_, stringsAsFactors = FALSE)
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

# ---- verdicts ----------------------------------------------------------------

# Relative tolerance added to the points' confidence limits when the model
# is compared with the curve: the intervals of short-tau points are a few
# tenths of a percent wide, finer than any filter needs; a model within 2%
# of such a point agrees with it for every use of the reading.
verdict_tolerance <- 0.02

# The verdict of each reading from the curve and the final model: measured
# only where the model stays within the points' confidence limits over the
# taus the reading rests on (N, K: where their term makes at least half of
# the model's AV, the -1/2 and +1/2 regions; B: the flat minimum, where the
# model's ADEV is within 10% of its least value); otherwise a bound (the
# side the model leaves the curve on) or not determined, with the reason.
reading_verdicts <- function(rd, curve, lay, ok, rel) {
  n <- nrow(rd)
  rd$verdict <- rep("measured", n)
  rd$why <- rep("", n)
  rd$tau_lo <- rep(NA_real_, n)
  rd$tau_hi <- rep(NA_real_, n)
  tau <- curve$tau
  model <- NULL
  if (!is.null(lay) && nrow(lay)) {
    tau0 <- if (!is.null(curve$m) && is.finite(curve$m[1L]) && curve$m[1L] > 0)
      tau[1L] / curve$m[1L] else NULL
    comp <- tryCatch(model_components(tau, tau0, lay), error = function(e) NULL)
    if (!is.null(comp) && all(is.finite(comp))) model <- rowSums(comp)
  }
  lim <- !is.null(curve$lower) && !is.null(curve$upper)
  for (i in seq_len(n)) {
    r <- rd[i, ]
    e <- reading_entry(r$role)
    set <- function(v, why, lo = NA_real_, hi = NA_real_) {
      rd$verdict[i] <<- v
      rd$why[i] <<- why
      rd$tau_lo[i] <<- lo
      rd$tau_hi[i] <<- hi
    }
    if (r$source == "none" || !is.finite(r$value)) {
      set("not_determined", paste0("no ", r$term, " could be read from the curve",
                                   if (grepl("fit .* = 0", r$method)) " (the fit set it to 0)"))
      next
    }
    if (r$source == "bound") {
      set("upper_bound", sprintf("the %+g/2 region is not reached: %s is at most the curve allows",
                                 2 * e$reading$slope, r$term),
          min(tau[ok]), max(tau[ok]))
      next
    }
    if (r$source == "slope" || is.null(model)) {
      # A slope line touches the curve where it is read.
      if (identical(e$reading$anchor, "min")) {
        j <- which(rel)
        last <- j[length(j)]
        at <- j[which.min(curve$adev[j])]
        if (at == last) {
          set("upper_bound", paste0("the Allan deviation still falls at the longest ",
                                    "reliable tau (EDF >= 10): the flat minimum is not reached"),
              tau[at], tau[at])
        } else {
          set("measured", "", tau[at], tau[at])
        }
      } else {
        set("measured", "", r$tau, r$tau)
      }
      next
    }
    share <- r$value^2 * e$basis(tau, NULL, NULL) / model
    if (identical(e$reading$anchor, "min")) {
      madev <- sqrt(model)
      at <- which(ok)[which.min(madev[ok])]
      span <- ok & madev <= 1.1 * madev[at]
      j <- which(rel)
      if (!length(j) || tau[at] >= tau[j[length(j)]]) {
        w <- which(span)
        set("upper_bound", paste0("the model's minimum lies at or beyond the longest ",
                                  "reliable tau (EDF >= 10): the flat minimum is not reached"),
            min(tau[w]), max(tau[w]))
        next
      }
    } else {
      span <- ok & is.finite(share) & share >= 0.5
    }
    if (!any(span)) {
      set("upper_bound", sprintf(paste0("the %s term never makes half of the model ",
                                        "within the curve's taus: %s is at most this"),
                                 r$term, r$term))
      next
    }
    lo <- min(tau[span])
    hi <- max(tau[span])
    if (!lim) {
      set("not_determined", "the curve has no confidence limits to check the model against",
          lo, hi)
      next
    }
    w <- which(span & is.finite(curve$lower) & is.finite(curve$upper))
    if (!length(w)) {
      set("not_determined", "no point with confidence limits in its range", lo, hi)
      next
    }
    m <- sqrt(model[w])
    above <- m > curve$upper[w] * (1 + verdict_tolerance)
    below <- m < curve$lower[w] * (1 - verdict_tolerance)
    rng <- sprintf("%.3g-%.3g s", lo, hi)
    if (!any(above | below)) {
      set("measured", "", lo, hi)
    } else if (!any(below)) {
      f <- max(m[above] / curve$adev[w][above])
      set("upper_bound", sprintf(paste0("the model lies above the curve's confidence ",
                                        "limits over %s (up to %.2gx): %s is at most this"),
                                 rng, f, r$term), lo, hi)
    } else if (!any(above)) {
      f <- max(curve$adev[w][below] / m[below])
      set("lower_bound", sprintf(paste0("the model lies below the curve's confidence ",
                                        "limits over %s (down to 1/%.2g): %s is at least this"),
                                 rng, f, r$term), lo, hi)
    } else {
      set("not_determined", sprintf(paste0("the model leaves the curve's confidence ",
                                           "limits on both sides over %s"), rng), lo, hi)
    }
  }
  rd$is_bound <- rd$verdict %in% c("upper_bound", "lower_bound")
  rd
}

# Verdict display: "measured", "upper bound", ...
verdict_label <- function(v) gsub("_", " ", v, fixed = TRUE)
