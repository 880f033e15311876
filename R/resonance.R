# A narrow-band random process (a damped resonance): the broad spectral
# bump that the ADIS16405 z gyroscopes show at 18-22 Hz. Not a line: its
# power is spread over a band of width ~1/(pi Tc) around f_r, so no
# sinusoid describes it. Math, simulator and raw-data evidence (issue 9,
# item 2).
#
# Model: the real part of a complex AR(1), z_k = r e^{i w} z_{k-1} + e_k,
# r = exp(-tau0 / Tc), w = 2 pi f_r tau0. Its autocovariance is
#   g(h) = sigma^2 r^|h| cos(w h),
# a Gauss-Markov process shifted to f_r (f_r = 0 gives the GM exactly);
# its PSD is a pair of Lorentzians at +-f_r with half width 1/(2 pi Tc).

resonance_acf <- function(h, tau0, sigma, fr, tc) {
  r <- exp(-tau0 / tc)
  sigma^2 * r^abs(h) * cos(2 * pi * fr * tau0 * h)
}

# Exact discrete AV at cluster sizes m: g(h) = Re(sigma^2 p^|h|) with
# p = r e^{iw}, so AV = Re(geometric_av(m, sigma^2, p)) (the AR(1) form,
# noise-models.md section 1, with a complex pole).
resonance_av <- function(m, tau0, sigma, fr, tc) {
  p <- exp(-tau0 / tc) * exp(1i * 2 * pi * fr * tau0)
  Re(geometric_av(m, sigma^2, p))
}

# Two-sided PSD (u^2/Hz) of the sampled process: tau0 sum_h g(h) e^{-i w' h}
# = tau0 sigma^2 Re[(1 + q) / (1 - q)] summed over q = p e^{-iw'} and its
# mirror, /2 each.
resonance_psd <- function(f, tau0, sigma, fr, tc) {
  r <- exp(-tau0 / tc)
  w <- 2 * pi * f * tau0
  w0 <- 2 * pi * fr * tau0
  one <- function(d) {
    q <- r * exp(1i * d)
    Re((1 + q) / (1 - q))
  }
  tau0 * sigma^2 * 0.5 * (one(w0 - w) + one(-w0 - w))
}

# n samples, started from the stationary law: x is the real part of z with
# E|z|^2 = 2 sigma^2, so x has variance sigma^2.
sim_resonance <- function(n, tau0, sigma, fr, tc) {
  p <- exp(-tau0 / tc) * exp(1i * 2 * pi * fr * tau0)
  s <- sigma * sqrt(1 - Mod(p)^2)
  z <- complex(n)
  z0 <- complex(real = stats::rnorm(1L, sd = sigma), imaginary = stats::rnorm(1L, sd = sigma))
  e <- complex(real = stats::rnorm(n, sd = s), imaginary = stats::rnorm(n, sd = s))
  # the real AR(2) form of Re z: x_k = 2 Re(p) x_{k-1} - |p|^2 x_{k-2} + u_k,
  # u_k = Re(e_k - conj(p) e_{k-1}); started from two exact samples
  u <- Re(e - Conj(p) * c(0, e[-n]))
  z1 <- p * z0 + e[1L]
  z2 <- p * z1 + e[2L]
  if (n <= 2L) return(Re(c(z1, z2))[seq_len(n)])
  u[1:2] <- 0
  x <- stats::filter(u, c(2 * Re(p), -Mod(p)^2), method = "recursive",
                     init = c(Re(z2), Re(z1)))
  c(Re(z1), Re(z2), as.numeric(x[3:n]))
}

