# Autocorrelation of a raw rate series, in one place: the sample ACF at a
# few lags or many, block means, the least-squares line taken out, and the
# exponential ACF of a Gauss-Markov process read from block means.

# Sample autocorrelation of x (mean removed) at lags 0..max_lag: direct
# sums (C++, src/evidence.cpp) for a few dozen lags, which beat two FFTs of
# n, otherwise an FFT zero-padded to n + max_lag (enough for lags up to
# max_lag: the circular products never wrap into them). O(n log n).
acf_lags <- function(x, max_lag) {
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

# Steps of the autocovariance at short lags, c(h) - c(h + 1) for h in
# `lags`: a slow process (random walk, flicker, a long GM, a ramp) is flat
# over a few lags and cancels; what is left is the short-memory part of
# the series (the sensor's filter, a resonance, lines). Standard errors
# from the spread over `blocks` consecutive blocks. Returns list(d, se).
acov_steps <- function(x, lags = 1:3, blocks = 50L) {
  K <- max(lags) + 1L
  one <- function(y) {
    a <- acf_sums(y - mean(y), K) / length(y)
    a[lags + 1L] - a[lags + 2L]
  }
  m <- length(x) %/% blocks
  per <- vapply(seq_len(blocks), function(b) one(x[(b - 1L) * m + seq_len(m)]),
                numeric(length(lags)))
  per <- matrix(per, nrow = length(lags))
  list(d = one(x), se = apply(per, 1L, stats::sd) / sqrt(blocks))
}

# Means of consecutive blocks of m samples (the last partial block dropped).
block_means <- function(x, m) {
  m <- as.integer(m)
  nb <- length(x) %/% m
  if (m <= 1L) return(x)
  # .colMeans reads the first nb * m values in place (no copy, no matrix)
  .colMeans(x, m, nb)
}

# x minus its least-squares line on 1..n (the residuals of
# lm.fit(cbind(1, t), x) in closed form: centred t is orthogonal to 1), in
# two passes over x in C++ (src/evidence.cpp) instead of five vectors of n.
detrend_linear <- function(x) detrend_line(as.double(x))

# Exponential ACF (a Gauss-Markov process) near a correlation time `tc` (s):
# block-average so that white noise shrinks and the GM stays, detrend, and
# fit log ACF on lag. Returns tc estimate, the lag-1 ACF and its z-score,
# and `shape`: the share of the ACF's variation about a line that the
# exponential explains (near 1 for a GM; a resonance's oscillating residue
# left by its removal reads as an exponential of a few samples at 0.3).
# `cache`: NULL or an environment (avrefine()'s, one per call and series)
# in which the ACF of the block means is kept by block size m, so that the
# checks of many candidate Tc that share m read the series once.
# `beside`: time constants (s) of other exponentials read with it, their
# amplitudes free (a model's other GMs: beside a faster one the block means'
# ACF falls steeply over the first lags, and one exponential alone reads
# between the two). `lines`: the series' periodogram lines (list(f0, amp)),
# read with it as cosines of free amplitude (a line the record's
# sinusoid does not take out whole, its frequency wandering, swings the
# block means' ACF: an accelerometer's 0.56 Hz line left a 6 s GM's
# exponential 16% of the ACF's shape).
acf_exponential <- function(x, freq, tc, cache = NULL, beside = numeric(),
                            lines = list(f0 = numeric(), amp = numeric())) {
  # the loop judges the same Tc again (a candidate screened, refitted,
  # judged at the next step): the whole result kept by its arguments
  if (is.null(cache)) return(acf_exponential_now(x, freq, tc, NULL, beside, lines))
  key <- paste0("acf_exponential:", sprintf("%a", freq), ":", sprintf("%a", tc),
                paste0(":", sprintf("%a", beside), collapse = ""),
                paste0("~", sprintf("%a", c(lines$f0, lines$amp)), collapse = ""))
  hit <- cache[[key]]
  if (is.null(hit)) {
    hit <- acf_exponential_now(x, freq, tc, cache, beside, lines)
    cache[[key]] <- hit
  }
  hit
}
# The block size (samples) the ACF of a GM of `tc` is read at, and the
# most lags read: the exponential spans a few lags of 8 blocks per Tc.
acf_block_size <- function(tc, freq) max(1L, floor(tc * freq / 8))
acf_max_lag <- 48L
acf_exponential_now <- function(x, freq, tc, cache, beside = numeric(),
                                lines = list(f0 = numeric(), amp = numeric())) {
  m <- acf_block_size(tc, freq)
  key <- paste0("acf_exponential.", m)
  hit <- if (!is.null(cache)) cache[[key]]
  if (is.null(hit)) {
    b <- block_means(x, m)
    nb <- length(b)
    r <- NULL
    v <- NA_real_
    if (nb >= 40L) {
      b <- detrend_linear(b)
      r <- acf_lags(b, min(nb - 2L, acf_max_lag))[-1L]
      v <- mean(b^2)
    }
    hit <- list(nb = nb, r = r, v = v)
    if (!is.null(cache)) cache[[key]] <- hit
  }
  nb <- hit$nb
  if (nb < 40L) return(list(tc = NA_real_, r1 = NA_real_, z = NA_real_, m = m))
  r <- hit$r
  max_lag <- length(r)
  lag <- seq_len(max_lag)
  # ACF = a exp(-lag m tau0 / Tc) + (c + d lag): the linear part absorbs the
  # slowly falling ACF of flicker and random walk over a few Tc. Tc is
  # profiled on a grid within a factor 5 of the hint; a minimum on the
  # grid's edge means Tc is not identified.
  grid <- tc * 10^seq(-0.7, 0.7, by = 0.02)
  # the other exponentials and the lines, beside the line
  rest <- cbind(vapply(beside, function(b) exp(-lag * m / (freq * b)), numeric(max_lag)),
                acf_line_cosines(lines, m, freq, lag, hit$v, nb), 1, lag)
  # (.lm.fit(): lm.fit()'s QR and residuals without its bookkeeping)
  rss <- vapply(grid, function(g) {
    X <- cbind(exp(-lag * m / (freq * g)), rest)
    sum(stats::.lm.fit(X, r)$residuals^2)
  }, 0)
  k <- which.min(rss)
  X <- cbind(exp(-lag * m / (freq * grid[k])), rest)
  a <- unname(stats::lm.fit(X, r)$coefficients[1L])
  est <- if (k > 1L && k < length(grid) && is.finite(a) && a > 0) grid[k] else NA_real_
  rss_line <- sum(stats::lm.fit(X[, -1L, drop = FALSE], r)$residuals^2)
  shape <- if (rss_line > 0) 1 - rss[k] / rss_line else NA_real_
  list(tc = est, r1 = r[1L], amp = a, z = a * sqrt(nb), m = m, shape = shape)
}

# The cosines the lines `lines` (list(f0, amp): frequencies in Hz, rate
# amplitudes) add to the ACF of means of blocks of m samples at lags `lag`,
# one column each, for the lines whose swing there is above the ACF's
# noise: amp^2 / 2 through the block mean's gain, over the block means'
# variance `v`, at least 2 / sqrt(nb) (at 30 s blocks a 0.56 Hz line is
# averaged away). A line whose alias in the block means completes less
# than a quarter period over the lags is left out too: the straight line
# takes that shape. (A sawtooth's 0.27 Hz fundamental over lags of 1.4 s,
# left out, read as an exponential of 0.43 s.)
acf_line_cosines <- function(lines, m, freq, lag, v, nb) {
  f0 <- lines$f0
  amp <- lines$amp
  dt <- m / freq
  gain <- abs(sin(pi * f0 * dt) / (m * sin(pi * f0 / freq)))
  swing <- (amp * gain)^2 / 2 / v
  alias <- abs(f0 - round(f0 * dt) / dt)
  keep <- is.finite(f0) & f0 > 0 & f0 < freq / 2 & is.finite(swing) &
    swing > 2 / sqrt(nb) & alias * max(lag) * dt >= 0.25
  # (the strongest first: a few lags per column stay free)
  f0 <- utils::head(f0[keep][order(-swing[keep])], floor(length(lag) / 4))
  matrix(vapply(f0, function(f) cos(2 * pi * f * dt * lag), numeric(length(lag))),
         nrow = length(lag))
}
