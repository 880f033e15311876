# Catalogue entries of the power-law terms of IEEE Std 952: quantization Q,
# white noise N, flicker (bias instability) B, rate random walk K and the
# rate ramp R. Derivations and their checks: vignette("noise-terms").
#
# With tau0 known, `basis` is the exact discrete expectation for a sampled
# record at m = tau / tau0; these expressions are smooth in m, so non-integer
# m gives a smooth curve through the exact integer-m values. With tau0 =
# NULL, or m < 1, the continuous IEEE 952 forms are used.

# TRUE where the discrete form applies.
discrete_tau <- function(tau, tau0) !is.null(tau0) & tau >= tau0 * (1 - 1e-9)

flicker_plateau <- 2 * log(2) / pi

# Start values at one end of the curve, for a term whose ADEV has slope
# `slope`: the excess AV at the first (short) or last (long) tau of a run
# there, divided by the term's continuous basis.
trace_edge <- function(end, slope, param, basis) {
  function(ctx) {
    ends <- if (end == "short") c("short_end", "global") else c("long_end", "global")
    if (ctx$sign <= 0 || !ctx$kind %in% ends) return(NULL)
    e <- if (end == "short") ctx$e_first else ctx$e_last
    t <- if (end == "short") ctx$tau_first else ctx$tau_last
    list(init = stats::setNames(list(sqrt(e / basis(t, NULL, NULL))), param),
         score = score_slope(ctx$slope, slope))
  }
}

# ---- Q: quantization --------------------------------------------------------

effect_quantization <- function() {
  basis <- function(tau, tau0, nl) 3 / tau^2
  new_effect(
    name = "Q", title = "quantization noise",
    params = effect_param("Q", "amp", "u*s",
                          "rate unit x second (angle quantum / sqrt(12))"),
    slope = -1, psd_alpha = 2,
    formula = "3 Q^2 / tau^2 (exact for differenced uniform noise)",
    signature = paste("ADEV slope -1, largest at the smallest tau;",
                      "lag-1 ACF of the rate near -1/2; LSB grid"),
    basis = basis,
    # y_k = (e_{k+1} - e_k) / tau0, Var e = Q^2
    acf = function(h, tau0, nl) ifelse(h == 0, 2, ifelse(abs(h) == 1, -1, 0)) / tau0^2,
    psd = NULL,
    sim = function(n, tau0, amp, nl) {
      e <- stats::runif(n + 1L, -sqrt(3) * amp[[1L]], sqrt(3) * amp[[1L]])
      diff(e) / tau0
    },
    edf_alpha = function(tau, tau0, nl) rep(2, length(tau)),
    # white phase: the structure function of the phase is 2 Q^2 / tau0^2 for l > 0
    exact_edf = function(amp, nl, tau0) list(list(shape = "step", coef = amp[[1L]]^2 / tau0^2)),
    trace = trace_edge("short", -1, "Q", basis),
    evidence = evidence_quantization,
    diagnose = list(part = "quantization", reads = "raw", needs = "lines",
                    make = function(x, freq, dg) {
                      quantization_lag1(x, freq, diag_part(dg, "lines"))
                    })
  )
}

# ---- N: white noise ---------------------------------------------------------

effect_white <- function() {
  basis <- function(tau, tau0, nl) 1 / tau
  new_effect(
    name = "N", title = "white noise (angle / velocity random walk)",
    params = effect_param("N", "amp", "u*sqrt(s)",
                          "rate unit x sqrt(second) (angle/velocity random walk)"),
    slope = -0.5, psd_alpha = 0,
    formula = "N^2 / tau",
    signature = "ADEV slope -1/2; flat PSD, ACF near 0",
    basis = basis,
    psd = function(f, nl) rep(1, length(f)),
    acf = function(h, tau0, nl) ifelse(h == 0, 1 / tau0, 0),
    sim = function(n, tau0, amp, nl) stats::rnorm(n, sd = amp[[1L]] / sqrt(tau0)),
    statespace = function(amp, nl, tau0) list(R = amp[[1L]]^2 / tau0),
    edf_alpha = function(tau, tau0, nl) rep(0, length(tau)),
    # random-walk phase: structure function (N^2 / tau0) l
    exact_edf = function(amp, nl, tau0) list(list(shape = "linear", coef = amp[[1L]]^2 / tau0)),
    trace = trace_edge("short", -0.5, "N", basis),
    evidence = evidence_noise_id(0),
    reading = list(symbol = "N", role = "white", tau = 1, slope = -0.5,
                   anchor = "first", unit = "N", bound = FALSE, resolve = FALSE,
                   pch = 21, legend = "N: -1/2 line at tau = 1 s",
                   slope_method = "slope -1/2 line"),
    discrete = function(par, dt, unit, opts) {
      n <- par[[1L]]
      discrete_row("N", "sigma_d", n / sqrt(dt), unit("rate"), n, unit("N"),
                   "white noise per sample: y[k] = sigma_d * w[k], sigma_d = N / sqrt(dt)")
    }
  )
}

