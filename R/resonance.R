# A narrow-band random process (a damped resonance): the broad spectral
# bump that the ADIS16405 z gyroscopes show at 18-22 Hz. Not a line: its
# power is spread over a band of width ~1/(pi Tc) around f_r, so no
# sinusoid describes it. Here: its math, simulator and raw-data evidence.
#
# Model: a damped second-order system driven by white noise, sampled: the
# real AR(2) x_k = 2 r cos(w) x_{k-1} - r^2 x_{k-2} + e_k with the poles
# p = r e^{+-i w}, r = exp(-tau0 / Tc), w = 2 pi f_r tau0 (0 < f_r < Nyquist).
# Its autocovariance is
#   g(h) = sigma^2 r^|h| (cos(w h) + c sin(w |h|)),  c = (1 - r^2) / (1 + r^2) cot(w),
# = Re(A p^|h|) with A = sigma^2 (1 - i c). The c term is the band's
# low-frequency skirt (its PSD is 1 / |1 - p e^{-iw'}|^2 |1 - conj(p) e^{-iw'}|^2,
# not a pair of Lorentzians); near f_r the two agree, FWHM ~ 1/(pi Tc).
# sigma is the process's sd, whatever fr and tc.

# c of the ACF's sine term
resonance_c <- function(tau0, fr, tc) {
  r <- exp(-tau0 / tc)
  (1 - r^2) / (1 + r^2) / tan(2 * pi * fr * tau0)
}

resonance_acf <- function(h, tau0, sigma, fr, tc) {
  r <- exp(-tau0 / tc)
  w <- 2 * pi * fr * tau0
  k <- abs(h)
  # c sin(w k) = (1 - r^2) / (1 + r^2) cos(w) sin(w k) / sin(w), whose
  # limit at sin(w) = 0 is k cos(w)^(k - 1)
  ratio <- if (sin(w) == 0) k * cos(w)^(k - 1) else sin(w * k) / sin(w)
  sigma^2 * r^k * (cos(w * k) + (1 - r^2) / (1 + r^2) * cos(w) * ratio)
}

# Exact discrete AV at cluster sizes m: g(h) = Re(A p^|h|), and the AR(1)
# form (noise-models.md section 1) is linear in A, so AV =
# Re(geometric_av(m, A, p)) with a complex A and pole.
# The searches evaluate it at every value they visit: in C++ (src/resonance.cpp,
# the R expression's operations in R's complex arithmetic), the R expression
# for anything but plain numbers.
resonance_av <- function(m, tau0, sigma, fr, tc) {
  # (is_plain_number() of each scalar, in primitives: a search calls this
  # at every value it visits)
  if (is.double(m) && is.null(attributes(m)) && !anyNA(m) && is.double(tau0) &&
      is.double(sigma) && is.double(fr) && is.double(tc) &&
      length(tau0) == 1L && length(sigma) == 1L && length(fr) == 1L &&
      length(tc) == 1L && !anyNA(c(tau0, sigma, fr, tc))) {
    return(resonance_av_cpp(m, tau0, sigma, fr, tc))
  }
  resonance_av_r(m, tau0, sigma, fr, tc)
}

resonance_av_r <- function(m, tau0, sigma, fr, tc) {
  p <- exp(-tau0 / tc) * exp(1i * 2 * pi * fr * tau0)
  s2 <- sigma^2
  A <- complex(real = s2, imaginary = -(s2 * resonance_c(tau0, fr, tc)))
  Re(geometric_av(m, A, p))
}

is_plain_number <- function(v) is.double(v) && length(v) == 1L && !is.na(v)

# Two-sided PSD (u^2/Hz) of the sampled process:
# tau0 s_e^2 / (|1 - p e^{-iw'}|^2 |1 - conj(p) e^{-iw'}|^2), w' = 2 pi f tau0,
# with the innovation variance s_e^2 = sigma^2 (1 - r^2) |1 - p^2|^2 / (1 + r^2)
# (src/resonance.cpp, in real arithmetic without cancellation near r = 1).
resonance_psd <- function(f, tau0, sigma, fr, tc) {
  resonance_psd_cpp(as.double(f), tau0, sigma, fr, tc)
}

