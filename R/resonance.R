# A narrow-band random process (a damped resonance): the broad spectral
# bump that the ADIS16405 z gyroscopes show at 18-22 Hz. Not a line: its
# power is spread over a band of width ~1/(pi Tc) around f_r, so no
# sinusoid describes it. Here: its math, simulator and raw-data evidence.
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
# The searches evaluate it at every value they visit: in C++ (src/resonance.cpp,
# the R expression's operations in R's complex arithmetic), the R expression
# for anything but plain numbers.
resonance_av <- function(m, tau0, sigma, fr, tc) {
  if (is.double(m) && is.null(attributes(m)) && !anyNA(m) && is_plain_number(tau0) && is_plain_number(sigma) &&
      is_plain_number(fr) && is_plain_number(tc)) {
    return(resonance_av_cpp(m, tau0, sigma, fr, tc))
  }
  resonance_av_r(m, tau0, sigma, fr, tc)
}

resonance_av_r <- function(m, tau0, sigma, fr, tc) {
  p <- exp(-tau0 / tc) * exp(1i * 2 * pi * fr * tau0)
  Re(geometric_av(m, sigma^2, p))
}

is_plain_number <- function(v) is.double(v) && length(v) == 1L && !is.na(v)

# Two-sided PSD (u^2/Hz) of the sampled process: tau0 sum_h g(h) e^{-i w' h}
# = tau0 sigma^2 Re[(1 + q) / (1 - q)] summed over q = p e^{-iw'} and its
# mirror, /2 each.
# (src/resonance.cpp: r = exp(-tau0 / tc), w = 2 pi f tau0, w0 = 2 pi fr tau0,
# one(d) = Re((1 + q) / (1 - q)) with q = r exp(1i d), and
# tau0 sigma^2 0.5 (one(w0 - w) + one(-w0 - w)), in real arithmetic)
resonance_psd <- function(f, tau0, sigma, fr, tc) {
  resonance_psd_cpp(as.double(f), tau0, sigma, fr, tc)
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

# Start values of a resonance term from a band of find_bands().
resonance_start <- function(band) {
  list(sigma = sqrt(band$power), fr = band$f_center, tc = band$tc)
}

# What the raw data say about a fitted resonance: a band of find_bands()
# whose centre lies within half its width (or 2 resolution bins) of f_r is
# support, with its power within a factor 2 of sigma^2; no band at all near
# f_r contradicts it, as does a width 1/(pi tc) more than 3x off the band's.
# The band's power is measured to a few percent; a band that is not quite
# Lorentzian puts its AV-equivalent power off by tens of percent (the
# accepted resonances of the 18 ADIS16405 axes: 0.93-1.5x). A resonance
# the curve wants at twice the band's power or more stands in for
# something else that shapes the curve near 1/(2 f_r) (unit 3 accel_y with
# a warm-up added took an 8.15 Hz resonance at 2.9x its band's power).
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
  list(text = txt, support = near && pr > 1 / 2 && pr < 2 && wr > 1 / 3 && wr < 3)
}