# ---- B: flicker (bias instability), exact discrete Kasdin form -------------
# AV(m) / (2 ln2 B^2 / pi) = 1 + c(m) / m^2, where
# AV(m) = (2 B^2 / pi) * int_0^{pi/2} sin^4(m u) / (m^2 sin^3 u) du.
# c(m) tabulated by composite Simpson integration (>= 40000 panels, >= 800 per
# period of sin^4(m u)); c(1) = 1/ln 2 - 1 exactly. For large m, c(m) grows by
# 3/16 per doubling of m (checked to 4096), which gives the extrapolation.
flicker_table <- list(
  m = c(1:16, 20, 24, 32, 48, 64, 96, 128, 192, 256, 512, 1024, 2048, 4096),
  c = c(0.4426950409, 0.6166241308, 0.7233065772, 0.8000228111, 0.8598628084,
        0.9088954024, 0.95042024, 0.9864279848, 1.018211104, 1.046655918,
        1.072396513, 1.095902098, 1.117529577, 1.137556726, 1.156203965,
        1.173649124, 1.233977033, 1.283277714, 1.36107907, 1.470746552,
        1.548561537, 1.65823876, 1.736057158, 1.845736824, 1.923556085,
        2.111055904, 2.298556211, 2.486057692, 2.673563682)
)
flicker_c <- local({
  spline <- stats::splinefun(log(flicker_table$m), flicker_table$c,
                             method = "monoH.FC")
  function(m) {
    big <- m > 4096
    out <- numeric(length(m))
    out[!big] <- spline(log(m[!big]))
    out[big] <- 2.673563682 + 3 / (16 * log(2)) * log(m[big] / 4096)
    out
  }
})

# Ratio of the exact discrete flicker AV to the IEEE plateau 2 ln2 B^2 / pi.
flicker_ratio <- function(m) 1 + flicker_c(m) / m^2

# Kasdin & Walter (1992) 1/f generator: y = h * w, h_k = h_{k-1} (k - 1/2)/k,
# w ~ N(0, q_d), q_d = B^2. Linear convolution by zero-padded FFT. A warm-up
# of `warm` samples is generated and dropped so that early samples have a
# (nearly) full filter history.
sim_flicker <- function(n, B, warm = n) {
  len <- n + warm
  k <- seq_len(len - 1L)
  h <- cumprod(c(1, (k - 0.5) / k))
  w <- stats::rnorm(len, sd = B)
  nfft <- stats::nextn(2L * len)
  hz <- c(h, numeric(nfft - len))
  wz <- c(w, numeric(nfft - len))
  y <- Re(stats::fft(stats::fft(hz) * stats::fft(wz), inverse = TRUE)) / nfft
  y[(warm + 1L):len]
}

effect_flicker <- function() {
  basis <- function(tau, tau0, nl) {
    out <- rep(flicker_plateau, length(tau))
    d <- discrete_tau(tau, tau0)
    if (any(d)) out[d] <- out[d] * flicker_ratio(tau[d] / tau0)
    out
  }
  new_effect(
    name = "B", title = "flicker noise (bias instability)",
    params = effect_param("B", "amp", "u", "rate unit (bias instability)"),
    slope = 0, psd_alpha = -1,
    formula = paste("(2 ln2 / pi) B^2 x exact Kasdin ratio",
                    "(1.443 at m = 1, 1.050 at m = 4)"),
    signature = "ADEV slope 0: a flat minimum; PSD ~ 1/f",
    basis = basis,
    psd = function(f, nl) 1 / (2 * pi * f),
    sim = function(n, tau0, amp, nl) sim_flicker(n, amp[[1L]]),
    edf_alpha = function(tau, tau0, nl) rep(-1, length(tau)),
    trace = function(ctx) {
      if (ctx$sign <= 0 || !is.finite(ctx$emax) ||
          !ctx$kind %in% c("bump", "long_end", "short_end", "oscillation")) {
        return(NULL)
      }
      list(init = list(B = sqrt(ctx$emax / flicker_plateau)),
           score = if (ctx$kind == "bump" && isTRUE(ctx$width > 30)) 2 else 1)
    },
    evidence = evidence_noise_id(-1),
    reading = list(symbol = "B", role = "flicker", tau = NA_real_, slope = 0,
                   anchor = "min", unit = "rate", bound = FALSE, resolve = FALSE,
                   pch = 24, legend = "B: flat minimum (ADEV = 0.664 B)",
                   slope_method = "min ADEV / 0.664",
                   # how kalman_params() may stand in for B (the first is
                   # its default): one Gauss-Markov term, or left out
                   approximations = c("gm", "omit")),
    # No finite-state model exists; optionally approximated by one GM whose
    # ADEV peak (0.6174 sigma at tau = 1.893 Tc) sits on the flat minimum.
    discrete = function(par, dt, unit, opts) {
      b <- par[[1L]]
      if (!identical(opts$bias_instability, "gm") || !is.finite(b) || !(b > 0) ||
          !is.finite(opts$tau_B)) {
        return(NULL)
      }
      gm_discrete_rows("B", 0.664 * b / gm_peak_adev,
                       opts$tau_B / gm_peak_ratio, dt, unit,
                       "bias instability approximated (Tc = tau_B / 1.893, sigma = 0.664 B / 0.6174) by ")
    }
  )
}

