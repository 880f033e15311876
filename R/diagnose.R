# Diagnostics for the closed loop (issue 4): structure in the standardized
# residuals of a fit, the effects whose signatures match it, and evidence
# read from the raw series itself. avrefine() uses all three; avdiagnose()
# exposes the raw-series part to users.

# ---------------------------------------------------------------------------
# Signature constants (noise-models.md section 5, checked there)
gm_peak_ratio <- 1.893        # GM ADEV peak at tau = 1.893 Tc
gm_peak_adev <- 0.6174        # ... where ADEV = 0.6174 sigma
sin_peak_ratio <- 0.3710      # sinusoid first ADEV peak at tau = 0.371 / f0
sin_peak_adev <- 0.7246       # ... where ADEV = 0.7246 A
flicker_plateau <- 2 * log(2) / pi

# ---------------------------------------------------------------------------
# (a) Residual signatures

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
    slope <- if (length(idx) >= 3L) {
      unname(stats::coef(stats::lm(z[idx] ~ log10(tau[idx])))[2L])
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

format_num <- function(x, digits = 3) {
  vapply(x, function(v) if (is.na(v)) "NA" else format(signif(v, digits)),
         character(1))
}

# ---------------------------------------------------------------------------
# (b) Tracing: from the excess of the measured AV over the fitted one to the
# candidate effects with initial parameters.

# Local log-log slope of the excess ADEV over a tau range (NA when the excess
# is not positive at >= 2 points).
excess_slope <- function(tau, excess) {
  ok <- is.finite(excess) & excess > 0
  if (sum(ok) < 2L) return(NA_real_)
  unname(stats::coef(stats::lm(log(sqrt(excess[ok])) ~ log(tau[ok])))[2L])
}

# `tau`, `avar`, `fitted`: the curve and the current model; `sig` from
# residual_signatures(); `present`: terms already in the model; `raw`: an
# avdiagnose object or NULL. Returns a data.frame of candidates: effect,
# tau_from, tau_to, init (list column of named start values), signature
# (character), score (how well the signature matches, larger is better).
trace_candidates <- function(tau, avar, fitted, sig, present,
                             candidates = c("Q", "N", "B", "K", "R", "gm", "sinusoid"),
                             raw = NULL) {
  excess <- avar - fitted
  out <- list()
  add <- function(effect, from, to, init, signature, score, from_raw = FALSE) {
    if (!effect %in% candidates) return(invisible())
    if (effect %in% c("Q", "N", "B", "K", "R") && effect %in% present) return(invisible())
    out[[length(out) + 1L]] <<- list(effect = effect, tau_from = from, tau_to = to,
                                     init = init, signature = signature,
                                     score = score, from_raw = from_raw)
  }
  for (i in seq_len(nrow(sig))) {
    s <- sig[i, ]
    inr <- tau >= s$tau_from & tau <= s$tau_to
    ex <- excess[inr]
    tr <- tau[inr]
    sl <- excess_slope(tr, ex)
    slope_txt <- if (is.na(sl)) "" else sprintf("; excess ADEV slope %+.2f", sl)
    label <- paste0(s$description, slope_txt)
    emax <- if (any(ex > 0)) max(ex) else NA_real_
    tpk <- if (any(ex > 0)) tr[which.max(ex)] else s$tau_peak
    if (s$sign > 0 && s$kind %in% c("short_end", "global")) {
      e1 <- max(ex[1L], 0)
      add("Q", s$tau_from, s$tau_to, list(Q = sqrt(e1 * tr[1L]^2 / 3)),
          label, score_slope(sl, -1))
      add("N", s$tau_from, s$tau_to, list(N = sqrt(e1 * tr[1L])), label,
          score_slope(sl, -0.5))
    }
    if (s$sign > 0 && s$kind %in% c("long_end", "global")) {
      el <- max(ex[length(ex)], 0)
      tl <- tr[length(tr)]
      add("R", s$tau_from, s$tau_to, list(R = sqrt(2 * el) / tl), label,
          score_slope(sl, 1))
      add("K", s$tau_from, s$tau_to, list(K = sqrt(3 * el / tl)), label,
          score_slope(sl, 0.5))
    }
    if (s$sign > 0 && s$kind %in% c("bump", "long_end", "short_end", "oscillation") &&
        is.finite(emax)) {
      add("gm", s$tau_from, s$tau_to,
          list(tc = tpk / gm_peak_ratio, sigma = sqrt(emax) / gm_peak_adev),
          label, if (s$kind == "bump") 2 else 1)
      add("B", s$tau_from, s$tau_to, list(B = sqrt(emax / flicker_plateau)),
          label, if (s$kind == "bump" && isTRUE(s$tau_to / s$tau_from > 30)) 2 else 1)
      add("sinusoid", s$tau_from, s$tau_to,
          list(f0 = sin_peak_ratio / tpk, amp = sqrt(emax) / sin_peak_adev),
          label, if (s$kind == "oscillation") 3 else 1)
    }
  }
  # Raw-series evidence proposes candidates by itself too.
  if (!is.null(raw)) {
    lines <- raw$lines
    if (!is.null(lines) && nrow(lines)) {
      for (j in seq_len(min(nrow(lines), 3L))) {
        f0 <- lines$f0[j]
        t1 <- sin_peak_ratio / f0
        if (t1 < min(tau) / 2 || t1 > max(tau)) next
        add("sinusoid", t1 / 2, 2 / f0, list(f0 = f0, amp = lines$amp[j]),
            paste0(overlapping_signature(sig, t1 / 2, 2 / f0),
                   sprintf("; proposed by a periodogram line at %s Hz", format_num(f0))), 2)
      }
    }
    if (isTRUE(raw$trend$significant)) {
      add("R", max(tau) / 10, max(tau), list(R = abs(raw$trend$slope)),
          paste0(overlapping_signature(sig, max(tau) / 10, max(tau)),
                 sprintf("; proposed by a linear trend of %s /s",
                         format_num(raw$trend$slope))), 1)
    }
  }
  if (!length(out)) {
    return(data.frame(effect = character(), tau_from = numeric(),
                      tau_to = numeric(), signature = character(),
                      score = numeric(), from_raw = logical(),
                      stringsAsFactors = FALSE))
  }
  df <- data.frame(effect = vapply(out, `[[`, "", "effect"),
                   tau_from = vapply(out, `[[`, 0, "tau_from"),
                   tau_to = vapply(out, `[[`, 0, "tau_to"),
                   signature = vapply(out, `[[`, "", "signature"),
                   score = vapply(out, `[[`, 0, "score"),
                   from_raw = vapply(out, `[[`, FALSE, "from_raw"),
                   stringsAsFactors = FALSE)
  df$init <- lapply(out, `[[`, "init")
  df[order(-df$score), , drop = FALSE]
}

# The strongest residual signature overlapping [from, to], as text.
overlapping_signature <- function(sig, from, to) {
  hit <- sig[sig$tau_to >= from & sig$tau_from <= to & sig$kind != "slope", , drop = FALSE]
  if (!nrow(hit)) return("no residual structure in that tau range")
  hit$description[which.max(abs(hit$strength))]
}

score_slope <- function(slope, target) {
  if (is.na(slope)) return(0.5)
  2 - min(abs(slope - target) / 0.25, 2)
}

# ---------------------------------------------------------------------------
# (c) Raw-series evidence

# Welch periodogram (Hann, 50% overlap), one-sided PSD in u^2/Hz.
welch_psd <- function(x, freq, seg = NULL) {
  n <- length(x)
  if (is.null(seg)) seg <- 2^floor(log2(max(n / 8, 64)))
  seg <- min(seg, 2^floor(log2(n)))
  t <- seq_len(n)
  x <- stats::residuals(stats::lm.fit(cbind(1, t), x))
  w <- 0.5 - 0.5 * cos(2 * pi * (seq_len(seg) - 1) / seg)
  U <- sum(w^2)
  starts <- seq(1, n - seg + 1, by = seg / 2)
  half <- seg / 2 + 1
  acc <- numeric(half)
  for (s in starts) {
    xs <- x[s:(s + seg - 1)]
    xs <- (xs - mean(xs)) * w
    acc <- acc + Mod(stats::fft(xs)[seq_len(half)])^2
  }
  p <- acc / length(starts) / (freq * U)
  p[2:(half - 1)] <- 2 * p[2:(half - 1)]
  # Welch EDF for Hann with 50% overlap (Percival & Walden): about 1.89 K for many segments.
  k <- length(starts)
  nu <- 2 * k / (1 + 2 * 0.167^2 * (k - 1) / k)
  list(f = (seq_len(half) - 1) * freq / seg, psd = p, nu = nu, seg = seg,
       df = freq / seg)
}

# Spectral lines: bins standing above a running-median background by more
# than chance allows (chi-square with the Welch EDF, Bonferroni over bins).
spectral_lines <- function(x, freq, alpha = 1e-3, seg = NULL, max_lines = 5L) {
  w <- welch_psd(x, freq, seg)
  p <- w$psd
  nb <- length(p)
  lp <- log(p)
  bg <- rep(NA_real_, nb)
  # Background: running median of log PSD with a window ~20% of frequency.
  bands <- unique(c(2^(0:floor(log2(nb))), nb + 1))
  for (b in seq_len(length(bands) - 1L)) {
    lo <- bands[b]
    hi <- bands[b + 1L] - 1L
    k <- max(11L, 2L * floor(0.1 * lo) + 1L)
    k <- min(k, 2L * floor((nb - 1L) / 2L) - 1L)
    idx <- lo:hi
    rm <- stats::runmed(lp, k, endrule = "median")
    bg[idx] <- rm[idx]
  }
  nu <- w$nu
  # Median of log(chi2_nu/nu) differs from log of the mean.
  bg <- exp(bg - log(stats::qchisq(0.5, nu) / nu))
  ratio <- p / bg
  pval <- stats::pchisq(ratio * nu, nu, lower.tail = FALSE)
  padj <- pmin(1, pval * (nb - 2))
  cand <- which(padj < alpha)
  # The lowest bins carry the red-noise roll-off, not resolvable lines.
  cand <- cand[cand > 4 & cand < nb - 1]
  lines <- data.frame(f0 = numeric(), amp = numeric(), ratio = numeric(),
                      p_value = numeric(), significance = numeric())
  if (length(cand)) {
    groups <- split(cand, cumsum(c(1, diff(cand) > 3)))
    rows <- lapply(groups, function(g) {
      i <- g[which.max(p[g])]
      # Parabolic interpolation of the log peak for a sub-bin f0.
      a <- lp[i - 1L]; b <- lp[i]; c <- lp[i + 1L]
      d <- 0.5 * (a - c) / (a - 2 * b + c)
      if (!is.finite(d) || abs(d) > 0.5) d <- 0
      f0 <- (i - 1 + d) * w$df
      j <- max(2L, i - 3L):min(nb, i + 3L)
      power <- sum(pmax(p[j] - bg[j], 0)) * w$df
      data.frame(f0 = f0, amp = sqrt(2 * power), ratio = ratio[i],
                 p_value = padj[i], significance = -log10(max(padj[i], 1e-300)))
    })
    lines <- do.call(rbind, rows)
    lines <- lines[order(-lines$ratio), , drop = FALSE]
    lines <- utils::head(lines, max_lines)
  }
  rownames(lines) <- NULL
  attr(lines, "resolution") <- w$df
  lines
}

# Autocorrelation of x (mean removed) at lags 0..max_lag via FFT.
acf_fft <- function(x, max_lag) {
  n <- length(x)
  x <- x - mean(x)
  nfft <- 2^ceiling(log2(2 * n))
  f <- stats::fft(c(x, numeric(nfft - n)))
  a <- Re(stats::fft(Mod(f)^2, inverse = TRUE))[seq_len(max_lag + 1L)] / nfft
  a / a[1L]
}

block_means <- function(x, m) {
  m <- as.integer(m)
  nb <- length(x) %/% m
  if (m <= 1L) return(x)
  colMeans(matrix(x[seq_len(nb * m)], nrow = m))
}

# Exponential ACF (a Gauss-Markov process) near a correlation time `tc` (s):
# block-average so that white noise shrinks and the GM stays, detrend, and
# fit log ACF on lag. Returns tc estimate, the lag-1 ACF and its z-score.
acf_exponential <- function(x, freq, tc) {
  m <- max(1L, floor(tc * freq / 8))
  b <- block_means(x, m)
  nb <- length(b)
  if (nb < 40L) return(list(tc = NA_real_, r1 = NA_real_, z = NA_real_, m = m))
  t <- seq_len(nb)
  b <- stats::residuals(stats::lm.fit(cbind(1, t), b))
  max_lag <- min(nb - 2L, 48L)
  r <- acf_fft(b, max_lag)[-1L]
  lag <- seq_len(max_lag)
  # ACF = a exp(-lag m tau0 / Tc) + (c + d lag): the linear part absorbs the
  # slowly falling ACF of flicker and random walk over a few Tc. Tc is
  # profiled on a grid within a factor 5 of the hint; a minimum on the
  # grid's edge means Tc is not identified.
  grid <- tc * 10^seq(-0.7, 0.7, by = 0.02)
  rss <- vapply(grid, function(g) {
    X <- cbind(exp(-lag * m / (freq * g)), 1, lag)
    sum(stats::lm.fit(X, r)$residuals^2)
  }, 0)
  k <- which.min(rss)
  X <- cbind(exp(-lag * m / (freq * grid[k])), 1, lag)
  a <- unname(stats::lm.fit(X, r)$coefficients[1L])
  est <- if (k > 1L && k < length(grid) && is.finite(a) && a > 0) grid[k] else NA_real_
  list(tc = est, r1 = r[1L], amp = a, z = a * sqrt(nb), m = m)
}

`%||%` <- function(a, b) if (is.null(a) || length(a) == 0L || is.na(a[1L])) b else a

# Quantization grid: the step between adjacent distinct values and the
# fraction of samples lying on that grid.
quantization_grid <- function(x) {
  n <- length(x)
  u <- sort(unique(x))
  if (length(u) < 2L) {
    return(list(step = NA_real_, levels = length(u), on_grid = 1,
                quantized = FALSE, sd_lsb = NA_real_))
  }
  d <- diff(u)
  step <- stats::median(d[d > 0])
  # The smallest gap that is a common divisor: take the small-gap mode.
  small <- d[d < 1.5 * step]
  if (length(small)) step <- stats::median(small)
  off <- (x - u[1L]) / step
  on <- mean(abs(off - round(off)) < 1e-3)
  quantized <- length(u) < n / 10 && on > 0.99
  list(step = step, levels = length(u), on_grid = on, quantized = quantized,
       sd_lsb = stats::sd(x) / step)
}

# Linear trend of block means (100 blocks) against time: slope (u/s) and its
# t value. Block means tame white noise; red noise still inflates t.
linear_trend <- function(x, freq, blocks = 100L) {
  m <- max(1L, length(x) %/% blocks)
  b <- block_means(x, m)
  t <- (seq_along(b) - 0.5) * m / freq
  fit <- summary(stats::lm(b ~ t))$coefficients
  slope <- fit[2L, 1L]
  tval <- fit[2L, 3L]
  list(slope = slope, t = tval, significant = is.finite(tval) && abs(tval) > 5)
}

# Lag-1 autocorrelation noise identification (Riley 2004) on rate data
# averaged by m: alpha = -2(delta + d).
lag1_noise_id <- function(x, m = 1L) {
  b <- block_means(x, m)
  if (length(b) < 30L) return(NA_real_)
  t <- seq_along(b)
  b <- stats::residuals(stats::lm.fit(cbind(1, t), b))
  d <- 0L
  repeat {
    bc <- b - mean(b)
    r1 <- sum(bc[-1L] * bc[-length(bc)]) / sum(bc^2)
    delta <- r1 / (1 + r1)
    if (delta < 0.25 || d >= 2L) break
    b <- diff(b)
    d <- d + 1L
  }
  -2 * (delta + d)
}

noise_name <- function(alpha) {
  a <- round(alpha)
  out <- rep("?", length(a))
  out[a >= 2] <- "white PM (Q)"
  out[a == 1] <- "flicker PM"
  out[a == 0] <- "white FM (N)"
  out[a == -1] <- "flicker FM (B)"
  out[a <= -2] <- "random walk FM (K)"
  out[is.na(a)] <- NA_character_
  out
}

#' Raw-data diagnostics for noise identification
#'
#' Reads, from a rate series itself, the evidence that backs (or does not
#' back) an effect suggested by the Allan variance: spectral lines in a Welch
#' periodogram (sinusoids), the lag-1 autocorrelation (quantization gives
#' about \eqn{-1/2}) and the lag-1 noise identification of Riley (2004) at
#' several averaging factors, the quantization grid (least significant bit),
#' and a linear trend (rate ramp). [avrefine()] uses the same diagnostics to
#' confirm an effect traced from the residuals of a fit.
#'
#' Line significance: the Welch estimate at each bin is compared with a
#' running-median background; under the null it is distributed as
#' \eqn{\chi^2_\nu/\nu} times the background (\eqn{\nu} the Welch EDF), and
#' the p-value is Bonferroni-corrected over all bins. The line amplitude is
#' read from the power above the background around the peak.
#' The trend t value uses 100 block means and ignores red noise, so it
#' overstates significance when rate random walk or flicker is present.
#'
#' @param x Numeric vector or `ts` of rate samples.
#' @param freq Sampling frequency in Hz. Defaults to `frequency(x)` for a
#'   `ts`.
#' @param alpha Family-wise false-alarm level for spectral lines.
#' @return An object of class `avdiagnose`: a list with `freq`, `n`,
#'   `lines` (data.frame `f0` (Hz), `amp` (input unit), `ratio` (peak over
#'   background), `p_value`, `significance` (\eqn{-\log_{10} p})),
#'   `acf1` (lag-1 autocorrelation of the raw samples) and `acf1_z` (its
#'   z-score), `noise_id` (data.frame `m`, `tau`, `alpha`, `noise`),
#'   `grid` (list `step`, `levels`, `on_grid` fraction, `quantized`,
#'   `sd_lsb` = standard deviation in steps) and `trend` (list `slope`
#'   (unit/s), `t`, `significant`).
#' @seealso [avrefine()]
#' @export
#' @examples
#' set.seed(1)
#' t <- seq_len(20000) / 100
#' x <- round((rnorm(20000) + 0.3 * sin(2 * pi * 2 * t)) / 0.05) * 0.05
#' avdiagnose(x, 100)
avdiagnose <- function(x, freq = NULL, alpha = 1e-3) {
  if (missing(x)) check_present(TRUE, "x", "a numeric vector of rate samples")
  if (is.null(freq) && stats::is.ts(x)) freq <- stats::frequency(x)
  freq <- check_freq(freq)
  x <- check_values(x, min_n = 256L, arg = "x")
  alpha <- check_number(alpha, "alpha", 0, 1, open = TRUE)
  n <- length(x)
  xc <- x - mean(x)
  r1 <- sum(xc[-1L] * xc[-n]) / sum(xc^2)
  ms <- 10^(0:floor(log10(n / 30)))
  alphas <- vapply(ms, function(m) lag1_noise_id(x, m), 0)
  structure(list(
    freq = freq, n = n,
    lines = spectral_lines(x, freq, alpha = alpha),
    acf1 = r1, acf1_z = r1 * sqrt(n),
    noise_id = data.frame(m = ms, tau = ms / freq, alpha = alphas,
                          noise = noise_name(alphas)),
    grid = quantization_grid(x),
    trend = linear_trend(x, freq)
  ), class = "avdiagnose")
}

#' @export
print.avdiagnose <- function(x, ...) {
  cat(sprintf("Raw-data diagnostics: %d samples at %s Hz (%s s)\n", x$n,
              format(x$freq), format(signif(x$n / x$freq, 4))))
  g <- x$grid
  if (isTRUE(g$quantized)) {
    cat(sprintf("Quantized: step %s on %d levels (%.1f%% of samples on the grid), sd = %.2f steps\n",
                format(signif(g$step, 4)), g$levels, 100 * g$on_grid, g$sd_lsb))
  } else {
    cat("No quantization grid found.\n")
  }
  cat(sprintf("Lag-1 ACF of raw samples: %.3f (z = %.1f; -0.5 means quantization-dominated)\n",
              x$acf1, x$acf1_z))
  cat(sprintf("Linear trend: %s /s (t = %.1f%s)\n", format(signif(x$trend$slope, 3)),
              x$trend$t, if (x$trend$significant) ", significant" else ""))
  if (nrow(x$lines)) {
    cat("Spectral lines:\n")
    l <- x$lines
    print(data.frame(f0 = signif(l$f0, 4), amp = signif(l$amp, 3),
                     ratio = signif(l$ratio, 3), p_value = signif(l$p_value, 2)),
          row.names = FALSE)
  } else {
    cat("No significant spectral lines.\n")
  }
  cat("Lag-1 noise identification:\n")
  ni <- x$noise_id
  print(data.frame(tau = signif(ni$tau, 3), alpha = round(ni$alpha, 2),
                   noise = ni$noise), row.names = FALSE)
  invisible(x)
}

# Evidence from the raw series for one candidate effect: a short string and
# whether the data support it (TRUE), contradict it (FALSE) or cannot tell (NA).
raw_evidence <- function(effect, init, raw, x, freq) {
  if (is.null(raw)) return(list(text = "", support = NA))
  switch(effect,
    sinusoid = {
      l <- raw$lines
      f0 <- init$f0 %||% NA_real_
      res <- attr(l, "resolution") %||% 0
      if (nrow(l) && is.finite(f0)) {
        near <- which(abs(l$f0 - f0) <= max(0.25 * f0, 2 * res))
        j <- near[which.max(l$ratio[near])]
        if (length(near)) {
          return(list(text = sprintf("periodogram line at %s Hz (amp %s, p = %.1g)",
                                     format_num(l$f0[j], 4), format_num(l$amp[j]),
                                     l$p_value[j]),
                      support = TRUE, f0 = l$f0[j]))
        }
      }
      if (is.finite(f0) && f0 < 4 * res) {
        return(list(text = sprintf("f0 = %s Hz is below the periodogram resolution",
                                   format_num(f0)), support = NA))
      }
      list(text = sprintf("no periodogram line near %s Hz", format_num(f0)),
           support = FALSE)
    },
    gm = {
      tc <- init$tc %||% NA_real_
      sigma <- init$sigma %||% NA_real_
      if (is.finite(tc) && tc * freq < 4) {
        # Tc of a few samples or less: the GM is the sample-to-sample
        # correlation itself; compare its lag-1 ACF with the raw one.
        phi <- exp(-1 / (tc * freq))
        pred <- if (is.finite(sigma)) sigma^2 * phi / stats::var(x) else NA_real_
        ok <- is.finite(pred) && raw$acf1_z > 3 && raw$acf1 > pred / 3 &&
          raw$acf1 < 3 * pred
        return(list(text = sprintf(
          "raw lag-1 ACF %.3f (z = %.0f) against %.3f predicted by the fitted GM",
          raw$acf1, raw$acf1_z, pred), support = ok))
      }
      if (!is.finite(tc) || tc * freq * 40 / 8 > length(x)) {
        return(list(text = "record too short for an ACF check", support = NA))
      }
      a <- acf_exponential(x, freq, tc)
      if (is.finite(a$tc) && a$z > 5) {
        list(text = sprintf("exponential ACF of %s-sample means, Tc = %s s (z = %.1f)",
                            a$m, format_num(a$tc), a$z),
             support = a$tc > tc / 2 && a$tc < tc * 2)
      } else {
        list(text = sprintf("no exponential ACF near Tc = %s s (z = %.1f)",
                            format_num(tc), a$z), support = FALSE)
      }
    },
    Q = {
      g <- raw$grid
      txt <- sprintf("raw lag-1 ACF %.3f (z = %.0f)", raw$acf1, raw$acf1_z)
      if (isTRUE(g$quantized)) {
        txt <- paste0(txt, sprintf("; LSB grid step %s (%.0f%% on grid)",
                                   format_num(g$step), 100 * g$on_grid))
      }
      list(text = txt, support = raw$acf1_z < -3)
    },
    R = {
      tr <- raw$trend
      list(text = sprintf("linear trend %s /s (t = %.1f)", format_num(tr$slope), tr$t),
           support = tr$significant)
    },
    {
      ni <- raw$noise_id
      ni <- ni[is.finite(ni$alpha), , drop = FALSE]
      want <- c(N = 0, B = -1, K = -2)[effect]
      hit <- ni[round(ni$alpha) == want, , drop = FALSE]
      if (nrow(hit)) {
        list(text = sprintf("lag-1 noise id %s at tau %s s", noise_name(want),
                            paste(format_num(hit$tau), collapse = ", ")),
             support = TRUE)
      } else {
        list(text = sprintf("lag-1 noise id never %s", noise_name(want)), support = NA)
      }
    }
  )
}
