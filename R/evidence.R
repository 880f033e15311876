# Raw-series diagnostics: what the rate samples themselves say (spectral
# lines, autocorrelation, quantization grid, trend, lag-1 noise
# identification). avdiagnose() exposes them; the closed loop asks each
# catalogue entry's `evidence()` to judge a fitted effect against them.

# Welch periodogram (Hann, 50% overlap), one-sided PSD in u^2/Hz.
welch_psd <- function(x, freq, seg = NULL) {
  n <- length(x)
  if (is.null(seg)) seg <- 2^floor(log2(max(n / 8, 64)))
  seg <- min(seg, 2^floor(log2(n)))
  x <- detrend_linear(x)
  w <- 0.5 - 0.5 * cos(2 * pi * (seq_len(seg) - 1) / seg)
  U <- sum(w^2)
  starts <- seq(1, n - seg + 1, by = seg / 2)
  half <- seg / 2 + 1
  acc <- numeric(half)
  tap <- function(s) {
    xs <- x[s:(s + seg - 1)]
    (xs - mean(xs)) * w
  }
  # Two real segments a, b per complex transform z = fft(a + i b): the sum
  # of their periodograms is (|z_k|^2 + |z_(seg-k)|^2) / 2, so half the
  # transforms give the same sum (to rounding).
  mirror <- c(1L, seg:(seg - half + 2L))
  np <- length(starts) %/% 2L
  for (i in seq_len(np)) {
    z <- Mod(stats::fft(complex(real = tap(starts[2L * i - 1L]),
                                imaginary = tap(starts[2L * i]))))^2
    acc <- acc + (z[seq_len(half)] + z[mirror]) / 2
  }
  if (length(starts) %% 2L) {
    acc <- acc + Mod(stats::fft(tap(starts[length(starts)]))[seq_len(half)])^2
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
  # Background: running median of log PSD with a window ~20% of frequency
  # (stats::runmed(lp, k, endrule = "median") per octave band). Each band's
  # median runs over the band and 2k bins either side only, and the end
  # rule is applied only at the ends of the whole vector, in O(k) by
  # smooth_ends(): the same values as a runmed() of the whole vector per
  # band, at O(nb) in all instead of O(nb) per band plus smoothEnds()'s
  # O(k^2).
  bands <- unique(c(2^(0:floor(log2(nb))), nb + 1))
  for (b in seq_len(length(bands) - 1L)) {
    lo <- bands[b]
    hi <- bands[b + 1L] - 1L
    k <- max(11L, 2L * floor(0.1 * lo) + 1L)
    k <- min(k, 2L * floor((nb - 1L) / 2L) - 1L)
    from <- max(1L, lo - 2L * k)
    to <- min(nb, hi + 2L * k)
    rm <- stats::runmed(lp[from:to], k, endrule = "keep")
    rm <- smooth_ends(rm, k, left = from == 1L, right = to == nb)
    bg[lo:hi] <- rm[(lo:hi) - from + 1L]
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

# x minus its least-squares line on 1..n (the residuals of
# lm.fit(cbind(1, t), x) in closed form: centred t is orthogonal to 1), in
# two passes over x in C++ (src/evidence.cpp) instead of five vectors of n.
detrend_linear <- function(x) detrend_line(as.double(x))

# stats::smoothEnds(y, k) (Tukey's end-point rule, the runmed() end rule
# "median") at the chosen ends, in O(k log k) instead of O(k^2): the medians
# of the growing windows y[1:j] (j = 3, 5, ..., k - 2) come from one sort
# and a linked list from which the window's elements are removed, longest
# window first, moving the median pointer by a step or two each time.
smooth_ends <- function(y, k, left = TRUE, right = TRUE) {
  k2 <- as.integer(k) %/% 2L
  n <- length(y)
  if (k2 < 1L) return(y)
  sm <- y
  med3 <- function(a, b, c) sort(c(a, b, c))[2L]
  if (k2 >= 2L) {
    J <- 2L * k2 - 1L
    if (left) sm[2:k2] <- growing_medians(y[seq_len(J)])
    if (right) sm[n - (2:k2) + 1L] <- growing_medians(y[n - seq_len(J) + 1L])
  }
  if (left) sm[1L] <- med3(y[1L], sm[2L], sm[2L] - 2L * (sm[3L] - sm[2L]))
  if (right) sm[n] <- med3(y[n], sm[n - 1L], sm[n - 1L] - 2L * (sm[n - 2L] - sm[n - 1L]))
  sm
}

# Medians of e[1:j] for j = 3, 5, ..., length(e) (odd), in that order.
growing_medians <- function(e) {
  J <- length(e)
  o <- order(e)
  rk <- integer(J)
  rk[o] <- seq_len(J)
  nxt <- c(seq_len(J - 1L) + 1L, NA_integer_)
  prv <- c(NA_integer_, seq_len(J - 1L))
  m <- (J + 1L) %/% 2L
  lower <- m - 1L
  out <- numeric((J - 1L) %/% 2L)
  out[length(out)] <- e[o[m]]
  L <- J
  while (L > 3L) {
    for (x in c(rk[L], rk[L - 1L])) {
      if (x < m) {
        lower <- lower - 1L
      } else if (x == m) {
        if (!is.na(nxt[m])) m <- nxt[m] else {
          m <- prv[m]
          lower <- lower - 1L
        }
      }
      p <- prv[x]
      q <- nxt[x]
      if (!is.na(p)) nxt[p] <- q
      if (!is.na(q)) prv[q] <- p
    }
    L <- L - 2L
    target <- (L - 1L) %/% 2L
    while (lower > target) { m <- prv[m]; lower <- lower - 1L }
    while (lower < target) { m <- nxt[m]; lower <- lower + 1L }
    out[(L - 1L) %/% 2L] <- e[o[m]]
  }
  out
}

# Autocorrelation of x (mean removed) at lags 0..max_lag: direct sums
# (C++, src/evidence.cpp) for a few dozen lags, otherwise an FFT zero-padded
# to n + max_lag (enough for lags up to max_lag: the circular products
# never wrap into them).
acf_fft <- function(x, max_lag) {
  n <- length(x)
  x <- x - mean(x)
  if (max_lag <= 64L) {
    a <- acf_sums(x, as.integer(max_lag))
    return(a / a[1L])
  }
  nfft <- stats::nextn(n + max_lag + 1L)
  f <- stats::fft(c(x, numeric(nfft - n)))
  a <- Re(stats::fft(Mod(f)^2, inverse = TRUE))[seq_len(max_lag + 1L)] / nfft
  a / a[1L]
}

block_means <- function(x, m) {
  m <- as.integer(m)
  nb <- length(x) %/% m
  if (m <= 1L) return(x)
  # .colMeans reads the first nb * m values in place (no copy, no matrix)
  .colMeans(x, m, nb)
}

# Exponential ACF (a Gauss-Markov process) near a correlation time `tc` (s):
# block-average so that white noise shrinks and the GM stays, detrend, and
# fit log ACF on lag. Returns tc estimate, the lag-1 ACF and its z-score.
acf_exponential <- function(x, freq, tc) {
  m <- max(1L, floor(tc * freq / 8))
  b <- block_means(x, m)
  nb <- length(b)
  if (nb < 40L) return(list(tc = NA_real_, r1 = NA_real_, z = NA_real_, m = m))
  b <- detrend_linear(b)
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

# Quantization grid: the step between adjacent distinct values and the
# fraction of samples lying on that grid.
quantization_grid <- function(x) {
  n <- length(x)
  # sort(unique(x)) without the hash table: the distinct values of the
  # sorted series
  xs <- sort(x)
  u <- xs[c(TRUE, xs[-1L] != xs[-n])]
  rm(xs)
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
  b <- detrend_linear(b)
  d <- 0L
  repeat {
    bc <- b - mean(b)
    a <- acf_sums(bc, 1L)
    r1 <- a[2L] / a[1L]
    delta <- r1 / (1 + r1)
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
  check_diagnosable(x, "x")
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

# Evidence from the raw series for one fitted effect (`par`: its parameters
# by name): a short string and whether the data support it (TRUE),
# contradict it (FALSE) or cannot tell (NA). The entry's evidence() decides.
raw_evidence <- function(effect, par, raw, x, freq) {
  if (is.null(raw)) return(list(text = "", support = NA))
  e <- effect_entry(split_term(effect)$kind, split_term(effect)$variant)
  if (is.null(e$evidence)) {
    return(list(text = "no raw-data check for this effect", support = NA))
  }
  e$evidence(par, raw, x, freq)
}