# ---- K: rate random walk ----------------------------------------------------

effect_random_walk <- function() {
  basis <- function(tau, tau0, nl) {
    out <- tau / 3
    d <- discrete_tau(tau, tau0)
    if (any(d)) out[d] <- out[d] + tau0^2 / (6 * tau[d])
    out
  }
  new_effect(
    name = "K", title = "rate random walk",
    params = effect_param("K", "amp", "u/sqrt(s)",
                          "rate unit / sqrt(second) (rate random walk)"),
    slope = 0.5, psd_alpha = -2,
    formula = "K^2 tau / 3 + K^2 tau0^2 / (6 tau)",
    signature = "ADEV slope +1/2 at long tau; PSD ~ 1/f^2",
    basis = basis,
    psd = function(f, nl) 1 / (2 * pi * f)^2,
    sim = function(n, tau0, amp, nl) cumsum(stats::rnorm(n, sd = amp[[1L]] * sqrt(tau0))),
    # the walk's level (the sensor's bias) is unknown: a diffuse start
    statespace = function(amp, nl, tau0) list(T = 1, Q = amp[[1L]]^2 * tau0, P0 = Inf),
    edf_alpha = function(tau, tau0, nl) rep(-2, length(tau)),
    # integrated random walk: structure function -K^2 tau0 (l^3 - l) / 6
    exact_edf = function(amp, nl, tau0) list(list(shape = "cubic", coef = amp[[1L]]^2 * tau0)),
    trace = trace_edge("long", 0.5, "K", basis),
    evidence = evidence_noise_id(-2),
    reading = list(symbol = "K", role = "random_walk", tau = 3, slope = 0.5,
                   anchor = "last", unit = "K", bound = TRUE, resolve = TRUE,
                   pch = 22, legend = "K: +1/2 line at tau = 3 s",
                   slope_method = "slope +1/2 line",
                   bound_method = "upper bound (+1/2 region not reached)"),
    discrete = function(par, dt, unit, opts) {
      k <- par[[1L]]
      discrete_row("K", "sigma_bd", k * sqrt(dt), unit("rate"), k, unit("K"), paste0(
        "bias random walk: b[k] = b[k-1] + sigma_bd * w[k], sigma_bd = K * sqrt(dt)",
        if (isTRUE(opts$bound)) " (K is an upper bound: +1/2 region not reached)" else ""))
    }
  )
}

# ---- R: rate ramp -----------------------------------------------------------

effect_ramp <- function() {
  basis <- function(tau, tau0, nl) tau^2 / 2
  new_effect(
    name = "R", title = "rate ramp",
    params = effect_param("R", "amp", "u/s", "rate unit / second (rate ramp)"),
    slope = 1, psd_alpha = NA_real_,
    formula = "R^2 tau^2 / 2 (exact for y_k = R tau0 k)",
    signature = "ADEV slope +1 at the longest tau; a trend in the data",
    basis = basis,
    sim = function(n, tau0, amp, nl) amp[[1L]] * tau0 * seq_len(n),
    # deterministic: the AV estimate of a ramp has no variance
    edf_alpha = function(tau, tau0, nl) rep(NA_real_, length(tau)),
    trace = trace_edge("long", 1, "R", basis),
    propose = function(raw, tau, sig) {
      tr <- diag_value(raw, "trend")
      if (!isTRUE(tr$significant) || isTRUE(tr$z <= 5)) return(list())
      list(list(init = list(R = abs(tr$slope)), tau_from = max(tau) / 10,
                tau_to = max(tau), score = 1,
                note = sprintf("proposed by a linear trend of %s /s",
                               format_num(tr$slope))))
    },
    evidence = evidence_trend
  )
}

