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
# N = 256, 1024, 4096 agree within their sampling error, ~0.03): near 0
# below u = 1/16, up to 0.6-0.9 where Theo1(m) shares the ladder's long
# end.

# The tables: log2 L - 1 (N = L - 1 = 64 ... 16384) by noise exponent (rows
# alpha = 2, 1, 0, -1, -2); rho at u = 2^-10 ... 2^0.
theobr_kappa_table <- function() {
  list(
    N = c(64, 256, 1024, 4096, 16384),
    nu = list(
      "N/6" = rbind(c(NA, 784, 4080, 18700, NA),
                    c(NA, 73.7, 117, 158, NA),
                    c(NA, 20.8, 23.6, 21.4, NA),
                    c(NA, 20.1, 24.7, 24.7, NA),
                    c(NA, 23.6, 26.3, 27.8, NA)),
      "N/30" = rbind(c(NA, 977, 13200, 96700, NA),
                     c(NA, 201, 486, 810, NA),
                     c(NA, 99.7, 157, 165, NA),
                     c(NA, 129, 227, 249, NA),
                     c(NA, 186, 289, 356, NA))),
    lu = -10:0,
    rho = list(
      "N/6" = rbind(c(0, 0, 0, 0, 0, 0, 0, 0.1, 0.1, 0, 0),
                    c(0, 0, 0, 0, 0, 0, 0, 0.1, 0.3, 0.55, 0.1),
                    c(0, 0, 0, 0, 0, 0, 0, 0, 0.2, 0.65, 0.55),
                    c(0, 0, 0, 0, 0, 0, 0, 0, 0.2, 0.7, 0.7),
                    c(0, 0, 0, 0, 0, 0.05, 0.1, 0.15, 0.35, 0.75, 0.8)),
      "N/30" = rbind(c(0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
                     c(0, 0, 0, 0, 0, 0, 0, 0.3, 0.6, 0.5, 0),
                     c(0, 0, 0, 0, 0, 0, 0, 0.35, 0.85, 0.75, 0.45),
                     c(0, 0, 0, 0, 0, 0, 0, 0.25, 0.8, 0.85, 0.45),
                     c(0, 0, 0, 0, 0, 0.1, 0.2, 0.45, 0.8, 0.9, 0.65)))
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
