# Filtered white noise: white rate noise seen through the sensor's own
# low-pass (decimation/averaging) filter. The math, the simulator and the
# raw-data evidence of one effect; the catalogue entry
# reads these functions.
#
# Normalisation. The filter has unit DC gain, so N keeps its meaning: N^2 is
# the two-sided rate PSD at f = 0 (the -1/2 line of the ADEV at long tau, the
# white level a navigation filter needs). The filter only bends the curve at
# tau of a few samples: the AV falls below N^2/tau there.
#
# A filter is a list `spec` with `family` and its parameters:
#   ma        moving average over L output periods; L >= 1 may be fractional
#             (a sensor averaging a fast internal stream over a window a bit
#             longer than its output period). Autocovariance triangular,
#             g(k) ~ max(L - |k|, 0), exactly that of the L-tap moving
#             average for whole L.
#   bartlett  n cascaded moving averages of L taps (L whole; n = 2 is the
#             triangular/Bartlett window).
#   lp1       first-order low-pass y_k = a y_{k-1} + (1 - a) w_k, with a
#             set so that the PSD is -3 dB at fc (Hz).
#   lp2       second-order Butterworth low-pass (bilinear transform,
#             pre-warped: -3 dB exactly at fc).
#   ar2       second-order all-pole low-pass y_k = a1 y_{k-1} + a2 y_{k-2}
#             + (1 - a1 - a2) w_k, its poles those of a continuous
#             second-order section of natural frequency fn (Hz) and
#             damping zeta mapped by z = exp(s tau0): a recursive sensor
#             filter of any damping (complex poles below zeta = 1), which
#             the Butterworth's fixed damping and zeros at Nyquist do not
#             describe.
#   fir       given FIR coefficients h (scaled to sum 1).

# ---- specification -----------------------------------------------------------

filter_families <- function() c("ma", "bartlett", "lp1", "lp2", "ar2", "fir")

# The families with a pole-residue form (filter_rational()).
rational_family <- function(spec) spec$family %in% c("lp1", "lp2", "ar2")

# Build and check a filter specification. `freq` (Hz) is needed for the
# cutoff families (fc must lie below the Nyquist frequency).
filter_spec <- function(family, L = NULL, n = 2L, fc = NULL, h = NULL,
                        freq = NULL, fn = NULL, zeta = NULL) {
  family <- check_choice(family, filter_families(), "family")
  switch(family,
    ma = list(family = "ma", L = check_number(L, "L", 1, 1e6)),
    bartlett = list(family = "bartlett",
                    L = check_number(L, "L", 1, 1e5, integer = TRUE),
                    n = check_number(n, "n", 1, 8, integer = TRUE)),
    lp1 = , lp2 = {
      freq <- check_freq(freq)
      hi <- freq / 2
      fc <- check_number(fc, "fc", 0, hi, open = family == "lp2")
      if (fc <= 0) {
        abort("`fc` must be a single positive number (cutoff in Hz), not ",
              format_value(fc), ".", class = "argument")
      }
      list(family = family, fc = fc, freq = freq)
    },
    ar2 = {
      freq <- check_freq(freq)
      fn <- check_number(fn, "fn", 0, freq / 2, open = TRUE)
      zeta <- check_number(zeta, "zeta", 0, Inf, open = TRUE)
      list(family = "ar2", fn = fn, zeta = zeta, freq = freq)
    },
    fir = {
      if (!is.numeric(h) || length(h) < 1L || anyNA(h) || any(!is.finite(h))) {
        abort("`h` must be a numeric vector of FIR coefficients, not ",
              describe_type(h), ".", class = "argument")
      }
      if (!(sum(h) > 0)) {
        abort("`h` must have a positive sum (a low-pass with gain at DC); ",
              "its sum is ", format(sum(h)), ".", class = "argument")
      }
      list(family = "fir", h = as.double(h) / sum(h))
    }
  )
}

# ---- autocovariance ------------------------------------------------------------

# FIR taps of a spec whose autocovariance has finite support (NULL for the
# IIR families and for fractional ma, whose autocovariance is given
# directly).
filter_taps <- function(spec) {
  switch(spec$family,
    ma = if (spec$L == round(spec$L)) rep(1 / spec$L, spec$L) else NULL,
    bartlett = {
      h <- rep(1 / spec$L, spec$L)
      out <- 1
      for (i in seq_len(spec$n)) out <- stats::convolve(out, rev(h), type = "open")
      out
    },
    fir = spec$h,
    NULL)
}

