# TheoBR's bias-removal factor (NIST SP 1065 eq. 33) and its fast path on
# long records (allan(type = "theobr" / "theoh"), kernel_theo() in
# R/stat-further.R). The options (`theo` of allan()) are fields of the
# catalogue entries: theo_defaults() below.
#
# The factor is the mean over the ladder i = 0..n of AVAR(m = 9 + 3i) /
# Theo1(m = 12 + 4i). Two ladder lengths are in use: n = floor(N/6 - 3)
# (Stable32's Run and Plot; the package's default) and n = floor(0.1 N/3 -
# 3), N/30 (Howe's TheoH papers, Riley's TheoBR.cpp, Stable32's "Sigma"
# calculations). The exact factor costs O(N log^2 N + kmax^2) with kmax ~
# N/3 (N/6 ladder): minutes at 1e6.
#
# The fast path (Taylor & Howe, "Fast TheoBR", IEEE TUFFC 57(9), 2010:
# average the phase before the ladder) takes the factor from the phase
# averaged over blocks of r points, N' = floor(N/r) <= `fast_points`, with
# the ladder on N', times a correction for the FM noise types: the ratio of
# the factor's expected value on the raw ladder to its expected value on
# the averaged one, computed here from the noise type's generalized
# covariance (the averaging is a box filter; white FM K(s) = -|s|/2,
# flicker FM s^2 log|s| / 2, random-walk FM |s|^3 / 12, each up to a
# scale). The type is the one identified most often along the ladder. (Taylor & Howe's own correction formula was not at hand; this one
# follows the same idea from first principles.) The Theo1 values
# themselves stay exact on the full record: only the factor is estimated.

# The options' defaults: the fields `theo` of the entries "theobr" and
# "theoh".
theo_defaults <- function() {
  list(ladder = "N/6", method = "auto", fast_above = 1e5,
       fast_points = 32768)
}

# `theo` of allan(): NULL or a list of some of ladder ("N/6", "N/30"),
# method ("auto", "exact", "fast"), fast_points (the averaged phase's
# length, a whole number >= 64); the entry's defaults fill the rest.
check_theo <- function(theo, e) {
  if (is.null(theo)) return(e$theo)
  if (is.null(e$theo)) {
    abort("`theo` applies to types \"theobr\" and \"theoh\" only, not \"",
          e$name, "\".", class = "argument")
  }
  if (!is.list(theo) || (length(theo) && is.null(names(theo))) ||
      !all(names(theo) %in% c("ladder", "method", "fast_points"))) {
    abort("`theo` must be NULL or a list with some of `ladder`, `method` ",
          "and `fast_points`, not ", describe_type(theo), ".",
          class = "argument")
  }
  o <- e$theo
  if (!is.null(theo$ladder)) {
    o$ladder <- check_choice(theo$ladder, c("N/6", "N/30"), "theo$ladder")
  }
  if (!is.null(theo$method)) {
    o$method <- check_choice(theo$method, c("auto", "exact", "fast"),
                             "theo$method")
  }
  if (!is.null(theo$fast_points)) {
    p <- theo$fast_points
    if (!is.numeric(p) || length(p) != 1L || !is.finite(p) || p < 64 ||
        p != round(p)) {
      abort("`theo$fast_points` must be a whole number >= 64, not ",
            format_value(p), ".", class = "argument")
    }
    o$fast_points <- p
  }
  o
}

# The ladder's last index n for L phase points (negative: no ladder).
theobr_ladder_n <- function(L, ladder = "N/6") {
  if (identical(ladder, "N/30")) floor(0.1 * L / 3 - 3) else floor(L / 6 - 3)
}

# The exact factor on phase (or rate) `v` of L phase points.
theobr_factor <- function(v, freq, rate, L, threads = 1L, ladder = "N/6") {
  n <- theobr_ladder_n(L, ladder)
  if (n < 0) return(NA_real_)
  i <- 0:n
  mt <- 12 + 4 * i
  ma <- 9 + 3 * i
  ok <- mt <= L - 1 & ma <= floor((L - 1) / 2)
  if (!any(ok)) return(NA_real_)
  mt <- mt[ok]
  ma <- ma[ok]
  T <- theo1_many(v, rate, mt, threads)
  th <- T / (0.75 * (L - mt) * mt^2)
  input <- if (rate) "rate" else "integrated"
  a <- allan(v, 1, taus = I(ma), type = "overlapping", input = input,
             ci = FALSE)
  mean(a$avar / th)
}

# The phase averaged over blocks of r points (the last partial block
# dropped).
theo_avg_phase <- function(v, rate, r) {
  x <- if (rate) c(0, cumsum(v)) else v
  n <- length(x) %/% r
  colMeans(matrix(x[seq_len(n * r)], nrow = r))
}

# The fast factor: on the phase averaged by r, times the correction of the
# noise type alpha (FM types; 1 for the others). NA like the exact one.
theobr_factor_fast <- function(v, rate, L, r, alpha, threads = 1L,
                               ladder = "N/6") {
  xb <- theo_avg_phase(v, rate, r)
  kf <- theobr_factor(xb, 1, FALSE, length(xb), threads, ladder)
  kf * theo_fast_correction(alpha, L, r, ladder)
}

