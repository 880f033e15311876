# TheoBR's limits at few averages (rows with N/m <= the exact threshold,
# R/ci-exact.R): Theo1's exact law joined with the bias factor's spread.
#
# TheoBR(m) = kappa * Theo1(m). Theo1(m) over its mean is a generalized
# chi-square (its dense quadratic form, R/ci-exact-forms.R); kappa, one
# factor estimated from the ladder, is close to log-normal (its EDF
# nu_kappa = 2 / Var(log kappa) is 14-30 under FM noise) and correlated
# with log Theo1(m) (rho: R/theobr-edf.R's tables). With X = log Theo1(m)
# from the exact law,
#   log kappa = const + rho s_k (X - E X) / s_X + sqrt(1 - rho^2) s_k Z,
# Z standard normal, s_k^2 = 2 / nu_kappa, so that
#   log TheoBR = const + (1 + rho s_k / s_X) X + sqrt(1 - rho^2) s_k Z,
# whose law (X on a grid of its CDF, Z integrated in closed form) over its
# mean gives the interval. The chi-square with the two-moment EDF it
# replaces is too skewed there: at N/m = 2-4 (N = 1024) its lower limit on
# the variance sat at 0.04-0.23 of the estimate where the Monte Carlo law
# has 0.19-0.35, and the 68% intervals covered 0.79-0.93.

# The law of log(Theo1(m) / E Theo1(m)) under alpha on L phase points, as
# masses on a grid (list(x, p)); NULL where the exact route does not solve
# the problem (exact_dense_problem()). Cached.
theobr_theo1_log_law <- function(m, L, alpha) {
  pr <- exact_dense_problem(m, L, alpha)
  if (is.null(pr)) return(NULL)
  key <- paste("theobr-law", pr[1L], pr[2L], alpha, sep = ":")
  hit <- exact_dense_cache[[key]]
  if (!is.null(hit)) return(hit)
  lam <- exact_dense_weights("exact_form_theo1", pr[1L], pr[2L], alpha)
  nu <- 1 / sum(lam^2)
  # the grid spans the law's 1e-7 .. 1 - 1e-7 (chi-square's reach, widened)
  lo <- stats::qchisq(1e-7, nu) / nu / 2
  hi <- stats::qchisq(1 - 1e-7, nu) / nu * 1.5
  g <- exp(seq(log(lo), log(hi), length.out = theobr_law_points))
  cdf <- c(0, gchisq_cdf_cpp(lam, g), 1)
  p <- pmax(0, diff(cdf))
  lg <- log(g)
  # each bin's mass at its log-midpoint; the tails at the ends
  x <- c(lg[1L], (lg[-1L] + lg[-length(lg)]) / 2, lg[length(lg)])
  out <- list(x = x, p = p / sum(p))
  assign(key, out, envir = exact_dense_cache)
  out
}
theobr_law_points <- 240L

# Factors c(lower, upper) on the deviation of TheoBR's interval at Theo1's
# m on L points, row type alpha, the factor's type `ka` (NA: the widest),
# its ladder `ladder` on `kL` points, level conf; NA where Theo1's exact
# law is not solved.
theobr_exact_factors <- function(m, L, alpha, ka, ladder, kL, conf) {
  law <- theobr_theo1_log_law(m, L, alpha)
  if (is.null(law)) return(c(NA_real_, NA_real_))
  sk <- sqrt(2 / theobr_nu_kappa(ka, kL, ladder))
  rho <- theobr_rho(ka, m, L, ladder)
  mx <- sum(law$p * law$x)
  sx <- sqrt(sum(law$p * (law$x - mx)^2))
  cx <- 1 + rho * sk / sx
  s <- sqrt(1 - rho^2) * sk
  y <- cx * (law$x - mx)
  # log E exp(Y): the ratio's mean is 1
  ly <- log(sum(law$p * exp(y - max(y)))) + max(y) + s^2 / 2
  cdf <- function(lw) sum(law$p * stats::pnorm((lw + ly - y) / s))
  p <- (1 - conf) / 2
  q <- vapply(c(p, 1 - p), function(pp) {
    stats::uniroot(function(lw) cdf(lw) - pp, c(-60, 20), tol = 1e-9,
                   extendInt = "upX")$root
  }, 0)
  sqrt(1 / exp(rev(q)))
}

# TheoBR's limits at its rows at few averages: the union over each row's
# candidate types (`alts`) of theobr_exact_factors(); list(rows, lower,
# upper) of the rows it solves (indices into m), the deviation `adev`.
theobr_limits_exact <- function(adev, m, L, alts, conf, kappa) {
  rows <- which(exact_rows(m, L))
  lower <- upper <- rep(NA_real_, length(rows))
  for (j in seq_along(rows)) {
    i <- rows[j]
    f <- vapply(alts[[i]], function(a) {
      theobr_exact_factors(m[i], L, a, kappa$alpha, kappa$ladder, kappa$L,
                           conf)
    }, numeric(2))
    if (anyNA(f)) next
    lower[j] <- adev[i] * min(f[1L, ])
    upper[j] <- adev[i] * max(f[2L, ])
  }
  ok <- !is.na(lower)
  list(rows = rows[ok], lower = lower[ok], upper = upper[ok])
}
