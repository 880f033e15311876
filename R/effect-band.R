# Catalogue entry of a measured spectral band: a narrow-band
# process that no parametric shape describes (the ADIS16405 z gyros' band
# near 20 Hz falls faster below its peak than a Lorentzian and has a
# shoulder above it). Its spectrum IS the raw data's: the Welch estimate
# over the band minus the background read on its flanks, tabulated on
# `band_knots` equal intervals (piecewise constant, its power kept
# exactly). Its Allan variance is the exact AV transfer function applied to
# that spectrum. Nothing is fitted but a scale (amp^2), which the raw data
# must confirm: within 2 of the band power's relative uncertainty `u`
# (the Welch chi-square of the band's bins and the spread between two
# background models). That makes it evidence, not a fitting device: the
# curve is asked whether the band the periodogram shows explains it.
#
# AV of a one-sided rate PSD S1 at cluster size m (sampled rate, tau0):
#   AV(m) = 2 int S1(f) sin^4(pi f m tau0) / (m sin(pi f tau0))^2 df
# (white noise of variance s2: S1 = 2 s2 tau0 gives s2 / m; a line of
# amplitude A gives the sinusoid's A^2 sin^4 / (m^2 sin^2)). Over a piece
# where S1 is constant, int sin^4(a f) df = [F4(a f)] / a with
# F4(x) = 3x/8 - sin(2x)/4 + sin(4x)/32; the denominator is taken at the
# centres of `band_sub` sub-pieces. Continuous form (tau0 NULL): m
# sin(pi f tau0) -> pi f tau.

band_knots <- 24L
band_sub <- 8L

# The knot edges of a band [f_lo, f_hi].
band_edges <- function(f_lo, f_hi, k = band_knots) seq(f_lo, f_hi, length.out = k + 1L)

# AV per unit scale at taus `tau` of the piecewise-constant one-sided PSD
# `s` (u^2/Hz) on the knots of [f_lo, f_hi].
band_av <- function(tau, tau0, f_lo, f_hi, s) {
  e <- band_edges(f_lo, f_hi, length(s) * band_sub)
  si <- rep(s, each = band_sub)
  lo <- e[-length(e)]
  hi <- e[-1L]
  ctr <- (lo + hi) / 2
  F4 <- function(x) 3 * x / 8 - sin(2 * x) / 4 + sin(4 * x) / 32
  vapply(tau, function(t) {
    a <- pi * t
    den <- if (is.null(tau0)) (pi * ctr * t)^2 else
      ((t / tau0) * sin(pi * ctr * tau0))^2
    2 * sum(si * (F4(a * hi) - F4(a * lo)) / a / den)
  }, 0)
}

# Autocovariance at lags h (samples): sum_j s_j int cos(2 pi f h tau0) df.
band_acf <- function(h, tau0, f_lo, f_hi, s) {
  e <- band_edges(f_lo, f_hi, length(s))
  vapply(h, function(l) {
    if (l == 0) return(sum(s * diff(e)))
    w <- 2 * pi * abs(l) * tau0
    sum(s * diff(sin(w * e))) / w
  }, 0)
}

# n samples of Gaussian noise with the band's spectrum (FFT synthesis:
# independent cosine and sine amplitudes of variance S1(f_k) df at each
# Fourier frequency).
sim_band <- function(n, tau0, scale, f_lo, f_hi, s) {
  freq <- 1 / tau0
  # made at a length with factors 2, 3, 5 (R's fft() is quadratic in a
  # large prime factor) and cut to n: a stretch of a stationary series
  nf <- stats::nextn(n, c(2L, 3L, 5L))
  k <- seq_len(nf %/% 2L)
  fk <- k * freq / nf
  j <- findInterval(fk, band_edges(f_lo, f_hi, length(s)), rightmost.closed = TRUE)
  S1 <- numeric(length(fk))
  inside <- j >= 1L & j <= length(s)
  S1[inside] <- s[j[inside]]
  sd <- sqrt(scale * S1 * freq / nf)
  c <- complex(nf)
  c[k + 1L] <- complex(real = stats::rnorm(length(k), sd = sd),
                       imaginary = -stats::rnorm(length(k), sd = sd))
  Re(stats::fft(c, inverse = TRUE))[seq_len(n)]
}

