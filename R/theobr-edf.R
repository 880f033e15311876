# TheoBR's EDF (the rule "theobr" of stat_edf_rules(), R/edf.R), for
# allan(type = "theobr") and TheoH's TheoBR rows.
#
# TheoBR(m) = kappa * Theo1(m), kappa the bias factor estimated from the
# same record (R/theo-fast.R): one random factor multiplying every row.
# In logs, for chi-square-like laws (Var log(chi2_nu / nu) ~ 2 / nu),
#   Var log TheoBR = Var log Theo1 + Var log kappa + 2 Cov
#   1 / nu = 1 / nu_T + 1 / nu_kappa + 2 rho / sqrt(nu_T nu_kappa),
# nu_T Theo1's EDF (its rule, at the row's noise type), nu_kappa = 2 /
# Var(log kappa) and rho the correlation of log kappa with log Theo1(m).
# Theo1's EDF alone (300-1000 at small m, N = 1024) ignored kappa, whose
# EDF under FM noise is 20-30 whatever N on the N/6 ladder: 68% coverage
# 0.10-0.35.
#
# nu_kappa and rho come from an offline Monte Carlo (tools/theobr-ratio-
# edf.R; own generators, 1000 records at each N = 64 .. 4096, 300 at
# 16384): nu_kappa by noise type, ladder and record length L (the ladder's:
# the averaged phase's on the fast path), interpolated in log L, constant
# below the first L and extrapolated on the last two points' power law
# above (PM noise: nu_kappa grows like N^0.3 to N^1.2; FM noise on the N/6
# ladder it is flat, as the ladder's long end, with few averages whatever
# N, dominates). rho is a function of u = m / (L - 1) alone (the runs at
# N = 256, 1024, 4096 agree within their sampling error, ~0.03): small
# below u = 1/32 (|rho| <= 0.16; white PM on the N/30 ladder -0.3, where
# nu_kappa is in the thousands), up to 0.6-0.9 where Theo1(m) shares the
# ladder's long end.
#
# The row's noise type (for nu_T) is Theo1's (theo1_alpha(), R/theo1-
# type.R: TheoBR's slope is Theo1's; beyond the Allan variance's reach
# starting from the factor's type), the interval the union over its
# candidate types (theobr_union() below); the factor's type (for nu_kappa
# and rho) the one Theo1's slope reads along the ladder
# (theobr_kappa_alpha() below), NA: the smallest nu_kappa and largest rho
# over the types.

# The tables (`MC_INSTALLED=1 Rscript tools/theobr-ratio-edf.R 1000
# 64,256,1024,4096 29`, 2026-11-28; N = 16384 from 300 records, seed 4):
# nu_kappa at N = L - 1 = 64 ... 16384 (columns) by noise exponent (rows
# alpha = 2, 1, 0, -1, -2); rho at u = 2^-10 ... 2^0, the mean over N =
# 256, 1024, 4096.
theobr_kappa_table <- function() {
  list(
    N = c(64, 256, 1024, 4096, 16384),
    nu = list(
      "N/6" = rbind(c(113, 841, 4170, 16100, 55300),
                    c(35.4, 70.2, 114, 148, 172),
                    c(14.4, 23.0, 22.0, 22.9, 24.6),
                    c(13.4, 22.0, 23.6, 23.9, 23.3),
                    c(13.6, 24.3, 27.9, 27.1, 29.1)),
      # no N/30 ladder below 90 phase points
      "N/30" = rbind(c(NA, 931, 11800, 97100, 610000),
                     c(NA, 202, 436, 722, 921),
                     c(NA, 108, 160, 189, 200),
                     c(NA, 128, 223, 255, 267),
                     c(NA, 217, 282, 356, 365))),
    lu = -10:0,
    rho = list(
      "N/6" = rbind(
        c(-0.06, -0.11, -0.09, -0.12, -0.09, -0.08, -0.06, -0.01, 0.08, 0.03, 0.05),
        c(-0.03, -0.04, -0.07, -0.10, -0.09, -0.07, -0.01, 0.09, 0.28, 0.55, 0.10),
        c(0.04, 0.04, 0.03, -0.01, -0.04, -0.06, -0.07, 0.00, 0.23, 0.67, 0.51),
        c(0.02, 0.02, 0.01, -0.01, -0.05, -0.07, -0.08, -0.03, 0.16, 0.68, 0.69),
        c(-0.05, -0.05, -0.04, -0.01, 0.00, 0.01, 0.04, 0.12, 0.32, 0.72, 0.77)),
      "N/30" = rbind(
        c(-0.27, -0.31, -0.24, -0.25, -0.20, -0.16, -0.09, -0.08, -0.05, -0.05, -0.04),
        c(-0.10, -0.11, -0.14, -0.15, -0.14, -0.04, 0.21, 0.54, 0.56, 0.52, 0.05),
        c(-0.05, -0.04, -0.08, -0.10, -0.14, -0.09, 0.27, 0.82, 0.74, 0.44, 0.11),
        c(-0.03, -0.07, -0.07, -0.10, -0.16, -0.10, 0.24, 0.80, 0.83, 0.47, 0.17),
        c(0.00, 0.01, 0.01, 0.02, 0.06, 0.18, 0.44, 0.80, 0.90, 0.68, 0.41)))
  )
}

