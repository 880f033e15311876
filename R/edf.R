# Equivalent degrees of freedom (EDF) and chi-square confidence intervals
# for allan(). The noise type at each tau comes from the C++ kernel (Riley's
# lag-1 autocorrelation identification); this file turns it into an EDF:
#  * exact Gaussian moments (Isserlis) for discrete white or random-walk
#    noise at small m, where Greenhall's continuous-time model overstates
#    the EDF (782 instead of 666 for white noise, m = 1, N = 1000);
#  * Greenhall & Riley (2004) general algorithm otherwise;
#  * NIST SP 1065 Table 11 for the total variance at m >= 8.

# The "d" (order of the difference) and whether each type is overlapped or
# modified, as Greenhall's algorithm needs them.
edf_setup <- function(type) {
  switch(type,
    standard = list(d = 2, overlapping = FALSE, modified = FALSE),
    overlapping = list(d = 2, overlapping = TRUE, modified = FALSE),
    modified = list(d = 2, overlapping = TRUE, modified = TRUE),
    hadamard = list(d = 3, overlapping = FALSE, modified = FALSE),
    ohadamard = list(d = 3, overlapping = TRUE, modified = FALSE),
    total = list(d = 2, overlapping = TRUE, modified = FALSE)
  )
}

greenhall_sw <- function(t, alpha) {
  lg <- function(t) ifelse(t == 0, 0, log(abs(t)))
  switch(as.character(alpha),
    "2" = -abs(t),
    "1" = t^2 * lg(t),
    "0" = abs(t)^3,
    "-1" = -t^4 * lg(t),
    "-2" = -abs(t)^5,
    "-3" = t^6 * lg(t),
    "-4" = abs(t)^7
  )
}

greenhall_sx <- function(t, F, alpha) {
  if (is.infinite(F)) return(greenhall_sw(t, alpha + 2))
  F^2 * (2 * greenhall_sw(t, alpha) - greenhall_sw(t - 1 / F, alpha) -
           greenhall_sw(t + 1 / F, alpha))
}

greenhall_sz <- function(t, F, alpha, d) {
  sx <- function(u) greenhall_sx(u, F, alpha)
  switch(d,
    2 * sx(t) - sx(t - 1) - sx(t + 1),
    6 * sx(t) - 4 * (sx(t - 1) + sx(t + 1)) + sx(t - 2) + sx(t + 2),
    20 * sx(t) - 15 * (sx(t - 1) + sx(t + 1)) + 6 * (sx(t - 2) + sx(t + 2)) -
      sx(t - 3) - sx(t + 3)
  )
}

greenhall_basic_sum <- function(J, M, S, F, alpha, d) {
  j <- if (J > 1) seq_len(J - 1) else numeric(0)
  greenhall_sz(0, F, alpha, d)^2 +
    (1 - J / M) * greenhall_sz(J / S, F, alpha, d)^2 +
    sum(2 * (1 - j / M) * greenhall_sz(j / S, F, alpha, d)^2)
}

greenhall_table1 <- function(alpha, d) {
  t1 <- list(c(2/3, 1/3, 7/9, 1/2, 22/25, 2/3), c(0.840, 0.345, 0.997, 0.616, 1.141, 0.843),
             c(1.079, 0.368, 1.033, 0.607, 1.184, 0.848), c(NA, NA, 1.048, 0.534, 1.180, 0.816),
             c(NA, NA, 1.302, 0.535, 1.175, 0.777), c(NA, NA, NA, NA, 1.194, 0.703),
             c(NA, NA, NA, NA, 1.489, 0.702))
  t1[[2 - alpha + 1]][2 * d - c(1, 0)]
}

greenhall_table2 <- function(alpha, d) {
  t2 <- list(c(3/2, 1/2, 35/18, 1, 231/100, 3/2), c(78.6, 25.2, 790, 410, 9950, 6520),
             c(2/3, 1/6, 2/3, 1/3, 7/9, 1/2), c(NA, NA, 0.852, 0.375, 0.997, 0.617),
             c(NA, NA, 1.079, 0.368, 1.033, 0.607), c(NA, NA, NA, NA, 1.053, 0.553),
             c(NA, NA, NA, NA, 1.302, 0.535))
  t2[[2 - alpha + 1]][2 * d - c(1, 0)]
}

greenhall_table3 <- function(d) list(c(6, 4), c(15.23, 12), c(47.8, 40))[[d]]