# Autocovariance of the unit-DC FIR taps at lags 0..length(h)-1.
taps_acov <- function(h) {
  L <- length(h)
  if (L == 1L) return(h^2)
  vapply(0:(L - 1L), function(k) sum(h[1:(L - k)] * h[(1 + k):L]), 0)
}

# Rational (pole-residue) form of the IIR families: H(z) = c0 +
# sum_j r_j / (1 - p_j z^-1). For unit-variance white input the
# autocovariance is g(k) = sum_l A_l p_l^|k| + d0 [k == 0] with
# A_l = r_l (c0 + sum_j r_j / (1 - p_j p_l)) and
# g(0) = c0^2 + 2 c0 sum r + sum_jl r_j r_l / (1 - p_j p_l)
# (sum the impulse response products; complex for conjugate poles).
filter_rational <- function(spec) {
  tau0 <- 1 / spec$freq
  if (spec$family == "ar2") return(ar2_rational(spec$fn, spec$zeta, tau0))
  w <- 2 * pi * spec$fc * tau0
  if (spec$family == "lp1") {
    # |H|^2 = (1-a)^2 / (1 - 2a cos w + a^2) = 1/2  =>  a^2 - 2a(2 - cos w) + 1 = 0
    cw <- cos(w)
    a <- (2 - cw) - sqrt((2 - cw)^2 - 1)
    return(list(c0 = 0, r = 1 - a + 0i, p = a + 0i))
  }
  # Butterworth, bilinear with pre-warping: K = tan(pi fc tau0).
  K <- tan(w / 2)
  den <- 1 + sqrt(2) * K + K^2
  b <- c(1, 2, 1) * K^2 / den
  a1 <- 2 * (K^2 - 1) / den
  a2 <- (1 - sqrt(2) * K + K^2) / den
  p <- polyroot(c(a2, a1, 1))             # roots of z^2 + a1 z + a2
  # H(z) = (b0 + b1 z^-1 + b2 z^-2) / ((1 - p1 z^-1)(1 - p2 z^-1))
  c0 <- b[3] / a2
  # residues: r_j = lim (1 - p_j z^-1) (H(z) - c0) at z = p_j
  res <- function(z, other) {
    num <- b[1] + b[2] / z + b[3] / z^2 - c0 * (1 + a1 / z + a2 / z^2)
    num / (1 - other / z)
  }
  r <- c(res(p[1L], p[2L]), res(p[2L], p[1L]))
  list(c0 = c0, r = r, p = p)
}

# The all-pole second-order section: poles exp(s tau0) with s = wn (-zeta
# +- sqrt(zeta^2 - 1)), gain (1 - p1)(1 - p2) for unit DC; residues
# r_j = g p_j / (p_j - p_other). A double pole (zeta = 1) is moved off by
# 1e-6 (its residues are the limit of the pair's).
ar2_rational <- function(fn, zeta, tau0) {
  if (abs(zeta - 1) < 1e-6) zeta <- 1 + 1e-6
  wn <- 2 * pi * fn
  root <- sqrt(as.complex(zeta^2 - 1))
  p <- exp(wn * tau0 * c(-zeta + root, -zeta - root))
  g <- Re((1 - p[1L]) * (1 - p[2L]))
  list(c0 = 0, r = g * p / (p - rev(p)), p = p)
}

# The recursion coefficients (a1, a2) and gain of the all-pole section.
ar2_coef <- function(fn, zeta, tau0) {
  p <- ar2_rational(fn, zeta, tau0)$p
  a <- c(Re(p[1L] + p[2L]), -Re(p[1L] * p[2L]))
  list(a = a, gain = 1 - a[1L] - a[2L])
}

# Geometric parts of the autocovariance of a rational filter (unit white
# input): list(A, p, d0).
rational_acov <- function(rat) {
  r <- rat$r
  p <- rat$p
  k <- length(p)
  # outer(u, v) is rep(u, k) * rep(v, each = k): the same products without
  # outer()'s overhead (most of a 60 us call, and a curve search makes
  # thousands)
  pp <- 1 - rep(p, k) * rep(p, each = k)
  G <- rep(r, k) * rep(r, each = k) / pp
  A <- r * (rat$c0 + colSums(matrix(r / pp, k)))
  g0 <- rat$c0^2 + 2 * rat$c0 * sum(r) + sum(G)
  list(A = A, p = p, d0 = Re(g0 - sum(A)))
}