# n samples of the AR(2), started from the stationary law (two samples
# with variance sigma^2 and lag-1 covariance g(1)).
sim_resonance <- function(n, tau0, sigma, fr, tc) {
  r <- exp(-tau0 / tc)
  w <- 2 * pi * fr * tau0
  rho <- resonance_acf(1, tau0, 1, fr, tc)
  se <- sigma * sqrt((1 - r^2) * ((1 - r^2)^2 + 4 * r^2 * sin(w)^2) / (1 + r^2))
  x1 <- stats::rnorm(1L, sd = sigma)
  x2 <- rho * x1 + stats::rnorm(1L, sd = sigma * sqrt(max(1 - rho^2, 0)))
  if (n <= 2L) return(c(x1, x2)[seq_len(n)])
  x <- stats::filter(stats::rnorm(n - 2L, sd = se), c(2 * r * cos(w), -r^2),
                     method = "recursive", init = c(x2, x1))
  c(x1, x2, as.numeric(x))
}

# Start values of a resonance term from a band of find_bands().
resonance_start <- function(band) {
  list(sigma = sqrt(band$power), fr = band$f_center, tc = band$tc)
}

# The resonances the raw data measure in the bands of find_bands(): a run
# with two peaks (its pair: closer than the sum of their widths, so one
# run, but the excess dips between them) gives the two, the stronger
# first, else the band's own fit;
# rows as find_bands()' (f_center, width, tc, power, share) and `paired`
# (one of two).
band_resonances <- function(bands) {
  if (!nrow(bands)) return(cbind(bands, paired = logical()))
  cols <- c("f_center", "f_from", "f_to", "width", "tc", "power", "share")
  rows <- lapply(seq_len(nrow(bands)), function(i) {
    b <- bands[i, cols, drop = FALSE]
    b$paired <- FALSE
    if (is.null(bands$pair_fr1) || is.na(bands$pair_fr1[i])) return(b)
    two <- b[c(1L, 1L), , drop = FALSE]
    two$paired <- TRUE
    two$f_center <- c(bands$pair_fr1[i], bands$pair_fr2[i])
    two$tc <- c(bands$pair_tc1[i], bands$pair_tc2[i])
    two$width <- 1 / (pi * two$tc)
    two$power <- c(bands$pair_power1[i], bands$pair_power2[i])
    two$share <- b$share * two$power / b$power
    two[order(-two$power), , drop = FALSE]
  })
  out <- do.call(rbind, rows)
  rownames(out) <- NULL
  attr(out, "resolution") <- attr(bands, "resolution")
  out
}

# What the raw data say about a fitted resonance: a band of find_bands()
# whose centre lies within half its width (or 2 resolution bins) of f_r is
# support, with its power within a factor 2 of sigma^2; no band at all near
# f_r contradicts it, as does a width 1/(pi tc) more than 3x off the band's.
# The band's power is measured to a few percent; a band whose shape is not
# quite the AR(2)'s puts its AV-equivalent power off by tens of percent
# (the accepted resonances of the 18 ADIS16405 axes: 0.93-1.5x). A resonance
# the curve wants at twice the band's power or more stands in for
# something else that shapes the curve near 1/(2 f_r) (unit 3 accel_y with
# a warm-up added took an 8.15 Hz resonance at 2.9x its band's power).
resonance_raw_support <- function(sigma, fr, tc, bands) {
  m <- resonance_band_match(fr, tc, bands)
  if (is.null(m)) {
    return(list(text = sprintf("no spectral band near %s Hz", format(signif(fr, 3))),
                support = FALSE))
  }
  pr <- m$band$power / sigma^2
  txt <- sprintf("spectral band at %s Hz (FWHM %s Hz, %.0f%% of the variance, power %.2g x and width %.2g x the fitted)",
                 format(signif(m$band$f_center, 4)), format(signif(m$band$width, 2)),
                 100 * m$band$share, pr, m$wr)
  # a resonance is a band, not a tone: its width matches the band's
  # within a factor 3; and at most twice as wide, where the raw data show
  # no band (a resonance beside a square wave's harmonics on its flanks,
  # 2.9 x the band's width, took their power and kept them out)
  list(text = txt, support = m$near && pr > 1 / 2 && pr < 2 && m$wr > 1 / 2 && m$wr < 3)
}

