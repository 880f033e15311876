# Tracing: from a residual signature (signatures.R) and the excess of the
# measured AV over the fitted one to candidate effects with start values.
# Each catalogue entry's `trace(ctx)` says whether a signature fits it, how
# well, and what its start values are; its `propose()` reads candidates from
# the raw-data diagnostics alone.

# Local log-log slope of the excess ADEV over a tau range (NA when the excess
# is not positive at >= 2 points).
excess_slope <- function(tau, excess) {
  ok <- is.finite(excess) & excess > 0
  if (sum(ok) < 2L) return(NA_real_)
  # lm()'s coefficient from lm.fit() (no model frame; the points are finite)
  unname(stats::lm.fit(cbind(1, log(tau[ok])), log(sqrt(excess[ok])))$coefficients[2L])
}

# How well a measured slope matches a term's ADEV slope: 2 for a match, down
# to 0 at 0.5 away; 0.5 when the slope is unknown.
score_slope <- function(slope, target) {
  if (is.na(slope)) return(0.5)
  2 - min(abs(slope - target) / 0.25, 2)
}

# What an entry's trace() sees of one signature `s` (a row of
# residual_signatures()): its kind, sign and tau range, and the excess AV
# (measured minus fitted) inside it.
trace_context <- function(s, tau, excess) {
  inr <- tau >= s$tau_from & tau <= s$tau_to
  ex <- excess[inr]
  tr <- tau[inr]
  sl <- excess_slope(tr, ex)
  pos <- any(ex > 0)
  list(kind = s$kind, sign = s$sign, tau_from = s$tau_from, tau_to = s$tau_to,
       width = s$tau_to / s$tau_from, slope = sl,
       e_first = max(ex[1L], 0), tau_first = tr[1L],
       e_last = max(ex[length(ex)], 0), tau_last = tr[length(tr)],
       emax = if (pos) max(ex) else NA_real_,
       tau_max = if (pos) tr[which.max(ex)] else s$tau_peak,
       text = paste0(s$description,
                     if (is.na(sl)) "" else sprintf("; excess ADEV slope %+.2f", sl)))
}

# `tau`, `avar`, `fitted`: the curve and the current model; `sig` from
# residual_signatures(); `present`: terms already in the model; `raw`: the
# loop's raw diagnostics (refine_diagnostics()) or NULL. Returns a data.frame of candidates: effect,
# tau_from, tau_to, init (list column of named start values), signature
# (character), score (how well the signature matches, larger is better).
trace_candidates <- function(tau, avar, fitted, sig, present,
                             candidates = effect_kinds(), raw = NULL) {
  excess <- avar - fitted
  present_kinds <- split_term(present)$kind
  usable <- Filter(function(e) {
    e$name %in% candidates && addable_kind(e$name, present)
  }, catalogue()[effect_kinds()])
  out <- list()
  one <- function(effect, from, to, init, signature, score, pin = NULL, after = NULL,
                  release = FALSE, release_late = FALSE) {
    list(effect = effect, tau_from = from, tau_to = to, init = init,
         signature = signature, score = score, pin = pin, after = after,
         release = isTRUE(release), release_late = isTRUE(release_late))
  }
  for (i in seq_len(nrow(sig))) {
    ctx <- trace_context(sig[i, ], tau, excess)
    for (e in usable) {
      if (is.null(e$trace)) next
      t <- e$trace(ctx)
      if (!is.null(t)) {
        out[[length(out) + 1L]] <- one(e$name, ctx$tau_from, ctx$tau_to, t$init,
                                       ctx$text, t$score)
      }
    }
  }
  # Raw-series evidence proposes candidates by itself too.
  if (!is.null(raw)) {
    for (e in usable) {
      if (is.null(e$propose)) next
      for (p in e$propose(raw, tau, sig)) {
        # a proposal may name a variant of its entry (a filter family)
        out[[length(out) + 1L]] <- one(
          p$effect %||% e$name, p$tau_from, p$tau_to, p$init,
          paste0(overlapping_signature(sig, p$tau_from, p$tau_to), "; ", p$note),
          p$score, p$pin, p$after, p$release, p$release_late)
      }
    }
  }
  if (!length(out)) {
    return(data.frame(effect = character(), tau_from = numeric(),
                      tau_to = numeric(), signature = character(),
                      score = numeric(), stringsAsFactors = FALSE))
  }
  df <- data.frame(effect = vapply(out, `[[`, "", "effect"),
                   tau_from = vapply(out, `[[`, 0, "tau_from"),
                   tau_to = vapply(out, `[[`, 0, "tau_to"),
                   signature = vapply(out, `[[`, "", "signature"),
                   score = vapply(out, `[[`, 0, "score"),
                   release = vapply(out, `[[`, NA, "release"),
                   release_late = vapply(out, `[[`, NA, "release_late"),
                   stringsAsFactors = FALSE)
  df$init <- lapply(out, `[[`, "init")
  df$pin <- lapply(out, function(o) o$pin)
  df$after <- lapply(out, function(o) o$after)
  df[order(-df$score), , drop = FALSE]
}

# The strongest residual signature overlapping [from, to], as text.
overlapping_signature <- function(sig, from, to) {
  hit <- sig[sig$tau_to >= from & sig$tau_from <= to & sig$kind != "slope", , drop = FALSE]
  if (!nrow(hit)) return("no residual structure in that tau range")
  hit$description[which.max(abs(hit$strength))]
}
