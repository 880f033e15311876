# Catalogue entries of the sensor's own filtering: white noise through the
# sensor's low-pass filter ("filter", a family of variants), and a narrow-band random process ("resonance"). The math,
# simulators and raw-data evidence live in R/filter-noise.R and
# R/resonance.R; this file states the facts the catalogue asks for.

# The filter spec of a fitted instance: variant and nonlinear values.
filter_spec_of <- function(variant, nl, tau0) {
  switch(variant,
    ma = list(family = "ma", L = max(1, nl[["L"]])),
    lp1 = , lp2 = list(family = variant, fc = nl[["fc"]], freq = 1 / tau0),
    ar2 = list(family = "ar2", fn = nl[["fn"]], zeta = nl[["zeta"]], freq = 1 / tau0))
}

# One variant's fields: the nonlinear parameters (L in samples for the
# moving average, fc in Hz for the low-passes, fn in Hz and the damping
# zeta for the all-pole section) and their search ranges.
filter_variant <- function(variant) {
  nlp <- switch(variant,
    ma = effect_param("L", "nonlinear", "samples",
                      "averaging window in output periods (may be fractional)",
                      profile = "smooth"),
    lp1 = , lp2 = effect_param("fc", "nonlinear", "Hz", "hertz (-3 dB cutoff)",
                               profile = "smooth", print_unit = TRUE),
    ar2 = rbind(effect_param("fn", "nonlinear", "Hz", "hertz (natural frequency)",
                             profile = "smooth", print_unit = TRUE),
                effect_param("zeta", "nonlinear", "1", "damping ratio",
                             profile = "smooth")),
    NULL)
  if (is.null(nlp)) return(NULL)
  list(
    params = rbind(effect_param("Nf", "amp", "u*sqrt(s)",
                                "rate unit x sqrt(second) (white level at DC, as N)"),
                   nlp),
    nl_range = function(tau, freq) {
      if (variant == "ma") list(L = c(1.001, 64))
      else if (variant == "ar2") list(fn = c(freq / 2000, 0.499 * freq), zeta = c(0.4, 3))
      else list(fc = c(freq / 2000, if (variant == "lp2") 0.499 * freq else 0.5 * freq))
    },
    # The filter acts between the sampling interval and the longest tau:
    # L from 1 sample (white) to tau_max; fc from 1/(2 pi tau_max) to
    # Nyquist (lp2's bilinear form needs fc below it).
    nl_bounds = function(tau, freq) {
      span <- if (is.null(freq)) max(tau) / min(tau) else max(tau) * freq
      nyq <- if (is.null(freq)) 0.5 / min(tau) else 0.5 * freq
      if (variant == "ma") return(list(L = c(1, max(span, 1.001))))
      fc <- c(min(1 / (2 * pi * max(tau)), nyq / 1000),
              if (variant == "lp1") nyq else 0.998 * nyq)
      if (variant == "ar2") list(fn = fc, zeta = ar2_zeta_bounds) else list(fc = fc)
    },
    # At its bounds the filter is no filter the data show: L = 1 is white
    # noise, and a first-order low-pass at Nyquist is as near white as
    # that family gets (lag-1 correlation 3 - sqrt(8) = 0.17, its least):
    # the fit has run into the family's edge, not onto a cutoff, so the
    # data ask for another family, or for N.
    admissible = function(par, tau, freq) {
      if (variant == "ma" && is.finite(par[["L"]]) && par[["L"]] <= 1.001) {
        return(sprintf("L = %s samples: that is white noise (N), not a filter",
                       format_num(par[["L"]])))
      }
      if (variant == "lp1" && !is.null(freq) &&
          (!is.finite(par[["fc"]]) || par[["fc"]] >= 0.499 * freq)) {
        return(sprintf(paste("fc = %s Hz is at the Nyquist bound, the edge of the",
                             "first-order family (the nearest it comes to white",
                             "noise), not a cutoff the data show"),
                       format_num(par[["fc"]])))
      }
      if (variant == "ar2") {
        z <- par[["zeta"]]
        if (!is.finite(z) || z <= ar2_zeta_bounds[1L] * 1.001) {
          return(sprintf(paste("zeta = %s: a peak that sharp is a resonance's,",
                               "not a low-pass filter's"), format_num(z)))
        }
        if (z >= ar2_zeta_bounds[2L] / 1.001 ||
            (!is.null(freq) && par[["fn"]] >= 0.997 * 0.5 * freq)) {
          return(sprintf(paste("fn = %s Hz, zeta = %s is at the edge of the",
                               "second-order family, not a filter the data show"),
                         format_num(par[["fn"]]), format_num(z)))
        }
      }
      NULL
    },
    formula = paste0("N^2 x exact AV of the ", variant,
                     " filter's autocovariance (unit DC gain)")
  )
}

