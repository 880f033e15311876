# Equivalent degrees of freedom (EDF) and chi-square confidence intervals
# for allan(). The noise type at each tau comes from the C++ kernel (Riley's
# lag-1 autocorrelation identification); this file turns it into an EDF
# (computed in src/edf.cpp):
#  * exact Gaussian moments (Isserlis) for discrete white or random-walk
#    noise at small m, where Greenhall's continuous-time model overstates
#    the EDF (782 instead of 666 for white noise, m = 1, N = 1000);
#  * Greenhall & Riley (2004) general algorithm otherwise;
#  * NIST SP 1065 Table 11 for the total variance at m >= 8.

# Where the noise id and the EDF are evaluated directly: every row of a
# short curve; for long ones ("all"), every m <= 64 plus 40 points per
# decade. The rest take the noise type of the nearest such m (in log tau)
# and a log-log interpolation of the EDF.
allan_subset <- function(m) {
  if (length(m) <= 200L) return(seq_along(m))
  big <- m > 64
  if (!any(big)) return(seq_along(m))
  t <- 10^seq(log10(min(m[big])), log10(max(m)), by = 1 / 40)
  sort(unique(c(which(!big), findInterval(t, m), which(big)[1L], length(m))))
}

# EDF for every row of a curve. alpha_int: identified noise exponent at the
# rows `sub` (NA where the data were too few: filled from the nearest
# shorter tau, else the nearest longer one).
allan_edf <- function(type, m, n, L, alpha_int, sub = seq_along(m)) {
  tab <- allan_type_table()
  d <- tab$d[match(type, tab$name)]
  a <- alpha_int
  if (all(is.na(a))) a[] <- 0L
  for (i in seq_along(a)) if (is.na(a[i]) && i > 1) a[i] <- a[i - 1]
  for (i in rev(seq_along(a))) if (is.na(a[i])) a[i] <- a[i + 1]
  a <- pmin(2L, pmax(if (d == 3) -4L else -2L, as.integer(a)))
  es <- allan_edf_direct(type, m[sub], n[sub], L, a)
  if (length(sub) == length(m)) {
    return(list(edf = pmax(es, 1e-3), alpha = a))
  }
  # m[1] is always in sub, so every row has an evaluated row at or below it.
  edf_interpolate_cpp(as.double(m), as.integer(sub), as.double(es),
                      as.integer(a))
}

# EDF at the rows where it is evaluated directly (src/edf.cpp).
allan_edf_direct <- function(type, m, n, L, alpha) {
  exact <- alpha %in% c(0L, -2L) & m <= 64
  if (type != "total") {
    e <- allan_edf_cpp(allan_type_code(type), m, n, L, alpha, exact)
    return(ifelse(is.finite(e) & e > 0, e, n))
  }
  # total: the overlapping EDF (the same terms at small m), or at m >= 8 the
  # larger of it and NIST SP 1065's b (L - 1)/m - c
  no <- L - 2 * m
  oav <- rep(NA_real_, length(m))
  ok <- no >= 1
  if (any(ok)) {
    oav[ok] <- allan_edf_cpp(allan_type_code("overlapping"), m[ok], no[ok], L,
                             alpha[ok], exact[ok])
  }
  b <- c(1.50, 1.17, 0.93)[match(alpha, c(0L, -1L, -2L))]
  cc <- c(0, 0.22, 0.36)[match(alpha, c(0L, -1L, -2L))]
  tab <- b * (L - 1) / m - cc
  e <- ifelse(m < 8 | is.na(tab), oav, pmax(oav, tab, na.rm = TRUE))
  e <- ifelse(is.na(e), tab, e)
  ifelse(is.finite(e) & e > 0, e, 1.5 * (L - 1) / m)
}

# Chi-square confidence limits of the deviation (NIST SP 1065 eq. 45). For
# long curves the quantile factors come from a cubic spline through 2000
# exact values in log(edf) (qchisq() with fractional df is slow); the
# interpolation error is below 1e-6 relative.
allan_ci <- function(avar, edf, conf) {
  p <- (1 - conf) / 2
  r <- range(edf)
  if (length(edf) <= 2000L || r[2] <= r[1] * (1 + 1e-12)) {
    lo <- edf / stats::qchisq(1 - p, edf)
    hi <- edf / stats::qchisq(p, edf)
  } else {
    g <- exp(seq(log(min(edf)), log(max(edf)), length.out = 2000L))
    lg <- log(g)
    le <- log(edf)
    lo <- exp(stats::splinefun(lg, log(g / stats::qchisq(1 - p, g)),
                               method = "fmm")(le))
    hi <- exp(stats::splinefun(lg, log(g / stats::qchisq(p, g)),
                               method = "fmm")(le))
  }
  list(lower = sqrt(avar * lo), upper = sqrt(avar * hi))
}