# Autocovariance of filtered white noise with N = 1 (units 1/s) at integer
# lags `lags`, for a spec and sample period tau0. Scaled so that
# tau0 * sum_k g(k) = 1 (unit DC level).
filter_acf <- function(spec, tau0, lags) {
  lags <- abs(lags)
  if (spec$family == "ma") {
    L <- spec$L
    fl <- floor(L)
    tot <- L + 2 * (fl * L - fl * (fl + 1) / 2)      # sum_k max(L - |k|, 0)
    return(pmax(L - lags, 0) / (tot * tau0))
  }
  h <- filter_taps(spec)
  if (!is.null(h)) {
    g <- taps_acov(h)
    out <- numeric(length(lags))
    ok <- lags < length(g)
    out[ok] <- g[lags[ok] + 1L]
    return(out / tau0)
  }
  ra <- rational_acov(filter_rational(spec))
  g <- vapply(lags, function(k) Re(sum(ra$A * ra$p^k)), 0) + ra$d0 * (lags == 0)
  # unit DC level: sum_k g(k) = H(1)^2 = 1 for unit input variance
  g / tau0
}

# S = sum_k g(k) and C = sum_{j >= 1} j g(j) of the moving average of
# length L in closed form (g(k) = max(L - |k|, 0) / (tot tau0), unit DC).
ma_sums <- function(L, tau0) {
  fl <- floor(L)
  tot <- L + 2 * (fl * L - fl * (fl + 1) / 2)
  list(S = 1 / tau0,
       C = (L * fl * (fl + 1) / 2 - fl * (fl + 1) * (2 * fl + 1) / 6) / (tot * tau0))
}

# Lags beyond which the autocovariance is zero (FIR, ma) or Inf (IIR).
filter_support <- function(spec) {
  if (spec$family == "ma") return(ceiling(spec$L))
  h <- filter_taps(spec)
  if (!is.null(h)) length(h) else Inf
}

# ---- exact discrete Allan variance ----------------------------------------------

# AV(m) of a stationary series whose autocovariance g(k) (k = 0, 1, ...) is
# zero from lag K = length(g) on (noise-models.md section 1):
#   AV(m) = {m [g(0) - g(m)] + sum_{i=1}^{m-1} i [2g(m-i) - g(i) - g(2m-i)]} / m^2.
# It needs lags < 2m only, and for m >= K collapses to
#   AV(m) = S / m - 3 C / m^2,  S = g(0) + 2 sum_{j>=1} g(j),  C = sum_j j g(j),
# so each m costs O(min(m, K)). m must be whole here.
acov_av <- function(m, g, sums = NULL) {
  K <- length(g)
  gz <- function(k) {
    out <- numeric(length(k))
    ok <- k < K
    out[ok] <- g[k[ok] + 1L]
    out
  }
  S <- g[1L] + 2 * sum(g[-1L])
  C <- sum(seq_len(K - 1L) * g[-1L])
  # `sums` (S and C of the whole support) when g holds only the first lags:
  # then every m is below K and reads lags < 2m < K
  if (!is.null(sums)) {
    S <- sums$S
    C <- sums$C
  }
  # beyond the support the smooth form, for all m at once (a search asks
  # for a hundred m at every value it visits); below it the sums
  out <- S / m - 3 * C / m^2
  for (j in which(m < K)) {
    mm <- m[j]
    i <- seq_len(mm - 1L)
    s <- mm * (g[1L] - gz(mm))
    if (mm > 1L) s <- s + sum(i * (2 * gz(mm - i) - gz(i) - gz(2 * mm - i)))
    out[j] <- s / mm^2
  }
  out
}

# AV(m) of g(k) = A p^|k| (the AR(1) / Gauss-Markov form; p may be
# complex, then the caller sums conjugate pairs):
#   A [m - 3p - m p^2 + 4 p^(m+1) - p^(2m+1)] / [m^2 (1 - p)^2].
geometric_av <- function(m, A, p) {
  A * (m - 3 * p - m * p^2 + 4 * p^(m + 1) - p^(2 * m + 1)) / (m^2 * (1 - p)^2)
}

