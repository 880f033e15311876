# Catalogue entry of a sinusoidal disturbance (vibration, a periodic
# environment). Derivation and checks: vignette("noise-terms").

# Signature constants of the continuous form (checked in test-terms.R):
sin_peak_ratio <- 0.3710      # sinusoid first ADEV peak at tau = 0.371 / f0
sin_peak_adev <- 0.7246       # ... where ADEV = 0.7246 A
# A fitted amplitude beyond this multiple of its periodogram line's (the
# curve asking for more than 9x the line's power) is not backed by it. The
# line's amplitude is read within +-3 Welch bins, and a measured line
# whose frequency wanders spreads beyond them: the ADIS16405
# accelerometers' own 1.6-1.7 Hz lines are fitted at 2.0-2.5x the amp read
# there, the curve's misplaced sinusoids at 5-9x.
sin_amp_factor <- 3
# A line's frequency is read to this many Welch bins over the square root
# of its peak's ratio to the background (at most 1.5 bins): 0.11 bins for
# a line 2192 x its background, the full 1.5 for one 11 x.
sin_f0_bins <- 5

# The periodogram line an instance stands on (the strongest within 1.5 bins
# of the periodogram's resolution, not a fraction of f0) and how the fitted
# values sit against it; NULL when there is none.
sin_line_of <- function(par, raw) {
  l <- diag_part(raw, "lines")
  f0 <- par[["f0"]] %||% NA_real_
  if (!nrow(l) || !is.finite(f0)) return(NULL)
  j <- match_line(f0, l, tol = 1.5, pick = "strongest")
  if (is.na(j)) return(NULL)
  res <- attr(l, "resolution") %||% 0
  amp <- abs(par[["amp"]] %||% NA_real_)
  # the line's frequency is measured to a fraction of a bin that shrinks
  # as it stands out (the log peak's interpolation): a fitted f0 beyond
  # that is the curve's own, not the line's (a curve far from its model
  # took 0.6123 Hz for a line the periodogram reads at 0.60997 Hz, 2192 x
  # its background, and the line's AV oscillation at 5-20 s went wrong)
  off <- abs(f0 - l$f0[j])
  prec <- res * min(1.5, sin_f0_bins / sqrt(max(l$ratio[j], 1)))
  list(line = l[j, , drop = FALSE], amp = amp, off = off, prec = prec,
       # the line must carry the power the curve asks for: a weak line next
       # to f0 does not back a sinusoid sized for a stronger one elsewhere
       # (on a measured accelerometer a bump's sinusoid landed on a line of
       # 1/7 its amplitude while the added line was 0.1 Hz away)
       big = is.finite(amp) && l$amp[j] > 0 && amp > sin_amp_factor * l$amp[j],
       # and a sinusoid the curve sizes far below the line is not the line
       # the raw data see: undecided (a harmonic of a held set, fitted at amp
       # 0, passed as confirmed)
       small = is.finite(amp) && amp < l$amp[j] / sin_amp_factor,
       away = off > prec)
}

# Raw-data evidence: a periodogram line near f0.
evidence_sinusoid <- function(par, raw, x, freq) {
  m <- sin_line_of(par, raw)
  f0 <- par[["f0"]] %||% NA_real_
  if (!is.null(m)) {
    l <- m$line
    amp <- m$amp
    return(list(text = sprintf("periodogram line at %s Hz (amp %s, p = %.1g)%s%s%s",
                               format_num(l$f0, 4), format_num(l$amp), l$p_value,
                               if (m$big) sprintf(", %.1f x weaker than the fitted amp %s",
                                                  amp / l$amp, format_num(amp)) else "",
                               if (m$small && amp > 0) sprintf(", %s x stronger than the fitted amp %s",
                                                  format_num(l$amp / amp, 2),
                                                  format_num(amp))
                               else if (m$small) ", the fitted amp 0" else "",
                               if (m$away) sprintf(", %s Hz from the fitted f0 (it reads f0 to %s Hz)",
                                                   format_num(m$off, 2), format_num(m$prec, 2)) else ""),
                support = if (!m$big && !m$away && m$small) NA else !m$big && !m$away))
  }
  res <- attr(diag_part(raw, "lines"), "resolution") %||% 0
  if (is.finite(f0) && f0 < 4 * res) {
    # Within 4 bins of DC the raw data cannot tell a sinusoid from the drift
    # or random walk beside it: with the raw data at hand such a "sinusoid"
    # is a fitting device for the long-tau end, not an effect.
    return(list(text = sprintf(paste("f0 = %s Hz is within 4 bins (%s Hz) of DC, where",
                                     "the periodogram cannot tell a sinusoid from drift"),
                               format_num(f0), format_num(4 * res)), support = FALSE))
  }
  list(text = sprintf("no periodogram line near %s Hz", format_num(f0)),
       support = FALSE)
}

