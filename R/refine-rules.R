# The loop's rules: which terms a step adds and replaces, which instances
# are valid, the candidate trials of a step, where an accepted effect's
# signature sits, and the row it adds to the steps.

# A trial's pinned values (named by parameter) as coefficients of the term
# `effect` would get next to `terms`.
pin_values <- function(terms, effect, pin) {
  if (!length(pin)) return(NULL)
  sp <- split_term(effect)
  e <- effect_entry(sp$kind, sp$variant)
  lab <- new_label(terms, effect)
  pin <- unlist(pin)
  j <- match(names(pin), e$params$name)
  out <- pin[!is.na(j)]
  names(out) <- coef_names(e, lab)[j[!is.na(j)]]
  out
}

# The model after adding `effect`: the kinds the effect's entry replaces
# (the filter replaces N) leave.
model_terms <- function(terms, effect) {
  sp <- split_term(effect)
  gone <- effect_entry(sp$kind, sp$variant)$replaces
  c(terms[!split_term(terms)$kind %in% gone], effect)
}

# Kinds that may still be added next to `present`: repeatable ones or those
# absent, and never one that a present term replaced.
addable_kind <- function(kind, present) {
  pk <- split_term(present)$kind
  replaced <- unlist(lapply(unique(pk), function(k) effect_entry(k)$replaces))
  e <- effect_entry(kind)
  !kind %in% replaced && (e$repeatable || !kind %in% pk)
}

# NULL when a fitted instance is valid on this curve, else the reason.
inadmissible <- function(effect, par, tau, freq) {
  sp <- split_term(effect)
  e <- effect_entry(sp$kind, sp$variant)
  if (is.null(e$admissible)) return(NULL)
  e$admissible(as.list(par), tau, freq)
}

# The residual structure left after the loop, as a table: kind, tau range,
# strength (sigma) and size (largest relative ADEV error inside, percent).
unexplained_table <- function(sig, fit) {
  s <- sig[sig$kind != "oscillation", , drop = FALSE]
  tau <- fit$data$tau
  err <- 100 * abs(sqrt(fit$data$avar / fit$data$fitted) - 1)
  size <- vapply(seq_len(nrow(s)), function(i) {
    inr <- tau >= s$tau_from[i] & tau <= s$tau_to[i]
    if (any(inr)) max(err[inr]) else NA_real_
  }, 0)
  data.frame(kind = s$kind, tau_from = s$tau_from, tau_to = s$tau_to,
             strength = abs(s$strength), size = size,
             description = s$description, stringsAsFactors = FALSE)
}

# ---- trials and steps ---------------------------------------------------------

# One trial per candidate kind: the best-scoring traced start (two for kinds
# with nonlinear parameters), or a generic start when no signature points
# at that kind (the refit then decides).
candidate_trials <- function(traced, present, candidates, sig) {
  kinds <- candidates[vapply(candidates, addable_kind, logical(1), present = present)]
  rows <- list()
  strongest <- if (nrow(sig)) sig[which.max(abs(sig$strength)), ] else
    data.frame(tau_from = NA_real_, tau_to = NA_real_,
               description = "no residual signature", stringsAsFactors = FALSE)
  for (k in kinds) {
    t <- if (nrow(traced)) traced[split_term(traced$effect)$kind == k, , drop = FALSE]
      else traced
    if (nrow(t)) {
      nonlinear <- any(effect_entry(k)$params$role == "nonlinear")
      take <- if (nonlinear) seq_len(min(2L, nrow(t))) else 1L
      # every raw-data proposal that pins a value (each periodogram line)
      # is tried, not only the two best-scoring starts; so is the best
      # start of every variant proposed (each filter family the raw data
      # support): the criterion chooses among them
      pinned <- which(lengths(t$pin) > 0L)
      take <- union(union(take, pinned), which(!duplicated(t$effect)))
      t$traced <- rep(TRUE, nrow(t))
      rows[[length(rows) + 1L]] <- t[take, , drop = FALSE]
    } else if (!isTRUE(effect_entry(k)$proposed_only)) {
      r <- data.frame(
        effect = k, tau_from = strongest$tau_from, tau_to = strongest$tau_to,
        signature = paste0(strongest$description, " (no signature specific to ", k, ")"),
        score = 0, traced = FALSE, stringsAsFactors = FALSE)
      r$init <- list(list())
      r$pin <- list(NULL)
      rows[[length(rows) + 1L]] <- r[, c("effect", "tau_from", "tau_to", "signature",
                                         "score", "init", "pin", "traced")]
    }
  }
  if (!length(rows)) return(data.frame())
  do.call(rbind, lapply(rows, function(r) r[, c("effect", "tau_from", "tau_to",
                                                "signature", "score", "init",
                                                "pin", "traced")]))
}

# The residual signature that matches an accepted term: the one whose tau
# range holds (or lies nearest, within a factor 3) the term's characteristic
# tau (the catalogue's peak_tau, otherwise the tau where the term's share of
# the model is largest). Without one, the tau range is where the term
# carries over a quarter of the model AV.
locate_signature <- function(sig, fit, label) {
  tau <- fit$data$tau
  comp <- fit$components
  share <- comp[, label] / rowSums(comp)
  e <- effect_entry(parse_labels(label)$kind, parse_labels(label)$variant)
  par <- instance_params(stats::coef(fit), fit$layout, label)
  tchar <- if (!is.null(e$peak_tau)) e$peak_tau(par)
    else if (all(is.na(share))) NA_real_ else tau[which.max(share)]
  big <- which(share > 0.25)
  range <- if (length(big)) range(tau[big]) else range(tau)
  s <- sig[sig$kind != "slope" & sig$kind != "oscillation", , drop = FALSE]
  if (is.finite(tchar) && nrow(s)) {
    dist <- ifelse(tchar < s$tau_from, log(s$tau_from / tchar),
                   ifelse(tchar > s$tau_to, log(tchar / s$tau_to), 0))
    dist <- dist - 0.01 * (s$sign > 0)       # prefer a positive run on ties
    j <- which.min(dist)
    if (dist[j] < log(3)) {
      return(list(tau_from = s$tau_from[j], tau_to = s$tau_to[j],
                  text = s$description[j]))
    }
  }
  list(tau_from = range[1L], tau_to = range[2L],
       text = sprintf("no residual signature near tau = %s s (the term carries >25%% of the model AV over tau %s-%s s)",
                      format_num(tchar), format_num(range[1L]), format_num(range[2L])))
}

# Largest share of the model AV carried by one term instance over the taus.
max_share <- function(fit, label) {
  comp <- fit$components
  if (!label %in% colnames(comp)) return(1)
  max(comp[, label] / rowSums(comp))
}

# One accepted step: the effect, where its signature sits (`loc`), its
# parameters, the evidence, and the fit before and after it.
step_row <- function(effect, label, loc, par, evidence, confirmed, before,
                     after, crit_before, crit_after) {
  new_steps(effect = effect, label = label,
            tau_from = loc$tau_from, tau_to = loc$tau_to,
            params = format_params(par, effect),
            evidence = evidence, confirmed = confirmed,
            chi2_before = before$chi2, chi2_after = after$chi2,
            rms_before = before$rms, rms_after = after$rms,
            crit_before = crit_before, crit_after = crit_after)
}