# Expected AV of filtered white noise with N = 1 at cluster sizes m (the AV
# per N^2, units 1/s; multiply by N^2). Closed forms for every family: the
# FIR/ma families through acov_av(), the IIR families through their
# pole-residue autocovariance (a white part d0/m plus geometric parts). For
# fractional m (curves from other tools) the FIR path interpolates AV
# linearly between the whole m around it below the support and uses the
# smooth form S/m - 3C/m^2 above it.
filter_av <- function(m, spec, tau0) {
  if (rational_family(spec)) {
    rat <- filter_rational(spec)
    # rational_acov() and the sums below in C++ (src/basis.cpp), the same
    # values
    if (is.double(m) && is.null(attributes(m)) && is_plain_number(tau0) &&
        is_plain_number(rat$c0) && is.complex(rat$r) && is.complex(rat$p)) {
      return(rational_av_cpp(m, rat$c0, rat$r, rat$p, tau0))
    }
    ra <- rational_acov(rat)
    out <- ra$d0 / m
    for (j in seq_along(ra$p)) out <- out + geometric_av(m, ra$A[j], ra$p[j])
    return(Re(out) / tau0)
  }
  # whole m of a moving average in C++ (src/basis.cpp), the same values
  if (spec$family == "ma" && is.double(m) && length(m) && is_plain_number(spec$L) &&
      is_plain_number(tau0)) {
    out <- filter_ma_av_cpp(m, spec$L, tau0)
    if (!is.null(out)) return(out)
  }
  K <- filter_support(spec)
  # AV(m) below the support reads lags < 2m only: a moving average longer
  # than the curve (a search may try L = 1e9) must not allocate its support
  need <- if (spec$family == "ma") min(K, 2 * ceiling(max(m)) + 2) else K
  g <- filter_acf(spec, tau0, 0:(need - 1L))
  # S and C of the whole support: from g when it holds all of it
  sums <- if (need < K) ma_sums(spec$L, tau0) else NULL
  whole <- abs(m - round(m)) < 1e-9
  out <- numeric(length(m))
  if (any(whole)) out[whole] <- acov_av(round(m[whole]), g, sums)
  frac <- which(!whole)
  if (length(frac)) {
    mf <- m[frac]
    big <- mf >= K
    S <- if (is.null(sums)) g[1L] + 2 * sum(g[-1L]) else sums$S
    C <- if (is.null(sums)) sum(seq_len(K - 1L) * g[-1L]) else sums$C
    out[frac[big]] <- S / mf[big] - 3 * C / mf[big]^2
    sm <- frac[!big]
    if (length(sm)) {
      lo <- pmax(floor(m[sm]), 1)
      w <- m[sm] - lo
      out[sm] <- (1 - w) * acov_av(lo, g, sums) + w * acov_av(lo + 1, g, sums)
    }
  }
  out
}

# ---- spectrum and bandwidth ------------------------------------------------------

# Two-sided rate PSD per N^2 at frequencies f (Hz): 1 at f = 0.
filter_psd <- function(f, spec, tau0) {
  w <- 2 * pi * f * tau0
  if (rational_family(spec)) {
    rat <- filter_rational(spec)
    z <- exp(1i * w)
    H <- rat$c0
    for (j in seq_along(rat$p)) H <- H + rat$r[j] / (1 - rat$p[j] / z)
    return(Mod(H)^2)
  }
  K <- filter_support(spec)
  g <- filter_acf(spec, tau0, 0:(K - 1L)) * tau0
  out <- rep(g[1L], length(w))
  for (k in seq_len(K - 1L)) out <- out + 2 * g[k + 1L] * cos(k * w)
  pmax(out, 0)
}