# The amplitude the periodogram measures, for a sinusoid on its line that
# the curve sizes far off it (two lines 0.1 Hz apart look alike on the
# curve, which gives one the other's power).
hold_sinusoid <- function(par, raw) {
  m <- sin_line_of(par, raw)
  if (is.null(m) || !(m$small || m$big) || m$away || !(m$line$amp > 0)) return(NULL)
  list(values = c(amp = m$line$amp),
       note = sprintf("amp held at the periodogram line's %s (the curve put it at %s)",
                      format_num(m$line$amp), format_num(m$amp)))
}

# The sharp lines (one frequency over the whole record: the periodogram
# measures f0 and the record's least-squares sinusoid its amplitude) that
# `fit` holds no sinusoid at (within 1% of f0); NULL when there are none.
known_lines <- function(raw, fit) {
  lines <- diag_part(raw, "lines")
  if (is.null(lines) || !nrow(lines) || is.null(lines$record_amp)) return(NULL)
  lines <- lines[is_sharp(lines$record_amp, lines$amp), , drop = FALSE]
  lay <- fit$layout
  held <- stats::coef(fit)[lay$name[lay$kind == "sinusoid" & lay$param == "f0"]]
  lines <- lines[!vapply(lines$f0, function(f) any(abs(held / f - 1) < 0.01), NA), , drop = FALSE]
  if (nrow(lines)) lines else NULL
}

# The same lines as instances to add at the raw data's values (the
# catalogue's `unheld`), the strongest (by the line's peak over its
# background) first.
unheld_lines <- function(raw, fit) {
  lines <- known_lines(raw, fit)
  if (is.null(lines)) return(NULL)
  lines <- lines[order(-lines$ratio), , drop = FALSE]
  lapply(seq_len(nrow(lines)), function(j) {
    list(values = c(amp = lines$record_amp[j], f0 = lines$f0[j]), at = lines$f0[j])
  })
}

# Their AV at `tau` and their autocovariance at lags `h` (samples): the
# sum over those lines of record_amp^2 times the entry's `basis` or `acf`.
known_lines_sum <- function(raw, fit, len, per_unit) {
  lines <- known_lines(raw, fit)
  if (is.null(lines)) return(NULL)
  rowSums(matrix(vapply(seq_len(nrow(lines)), function(j) {
    lines$record_amp[j]^2 * per_unit(list(f0 = lines$f0[j]))
  }, numeric(len)), nrow = len))
}
known_av_sinusoid <- function(raw, fit, tau, tau0) {
  known_lines_sum(raw, fit, length(tau),
                  function(nl) effect_entry("sinusoid")$basis(tau, tau0, nl))
}
known_acov_sinusoid <- function(raw, fit, h, tau0) {
  known_lines_sum(raw, fit, length(h),
                  function(nl) effect_entry("sinusoid")$acf(h, tau0, nl))
}