# One row of kalman_params().
discrete_row <- function(term, parameter, value, unit, continuous,
                         continuous_unit, convention) {
  data.frame(term = term, parameter = parameter, value = value, unit = unit,
             continuous = continuous, continuous_unit = continuous_unit,
             convention = convention, stringsAsFactors = FALSE)
}

# ---- raw-data evidence of the power-law terms --------------------------------

# Quantization: the lag-1 ACF of differenced uniform noise is -1/2; an LSB
# grid is reported when present. The lag-1 ACF is read without the
# periodogram's lines (quantization_lag1()): a line near Nyquist makes it
# negative too (a 46.8 Hz line at 100 Hz: -0.10 on a sensor whose lag-1 ACF
# without it is positive). (A bare avdiagnose(): its raw lag-1 ACF.)
evidence_quantization <- function(par, raw, x, freq) {
  g <- diag_value(raw, "grid")
  q <- diag_part(raw, "quantization") %||%
    list(r1 = diag_value(raw, "acf1"), z1 = diag_value(raw, "acf1_z"), lines = 0L)
  txt <- sprintf("raw lag-1 ACF %.3f (z = %.0f)%s", q$r1, q$z1,
                 if (q$lines > 0L) sprintf(" without its %d periodogram line%s", q$lines,
                                           if (q$lines > 1L) "s" else "") else "")
  if (isTRUE(g$quantized)) {
    txt <- paste0(txt, sprintf("; LSB grid step %s (%.0f%% on grid)",
                               format_num(g$step), 100 * g$on_grid))
  }
  list(text = txt, support = q$z1 < -3)
}

# The raw lag-1 autocorrelation with the periodogram's lines taken out of
# the autocovariances (a line of amplitude a at f adds a^2/2 to the
# variance and a^2/2 cos(2 pi f tau0) at lag 1).
quantization_lag1 <- function(x, freq, lines) {
  n <- length(x)
  a <- acf_sums(x - mean(x), 1L) / n
  p <- lines$amp^2 / 2
  c0 <- a[1L] - sum(p)
  c1 <- a[2L] - sum(p * cos(2 * pi * lines$f0 / freq))
  r1 <- if (c0 > 0) c1 / c0 else NA_real_
  list(r1 = r1, z1 = r1 * sqrt(n), lines = NROW(lines))
}

# A ramp: a significant linear trend (read beyond the series effects left
# in the data: stage_prepare()) of the size the curve asks for. A fitted R
# beyond this multiple of the raw slope stands in for something else: on
# white noise and a random walk with a 900 s warm-up left in, the curve's
# long-tau rise took a ramp of 21x the slope left beside the warm-up.
ramp_slope_factor <- 3
evidence_trend <- function(par, raw, x, freq) {
  tr <- diag_value(raw, "trend")
  R <- abs(par[["R"]] %||% NA_real_)
  big <- is.finite(R) && R > ramp_slope_factor * abs(tr$slope)
  # (a significant t that the likelihood beside the noise's own wander
  # does not back, z <= 5, is a random walk's drift)
  z <- tr$z %||% NA_real_
  red <- is.finite(z) && z <= 5
  list(text = sprintf("linear trend %s /s (t = %.1f%s)%s", format_num(tr$slope), tr$t,
                      if (is.finite(z)) sprintf(", likelihood z = %.1f", z) else "",
                      if (big) sprintf(", %.1f x below the fitted R %s",
                                       R / abs(tr$slope), format_num(R)) else ""),
       support = tr$significant && !big && !red)
}

# A power-law term of rate-PSD exponent `alpha`: the lag-1 noise
# identification finds that exponent at some averaging time.
evidence_noise_id <- function(alpha) {
  force(alpha)
  function(par, raw, x, freq) {
    ni <- diag_value(raw, "noise_id")
    ni <- ni[is.finite(ni$alpha), , drop = FALSE]
    hit <- ni[round(ni$alpha) == alpha, , drop = FALSE]
    if (nrow(hit)) {
      list(text = sprintf("lag-1 noise id %s at tau %s s", noise_name(alpha),
                          paste(format_num(hit$tau), collapse = ", ")),
           support = TRUE)
    } else {
      list(text = sprintf("lag-1 noise id never %s", noise_name(alpha)), support = NA)
    }
  }
}
