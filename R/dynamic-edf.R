# Equivalent degrees of freedom of an Allan-family estimator of a record of
# given length under power-law noise, for dynamic_allan() (whose windows all
# have the same length, so one table per tau and noise type serves every
# window). Greenhall & Riley, "Uncertainty of stability variances based on
# finite differences", 35th PTTI, 2003/2004: eqs. 7-13 and Tables 1-3. Our
# own implementation of the published algorithm.

# sw(t): the structure function of the noise (eq. 7); log terms are 0 at 0.
gh_sw <- function(t, alpha) {
  a <- abs(t)
  lg <- function(p) ifelse(a == 0, 0, t^p * log(ifelse(a == 0, 1, a)))
  switch(as.character(alpha),
    "2" = -a, "1" = lg(2), "0" = a^3, "-1" = lg(4), "-2" = a^5,
    "-3" = lg(6), "-4" = a^7)
}

# sx(t): after phase averaging over 1/F of the sampling interval (eq. 8).
gh_sx <- function(t, F, alpha) {
  if (is.infinite(F)) return(gh_sw(t, alpha + 2))
  F^2 * (2 * gh_sw(t, alpha) - gh_sw(t - 1 / F, alpha) -
           gh_sw(t + 1 / F, alpha))
}

# sz(t): the d-th difference (eq. 9), weights (-1)^k choose(2d, d + k).
gh_sz <- function(t, F, alpha, d) {
  k <- -d:d
  w <- (-1)^abs(k) * choose(2 * d, d + k)
  out <- 0
  for (i in seq_along(k)) out <- out + w[i] * gh_sx(t + k[i], F, alpha)
  out
}

# BasicSum (eq. 10).
gh_basic_sum <- function(J, M, S, F, alpha, d) {
  j <- seq_len(max(J - 1, 0))
  gh_sz(0, F, alpha, d)^2 + (1 - J / M) * gh_sz(J / S, F, alpha, d)^2 +
    2 * sum((1 - j / M) * gh_sz(j / S, F, alpha, d)^2)
}

# Table 1 (modified variances), Table 2 (unmodified), rows alpha = 2..-4,
# columns d = 2, 3 (a0, a1); Table 3 (alpha = 1, unmodified) (b0, b1).
gh_table1 <- list(
  "2" = list(c(7 / 9, 1 / 2), c(22 / 25, 2 / 3)),
  "1" = list(c(0.997, 0.616), c(1.141, 0.843)),
  "0" = list(c(1.033, 0.607), c(1.184, 0.848)),
  "-1" = list(c(1.048, 0.534), c(1.180, 0.816)),
  "-2" = list(c(1.302, 0.535), c(1.175, 0.777)),
  "-3" = list(NULL, c(1.194, 0.703)),
  "-4" = list(NULL, c(1.489, 0.702)))
gh_table2 <- list(
  "2" = list(c(35 / 18, 1), c(231 / 100, 3 / 2)),
  "1" = list(c(790, 410), c(9950, 6520)),
  "0" = list(c(2 / 3, 1 / 3), c(7 / 9, 1 / 2)),
  "-1" = list(c(0.852, 0.375), c(0.997, 0.617)),
  "-2" = list(c(1.079, 0.368), c(1.033, 0.607)),
  "-3" = list(NULL, c(1.053, 0.553)),
  "-4" = list(NULL, c(1.302, 0.535)))
gh_table3 <- list(c(15.23, 12.0), c(47.8, 40.0))

# EDF of one estimator: d = 2 (Allan) or 3 (Hadamard), m the cluster size,
# L the number of phase points, S = m for overlapping estimators and 1
# otherwise, modified = TRUE for the modified Allan variance.
gh_edf1 <- function(alpha, d, m, L, overlapping, modified) {
  F <- if (modified) 1 else m
  S <- if (overlapping) m else 1
  M <- 1 + floor(S * (L - m / F - m * d) / m)
  if (M < 1) return(NA_real_)
  J <- min(M, (d + 1) * S)
  r <- M / S
  Jmax <- 100
  key <- as.character(alpha)
  basic <- function(J, M, S, F) {
    M * gh_sz(0, F, alpha, d)^2 / gh_basic_sum(J, M, S, F, alpha, d)
  }
  if (modified) {
    if (J <= Jmax) return(basic(J, M, S, 1))
    if (r > d + 1) {
      a <- gh_table1[[key]][[d - 1]]
      return(r / (a[1] - a[2] / r))
    }
    return(basic(Jmax, Jmax, Jmax / r, 1))
  }
  if (alpha <= 0) {
    if (J <= Jmax) return(basic(J, M, S, if (m * (d + 1) <= Jmax) m else Inf))
    if (r > d + 1) {
      a <- gh_table2[[key]][[d - 1]]
      return(r / (a[1] - a[2] / r))
    }
    return(basic(Jmax, Jmax, Jmax / r, Inf))
  }
  a <- gh_table2[[key]][[d - 1]]
  if (alpha == 2) {
    # white phase noise: closed form unless the record holds at most d
    # strides (then the exact sum, whose support is finite)
    if (ceiling(r) > d) return(M / (a[1] - a[2] / r))
    return(basic(J, M, S, m))
  }
  if (J <= Jmax) return(basic(J, M, S, m))
  b <- gh_table3[[d - 1]]
  if (r > d + 1) return((b[1] + b[2] * log(m))^2 * r / (a[1] - a[2] / r))
  Jmax * (b[1] + b[2] * log(m))^2 /
    gh_basic_sum(Jmax, Jmax, Jmax / r, Jmax / r, alpha, d)
}

# EDF for every cluster size in m (rows) and noise exponent in `alphas`
# (columns) of estimator `type` on L phase points.
greenhall_edf <- function(type, m, L, alphas) {
  tab <- allan_type_table()
  e <- tab[match(type, tab$name), ]
  d <- e$d
  ov <- e$overlapping
  mod <- e$modified
  out <- matrix(NA_real_, length(m), length(alphas),
                dimnames = list(NULL, alphas))
  for (j in seq_along(alphas)) {
    for (i in seq_along(m)) {
      out[i, j] <- gh_edf1(alphas[j], d, m[i], L, ov, mod)
    }
  }
  out
}
