# The steps of the closed loop: one schema, built by new_steps(), carried by
# every fit (zero rows from avfit(), one row per accepted effect from
# avrefine()), and their display.

#' Refinement steps (internal constructor)
#'
#' One row per accepted step: `effect` (the term added), `label` (its
#' coefficient prefix, e.g. "gm1"), `tau_from`, `tau_to` (the tau range of
#' its residual signature, s), `params` (its fitted parameters, as text),
#' `evidence` (the residual signature and the raw-data evidence, as text),
#' `confirmed` (TRUE/FALSE when the raw data support/contradict the effect,
#' NA when not given or not decidable), `chi2_before`, `chi2_after`,
#' `rms_before`, `rms_after`, `crit_before`, `crit_after`.
#' @noRd
new_steps <- function(effect = character(), label = character(),
                      tau_from = numeric(), tau_to = numeric(),
                      params = character(), evidence = character(),
                      confirmed = logical(), chi2_before = numeric(),
                      chi2_after = numeric(), rms_before = numeric(),
                      rms_after = numeric(), crit_before = numeric(),
                      crit_after = numeric()) {
  # every fit carries the empty table (each of the loop's refits builds
  # one): made once
  if (!nargs() && !is.null(steps_store$empty)) return(steps_store$empty)
  out <- data.frame(effect = effect, label = label, tau_from = tau_from,
                    tau_to = tau_to, params = params, evidence = evidence,
                    confirmed = as.logical(confirmed), chi2_before = chi2_before,
                    chi2_after = chi2_after, rms_before = rms_before,
                    rms_after = rms_after, crit_before = crit_before,
                    crit_after = crit_after, stringsAsFactors = FALSE)
  out <- validate_steps(out)
  if (!nargs()) steps_store$empty <- out
  out
}
steps_store <- new.env(parent = emptyenv())

steps_columns <- c("effect", "label", "tau_from", "tau_to", "params",
                   "evidence", "confirmed", "chi2_before", "chi2_after",
                   "rms_before", "rms_after", "crit_before", "crit_after")

validate_steps <- function(x) {
  if (!is.data.frame(x) || !identical(names(x), steps_columns)) {
    abort("Invalid refinement steps: the columns must be ",
          paste(steps_columns, collapse = ", "), ".", class = "avfit")
  }
  x
}

# Steps of two loops, one after the other.
bind_steps <- function(old, new) {
  out <- rbind(validate_steps(old), validate_steps(new))
  rownames(out) <- NULL
  # (a step row's `values`, the loop's record of what it took, is no part
  # of the table: rbind() would keep the first row's)
  attr(out, "values") <- NULL
  out
}

# Fitted parameters as text: "sigma=0.01, tc=1.2 s" (units shown for the
# parameters the catalogue marks print_unit).
format_params <- function(par, effect) {
  sp <- split_term(effect)
  p <- effect_entry(sp$kind, sp$variant)$params
  hidden <- p$name[p$hidden %in% TRUE]
  par <- par[!names(par) %in% hidden]
  nm <- names(par)
  txt <- vapply(seq_along(par), function(i) {
    j <- match(nm[i], p$name)
    u <- if (!is.na(j) && isTRUE(p$print_unit[j])) paste0(" ", p$unit[j]) else ""
    sprintf("%s=%s%s", nm[i], format(signif(par[[i]], 3)), u)
  }, character(1))
  paste(txt, collapse = ", ")
}

# Steps as text for print/summary of a refined fit.
format_steps <- function(steps) {
  if (is.null(steps) || !nrow(steps)) return(character(0))
  vapply(seq_len(nrow(steps)), function(i) {
    s <- steps[i, ]
    sprintf("%d. + %s (%s), tau %s-%s s: chi2/dof %.2f -> %.2f, RMS %.1f%% -> %.1f%%\n     evidence: %s",
            i, s$effect, s$params, format_num(s$tau_from), format_num(s$tau_to),
            s$chi2_before, s$chi2_after, s$rms_before, s$rms_after, s$evidence)
  }, character(1))
}

# Print the steps of a refined fit (after the avfit print).
print_steps <- function(x, ...) {
  txt <- format_steps(x$steps)
  if (length(txt)) {
    cat("Refinement steps (avrefine):\n")
    cat(txt, sep = "\n")
  } else if (!is.null(x$refine)) {
    cat("Refinement: nothing added (no effect paid by ", x$refine$criterion, ").\n",
        sep = "")
  }
  nf <- NROW(x$refine$failures)
  if (nf) {
    cat(nf, " refit(s) failed and were skipped; see $refine$failures.\n", sep = "")
  }
  invisible(x)
}

format_num <- function(x, digits = 3) {
  vapply(x, function(v) if (is.na(v)) "NA" else format(signif(v, digits)),
         character(1))
}
