# Equivalent degrees of freedom (EDF) and chi-square confidence intervals
# for allan(). The noise type at each tau comes from the C++ kernel (Riley's
# lag-1 autocorrelation identification); this file turns it into an EDF
# (computed in src/edf.cpp):
#  * exact Gaussian moments (Isserlis) for discrete white or random-walk
#    noise at small m, where Greenhall's continuous-time model overstates
#    the EDF (782 instead of 666 for white noise, m = 1, N = 1000);
#  * Greenhall & Riley (2004) general algorithm otherwise;
#  * NIST SP 1065 Tables 5 and 7 for the total variance (src/edf.cpp).

# Where the noise id and the EDF are evaluated directly: every row of a
# short curve; for long ones ("all"), every m <= 64 plus 40 points per
# decade. The rest take the noise type of the nearest such m (in log tau)
# and a log-log interpolation of the EDF.
allan_subset <- function(m) {
  if (length(m) <= 200L) return(seq_along(m))
  first <- findInterval(64, m) + 1L  # m is sorted: the first m > 64
  if (first > length(m)) return(seq_along(m))
  t <- 10^seq(log10(m[first]), log10(m[length(m)]), by = 1 / 40)
  sort(unique(c(seq_len(first - 1L), findInterval(t, m), first, length(m))))
}

# EDF for every row of a curve. alpha_int: identified noise exponent at the
# rows `sub`; NA where the data were too few to tell (fewer than three
# averaged frequencies): such a row gets the smallest EDF over the exponents
# the type admits (the widest interval) and alpha NA. No row takes its type
# from another row.
allan_edf <- function(type, m, n, L, alpha_int, sub = seq_along(m)) {
  tab <- allan_type_table()
  d <- tab$d[match(type, tab$name)]
  lo <- if (d == 3) -4L else -2L
  a <- pmin(2L, pmax(lo, as.integer(alpha_int)))
  es <- rep(NA_real_, length(sub))
  known <- !is.na(a)
  if (any(known)) {
    es[known] <- allan_edf_direct(type, m[sub][known], n[sub][known], L,
                                  a[known])
  }
  for (i in which(!known)) {
    es[i] <- min(vapply(lo:2L, function(al) {
      allan_edf_direct(type, m[sub][i], n[sub][i], L, al)
    }, 0))
  }
  if (length(sub) == length(m)) {
    return(list(edf = pmax(es, 1e-3), alpha = a))
  }
  # m[1] is always in sub, so every row has an evaluated row at or below it.
  edf_interpolate_cpp(as.double(m), as.integer(sub), as.double(es),
                      as.integer(a))
}

# EDF at the rows where it is evaluated directly (src/edf.cpp): type
# "standard", "overlapping", ... (allan()'s names), cluster sizes m, terms n,
# L phase points, integer noise exponents alpha. Where no formula gives a
# positive finite EDF the number of terms is used (the total type: 1.5
# (L - 1)/m, NIST SP 1065 Table 7's white-FM value).
allan_edf_direct <- function(type, m, n, L, alpha) {
  alpha <- rep_len(as.integer(alpha), length(m))
  n <- rep_len(as.double(n), length(m))
  exact <- alpha %in% c(0L, -2L) & m <= 64
  e <- allan_edf_cpp(allan_type_code(type), as.double(m), as.double(n),
                     as.double(L), alpha, exact)
  fallback <- if (type == "total") 1.5 * (L - 1) / m else n
  ifelse(is.finite(e) & e > 0, e, fallback)
}

# Chi-square confidence limits of the deviation (NIST SP 1065 eq. 45). For
# long curves the quantile factors come from cubic interpolation between
# 2000 exact values uniform in log(edf) (qchisq() with fractional df is
# slow); the interpolation error is below 1e-6 relative.
allan_ci <- function(avar, edf, conf) {
  p <- (1 - conf) / 2
  r <- c(min(edf), max(edf))  # range() would copy a long curve's edf
  if (length(edf) <= 2000L || r[2] <= r[1] * (1 + 1e-12)) {
    lo <- edf / stats::qchisq(1 - p, edf)
    hi <- edf / stats::qchisq(p, edf)
  } else {
    # half the log factor on a grid uniform in log(edf), interpolated in
    # one C++ pass (src/edf.cpp): one exp() per limit gives the deviation's
    lg <- seq(log(r[1]), log(r[2]), length.out = 2000L)
    g <- exp(lg)
    half_log <- function(q) 0.5 * log(g / stats::qchisq(q, g))
    # half_log() is Inf where qchisq() underflows (edf ~0.01): those grid
    # points lie below 0.05, where the C++ pass calls qchisq() itself
    return(ci_long_cpp(avar, edf, lg[1L], lg[2L] - lg[1L], half_log(1 - p),
                       half_log(p), p))
  }
  # sqrt of each factor: avar * hi may overflow where the limit does not
  adev <- sqrt(avar)
  list(lower = adev * sqrt(lo), upper = adev * sqrt(hi), adev = adev)
}