# The band's spectrum measured from the raw series: `b` a row of
# find_bands(). The background under it is log-quadratic in f through the
# flanks (one band width either side, below 0.49 freq, without the other
# bands found, `others`: rows of find_bands()); a log-linear one
# gives the systematic spread. Returns list(f_lo, f_hi, f_c, s, u, power)
# or NULL when the band has no measurable excess; f_c is its centre: the
# power centroid of the knots at half the peak or above (a resonance's
# skirt, or a neighbour's, widens the edges unevenly and tilts the whole
# band's centroid: 13.2 and 14.8 Hz for a 15 Hz resonator's band, 14.9
# over its half-power knots).
measure_band <- function(x, freq, b, seg = 512L, knots = band_knots,
                         welch = centred_welch, others = NULL) {
  w <- welch(x, freq, seg)
  wd <- band_reach(b, w$df)
  fl <- (w$f > b$f_from - wd & w$f < b$f_from & w$f > 0) |
    (w$f > b$f_to & w$f < min(b$f_to + wd, 0.49 * freq))
  # the other bands found are not background (a band beside it would lift
  # the background under this one; their leakage reaches 2 bins)
  for (k in seq_len(NROW(others))) {
    fl <- fl & !(w$f >= others$f_from[k] - 2 * w$df & w$f <= others$f_to[k] + 2 * w$df)
  }
  # the band's bins, and 2 more either side: the Hann window spreads each
  # frequency over +-2 bins, so the band's edges leak that far
  inb <- which(w$f >= b$f_from - 2 * w$df & w$f <= b$f_to + 2 * w$df & w$f > 0)
  fl <- fl & (w$f < w$f[inb[1L]] | w$f > w$f[inb[length(inb)]])
  if (sum(fl) < 6L || length(inb) < 2L) return(NULL)
  excess <- function(degree) {
    X <- outer(w$f[fl], 0:degree, `^`)
    cf <- stats::lm.fit(X, log(w$psd[fl]))$coefficients
    bg <- exp(drop(outer(w$f[inb], 0:degree, `^`) %*% cf))
    pmax(w$psd[inb] - bg, 0)
  }
  ex <- excess(2L)
  p2 <- sum(ex) * w$df
  p1 <- sum(excess(1L)) * w$df
  if (!(p2 > 0)) return(NULL)
  f_lo <- w$f[inb[1L]] - w$df / 2
  f_hi <- w$f[inb[length(inb)]] + w$df / 2
  # the bins' power, cumulated over their edges, read at the knot edges
  cum <- c(0, cumsum(ex) * w$df)
  be <- c(f_lo, w$f[inb] + w$df / 2)
  ke <- band_edges(f_lo, f_hi, knots)
  s <- diff(stats::approx(be, cum, xout = ke, rule = 2)$y) / diff(ke)
  # (a knot with no excess carries 1e-9 of the peak: fixed values are positive)
  s <- pmax(s, 1e-9 * max(s))
  # relative uncertainty: the bins' chi-square, the spread between the two
  # backgrounds, and the power of the 2 outermost bins either side (where
  # the window's leakage leaves the band's edges uncertain at that size)
  k <- length(ex)
  edge <- sum(ex[unique(c(1:2, (k - 1L):k))]) * w$df
  u <- sqrt(2 / (w$nu * length(inb)) + ((p1 - p2) / p2)^2 + (edge / p2)^2)
  mids <- (ke[-1L] + ke[-length(ke)]) / 2
  top <- s >= max(s) / 2
  f_c <- sum(s[top] * mids[top]) / sum(s[top])
  list(f_lo = f_lo, f_hi = f_hi, f_c = f_c, s = s, u = u, power = p2)
}