effect_sinusoid <- function() {
  new_effect(
    name = "sinusoid", title = "sinusoidal disturbance",
    params = rbind(
      effect_param("amp", "amp", "u", "rate unit (amplitude)"),
      effect_param("f0", "nonlinear", "Hz", "hertz (frequency)",
                   profile = "oscillatory", print_unit = TRUE)),
    repeatable = TRUE, slope = -1, psd_alpha = NA_real_,
    formula = paste("amp^2 sin^4(pi f0 m tau0) / (m^2 sin^2(pi f0 tau0)),",
                    "phase-averaged"),
    signature = paste("nulls at tau = k / f0; first peak 0.7246 amp at",
                      "tau = 0.371 / f0; envelope slope -1;",
                      "periodogram line at f0"),
    basis = function(tau, tau0, nl) {
      f0 <- nl[["f0"]]
      x <- pi * f0 * tau
      out <- sin(x)^4 / x^2
      d <- discrete_tau(tau, tau0)
      if (any(d)) {
        s1 <- sin(pi * f0 * tau0)^2
        out[d] <- if (s1 < 1e-300) 0 else
          sin(x[d])^4 / ((tau[d] / tau0)^2 * s1)
      }
      out
    },
    # phase-averaged: E[A^2 sin(a) sin(a + 2 pi f0 h tau0)] = A^2 cos(.) / 2
    acf = function(h, tau0, nl) cos(2 * pi * nl[["f0"]] * h * tau0) / 2,
    sim = function(n, tau0, amp, nl) {
      amp[[1L]] * sin(2 * pi * nl[["f0"]] * tau0 * seq_len(n) +
                        stats::runif(1L, 0, 2 * pi))
    },
    sim_check = function(par, freq, arg) {
      if (any(par$f0 >= freq / 2)) {
        abort("`", arg, "` frequencies `f0` must be below the Nyquist frequency ",
              "freq / 2 = ", format(freq / 2), " Hz.", class = "argument")
      }
    },
    # deterministic: treated as adding no estimation variance
    edf_alpha = function(tau, tau0, nl) rep(NA_real_, length(tau)),
    # searched only where the curve can see a line (visible_band())
    nl_range = function(tau, freq) {
      b <- visible_band(min(tau), max(tau), freq)
      hi <- if (is.null(freq)) b[["hi"]] else min(b[["hi"]], 0.499 * freq)
      list(f0 = c(min(b[["lo"]], hi / 10), hi))
    },
    admissible = function(par, tau, freq) {
      f0 <- par[["f0"]]
      b <- visible_band(min(tau), max(tau), freq)
      if (!is.finite(f0) || f0 < b[["lo"]] * (1 - 1e-6) || f0 > b[["hi"]] * (1 + 1e-6)) {
        sprintf("f0 = %s Hz is outside the band the curve can see (%s-%s Hz)",
                format_num(f0), format_num(b[["lo"]]), format_num(b[["hi"]]))
      }
    },
    trace = function(ctx) {
      if (ctx$sign <= 0 || !is.finite(ctx$emax) ||
          !ctx$kind %in% c("bump", "long_end", "short_end", "oscillation")) {
        return(NULL)
      }
      list(init = list(f0 = sin_peak_ratio / ctx$tau_max,
                       amp = sqrt(ctx$emax) / sin_peak_adev),
           score = if (ctx$kind == "oscillation") 3 else 1)
    },
    propose = function(raw, tau, sig) {
      lines <- diag_part(raw, "lines")
      out <- list()
      if (is.null(lines) || !nrow(lines)) return(out)
      # only lines the curve can see; harmonics of one source say so
      lines <- visible_lines(harmonic_sets(lines), min(tau), max(tau),
                             diag_value(raw, "freq"))
      sharp <- if (is.null(lines$record_amp)) logical(nrow(lines))
        else is_sharp(lines$record_amp, lines$amp)
      # a sharp line where a band's shape has power enters at its measured
      # amplitude: sized free on the curve it took 10-15% more and, with
      # it, the band's power (a line 0.6 Hz beside a measured
      # accelerometer's 9.9 Hz band: the band was lost); the record's
      # least-squares sinusoid measures it
      on_band <- sharp & by_band_shape(diag_part(raw, "bands"), lines$f0)
      for (j in seq_len(nrow(lines))) {
        f0 <- lines$f0[j]
        if (!lines$visible[j]) next
        t1 <- sin_peak_ratio / f0
        h <- lines$harmonic[j]
        src <- if (lines$pattern[j] != "single") {
          sprintf(" (harmonic %d of the %s Hz source, %s harmonics)", h,
                  format_num(f0 / h, 4), lines$pattern[j])
        } else ""
        # a harmonic set is entered strongest line first: on the curve a
        # weak harmonic fitted early takes the power of the ones above it
        stronger <- lines$visible & lines$source == lines$source[j] &
          lines$amp > lines$amp[j]
        out[[length(out) + 1L]] <- list(
          after = if (any(stronger)) list(f0 = lines$f0[stronger]),
          init = list(f0 = f0, amp = lines$amp[j]), tau_from = t1 / 2,
          tau_to = 2 / f0, score = 2,
          # the periodogram measures f0 far better than the curve does,
          # and a sharp line's amp too: a further line of a set pinned
          # there cannot take the power of the set's lines not yet in the
          # model (a square wave's 9th and 11th harmonics, free, took 2.8
          # x their lines, and the axis's resonance beside them was lost)
          pin = if (on_band[j]) list(f0 = f0, amp = lines$record_amp[j])
            else if (any(stronger) && sharp[j]) list(f0 = f0, amp = lines$amp[j])
            else list(f0 = f0),
          note = sprintf("proposed by a periodogram line at %s Hz%s",
                         format_num(f0, 4), src))
      }
      out
    },
    evidence = evidence_sinusoid,
    raw_hold = hold_sinusoid,
    known_av = known_av_sinusoid,
    known_acov = known_acov_sinusoid,
    unheld = unheld_lines,
    # The periodogram's lines, less the bins of the broad bands (a
    # resonance's bins are not sinusoids); the checks of the other effects
    # see the series with them taken out (a line disturbs the ACF that
    # confirms a Gauss-Markov process).
    diagnose = list(
      part = "lines", reads = "raw", needs = "bands",
      make = function(x, freq, dg) {
        lines <- lines_outside_bands(diag_value(dg, "lines"), diag_part(dg, "bands"))
        # each line's least-squares sinusoid over the whole record: its
        # amplitude says whether the line holds one frequency (sharp), and
        # clean() takes the same sinusoids out
        fits <- record_line_fits(x, freq, lines$f0)
        lines$record_amp <- fits$amp
        attr(lines, "fits") <- fits
        lines
      },
      clean = function(x, freq, lines) {
        fits <- attr(lines, "fits")
        if (!nrow(lines)) x
        else if (!is.null(fits)) subtract_line_fits(x, freq, fits)
        else remove_lines(x, freq, lines$f0)
      }),
    peak_tau = function(par) sin_peak_ratio / par[["f0"]],
    describe = function(values) {
      sprintf("sinusoid (f0 = %s Hz)", paste(signif(values$f0, 3), collapse = ", "))
    }
  )
}