# The families the loop chooses among (the bare "filter" is the first).
filter_family_variants <- c("ma", "lp1", "lp2", "ar2")

effect_filter <- function() {
  base <- filter_variant("ma")
  basis <- function(variant) {
    force(variant)
    function(tau, tau0, nl) {
      out <- 1 / tau
      d <- discrete_tau(tau, tau0)
      if (any(d)) {
        sp <- filter_spec_of(variant, nl, tau0)
        out[d] <- filter_av(tau[d] / tau0, sp, tau0)
      }
      out
    }
  }
  entry <- function(variant) {
    v <- filter_variant(variant)
    if (is.null(v)) return(NULL)
    c(v, list(
      basis = basis(variant),
      acf = function(h, tau0, nl) filter_acf(filter_spec_of(variant, nl, tau0), tau0, h),
      sim = function(n, tau0, amp, nl) {
        sim_filtered_white(n, tau0, amp[[1L]], filter_spec_of(variant, nl, tau0))
      },
      evidence = function(par, raw, x, freq) {
        if (is.null(x)) return(list(text = "", support = NA))
        sp <- filter_spec_of(variant, par, 1 / freq)
        # the diagnostics' filter part: filter_evidence() of this same
        # series, read once
        filter_raw_support(sp, par[["Nf"]],
                           diag_part(raw, "filter") %||% filter_evidence(x, freq),
                           diag_var(raw, x), freq)
      },
      # a second shape parameter must be seen beyond lag 1, beside the
      # model's other terms
      model_evidence = if (variant == "ar2") function(ev, fit, label, raw, freq) {
        par <- instance_params(stats::coef(fit), fit$layout, label)
        sp <- filter_spec_of(variant, as.list(par), 1 / freq)
        filter_shape_support(ev, sp, par[["Nf"]], fit, raw, freq)
      }
    ))
  }
  e <- new_effect(
    name = "filter", title = "white noise through the sensor's filter",
    params = base$params, variants = entry,
    slope = -0.5, psd_alpha = 0,
    formula = base$formula,
    signature = paste("ADEV below the white -1/2 line at the first taus",
                      "(AV = N^2/tau - 3C/tau^2 beyond the filter's length);",
                      "positive short-lag ACF; periodogram rolling off towards Nyquist"),
    basis = basis("ma"),
    acf = function(h, tau0, nl) filter_acf(filter_spec_of("ma", nl, tau0), tau0, h),
    sim = function(n, tau0, amp, nl) {
      sim_filtered_white(n, tau0, amp[[1L]], filter_spec_of("ma", nl, tau0))
    },
    edf_alpha = function(tau, tau0, nl) rep(0, length(tau)),
    nl_range = base$nl_range,
    nl_bounds = base$nl_bounds,
    admissible = base$admissible,
    trace = function(ctx) {
      # the model's white line runs above the first points
      if (ctx$kind != "short_end" || ctx$sign >= 0) return(NULL)
      list(init = list(L = 2), score = 2)
    },
    # The raw data propose the filter themselves when the short-lag ACF
    # beyond the slow processes is significant: one start per family the
    # lag-1 excess can be inverted for (moving average, first- and
    # second-order low-pass); the criterion picks the family.
    propose = function(raw, tau, sig) {
      fe <- diag_part(raw, "filter")
      if (is.null(fe) || !isTRUE(fe$filtered)) return(list())
      out <- list()
      for (v in filter_family_variants) {
        st <- fe$start[[v]]
        if (is.null(st)) next
        out[[length(out) + 1L]] <- list(
          effect = family_term("filter", filter_family_variants, v),
          init = st, tau_from = min(tau), tau_to = 4 * min(tau), score = 2,
          note = sprintf(paste("proposed by the raw lag-1 autocorrelation beyond the",
                               "slow processes, %.3f (z = %.0f): %s family"),
                         fe$r1, fe$z1, v))
      }
      out
    },
    evidence = entry("ma")$evidence,
    # the filter keeps the DC level: N is the white reading
    fold = list(into = "white", when = function(par) TRUE,
                amount = function(par) par[["Nf"]]^2,
                note = "white level of the filtered term"),
    describe = function(values) "filter (the sensor's averaging)",
    # the short-lag ACF beyond the slow processes, of the series without
    # lines and bands (a resonance raises the short-lag ACF too)
    diagnose = list(part = "filter", reads = "clean",
                    make = function(x, freq, dg) filter_evidence(x, freq)),
    # the families describe one filter: the loop chooses among them again
    # on the final model, each started from the raw lag-1 excess
    family = list(variants = filter_family_variants,
                  start = function(raw, variant) diag_part(raw, "filter")$start[[variant]]),
    # the filtered white term carries the white level itself (N^2 = S(0))
    replaces = "N"
  )
  e
}