band_params <- function() {
  rbind(
    effect_param("amp", "amp", "1", "square root of the band's scale (1: as measured)"),
    effect_param("f_lo", "nonlinear", "Hz", "hertz (lower edge, measured)",
                 profile = "smooth", print_unit = TRUE),
    effect_param("f_hi", "nonlinear", "Hz", "hertz (upper edge, measured)",
                 profile = "smooth", print_unit = TRUE),
    effect_param("f_c", "nonlinear", "Hz", "hertz (centre: half-power centroid, measured)",
                 profile = "smooth", print_unit = TRUE),
    effect_param("u", "nonlinear", "1", "relative uncertainty of the band's power",
                 profile = "smooth", hidden = TRUE),
    do.call(rbind, lapply(seq_len(band_knots), function(j) {
      effect_param(paste0("s", j), "nonlinear", "u^2/Hz",
                   "one-sided PSD of the band on knot j (measured)",
                   profile = "smooth", hidden = TRUE)
    })))
}

# The scale the curve asks for must be the measured one, within twice the
# band power's relative uncertainty.
band_scale_ok <- function(par) {
  sc <- par[["amp"]]^2
  is.finite(sc) && sc > 0 && abs(log(sc)) <= 2 * par[["u"]]
}

band_spectrum <- function(nl) {
  vapply(seq_len(band_knots), function(j) nl[[paste0("s", j)]], 0)
}

