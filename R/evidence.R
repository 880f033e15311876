# Raw-series diagnostics: what the rate samples themselves say (spectral
# lines from R/spectrum.R, lag-1 autocorrelation, quantization grid, trend,
# lag-1 noise identification). avdiagnose() exposes them; the closed loop
# asks each catalogue entry's `evidence()` to judge a fitted effect against
# them (raw_evidence()).

# Quantization grid: the step between adjacent distinct values and the
# fraction of samples lying on that grid. The sort (a radix sort), the
# distinct values, gaps, medians and the on-grid count are done in C++
# (src/evidence.cpp, grid_stats()) with R's rounding; the R form was
#   u <- unique(sort(x)); d <- diff(u); step <- median(d[d > 0])
#   small <- d[d < 1.5 * step]; if (length(small)) step <- median(small)
#   off <- (x - u[1]) / step; on <- mean(abs(off - round(off)) < 1e-3)
quantization_grid <- function(x) {
  n <- length(x)
  g <- grid_stats(as.double(x))
  levels <- as.integer(g[1L])
  if (levels < 2L) {
    return(list(step = NA_real_, levels = levels, on_grid = 1,
                quantized = FALSE, sd_lsb = NA_real_))
  }
  step <- g[2L]
  on <- g[3L]
  quantized <- levels < n / 10 && on > 0.99
  list(step = step, levels = levels, on_grid = on, quantized = quantized,
       sd_lsb = stats::sd(x) / step)
}

# Linear trend of block means (100 blocks) against time: slope (u/s) and its
# t value. Block means tame white noise; red noise still inflates t (a
# random walk's own drift over a record reads t of 10-30), so the line is
# also judged by a likelihood ratio in which the block means with and
# without it each fit their own noise model (white, random walk, AR(1)s:
# warmup_ml()): `z` = sqrt(2 log LR). `beside`: a function(m) giving
# columns of block means (of m samples) of other shapes the series carries
# (series_shapes()), fitted with the line so that the trend is the one
# beyond them.
linear_trend <- function(x, freq, blocks = 100L, beside = NULL) {
  m <- max(1L, length(x) %/% blocks)
  b <- block_means(x, m)
  t <- (seq_along(b) - 0.5) * m / freq
  other <- if (!is.null(beside)) beside(m)
  model <- if (is.null(other)) b ~ t else b ~ t + other
  fit <- summary(stats::lm(model))$coefficients
  slope <- fit[2L, 1L]
  tval <- fit[2L, 3L]
  list(slope = slope, t = tval, significant = is.finite(tval) && abs(tval) > 5,
       z = trend_lr_z(b, t, other, m / freq))
}

# z = sqrt(2 log LR) of a line in block means `b` (times `t`, block length
# `dt`) beside the columns `other`, each model fitting its own noise by
# maximum likelihood, each started from the other's optimum.
trend_lr_z <- function(b, t, other, dt) {
  s <- stats::sd(b)
  if (length(b) < 16L || !is.finite(s) || s == 0) return(NA_real_)
  y <- (b - mean(b)) / s
  line <- matrix(t - mean(t), ncol = 1L) / max(abs(t))
  start <- list(warmup_noise(y, dt))
  f0 <- warmup_ml(y, other, start)
  f1 <- warmup_ml(y, cbind(other, line), c(start, list(f0$model)))
  f0b <- warmup_ml(y, other, list(f1$model))
  ll0 <- max(f0$ll, f0b$ll)
  sqrt(max(0, 2 * (f1$ll - ll0)))
}

# Lag-1 autocorrelation noise identification (Riley 2004) on rate data
# averaged by m: alpha = -2(delta + d).
lag1_noise_id <- function(x, m = 1L) {
  b <- block_means(x, m)
  if (length(b) < 30L) return(NA_real_)
  b <- detrend_linear(b)
  d <- 0L
  repeat {
    bc <- b - mean(b)
    a <- acf_sums(bc, 1L)
    r1 <- a[2L] / a[1L]
    delta <- r1 / (1 + r1)
    # a series with no variance left (constant after differencing) has no
    # noise type
    if (!is.finite(delta)) return(NA_real_)
    if (delta < 0.25 || d >= 2L) break
    b <- diff(b)
    d <- d + 1L
  }
  -2 * (delta + d)
}

# Name of a power-law noise type, with the catalogue term it corresponds to
# (the entry whose rate PSD has that exponent): "white FM (N)".
noise_name <- function(alpha) {
  a <- round(alpha)
  words <- c("2" = "white PM", "1" = "flicker PM", "0" = "white FM",
             "-1" = "flicker FM", "-2" = "random walk FM")
  a <- pmin(pmax(a, -2), 2)
  out <- unname(words[as.character(a)])
  kinds <- catalogue()
  for (k in unique(stats::na.omit(a))) {
    hit <- Filter(function(e) isTRUE(e$psd_alpha == k), kinds)
    if (length(hit)) {
      i <- which(a == k)
      out[i] <- paste0(out[i], " (", hit[[1L]]$name, ")")
    }
  }
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
#'   background), `p_value`, `significance` (\eqn{-\log_{10} p}),
#'   `concentration` (share of the excess power within 64 bins that sits in
#'   the peak's main lobe) and `kind` (`"line"`, or `"band"` for the top of
#'   a broad band)),
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
  check_diagnosable(x, "x")
  diagnose_record(x, freq, alpha)
}

# avdiagnose() of a checked series. `beside`: linear_trend()'s, the shapes
# of the series effects the trend is read beyond (the loop's; NULL for
# none).
diagnose_record <- function(x, freq, alpha = 1e-3, beside = NULL) {
  n <- length(x)
  a1 <- acf_sums(x - mean(x), 1L)
  r1 <- a1[2L] / a1[1L]
  ms <- 10^(0:floor(log10(n / 30)))
  alphas <- vapply(ms, function(m) lag1_noise_id(x, m), 0)
  structure(list(
    freq = freq, n = n,
    lines = spectral_lines(x, freq, alpha = alpha),
    acf1 = r1, acf1_z = r1 * sqrt(n),
    noise_id = data.frame(m = ms, tau = ms / freq, alpha = alphas,
                          noise = noise_name(alphas)),
    grid = quantization_grid(x),
    trend = linear_trend(x, freq, beside = beside)
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

# Evidence from the raw series for one fitted effect (`par`: its parameters
# by name): a short string and whether the data support it (TRUE),
# contradict it (FALSE) or cannot tell (NA). The entry's evidence() decides;
# given the model `fit` that holds the instance (`label`), an entry's
# model_evidence() reads the raw data beside the model's other terms too.
raw_evidence <- function(effect, par, raw, x, freq, fit = NULL, label = NULL) {
  if (is.null(raw)) return(list(text = "", support = NA))
  e <- effect_entry(split_term(effect)$kind, split_term(effect)$variant)
  if (is.null(e$evidence)) {
    return(list(text = "no raw-data check for this effect", support = NA))
  }
  ev <- e$evidence(par, raw, x, freq)
  if (is.function(e$model_evidence) && !is.null(fit) && !is.null(label)) {
    ev <- e$model_evidence(ev, fit, label, raw, freq)
  }
  ev
}

# What the raw series measures of a fitted instance the curve sizes far
# off it: NULL, or list(values, note) from the entry's raw_hold().
raw_hold_values <- function(effect, par, raw) {
  if (is.null(raw)) return(NULL)
  sp <- split_term(effect)
  e <- effect_entry(sp$kind, sp$variant)
  if (!is.function(e$raw_hold)) return(NULL)
  e$raw_hold(par, raw)
}