# Bandwidth of the filter: the -3 dB frequency of the PSD (the first f where
# it falls to half its DC level; NA when it stays above half up to the
# Nyquist frequency) and the noise-equivalent bandwidth g(0) / (2 N^2)
# (one-sided, Hz; fs/2 for an unfiltered white sensor).
filter_bandwidth <- function(spec, tau0) {
  fn <- 0.5 / tau0
  f <- seq(0, fn, length.out = 2049L)
  s <- filter_psd(f, spec, tau0) - 0.5
  i <- which(s <= 0)[1L]
  f3 <- if (is.na(i)) NA_real_ else if (s[i] == 0) f[i] else
    stats::uniroot(function(x) filter_psd(x, spec, tau0) - 0.5,
                   c(f[i - 1L], f[i]), tol = 1e-10 * fn)$root
  enbw <- filter_acf(spec, tau0, 0) / 2
  list(f3db = f3, enbw = enbw, nyquist = fn)
}

# ---- simulation ------------------------------------------------------------------

# n samples of filtered white noise with white level N (rate unit sqrt(s)).
# FIR families: convolution of white noise with the taps (a start-up of
# length(h) - 1 samples is drawn and dropped, so every sample is stationary).
# Fractional ma: the process is the MA(q) whose autocovariance is the
# triangle, drawn by circulant embedding (exact for a finite-support
# autocovariance with a non-negative spectrum). IIR: the recursion started
# from a long burn-in (until the impulse response has decayed below 1e-12).
sim_filtered_white <- function(n, tau0, N, spec) {
  sd <- N / sqrt(tau0)
  h <- filter_taps(spec)
  if (!is.null(h)) {
    L <- length(h)
    w <- stats::rnorm(n + L - 1L, sd = sd)
    y <- stats::filter(w, h, method = "convolution", sides = 1L)
    return(as.numeric(y[L:(n + L - 1L)]))
  }
  if (spec$family == "ma") {
    K <- filter_support(spec)
    g <- filter_acf(spec, tau0, 0:(K - 1L)) * N^2
    return(sim_circulant(n, g))
  }
  rat <- filter_rational(spec)
  rho <- max(Mod(rat$p))
  burn <- if (rho > 0) ceiling(log(1e-12) / log(rho)) else 0L
  w <- stats::rnorm(n + burn, sd = sd)
  if (spec$family == "lp1") {
    a <- Re(rat$p[1L])
    y <- stats::filter((1 - a) * w, a, method = "recursive")
  } else if (spec$family == "ar2") {
    co <- ar2_coef(spec$fn, spec$zeta, tau0)
    y <- stats::filter(co$gain * w, co$a, method = "recursive")
  } else {
    K <- tan(pi * spec$fc * tau0)
    den <- 1 + sqrt(2) * K + K^2
    b <- c(1, 2, 1) * K^2 / den
    a1 <- 2 * (K^2 - 1) / den
    a2 <- (1 - sqrt(2) * K + K^2) / den
    v <- stats::filter(w, b, method = "convolution", sides = 1L)
    v[1:2] <- b[1] * w[1:2]
    y <- stats::filter(v, c(-a1, -a2), method = "recursive")
  }
  as.numeric(y[(burn + 1L):(burn + n)])
}

# Gaussian series with autocovariance g(0..K-1) (zero beyond) by circulant
# embedding (Dietrich & Newsam 1997; Wood & Chan 1994).
sim_circulant <- function(n, g) {
  K <- length(g)
  M <- stats::nextn(2L * (n + K))
  row <- numeric(M)
  row[seq_len(K)] <- g
  row[M - seq_len(K - 1L) + 1L] <- g[-1L]
  lam <- Re(stats::fft(row))
  lam[lam < 0 & lam > -1e-10 * max(lam)] <- 0
  if (any(lam < 0)) abort("The autocovariance is not embeddable.", class = "internal")
  z <- complex(real = stats::rnorm(M), imaginary = stats::rnorm(M))
  y <- stats::fft(sqrt(lam / M) * z)
  Re(y)[seq_len(n)]
}

# ---- raw-data evidence -------------------------------------------------------------

# Lag-1 autocorrelation of the family as a function of its parameter, and
# its inverse (the start value read from the raw ACF).
filter_rho1 <- function(spec, tau0) {
  g <- filter_acf(spec, tau0, 0:1)
  g[2L] / g[1L]
}