# Greenhall & Riley (2004), "Uncertainty of stability variances based on
# finite differences", for one (alpha, d, m) with N phase points.
edf_greenhall <- function(alpha, d, m, N, overlapping, modified) {
  F <- if (modified) 1 else m
  S <- if (overlapping) m else 1
  L <- m / F + m * d
  M <- 1 + floor(S * (N - L) / m)
  if (M < 1) return(NA_real_)
  J <- min(M, (d + 1) * S)
  Jmax <- 100
  r <- M / S
  eq13 <- function(J, M, S, F, Fz = F) {
    M * greenhall_sz(0, Fz, alpha, d)^2 / greenhall_basic_sum(J, M, S, F, alpha, d)
  }
  if (modified) {
    if (J <= Jmax) return(eq13(J, M, S, 1))
    if (r > d + 1) {
      a <- greenhall_table1(alpha, d)
      return(1 / ((a[1] - a[2] / r) / r))
    }
    return(Jmax * greenhall_sz(0, 1, alpha, d)^2 /
             greenhall_basic_sum(Jmax, Jmax, Jmax / r, 1, alpha, d))
  }
  if (alpha <= 0) {
    if (J <= Jmax) {
      Fp <- if (m * (d + 1) <= Jmax) m else Inf
      return(eq13(J, M, S, Fp))
    }
    if (r > d + 1) {
      a <- greenhall_table2(alpha, d)
      return(1 / ((a[1] - a[2] / r) / r))
    }
    return(Jmax * greenhall_sz(0, Inf, alpha, d)^2 /
             greenhall_basic_sum(Jmax, Jmax, Jmax / r, Inf, alpha, d))
  }
  if (alpha == 1) {
    if (J <= Jmax) return(eq13(J, M, S, m))
    b <- greenhall_table3(d)
    if (r > d + 1) {
      a <- greenhall_table2(alpha, d)
      return(1 / ((a[1] - a[2] / r) / ((b[1] + b[2] * log(m))^2 * r)))
    }
    return(Jmax * (b[1] + b[2] * log(m))^2 /
             greenhall_basic_sum(Jmax, Jmax, Jmax / r, Jmax / r, 1, d))
  }
  # alpha = 2
  if (ceiling(r) > d) {
    a0 <- choose(4 * d, 2 * d) / choose(2 * d, d)^2
    return(1 / ((a0 - d / 2 / r) / M))
  }
  eq13(J, M, S, m)
}

# Weights of one term of the estimator on the i.i.d. innovations of a
# discrete white (rw = FALSE) or random-walk (rw = TRUE) rate series.
edf_weights <- function(type, m, rw) {
  p2 <- c(rep(-1, m), rep(1, m))
  g <- switch(type,
    standard = , overlapping = , total = p2,
    hadamard = , ohadamard = c(rep(1, m), rep(-2, m), rep(1, m)),
    modified = {
      cs <- cumsum(c(p2, rep(0, m - 1)))
      cs - c(rep(0, m), cs[seq_len(length(cs) - m)])
    }
  )
  if (rw) g <- rev(cumsum(rev(g)))[-1]
  g
}

# Exact EDF 2 E[AV]^2 / Var[AV] for Gaussian discrete white or random-walk
# noise (Isserlis): with c(h) the autocovariance of one term's weights and
# terms spaced s samples apart, edf = n^2 c(0)^2 / sum (n - |h|) c(h s)^2.
edf_discrete <- function(type, m, n, rw) {
  g <- edf_weights(type, m, rw)
  G <- length(g)
  cc <- vapply(0:(G - 1), function(h) sum(g[1:(G - h)] * g[(1 + h):G]), 0)
  s <- if (type %in% c("standard", "hadamard")) m else 1
  h <- 0:min(n - 1, floor((G - 1) / s))
  w <- ifelse(h == 0, n, 2 * (n - h))
  n^2 * cc[1]^2 / sum(w * cc[h * s + 1]^2)
}

# EDF for every row of a curve. alpha_int: identified noise exponent (NA
# where the data were too few; filled from the nearest shorter tau).
allan_edf <- function(type, m, n, L, alpha_int) {
  d <- edf_setup(type)$d
  a <- alpha_int
  if (all(is.na(a))) a[] <- 0L
  for (i in seq_along(a)) if (is.na(a[i])) a[i] <- if (i > 1) a[i - 1] else NA
  for (i in rev(seq_along(a))) if (is.na(a[i])) a[i] <- a[i + 1]
  a <- pmin(2L, pmax(if (d == 3) -4L else -2L, as.integer(a)))
  edf <- numeric(length(m))
  for (i in seq_along(m)) {
    edf[i] <- allan_edf1(type, m[i], n[i], L, a[i])
  }
  list(edf = pmax(edf, 1e-3), alpha = a)
}

allan_edf1 <- function(type, m, n, L, alpha) {
  s <- edf_setup(type)
  if (alpha %in% c(0L, -2L) && m <= 64 && type != "total") {
    return(edf_discrete(type, m, n, rw = alpha == -2L))
  }
  if (type == "total") {
    oav <- allan_edf1("overlapping", m, max(1, L - 2 * m), L, alpha)
    if (m < 8 || !alpha %in% c(0L, -1L, -2L) || is.na(oav)) return(oav)
    bc <- list("0" = c(1.50, 0), "-1" = c(1.17, 0.22), "-2" = c(0.93, 0.36))[[as.character(alpha)]]
    return(max(oav, bc[1] * (L - 1) / m - bc[2]))
  }
  e <- edf_greenhall(alpha, s$d, m, L, s$overlapping, s$modified)
  if (is.na(e) || !is.finite(e) || e <= 0) e <- n
  e
}

# Chi-square confidence limits of the deviation (NIST SP 1065 eq. 45).
allan_ci <- function(avar, edf, conf) {
  p <- (1 - conf) / 2
  list(lower = sqrt(edf * avar / stats::qchisq(1 - p, edf)),
       upper = sqrt(edf * avar / stats::qchisq(p, edf)))
}