#' Spectral bands of a rate series (internal)
#'
#' Narrow-band processes found at a coarse resolution (`seg` samples per
#' Welch segment, default 512). Pass 1: bins standing above a wide (about
#' an octave) running-median background significantly (the Welch
#' estimate's chi-square with its EDF, false-alarm rate `alpha` over the
#' bins searched), in contiguous runs of at least `min_bins` bins. Pass 2: those runs, widened by their own width on each side, are
#' masked and the background is re-read from the bins around them (a band
#' lifts the median of its own window). Each band is then described by the
#' resonance model fitted to the excess over the background by least
#' squares (relative to the background): centre `f_center`, `tc` (its
#' Lorentzian FWHM is 1/(pi tc), given as `width`), `power` (its variance,
#' sigma^2) and `share` of the series' variance.
#' Cost O(n log seg).
#' @noRd
find_bands <- function(x, freq, seg = 512L, min_bins = 3L, alpha = 1e-3) {
  n <- length(x)
  tau0 <- 1 / freq
  seg <- as.integer(min(seg, 2^floor(log2(n / 8))))
  w <- welch_psd_lin(x - mean(x), freq, seg)
  p <- w$psd
  nb <- length(p)
  lp <- log(pmax(p, .Machine$double.xmin))
  corr <- log(stats::qchisq(0.5, w$nu) / w$nu)
  octave <- function(i) 2L * as.integer(max(8, 0.35 * i)) + 1L
  edge <- octave(1L) %/% 2L + 1L
  runs <- function(bg) {
    ratio <- p / bg
    pval <- stats::pchisq(ratio * w$nu, w$nu, lower.tail = FALSE)
    # significant against the Welch estimate's chi-square (EDF nu), with a
    # false-alarm rate alpha over the nb bins searched (Bonferroni); no
    # fixed power ratio (a weak band over a long record is still a band)
    hot <- ratio > 1 & pval * nb < alpha
    # only where the background window is centred: at the low end it slides
    # up in frequency and under-reads a falling spectrum (RW, GM, roll-off)
    hot[seq_len(min(nb, edge))] <- FALSE
    # one band is one run: a gap between hot runs shorter than min_bins, or
    # than a quarter of the wider neighbour (a broad band's tail broken up
    # by the noise), is closed, so one band is not fitted as two
    r <- rle(hot)
    nr <- length(r$values)
    nbr <- pmax(c(0L, r$lengths[-nr]), c(r$lengths[-1L], 0L))
    gap <- !r$values & (r$lengths < min_bins | 4L * r$lengths < nbr) &
      seq_len(nr) > 1L & seq_len(nr) < nr
    r$values[gap] <- TRUE
    r <- rle(inverse.rle(r))
    ends <- cumsum(r$lengths)
    starts <- ends - r$lengths + 1L
    keep <- which(r$values & r$lengths >= min_bins)
    list(from = starts[keep], to = ends[keep], ratio = ratio)
  }
  bg <- exp(sparse_running_median(lp, octave) - corr)
  r1 <- runs(bg)
  if (length(r1$from)) {
    mask <- rep(FALSE, nb)
    for (k in seq_along(r1$from)) {
      wd <- r1$to[k] - r1$from[k] + 1L
      mask[max(1L, r1$from[k] - wd):min(nb, r1$to[k] + wd)] <- TRUE
    }
    keep <- which(!mask)
    if (length(keep) > 10L) {
      bg2 <- exp(sparse_running_median(lp[keep], octave) - corr)
      bg <- exp(stats::approx(keep, log(bg2), xout = seq_len(nb), rule = 2)$y)
    }
  }
  r2 <- runs(bg)
  total <- stats::var(x)
  rows <- lapply(seq_along(r2$from), function(k) {
    j <- r2$from[k]:r2$to[k]
    ex <- pmax(p[j] - bg[j], 0)
    fc <- sum(w$f[j] * ex) / sum(ex)
    sdf <- sqrt(sum((w$f[j] - fc)^2 * ex) / sum(ex))
    wd <- length(j)
    # the fit region stops short of the neighbouring bands (else a weak
    # band's fit slides onto a strong neighbour)
    lo <- if (k > 1L) r2$to[k - 1L] + 1L else 2L
    hi <- if (k < length(r2$from)) r2$from[k + 1L] - 1L else nb
    reg <- max(2L, lo, r2$from[k] - 2L * wd):min(nb, hi, r2$to[k] + 2L * wd)
    fit <- fit_lorentz(w$f[reg], p[reg] - bg[reg], bg[reg], tau0,
                       fc, sum(ex) * w$df, max(sdf, w$df))
    data.frame(f_center = fit$fr, f_from = w$f[j[1L]], f_to = w$f[j[length(j)]],
               width = 1 / (pi * fit$tc), tc = fit$tc, power = fit$sigma^2,
               share = fit$sigma^2 / total, peak_ratio = max(r2$ratio[j]))
  })
  out <- if (length(rows)) do.call(rbind, rows) else
    data.frame(f_center = numeric(), f_from = numeric(), f_to = numeric(),
               width = numeric(), tc = numeric(), power = numeric(),
               share = numeric(), peak_ratio = numeric())
  attr(out, "resolution") <- w$df
  out
}