# Start value of a family's parameter from the lag-1 autocorrelation r1 of
# the filter's part of the series (see filter_evidence()): ma L = 1/(1 - r1)
# (for every L >= 1); lp1 a = r1; bartlett and lp2 by inverting their r1
# numerically; ar2 from r1 and the lag-2 autocorrelation r2 by Yule-Walker
# (its poles, hence fn and zeta), else at damping 0.75 from r1. NULL when
# r1 is out of the family's range.
filter_start <- function(r1, family, freq, r2 = NA_real_) {
  tau0 <- 1 / freq
  if (!is.finite(r1) || r1 <= 0 || r1 >= 1) return(NULL)
  switch(family,
    ma = list(L = 1 / (1 - r1)),
    lp1 = {
      # a = r1; cutoff where |H|^2 = 1/2.
      a <- r1
      cw <- 1 - (1 - a)^2 / (2 * a)
      if (cw < -1) return(NULL)
      list(fc = acos(cw) / (2 * pi * tau0))
    },
    lp2 = {
      f <- function(fc) filter_rho1(list(family = "lp2", fc = fc, freq = freq), tau0) - r1
      lo <- freq * 1e-4
      hi <- freq * 0.499
      if (f(lo) * f(hi) > 0) return(NULL)
      list(fc = stats::uniroot(f, c(lo, hi), tol = 1e-8 * freq)$root)
    },
    ar2 = {
      st <- if (is.finite(r2)) ar2_yule_walker(r1, r2, freq) else NULL
      if (!is.null(st)) return(st)
      gap <- function(fn) {
        filter_rho1(list(family = "ar2", fn = fn, zeta = 0.75, freq = freq), tau0) - r1
      }
      lo <- freq * 1e-4
      hi <- freq * 0.499
      if (gap(lo) * gap(hi) > 0) return(NULL)
      list(fn = stats::uniroot(gap, c(lo, hi), tol = 1e-8 * freq)$root, zeta = 0.75)
    },
    bartlett = {
      # two cascaded L-tap averages: triangular taps L - |k|, k = -(L-1)..L-1
      Ls <- 1:512
      r <- vapply(Ls, function(L) {
        h <- L - abs(seq.int(-(L - 1L), L - 1L))
        sum(h[-1L] * h[-length(h)]) / sum(h^2)
      }, 0)
      list(L = Ls[which.min(abs(r - r1))], n = 2L)
    },
    NULL)
}

# fn and zeta of the AR(2) whose lag-1 and lag-2 autocorrelations are r1
# and r2 (Yule-Walker), NULL when its poles are not those of a low-pass
# section (both inside the unit circle, on the positive real side or a
# conjugate pair, damping within the family's bounds).
ar2_yule_walker <- function(r1, r2, freq) {
  tau0 <- 1 / freq
  if (abs(r1) >= 1) return(NULL)
  a1 <- r1 * (1 - r2) / (1 - r1^2)
  a2 <- (r2 - r1^2) / (1 - r1^2)
  p <- (a1 + c(1, -1) * sqrt(as.complex(a1^2 + 4 * a2))) / 2
  if (any(Mod(p) >= 1) || any(Mod(p) <= 1e-9)) return(NULL)
  if (all(abs(Im(p)) < 1e-12) && any(Re(p) <= 0)) return(NULL)
  s <- log(p) / tau0
  wn <- sqrt(Re(s[1L] * s[2L]))
  zeta <- -Re(s[1L] + s[2L]) / (2 * wn)
  fn <- wn / (2 * pi)
  ok <- is.finite(fn) && is.finite(zeta) && fn < 0.499 * freq &&
    zeta >= ar2_zeta_bounds[1L] && zeta <= ar2_zeta_bounds[2L]
  if (ok) list(fn = fn, zeta = zeta) else NULL
}

# The damping the ar2 family is searched over: below 0.25 its peak is a
# resonance's (another entry), above 8 one pole is white noise's.
ar2_zeta_bounds <- c(0.25, 8)