# Generalized covariance of the power-law noise types (up to a scale), lag
# s: white PM, the discrete flicker PM of Kasdin's filter (its R(0) - R(s)
# is (digamma(s + 1/2) - digamma(1/2)) / pi exactly), and the FM types.
theo_gcov <- function(alpha) {
  switch(as.character(alpha),
         "2" = function(s) as.numeric(s == 0),
         "1" = function(s) -(digamma(abs(s) + 0.5) - digamma(0.5)) / pi,
         "0" = function(s) -abs(s) / 2,
         "-1" = function(s) ifelse(s == 0, 0, s^2 * log(abs(s)) / 2),
         "-2" = function(s) abs(s)^3 / 12,
         NULL)
}

# E AVAR(ma) / E Theo1(mt) at the ladder's points i, for the structure
# function D (lag in the ladder's units); a geometric subset of at most 60
# points, interpolated in log m, averaged over the whole ladder.
theo_ladder_ratio <- function(D, n) {
  i <- 0:n
  ii <- unique(round(exp(seq(0, log(n + 1), length.out = min(n + 1, 60))) - 1))
  f <- vapply(ii, function(j) {
    ma <- 9 + 3 * j
    mt <- 12 + 4 * j
    k <- mt / 2
    L <- seq_len(k)
    av <- (4 * D(ma) - D(2 * ma)) / (2 * ma^2)
    th <- sum((2 * D(L) + 2 * D(mt - L) - D(mt) - D(abs(mt - 2 * L))) / L) /
      (0.75 * mt^2)
    av / th
  }, 0)
  if (length(ii) == 1L) return(f)
  mean(stats::approx(log(9 + 3 * ii), f, xout = log(9 + 3 * i))$y)
}

# The correction of the fast factor for noise type alpha: the factor's
# expected value on the raw ladder over its expected value on the ladder
# of the phase averaged by r (1 for PM types or an unknown type).
theo_fast_correction <- function(alpha, L, r, ladder = "N/6") {
  K <- if (is.na(alpha)) NULL else theo_gcov(alpha)
  if (is.null(K)) return(1)
  n <- theobr_ladder_n(L, ladder)
  nb <- theobr_ladder_n(L %/% r, ladder)
  if (n < 0 || nb < 0) return(1)
  D <- function(s) 2 * (K(0) - K(s))
  u <- seq(-(r - 1), r - 1)
  w <- (r - abs(u)) / r^2
  Kr <- function(t) {
    out <- numeric(length(t))
    for (j in seq_along(u)) out <- out + w[j] * K(t + u[j])
    out
  }
  Dr <- function(s) 2 * (Kr(0) - Kr(r * s))
  theo_ladder_ratio(D, n) / theo_ladder_ratio(Dr, nb)
}

# The factor of kernel_theo() (ctx: its context, ctx$theo the options):
# the fast path when asked, or with method "auto" above `fast_above` phase
# points (with a message); the exact factor otherwise, and wherever the
# averaging would keep every point (r = 1). Its attribute `kappa` is what
# the factor's EDF needs (edf_rule_theobr(), R/theobr-edf.R): the ladder,
# its record length (the averaged phase's on the fast path) and the noise
# type read along it (NA where no limits are asked).
theobr_kernel_factor <- function(ctx) {
  o <- ctx$theo
  L <- ctx$L
  r <- ceiling(L / o$fast_points)
  fast <- r >= 2 && (identical(o$method, "fast") ||
                       (identical(o$method, "auto") && L > o$fast_above))
  if (!fast) {
    kf <- theobr_factor(ctx$v, ctx$freq, ctx$rate, L, ctx$threads, o$ladder)
    alpha <- if (isTRUE(ctx$ci) || isTRUE(ctx$unbiased)) {
      theobr_kappa_alpha(ctx$v, ctx$rate, L, o$ladder, ctx$threads)
    } else NA_integer_
    return(structure(kf, kappa = list(ladder = o$ladder, L = L,
                                      alpha = alpha)))
  }
  if (identical(o$method, "auto")) {
    inform("TheoBR's bias factor from the phase averaged over ", r,
           " points (fast path above ", format(o$fast_above, scientific = FALSE),
           " phase points, ", L, " here); `theo = list(method = \"exact\")` ",
           "for the exact factor.", class = "theo_fast")
  }
  alpha <- theobr_ladder_alpha(ctx$v, ctx$freq, ctx$input, L, o$ladder)
  kf <- theobr_factor_fast(ctx$v, ctx$rate, L, r, alpha, ctx$threads, o$ladder)
  ak <- if (isTRUE(ctx$ci) || isTRUE(ctx$unbiased)) {
    xb <- theo_avg_phase(ctx$v, ctx$rate, r)
    theobr_kappa_alpha(xb, FALSE, length(xb), o$ladder, ctx$threads)
  } else NA_integer_
  structure(kf, kappa = list(ladder = o$ladder, L = L %/% r, alpha = ak))
}

# The noise type of the ladder, for the fast factor's correction: the most
# frequent of the types identified at five averaging factors spaced
# geometrically over the ladder (ties: the longer tau); the identification
# fails (NA) at the ladder's long end, where few averages remain. NA when
# none is read.
theobr_ladder_alpha <- function(v, freq, input, L, ladder = "N/6") {
  n <- theobr_ladder_n(L, ladder)
  m <- unique(round(exp(seq(log(9), log(9 + 3 * max(n, 0)), length.out = 5))))
  a <- extra_alpha(v, freq, m, "overlapping", input, L)
  a <- rev(a[!is.na(a)])
  if (!length(a)) return(NA_integer_)
  tab <- table(a)
  top <- names(tab)[tab == max(tab)]
  a[match(TRUE, as.character(a) %in% top)]
}