# nu_kappa for noise exponents alpha (-2..2, vector) on a ladder of record
# length L; alpha NA: the smallest over the types (the widest interval).
theobr_nu_kappa <- function(alpha, L, ladder = "N/6") {
  tab <- theobr_kappa_table()
  nu <- tab$nu[[ladder]]
  x <- log(tab$N)
  one <- function(a) {
    y <- log(nu[3L - a, ])
    ok <- is.finite(y)
    xs <- x[ok]
    ys <- y[ok]
    t <- log(max(L - 1, 1))
    k <- length(xs)
    if (t <= xs[1L]) return(exp(ys[1L]))
    if (t >= xs[k]) {
      return(exp(ys[k] + (t - xs[k]) * (ys[k] - ys[k - 1L]) / (xs[k] - xs[k - 1L])))
    }
    exp(stats::approx(xs, ys, xout = t)$y)
  }
  a <- as.integer(alpha)
  vapply(a, function(ai) {
    if (is.na(ai)) return(min(vapply(-2:2, one, 0)))
    one(min(2L, max(-2L, ai)))
  }, 0)
}

# rho at cluster sizes m (Theo1's m) on L phase points, noise exponent
# alpha (vector, recycled; NA: the largest over the types).
theobr_rho <- function(alpha, m, L, ladder = "N/6") {
  tab <- theobr_kappa_table()
  r <- tab$rho[[ladder]]
  lu <- pmin(0, pmax(min(tab$lu), log2(m / (L - 1))))
  a <- rep_len(as.integer(alpha), length(m))
  out <- numeric(length(m))
  for (i in seq_along(m)) {
    rows <- if (is.na(a[i])) 1:5 else 3L - min(2L, max(-2L, a[i]))
    out[i] <- max(vapply(rows, function(j) {
      stats::approx(tab$lu, r[j, ], xout = lu[i])$y
    }, 0))
  }
  out
}

# The rule: Theo1's EDF at the row's type combined with the factor's.
# `kappa`: the factor's ladder (list(ladder, L, alpha): convention, record
# length of the ladder, noise type read along it; R/theo-fast.R); NULL: the
# N/6 ladder on the record, the row's type.
edf_rule_theobr <- function(e, m, n, L, alpha, kappa = NULL) {
  nt <- edf_rule_theo1(e, m, n, L, alpha)
  if (is.null(kappa)) kappa <- list(ladder = "N/6", L = L, alpha = alpha)
  ak <- rep_len(as.integer(kappa$alpha), length(m))
  nk <- theobr_nu_kappa(ak, kappa$L, kappa$ladder)
  rho <- theobr_rho(ak, m, L, kappa$ladder)
  v <- 1 / nt + 1 / nk + 2 * rho / sqrt(nt * nk)
  pmax(1, 1 / v)
}

# TheoBR limits where the row's noise type is ambiguous (theo1_alpha()'s
# candidates `alts`): the union of the candidate types' chi-square
# intervals, each with its EDF by the rule above (as theo1_union() does for
# Theo1, without a bias correction: TheoBR is bias-removed by its factor).
# `type`: the statistic's name, for its EDF rule.
theobr_union <- function(type, av, m, L, alts, n, conf, kappa) {
  row <- rep(seq_along(m), lengths(alts))
  al <- unlist(alts, use.names = FALSE)
  e <- extra_edf(type, m[row], L, al, n[row], kappa = kappa)
  ci <- allan_ci(av[row], e, conf)
  list(lower = vapply(split(ci$lower, row), min, 0),
       upper = vapply(split(ci$upper, row), max, 0))
}

# The factor's noise type (for nu_kappa and rho): the most frequent of the
# types Theo1's slope reads (theo1_alpha()) at five even m spaced
# geometrically over the ladder's Theo1 span, 16 .. 12 + 4n (ties: the
# longer tau); NA when none is read. The Allan variance's identification
# alone, as the fast factor's correction takes it (theobr_ladder_alpha()),
# reads random-walk FM as flicker or white FM at m = 25-510 in 55-95% of
# records (N = 1024), and so the factor's EDF as 22 where it is 28.
# v: the phase (or rate) the factor was computed on (the averaged phase on
# the fast path), L its phase points.
theobr_kappa_alpha <- function(v, rate, L, ladder, threads) {
  n <- theobr_ladder_n(L, ladder)
  if (n < 1) return(NA_integer_)
  top <- min(12 + 4 * n, L - 1)
  m <- unique(2 * round(exp(seq(log(16), log(top), length.out = 5)) / 2))
  m <- m[m >= 2 & m <= L - 1]
  if (!length(m)) return(NA_integer_)
  t1 <- theo1_sums_cpp(v, rate, m, threads) / (0.75 * (L - m) * m^2)
  input <- if (rate) "rate" else "integrated"
  a0 <- extra_alpha(v, 1, round(0.75 * m), "overlapping", input, L)
  a <- as.integer(theo1_alpha(v, rate, L, m, t1, a0, threads))
  a <- rev(a[!is.na(a)])
  if (!length(a)) return(NA_integer_)
  tab <- table(a)
  top <- names(tab)[tab == max(tab)]
  a[match(TRUE, as.character(a) %in% top)]
}
