# The exact law at few averages of the statistics whose terms are not a
# stationary sequence of differences: the total variance (reflected
# record), MTOT/TTOT and HTOT (detrended, reflected windows) and Theo1.
# Each is still a quadratic form in the phase, V = x' A x; under discrete
# power-law noise x = H e (H lower triangular Toeplitz with the
# coefficients of (1 - B)^(-(2 - alpha)/2), Kasdin's record started at
# rest; the forms annihilate a constant and a line, so random-walk FM's
# start does not matter) the estimate over its expectation is the
# generalized chi-square with weights the eigenvalues of H' A H over their
# sum. A is dense in L phase points: under PM noise the problem is solved
# as it is up to exact_dense_max points, beyond the chi-square interval is
# kept (the law moves with m at fixed N/m: white PM's total EDF at N/m = 8
# is 59 at N = 256, 84 at N = 1024); under FM noise it is solved at the
# same N/m on at most exact_dense_fm points (the law at fixed N/m tends to
# that of continuous time as m grows). The catalogue entry's `exact_form`
# names the form (R/stat-allan.R, R/stat-further.R). Cost (2026-11-28,
# loaded machine): 1-3.5 s at L = 1025, 0.2-0.5 s at 513.

exact_dense_max <- 1100L
exact_dense_fm <- 513L
exact_dense_cache <- new.env(parent = emptyenv())

# Total variance (SP 1065 eq. 25): second differences at span m centred on
# every inner point of the phase, extended by odd reflection at both ends
# (x*_{1-j} = 2 x_1 - x_{1+j}, x*_{L+j} = 2 x_L - x_{L-j}); returned as
# its terms' matrix W (V = |W x|^2), each row a stencil of <= 5 points.
exact_form_total <- function(m, L) {
  W <- matrix(0, L - 2, L)
  i <- 2:(L - 1)
  row <- seq_along(i)
  # rows are distinct within one call, so each assignment adds once
  add <- function(W, r, c, v) {
    W[cbind(r, c)] <- W[cbind(r, c)] + v
    W
  }
  put <- function(W, t, w) {
    lo <- t < 1
    hi <- t > L
    mid <- !lo & !hi
    W <- add(W, row[mid], t[mid], w)
    if (any(lo)) {
      W <- add(W, row[lo], 1, 2 * w)
      W <- add(W, row[lo], 2 - t[lo], -w)
    }
    if (any(hi)) {
      W <- add(W, row[hi], L, 2 * w)
      W <- add(W, row[hi], 2 * L - t[hi], -w)
    }
    W
  }
  W <- put(W, i - m, 1)
  W <- put(W, i, -2)
  structure(put(W, i + m, 1), terms = TRUE)
}

# The window of MTOT and HTOT (SP 1065 eqs. 27, 29): 3m points less their
# half-average slope, reflected evenly at both ends (9m points), the 6m
# second differences of m-averages (third differences of the sums); its
# matrix D (6m x 3m), so that the window contributes |D s|^2.
exact_window_total <- function(m) {
  n3 <- 3 * m
  h <- floor(n3 / 2)
  one <- function(s) {
    slope <- (mean(s[(n3 - h + 1):n3]) - mean(s[1:h])) / (n3 - h)
    s0 <- s - slope * (0:(n3 - 1))
    E <- c(0, cumsum(c(rev(s0), s0, rev(s0))))
    j <- 1:(6 * m)
    (E[j + 3 * m] - 3 * E[j + 2 * m] + 3 * E[j + m] - E[j]) / m
  }
  vapply(seq_len(n3), function(k) one(as.numeric(seq_len(n3) == k)),
         numeric(6 * m))
}

# Sum of B (w x w) over the windows starting at 1..nw of a series of
# length P: along each diagonal of B a running sum of nw of its entries.
form_windows <- function(B, P, nw) {
  A <- matrix(0, P, P)
  w <- nrow(B)
  for (dl in 0:(w - 1L)) {
    lb <- w - dl
    cs <- c(0, cumsum(B[cbind(seq_len(lb), seq_len(lb) + dl)]))
    p <- seq_len(P - dl)
    hi <- pmin(lb, p)
    lo <- pmax(1, p - nw + 1)
    v <- ifelse(hi >= lo, cs[hi + 1] - cs[pmax(lo, 1)], 0)
    A[cbind(p, p + dl)] <- v
    if (dl > 0) A[cbind(p + dl, p)] <- v
  }
  A
}

exact_form_mtot <- function(m, L) {
  D <- exact_window_total(m)
  form_windows(crossprod(D), L, L - 3 * m + 1)
}