#' Raw-data evidence of a sensor filter (internal)
#'
#' The sensor's filter makes successive samples of white noise correlated
#' over a few lags and rolls the periodogram off towards the Nyquist
#' frequency. Slow processes (random walk, flicker, Gauss-Markov with Tc of
#' many samples) also raise the sample autocorrelation, but almost equally
#' at every short lag: their contribution is read from the level of the
#' autocorrelation at lags `base_lags` (beyond any filter of interest) and
#' subtracted, which leaves the filter's short-lag part. Standard errors
#' are Bartlett's \eqn{\sqrt{(1 + 2\sum_{j<k} r_j^2)/n}} for each lag.
#'
#' @return list: `acf` (data.frame lag, r (sample ACF), excess (r minus the
#'   slow-process level), se, z), `base` (slow-process level), `r1` (lag-1
#'   excess), `length` (last lag whose excess is significant: the filter
#'   length in samples), `psd_ratio` (Welch PSD near Nyquist over the PSD in
#'   the white band around fs/20, the roll-off), `filtered` (TRUE when the
#'   lag-1 excess is significantly positive), `start` (start values per
#'   family, from the lag-1 excess).
#' @noRd
filter_evidence <- function(x, freq, max_lag = 16L, base_lags = 24:48,
                            z_level = 5) {
  n <- length(x)
  tau0 <- 1 / freq
  K <- max(max(base_lags), max_lag)
  r <- acf_lags(x, K)[-1L]
  base <- stats::median(r[base_lags])
  se <- sqrt((1 + 2 * cumsum(c(0, r[seq_len(max_lag - 1L)]^2))) / n)
  se_base <- 1.25 / sqrt(n * length(base_lags))
  exc <- r[seq_len(max_lag)] - base
  z <- exc / sqrt(se^2 + se_base^2)
  sig <- which(z > z_level)
  len <- if (length(sig) && sig[1L] == 1L) {
    run <- which(diff(c(sig, Inf)) != 1L)[1L]
    sig[run]
  } else 0L
  # Roll-off of the periodogram: mean PSD in the top 5% of the band over the
  # mean PSD in [fs/25, fs/15] (white-dominated for sensors whose slow
  # processes sit below 1 Hz).
  w <- welch_psd(x, freq, seg = min(512L, 2^floor(log2(n / 8))), detrend = FALSE)
  top <- w$f > 0.95 * freq / 2
  mid <- w$f > freq / 25 & w$f < freq / 15
  ratio <- mean(w$psd[top]) / mean(w$psd[mid])
  r1 <- exc[1L]
  start <- lapply(stats::setNames(nm = c("ma", "bartlett", "lp1", "lp2", "ar2")),
                  function(fam) filter_start(r1 / (1 - base), fam, freq,
                                             r2 = exc[2L] / (1 - base)))
  list(acf = data.frame(lag = seq_len(max_lag), r = r[seq_len(max_lag)],
                        excess = exc, se = sqrt(se^2 + se_base^2), z = z),
       base = base, r1 = r1, z1 = z[1L], length = len, psd_ratio = ratio,
       filtered = isTRUE(z[1L] > z_level), start = start)
}

# The shape of a two-parameter form beyond lag 1, beside the model `fit`
# that holds it: the raw series' autocovariance steps g(k) - g(k+1) at lags
# 2 and 3 (acov_steps(), se over 50 blocks) against the model's, and
# against the model's with this form's own steps there taken out (what a
# moving average over up to two samples, which has none there, leaves). A
# two-pole section with complex poles swings below zero beyond lag 1; its
# second parameter must be seen there: the form must fit the two steps
# better than none by the chi-square's 0.999 point (2 dof), else a
# one-parameter form describes the data and this one is refused. And it
# must take most of their misfit (what is left at most a quarter of the
# misfit without it): steps the model still misses hold something it
# lacks, which the form's swing would stand in for. On a simulated moving
# average beside a 9.9 Hz resonance the section (fn 27.5 Hz, zeta 0.77)
# fitted them worse than none and read N 4.6% low; on a measured
# accelerometer with a square wave added, taken before the axis's 10 Hz
# resonance, it left chi-square 664 of 1182 and lost two harmonics; on
# white noise through a two-pole recursion beside a band and a line the
# final model's steps fit within 1 se, from z 21-28 without.
filter_shape_support <- function(ev, spec, N, fit, raw, freq) {
  if (isFALSE(ev$support)) return(ev)
  st <- diag_acov_steps(raw)
  if (is.null(st)) return(ev)
  tau0 <- 1 / freq
  # the model's steps and those of the sharp lines it does not hold yet
  md <- -diff(model_acov(fit$layout, stats::coef(fit), 1:4, tau0) +
                unheld_acov(raw, fit, 1:4, tau0))[2:3]
  own <- -diff(N^2 * filter_acf(spec, tau0, 1:4))[2:3]
  d <- st$d[2:3]
  z <- (d - md) / st$se[2:3]
  z0 <- (d - md + own) / st$se[2:3]
  gain <- sum(z0^2) - sum(z^2)
  seen <- gain > stats::qchisq(0.999, 2L) && sum(z^2) <= 0.25 * sum(z0^2)
  text <- sprintf(paste("%s; the raw autocovariance steps at lags 2-3 fit the",
                        "model with this form's at z %s, without them at z %s",
                        "(chi-square gain %s)"), ev$text,
                  paste(sprintf("%.1f", z), collapse = ", "),
                  paste(sprintf("%.1f", z0), collapse = ", "), format_num(gain))
  list(text = text,
       support = if (seen) ev$support else FALSE)
}