# Least-squares fit of the resonance's one-sided PSD (2 x two-sided) to the
# excess `ex` over a background `bg` at frequencies f, relative to the
# background; starts from the band's moments.
fit_lorentz <- function(f, ex, bg, tau0, fc, power, sdf) {
  model <- function(q) 2 * resonance_psd(f, tau0, exp(q[1L]), q[2L], exp(q[3L]))
  obj <- function(q) sum(((ex - model(q)) / bg)^2)
  q0 <- c(log(sqrt(power)), fc, log(1 / (2 * pi * sdf)))
  o <- stats::optim(q0, obj, control = list(maxit = 500L, reltol = 1e-10))
  list(sigma = exp(o$par[1L]), fr = o$par[2L], tc = exp(o$par[3L]))
}

# Start values of a resonance term from a band of find_bands().
resonance_start <- function(band) {
  list(sigma = sqrt(band$power), fr = band$f_center, tc = band$tc)
}

# What the raw data say about a fitted resonance: a band of find_bands()
# whose centre lies within half its width (or 2 resolution bins) of f_r is
# support; its power within a factor 3 of sigma^2 as well; no band at all
# near f_r contradicts it, as does a width 1/(pi tc) more than 3x off the band's.
resonance_raw_support <- function(sigma, fr, tc, bands) {
  if (!nrow(bands)) {
    return(list(text = sprintf("no spectral band near %s Hz", format(signif(fr, 3))),
                support = FALSE))
  }
  res <- attr(bands, "resolution")
  if (is.null(res)) res <- 0
  d <- abs(bands$f_center - fr)
  j <- which.min(d)
  near <- d[j] <= max(0.5 * bands$width[j], 2 * res)
  pr <- bands$power[j] / sigma^2
  # a resonance is a band, not a tone: its width 1/(pi tc) must match the
  # band's within a factor 3 (both at least the resolution)
  wr <- max(bands$width[j], res) / max(1 / (pi * tc), res)
  txt <- sprintf("spectral band at %s Hz (FWHM %s Hz, %.0f%% of the variance, power %.2g x and width %.2g x the fitted)",
                 format(signif(bands$f_center[j], 4)), format(signif(bands$width[j], 2)),
                 100 * bands$share[j], pr, wr)
  list(text = txt, support = near && pr > 1 / 3 && pr < 3 && wr > 1 / 3 && wr < 3)
}

# The series with each broad band of find_bands() brought down to its
# background: every FFT bin is scaled by sqrt(bg / (bg + M(f))), where M is
# the band's fitted Lorentzian (one-sided PSD) and bg the background PSD
# read 3-6 band widths away (M taken off), so that the expected power of
# each bin becomes the background's. Phases are kept, so the white noise
# and the filter's roll-off under the band stay; only the band's excess
# goes. Used for the raw-data checks of the other effects (the filter's
# short-lag ACF, a Gauss-Markov ACF), which a resonance disturbs.
remove_bands <- function(x, freq, bands) {
  if (is.null(bands) || !nrow(bands)) return(x)
  n <- length(x)
  m <- mean(x)
  tau0 <- 1 / freq
  X <- stats::fft(x - m)
  f <- (seq_len(n) - 1) * freq / n
  fa <- pmin(f, freq - f)
  P <- 2 * Mod(X)^2 / (n * freq)
  for (k in seq_len(nrow(bands))) {
    b <- bands[k, ]
    M <- 2 * resonance_psd(fa, tau0, sqrt(b$power), b$f_center, b$tc)
    w <- max(b$width, b$f_to - b$f_from)
    d <- abs(fa - b$f_center)
    near <- d > 3 * w & d < 6 * w
    bg <- mean(P[near] - M[near])
    if (!is.finite(bg) || bg <= 0) next
    g <- sqrt(bg / (bg + M))
    X <- X * g
    P <- P * g^2
  }
  Re(stats::fft(X, inverse = TRUE)) / n + m
}
