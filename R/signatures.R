# Residual signatures: structure in the standardized residuals of a fit
# (runs of one sign, an oscillation with nulls, an overall slope) and where
# it sits in tau. The closed loop (avrefine()) traces them to effects
# (trace.R).

# Structure in standardized residuals `z` over increasing `tau`: runs of one
# sign whose combined strength sum(z)/sqrt(length) exceeds `level`, classed by
# where they sit (short-tau end, long-tau end, interior bump or dip), plus an
# oscillation (alternating significant runs) and an overall slope. Adjacent
# overlapping-AV points are correlated, so `level` is deliberately high.
# Returns a data.frame: kind, tau_from, tau_to, tau_peak, strength, sign,
# slope (of z against log10 tau inside the run), description.
residual_signatures <- function(tau, z, level = 3.5, z0 = 1) {
  ok <- is.finite(tau) & is.finite(z)
  tau <- tau[ok]
  z <- z[ok]
  n <- length(z)
  empty <- data.frame(kind = character(), tau_from = numeric(),
                      tau_to = numeric(), tau_peak = numeric(),
                      strength = numeric(), sign = integer(),
                      slope = numeric(), description = character(),
                      stringsAsFactors = FALSE)
  if (n < 3L) return(empty)
  o <- order(tau)
  tau <- tau[o]
  z <- z[o]
  # Points within +-z0 are neutral: they end a run without starting one.
  s <- ifelse(z > z0, 1L, ifelse(z < -z0, -1L, 0L))
  r <- rle(s)
  ends <- cumsum(r$lengths)
  starts <- ends - r$lengths + 1L
  rows <- list()
  for (i in seq_along(starts)) {
    if (r$values[i] == 0L) next
    idx <- starts[i]:ends[i]
    strength <- sum(z[idx]) / sqrt(length(idx))
    if (abs(strength) < level && max(abs(z[idx])) < level + 1.5) next
    peak <- idx[which.max(abs(z[idx]))]
    at_start <- starts[i] == 1L
    at_end <- ends[i] == n
    kind <- if (at_start && at_end) "global" else if (at_start) "short_end"
      else if (at_end) "long_end" else if (r$values[i] > 0) "bump" else "dip"
    # (lm()'s coefficients from its own QR, lm.fit(), without the model
    # frame: every fit of the loop reads its signature)
    slope <- if (length(idx) >= 3L) {
      if (anyNA(z[idx])) unname(stats::coef(stats::lm(z[idx] ~ log10(tau[idx])))[2L])
      else unname(stats::lm.fit(cbind(1, log10(tau[idx])), z[idx])$coefficients[2L])
    } else NA_real_
    rows[[length(rows) + 1L]] <- data.frame(
      kind = kind, tau_from = tau[starts[i]], tau_to = tau[ends[i]],
      tau_peak = tau[peak], strength = strength,
      sign = as.integer(r$values[i]), slope = slope,
      description = "", stringsAsFactors = FALSE)
  }
  out <- if (length(rows)) do.call(rbind, rows) else empty
  # Oscillation: two or more significant positive runs with a null (the
  # lowest z) between each pair, or three alternating runs.
  nulls <- NULL
  pos <- which(out$sign > 0 & out$kind != "global")
  if (length(pos) >= 2L || (nrow(out) >= 3L && length(rle(out$sign)$lengths) >= 3L)) {
    nulls <- numeric(0)
    if (length(pos) >= 2L) {
      for (k in seq_len(length(pos) - 1L)) {
        gap <- tau > out$tau_to[pos[k]] & tau < out$tau_from[pos[k + 1L]]
        if (any(gap)) nulls <- c(nulls, tau[gap][which.min(z[gap])])
      }
    }
    neg <- out$tau_peak[out$sign < 0]
    nulls <- sort(unique(c(nulls, neg)))
    first <- if (length(pos)) pos[1L] else which(out$sign > 0)[1L]
    out <- rbind(out, data.frame(
      kind = "oscillation", tau_from = min(out$tau_from),
      tau_to = max(out$tau_to),
      tau_peak = out$tau_peak[first],
      strength = sqrt(sum(out$strength^2)), sign = 0L,
      slope = NA_real_, description = "", stringsAsFactors = FALSE))
  }
  # Overall slope of z against log10(tau), judged on well-separated points.
  fit <- stats::lm(z ~ log10(tau))
  cf <- summary(fit)$coefficients
  if (nrow(cf) == 2L && is.finite(cf[2L, 3L])) {
    t_slope <- cf[2L, 1L] * stats::sd(log10(tau)) * sqrt(n) / sqrt(max(n / 4, 1))
    if (abs(t_slope) > 2 * level) {
      out <- rbind(out, data.frame(
        kind = "slope", tau_from = tau[1L], tau_to = tau[n],
        tau_peak = NA_real_, strength = t_slope, sign = as.integer(sign(cf[2L, 1L])),
        slope = cf[2L, 1L], description = "", stringsAsFactors = FALSE))
    }
  }
  if (nrow(out)) out$description <- describe_signature(out)
  rownames(out) <- NULL
  if (!is.null(nulls)) attr(out, "nulls") <- nulls
  out
}

describe_signature <- function(sig) {
  what <- c(short_end = "run at the short-tau end", long_end = "run at the long-tau end",
            bump = "localized bump", dip = "localized dip",
            oscillation = "oscillation with nulls", slope = "slope over all tau",
            global = "offset over all tau")[sig$kind]
  sgn <- ifelse(sig$sign > 0, "positive ", ifelse(sig$sign < 0, "negative ", ""))
  sgn[sig$kind %in% c("bump", "dip", "oscillation")] <- ""
  sprintf("%s%s, tau %s-%s s, strength %.1f sigma",
          sgn, what, format_num(sig$tau_from), format_num(sig$tau_to),
          abs(sig$strength))
}