# The band of find_bands() nearest a resonance at fr (a band's own fit and,
# where two resonances fit it better, each of them): list(band (its row),
# near (centre within half its width or 2 resolution bins), wr (its width
# over the resonance's 1/(pi tc))), or NULL when there is no band.
resonance_band_match <- function(fr, tc, bands) {
  if (nrow(bands) && !is.null(bands$pair_fr1) && any(!is.na(bands$pair_fr1))) {
    res <- attr(bands, "resolution")
    cols <- c("f_center", "width", "tc", "power", "share")
    bands <- rbind(bands[, cols, drop = FALSE],
                   band_resonances(bands[!is.na(bands$pair_fr1), , drop = FALSE])[, cols, drop = FALSE])
    attr(bands, "resolution") <- res
  }
  if (!nrow(bands)) return(NULL)
  res <- attr(bands, "resolution")
  if (is.null(res)) res <- 0
  d <- abs(bands$f_center - fr)
  j <- which.min(d)
  # both widths are read at least at the resolution, but a resonance
  # narrower than a tenth of it keeps its own (a resonance of tc 2620 s
  # took a 2.05 Hz line's place beside a band of FWHM 0.22 Hz, one Welch
  # bin: floored there, the widths agreed)
  fw <- 1 / (pi * tc)
  list(band = bands[j, , drop = FALSE],
       near = d[j] <= max(0.5 * bands$width[j], 2 * res),
       wr = max(bands$width[j], res) / (if (fw < res / 10) fw else max(fw, res)))
}

# A resonance the curve makes more than twice as narrow or as wide as the
# band the raw data measure at its centre is held at the band's centre
# and width (stage_hold()): beside a measured band its tc runs off where
# the other band's edge leaves the curve room (a 27 Hz band of FWHM 2.2 Hz
# fitted at 1.0 Hz beside a 13 Hz band, N +5%).
hold_resonance <- function(par, raw) {
  bands <- diag_part(raw, "bands")
  if (is.null(bands)) return(NULL)
  m <- resonance_band_match(par[["fr"]], par[["tc"]], bands)
  if (is.null(m) || !m$near || (m$wr > 1 / 2 && m$wr < 2)) return(NULL)
  list(values = c(fr = m$band$f_center, tc = m$band$tc),
       note = sprintf("fr and tc held at the spectral band's %s Hz and %s s (the curve put tc at %s s)",
                      format_num(m$band$f_center, 4), format_num(m$band$tc),
                      format_num(par[["tc"]])))
}

# Where a resonance's shape can take a line's power (the catalogue's
# `absorbs`): the band of find_bands() it stands on (read without the
# lines there) and that band's background either side (band_reach(), at
# least 4 bins). Fitted while such a line was not yet in the model, the
# resonance moved towards it and took its power (an AR(2) at 9.8 Hz with a
# line at 8.97 Hz: 9.65 Hz, tc 0.48 s against the band's 9.80 Hz, 0.38
# s), and the line screened beside it held there gained nothing. Its
# start: the band's own centre and width.
resonance_absorbs <- function(par, raw) {
  bands <- diag_part(raw, "bands")
  if (!NROW(bands)) return(NULL)
  m <- resonance_band_match(par[["fr"]], par[["tc"]], bands)
  if (is.null(m) || !m$near) return(NULL)
  b <- m$band
  res <- attr(bands, "resolution") %||% 0
  # (one of a run's two resonances has its own centre and width only)
  lo <- if (is.null(b$f_from)) b$f_center - b$width / 2 else b$f_from
  hi <- if (is.null(b$f_to)) b$f_center + b$width / 2 else b$f_to
  wd <- band_reach(list(f_from = lo, f_to = hi), res)
  list(lo = lo - wd, hi = hi + wd, start = c(fr = b$f_center, tc = b$tc),
       what = sprintf("the resonance at %s Hz", format_num(b$f_center, 4)))
}