# ---- reading the filter from a curve or checking it against the data ----------

# Start value of a family's parameter from a curve alone: the ratio
# q = AV(tau0) tau0 / N^2 of the first point to the white line through the
# longer taus (1 for white noise, less for a filter). For ma, L = (1/q + 2)/3
# when L <= 2 (AV(1) = N^2 / (tau0 (3L - 2))); otherwise, and for the other
# families, by inverting filter_av(1) numerically. NULL when q is not in
# (0, 1).
filter_start_from_curve <- function(q, family, freq) {
  tau0 <- 1 / freq
  if (!is.finite(q) || q <= 0 || q >= 1) return(NULL)
  av1 <- function(p) {
    sp <- switch(family,
      ma = list(family = "ma", L = p),
      bartlett = list(family = "bartlett", L = max(1L, round(p)), n = 2L),
      lp1 = list(family = "lp1", fc = p, freq = freq),
      lp2 = list(family = "lp2", fc = p, freq = freq),
      ar2 = list(family = "ar2", fn = p, zeta = 0.75, freq = freq))
    filter_av(1, sp, tau0) * tau0 - q
  }
  switch(family,
    ma = {
      if (q >= 0.25) return(list(L = (1 / q + 2) / 3))
      list(L = stats::uniroot(av1, c(2, 1e4), tol = 1e-9)$root)
    },
    bartlett = {
      Ls <- 1:256
      v <- vapply(Ls, av1, 0)
      list(L = Ls[which.min(abs(v))], n = 2L)
    },
    lp1 = , lp2 = {
      lo <- freq * 1e-4
      hi <- freq * if (family == "lp1") 0.5 else 0.4999
      if (av1(lo) * av1(hi) > 0) return(NULL)
      list(fc = stats::uniroot(av1, c(lo, hi), tol = 1e-9 * freq)$root)
    },
    ar2 = {
      lo <- freq * 1e-4
      hi <- freq * 0.499
      if (av1(lo) * av1(hi) > 0) return(NULL)
      list(fn = stats::uniroot(av1, c(lo, hi), tol = 1e-9 * freq)$root, zeta = 0.75)
    },
    NULL)
}

# What the raw data say about a fitted filter: the lag-1 autocorrelation the
# filter predicts for the whole series, N^2 g(1) / var(x), against the raw
# one's filter part (filter_evidence(): the excess over the slow-process
# level). Supported when the raw excess is significant (z > 5) and within a
# factor 1.5 of the prediction; contradicted when the raw data show no
# short-lag correlation (z < 2) or disagree by more than a factor 2 (a
# first-order low-pass taken first for a resonance's and a square wave's
# bumps predicted 2.9 x the raw 0.247 at z = 170, and kept them out);
# otherwise undecided.
filter_raw_support <- function(spec, N, fe, var_x, freq) {
  tau0 <- 1 / freq
  pred <- N^2 * filter_acf(spec, tau0, 1) / var_x
  obs <- fe$r1
  z <- fe$z1
  ratio <- obs / pred
  support <- if (is.finite(z) && z > 5 && is.finite(ratio) && ratio > 1 / 1.5 &&
                 ratio < 1.5) TRUE
    else if (!is.finite(z) || z < 2 || !is.finite(ratio) || ratio < 1 / 2 ||
             ratio > 2) FALSE
    else NA
  list(text = sprintf(paste("raw lag-1 autocorrelation beyond the slow processes",
                            "%.3f (z = %.0f) against %.3f predicted by the filter"),
                      obs, z, pred),
       support = support)
}