effect_band <- function() {
  new_effect(
    name = "band", title = "measured spectral band",
    params = band_params(),
    repeatable = TRUE, slope = NA_real_, psd_alpha = NA_real_,
    formula = paste("amp^2 x exact AV of the measured band spectrum:",
                    "2 int S1(f) sin^4(pi f tau) / (m sin(pi f tau0))^2 df"),
    signature = paste("a bump near tau ~ 0.37 / f of the band with damped",
                      "nulls; a broad periodogram band of any shape"),
    basis = function(tau, tau0, nl) {
      band_av(tau, tau0, nl[["f_lo"]], nl[["f_hi"]], band_spectrum(nl))
    },
    psd = function(f, nl) {
      j <- findInterval(f, band_edges(nl[["f_lo"]], nl[["f_hi"]]),
                        rightmost.closed = TRUE)
      s <- band_spectrum(nl)
      out <- numeric(length(f))
      ok <- j >= 1L & j <= length(s)
      out[ok] <- s[j[ok]] / 2
      out
    },
    acf = function(h, tau0, nl) {
      band_acf(h, tau0, nl[["f_lo"]], nl[["f_hi"]], band_spectrum(nl))
    },
    sim = function(n, tau0, amp, nl) {
      sim_band(n, tau0, amp[[1L]]^2, nl[["f_lo"]], nl[["f_hi"]], band_spectrum(nl))
    },
    edf_alpha = function(tau, tau0, nl) rep(0, length(tau)),
    # every parameter but the scale is measured and pinned by propose();
    # the ranges only describe where such values live
    nl_range = function(tau, freq) {
      hi <- if (is.null(freq)) 0.5 / min(tau) else 0.5 * freq
      c(list(f_lo = c(hi / 1000, hi), f_hi = c(hi / 1000, hi), f_c = c(hi / 1000, hi),
             u = c(1e-6, 1)),
        stats::setNames(rep(list(c(1e-300, 1e300)), band_knots),
                        paste0("s", seq_len(band_knots))))
    },
    # The bands of the raw data propose their own spectrum: each band the
    # curve can see, strongest first, every parameter but the scale pinned
    # (a band already in the model is not proposed again: its pinned values
    # are).
    propose = function(raw, tau, sig) {
      mb <- diag_part(raw, "band_spectra")
      if (!length(mb)) return(list())
      hi <- min(0.5 / min(tau), 0.499 * diag_value(raw, "freq"))
      ok <- vapply(mb, function(m) (m$f_lo + m$f_hi) / 2 > 1 / max(tau) &&
                     (m$f_lo + m$f_hi) / 2 < hi, NA)
      mb <- mb[ok]
      mb <- mb[order(-vapply(mb, `[[`, 0, "power"))]
      lapply(mb, function(m) {
        pin <- c(list(f_lo = m$f_lo, f_hi = m$f_hi, f_c = m$f_c, u = m$u),
                 stats::setNames(as.list(m$s), paste0("s", seq_along(m$s))))
        list(init = list(amp = 1), pin = pin,
             tau_from = 0.371 / m$f_hi / 2, tau_to = 2 / m$f_lo, score = 2,
             note = sprintf(paste("proposed by the spectral band at %s-%s Hz",
                                  "(its measured spectrum, power %s)"),
                            format_num(m$f_lo, 4), format_num(m$f_hi, 4),
                            format_num(m$power)))
      })
    },
    evidence = function(par, raw, x, freq) {
      sc <- par[["amp"]]^2
      list(text = sprintf(paste("the measured band %s-%s Hz: the curve asks for %.3f x its",
                                "power (uncertainty %.1f%%)"),
                          format_num(par[["f_lo"]], 4), format_num(par[["f_hi"]], 4),
                          sc, 100 * par[["u"]]),
           support = band_scale_ok(par))
    },
    # sized off its measured power, the band is held at that power (scale 1)
    raw_hold = function(par, raw) {
      if (band_scale_ok(par)) return(NULL)
      list(values = c(amp = 1),
           note = sprintf("amp held at the measured band's power (the curve asked for %.3f x it)",
                          par[["amp"]]^2))
    },
    # its measured spectrum, read without the lines in its reach, is
    # pinned; its scale can still take such a line's power on the curve
    absorbs = function(par, raw) {
      res <- attr(diag_part(raw, "bands"), "resolution") %||% 0
      wd <- band_reach(list(f_from = par[["f_lo"]], f_to = par[["f_hi"]]), res)
      list(lo = par[["f_lo"]] - wd, hi = par[["f_hi"]] + wd, start = numeric(0),
           what = sprintf("the measured band at %s-%s Hz", format_num(par[["f_lo"]], 4),
                          format_num(par[["f_hi"]], 4)))
    },
    peak_tau = function(par) 0.371 * 2 / (par[["f_lo"]] + par[["f_hi"]]),
    # each band of the raw periodogram's own spectrum, read once per call
    diagnose = list(
      part = "band_spectra", reads = "raw", needs = c("bands", "lines"),
      make = function(x, freq, dg) {
        bands <- diag_part(dg, "bands")
        # a line on a band or in its background is a sinusoid, not the
        # band's: measured without it (an 8.97 Hz line added on an
        # accelerometer's band moved its measured centre from 10.09 to
        # 9.39 Hz, and the band took the line's place in the model)
        xb <- without_lines_on_bands(x, freq, bands, diag_part(dg, "lines"))
        welch <- if (identical(xb, x)) raw_welch(dg) else centred_welch
        Filter(Negate(is.null), lapply(seq_len(nrow(bands)), function(j) {
          # a run with two peaks is two resonances (the resonance entry
          # proposes both, each measured), not one measured band: measured
          # as one, it took a sensor filter's form with it (unit 3 accel_x
          # + an 8.1 Hz band beside its 9.86 Hz resonance: a first-order
          # low-pass in place of its moving average, N +9%)
          if (isTRUE(!is.na(bands$pair_fr1[j]))) return(NULL)
          measure_band(xb, freq, bands[j, ], welch = welch, others = bands[-j, ])
        }))
      }),
    describe = function(values) {
      sprintf("measured band (%s)", paste(sprintf("%s-%s Hz, centre %s Hz", signif(values$f_lo, 3),
                                                   signif(values$f_hi, 3), signif(values$f_c, 3)),
                                           collapse = "; "))
    },
    # the measured band is the resonance's band as the data show it: it
    # replaces the resonance whose centre lies in it, not one elsewhere
    replaces = "resonance",
    replaces_instance = function(par, kind, old) {
      fr <- old$fr %||% NA_real_
      is.finite(fr) && !is.null(par$f_lo) && fr >= par$f_lo && fr <= par$f_hi
    },
    # its spectrum is measured, never searched: tried only where proposed
    proposed_only = TRUE
  )
}