# HTOT: MTOT's window on the frequency y = diff(x) (m = 1: the overlapping
# Hadamard variance's third differences of the phase).
exact_form_htot <- function(m, L) {
  if (m == 1) {
    W <- matrix(0, L - 3, L)
    i <- seq_len(L - 3)
    for (k in 0:3) W[cbind(i, i + k)] <- c(-1, 3, -3, 1)[k + 1L]
    return(crossprod(W))
  }
  D <- exact_window_total(m)
  Ay <- form_windows(crossprod(D), L - 1, L - 3 * m)
  Dx <- diff(diag(L))  # (L - 1) x L first differences
  crossprod(Dx, Ay %*% Dx)
}

# Theo1 (SP 1065 eq. 30) at even m = 2k: terms x_i - x_{i-d+k} + x_{i+m}
# - x_{i+d+k}, weight 1/(k - d), i = 1..L - m, d = 0..k-1.
exact_form_theo1 <- function(m, L) {
  k <- m / 2
  A <- numeric(L * L)
  i <- seq_len(L - m)
  off <- function(d) c(0, k - d, m, k + d)
  cf <- c(1, -1, 1, -1)
  for (d in 0:(k - 1)) {
    o <- off(d)
    for (p in 1:4) for (q in 1:4) {
      # the run A[i + o_p, i + o_q], i = 1..L - m: step L + 1
      idx <- (i + o[q] - 1) * L + i + o[p]
      A[idx] <- A[idx] + cf[p] * cf[q] / (k - d)
    }
  }
  matrix(A, L, L)
}

# M H for H the noise matrix of alpha over L points (the coefficients of
# (1 - B)^(-delta), delta = (2 - alpha)/2): at integer delta delta
# running sums from the right, else a product with the Toeplitz matrix.
noise_right <- function(M, alpha) {
  delta <- (2 - alpha) / 2
  L <- ncol(M)
  if (delta == round(delta)) {
    for (k in seq_len(delta)) {
      M <- t(apply(M[, L:1, drop = FALSE], 1, cumsum))[, L:1, drop = FALSE]
    }
    return(M)
  }
  h <- numeric(L)
  h[1] <- 1
  if (L > 1) for (j in 2:L) h[j] <- h[j - 1] * (j - 2 + delta) / (j - 1)
  H <- matrix(0, L, L)
  for (j in seq_len(L)) H[j:L, j] <- h[seq_len(L - j + 1)]
  M %*% H
}

# The problem solved for (m, L) under alpha: PM noise as it is up to
# exact_dense_max points (else NULL: the law moves with m at fixed N/m);
# FM noise at the same N/m with at most exact_dense_fm points.
exact_dense_problem <- function(m, L, alpha) {
  if (alpha >= 1L) return(if (L <= exact_dense_max) c(m, L))
  if (L <= exact_dense_fm) return(c(m, L))
  # rounded down, so that the window (3m points for MTOT, N/m >= 3) still
  # fits in the scaled record: rounding up broke m = 500, L = 1501
  mp <- max(1, floor(m * (exact_dense_fm - 1) / (L - 1)))
  # an even m stays even (Theo1 is defined at even m only)
  if (m %% 2 == 0) mp <- max(2, 2 * floor(mp / 2))
  c(mp, min(exact_dense_fm, round((L - 1) * mp / m) + 1))
}

# Weights (decreasing, over their sum) of the law of the statistic with
# form `form_name` (a function(m, L) giving A, or its terms' matrix W with
# attribute `terms`) at (m, L) under alpha; cached.
exact_dense_weights <- function(form_name, m, L, alpha) {
  key <- paste(form_name, m, L, alpha, sep = ":")
  hit <- exact_dense_cache[[key]]
  if (!is.null(hit)) return(hit)
  A <- get(form_name, mode = "function")(m, L)
  if (isTRUE(attr(A, "terms"))) {
    WH <- noise_right(A, alpha)
    G <- if (nrow(WH) < ncol(WH)) tcrossprod(WH) else crossprod(WH)
  } else {
    G <- t(noise_right(t(noise_right(A, alpha)), alpha))
  }
  ev <- eigen((G + t(G)) / 2, symmetric = TRUE, only.values = TRUE)$values
  ev <- ev[ev > 1e-13 * ev[1L]]
  out <- ev / sum(ev)
  assign(key, out, envir = exact_dense_cache)
  out
}

# Lower and upper factors (times the deviation) of the exact interval of
# a statistic with a dense form at (m, L) under alpha; NA where the
# problem is not solved (exact_dense_problem()).
exact_dense_factors <- function(form_name, m, L, alpha, conf) {
  pr <- exact_dense_problem(m, L, alpha)
  if (is.null(pr)) return(c(NA_real_, NA_real_))
  key <- paste(form_name, pr[1L], pr[2L], alpha, format(conf, digits = 15),
               "q", sep = ":")
  hit <- exact_dense_cache[[key]]
  if (!is.null(hit)) return(hit)
  lam <- exact_dense_weights(form_name, pr[1L], pr[2L], alpha)
  out <- gchisq_factors(lam, conf)
  assign(key, out, envir = exact_dense_cache)
  out
}