effect_resonance <- function() {
  new_effect(
    name = "resonance", title = "narrow-band random process (a resonance)",
    params = rbind(
      effect_param("sigma", "amp", "u", "rate unit (standard deviation)"),
      effect_param("fr", "nonlinear", "Hz", "hertz (centre frequency)",
                   profile = "oscillatory", print_unit = TRUE),
      effect_param("tc", "nonlinear", "s", "second (damping time; FWHM 1/(pi tc))",
                   profile = "smooth", print_unit = TRUE)),
    repeatable = TRUE, slope = NA_real_, psd_alpha = NA_real_,
    formula = "a real AR(2) (damped oscillator) with poles exp(-tau0/tc +- 2 pi i fr tau0)",
    signature = paste("a bump at tau ~ 0.37/fr with nulls like a sinusoid's but",
                      "damped; a broad periodogram band at fr of width 1/(pi tc)"),
    basis = function(tau, tau0, nl) {
      if (is.null(tau0)) tau0 <- min(tau) / 4
      m <- tau / tau0
      m[m < 1] <- 1  # pmax(tau / tau0, 1): a search calls this thousands of times
      resonance_av(m, tau0, 1, nl[["fr"]], nl[["tc"]])
    },
    acf = function(h, tau0, nl) resonance_acf(h, tau0, 1, nl[["fr"]], nl[["tc"]]),
    sim = function(n, tau0, amp, nl) sim_resonance(n, tau0, amp[[1L]], nl[["fr"]], nl[["tc"]]),
    edf_alpha = function(tau, tau0, nl) rep(0, length(tau)),
    nl_range = function(tau, freq) {
      hi <- if (is.null(freq)) 0.5 / min(tau) else 0.499 * freq
      list(fr = c(hi / 100, hi), tc = c(min(tau) / 2, max(tau)))
    },
    # fr within the band the curve sees and below Nyquist; tc from a sample
    # (a band as wide as the spectrum) to the record (a line)
    nl_bounds = function(tau, freq) {
      b <- visible_band(min(tau), max(tau), freq)
      hi <- if (is.null(freq)) b[["hi"]] else min(b[["hi"]], 0.499 * freq)
      tc_lo <- if (is.null(freq)) min(tau) / 4 else min(1 / freq, min(tau) / 2)
      list(fr = c(min(b[["lo"]], hi / 100), hi), tc = c(tc_lo, max(tau)))
    },
    evidence = function(par, raw, x, freq) {
      if (is.null(x)) return(list(text = "", support = NA))
      # the bands of the raw data (the diagnostics' part), not of `x`, the
      # series with the bands brought down to their background
      resonance_raw_support(par[["sigma"]], par[["fr"]], par[["tc"]],
                            diag_part(raw, "bands") %||% find_bands(x, freq))
    },
    # A broad band of the periodogram proposes a resonance with its centre
    # and width pinned where find_bands() measures them: the curve sees the
    # band only through the AV's sinc filter, places fr poorly and cannot
    # tell a band 0.5 Hz wide from a tone, so a free tc runs off. Once the
    # pinned trial passes, they are released (`release`): refitted free
    # from there, the curve refines a centre the Welch spectrum read 0.2%
    # off; the raw-data check still asks for the band within half its
    # width of fr. (A free trial beside the pinned one, screened whether or
    # not the pinned one passed, paid 0 of 68 times on the 18 ADIS16405
    # axes for a quarter of the screening time.) A band whose shape is not
    # the AR(2)'s is the measured band's (entry "band").
    propose = function(raw, tau, sig) {
      b <- diag_part(raw, "bands")
      out <- list()
      if (is.null(b) || !nrow(b)) return(out)
      hi <- min(0.5 / min(tau), 0.499 * diag_value(raw, "freq"))
      b <- b[b$f_center > 1 / max(tau) & b$f_center < hi, , drop = FALSE]
      b <- b[order(-b$power), , drop = FALSE]
      # the two strongest bands; a band two resonances fit better gives both
      b <- band_resonances(b[seq_len(min(2L, nrow(b))), , drop = FALSE])
      b <- b[b$f_center > 1 / max(tau) & b$f_center < hi, , drop = FALSE]
      for (j in seq_len(nrow(b))) {
        st <- resonance_start(b[j, ])
        note <- sprintf("proposed by a spectral band at %s Hz (FWHM %s Hz, %.0f%% of the variance)",
                        format_num(b$f_center[j], 4), format(signif(b$width[j], 2)),
                        100 * b$share[j])
        one <- list(init = st, tau_from = 0.371 / st$fr / 2, tau_to = 2 / st$fr,
                    score = 2, note = note)
        # One of two resonances the run resolves stays where the raw data
        # measure it until the loop ends (`release_late`): released at once, the
        # first one in spread over its neighbour (a 9.86 Hz resonance beside
        # an added 8.1 Hz band: one resonance at 8.25 Hz); freed beside the
        # other, the curve refines a shape that is not quite the AR(2)'s (a
        # z gyro's own 20 Hz band beside an added 22.1 Hz one)
        out[[length(out) + 1L]] <- c(one, list(pin = list(fr = b$f_center[j], tc = b$tc[j]),
                                               release = !b$paired[j], release_late = b$paired[j]))
      }
      out
    },
    raw_hold = hold_resonance,
    absorbs = resonance_absorbs,
    peak_tau = function(par) 0.371 / par[["fr"]],
    # the broad bands of the raw periodogram; the checks of the other
    # effects see them brought down to their background
    diagnose = list(part = "bands", reads = "raw",
                    make = function(x, freq, dg) {
                      bands_without_lines(x, freq, diag_value(dg, "lines"), raw_welch(dg))
                    },
                    clean = function(x, freq, bands) remove_bands(x, freq, bands)),
    describe = function(values) {
      sprintf("resonance (%s Hz)", paste(signif(values$fr, 3), collapse = ", "))
    }
  )
}
