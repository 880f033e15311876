# Exact two-moment EDF of the statistics built from windows: MTOT and TTOT
# (3m phase points less their slope, reflected), HTOT (the same window on
# the frequency) and Theo1 (m + 1 points). A window starting at t gives a
# quadratic form q_t = x_t' B x_t, a window starts at every point (M of
# them) and B annihilates polynomials of degree < d, so under discrete
# power-law noise (Kasdin: the d-th differences of the phase are
# fractionally differenced white noise, src/term_acov.h) the q_t are a
# stationary sequence. With B = sum_k lambda_k u_k u_k' and z_k = u_k' x_t,
# whose cross-covariances rho_kl(h) follow from that of the differences,
#   E q = sum_k lambda_k rho_kk(0),
#   Cov(q_t, q_{t+h}) = 2 sum_kl lambda_k lambda_l rho_kl(h)^2,
#   EDF = 2 (E q)^2 / Var(mean q),
#   Var(mean q) = M^-2 sum_{|h| < M} (M - |h|) Cov(q_t, q_{t+h}).
# Lags reach the window's span under white, random-walk FM and white PM
# (finite filters) and 16 spans under the flicker noises (as PDEV's
# terms_edf_cpp()). Cost: O(K^2 (w + lags)) for a window of w points and
# K <= w filters; the rules use it up to windows_edf_wmax points (where
# the table formulas are least right: at m = 2, N = 1024, MTOT's EDF under
# flicker FM is 602 by Monte Carlo, the modified Allan EDF it took 487;
# Theo1's under flicker PM 567, Howe's formula 664). Cached per session.

windows_edf_wmax <- 50L
windows_edf_cache <- new.env(parent = emptyenv())

# Autocovariance of (1 - B)^(-f) e at lags 0..H (unit innovations), f <= 0
# (src/term_acov.h farima_acf()).
farima_acf_r <- function(f, H) {
  g <- numeric(H + 1L)
  g[1L] <- exp(lgamma(1 - 2 * f) - 2 * lgamma(1 - f))
  if (H >= 1L) {
    for (h in 0:(H - 1L)) g[h + 2L] <- g[h + 1L] * (h + f) / (h + 1 - f)
  }
  g
}

# EDF of the mean of M windows' forms x_t' B x_t under the power law alpha,
# B annihilating polynomials of degree < d (alpha + 2 d > 1).
windows_edf <- function(B, d, alpha, M) {
  if (M < 1) return(NA_real_)
  es <- eigen((B + t(B)) / 2, symmetric = TRUE)
  keep <- es$values > 1e-12 * max(es$values)
  lam <- es$values[keep]
  V <- es$vectors[, keep, drop = FALSE]
  # u_k = (1 - B)^d v_k: d running sums, each dropping its last entry
  for (k in seq_len(d)) {
    V <- apply(V, 2L, cumsum)
    V <- V[-nrow(V), , drop = FALSE]
  }
  P <- nrow(V)
  K <- ncol(V)
  f <- (2 - alpha) / 2 - d
  # an integer f: a finite filter, its autocovariance zero beyond lag -f
  reach <- if (f == round(f)) P - 1L - f else 16L * (nrow(B) + 2L)
  H <- as.integer(min(M - 1, reach))
  g <- farima_acf_r(f, H + P)
  taus <- seq.int(-(P - 1L), P - 1L)
  # C_tau[k, l] = sum_i V[i, k] V[i + tau, l], one column per tau
  Cs <- vapply(taus, function(tau) {
    if (tau >= 0) {
      crossprod(V[seq_len(P - tau), , drop = FALSE],
                V[seq.int(1L + tau, P), , drop = FALSE])
    } else {
      crossprod(V[seq.int(1L - tau, P), , drop = FALSE],
                V[seq_len(P + tau), , drop = FALSE])
    }
  }, numeric(K * K))
  Cs <- matrix(Cs, K * K, length(taus))
  G <- outer(taus, 0:H, function(tau, h) g[abs(h + tau) + 1L])
  R <- Cs %*% G  # rho_kl(h), column h + 1
  kap <- 2 * colSums(as.vector(outer(lam, lam)) * R^2)
  Eq <- sum(lam * diag(matrix(R[, 1L], K, K)))
  h <- seq_len(H)
  v <- (M * kap[1L] + 2 * sum((M - h) * kap[-1L])) / M^2
  2 * Eq^2 / v
}

# The window forms, by statistic (d: the degree they annihilate).
window_form_mtot <- function(m) {
  list(B = crossprod(exact_window_total(m)), d = 2L)
}
window_form_htot <- function(m) {
  Dx <- diff(diag(3 * m + 1))  # the frequency window from its phase
  list(B = crossprod(Dx, crossprod(exact_window_total(m)) %*% Dx), d = 3L)
}
window_form_theo1 <- function(m) {
  k <- m / 2
  B <- matrix(0, m + 1, m + 1)
  for (dd in 0:(k - 1)) {
    w <- numeric(m + 1)
    o <- c(0, k - dd, m, k + dd) + 1
    for (j in 1:4) w[o[j]] <- w[o[j]] + c(1, -1, 1, -1)[j]  # d = 0: k twice
    B <- B + tcrossprod(w) / (k - dd)
  }
  list(B = B, d = 2L)
}

# Each form's window length in phase points (checked before it is built:
# the rules ask at every m of a curve).
windows_edf_size <- list(window_form_mtot = function(m) 3 * m,
                         window_form_htot = function(m) 3 * m + 1,
                         window_form_theo1 = function(m) m + 1)

# The EDF of the rows (m, windows M, alpha) of a statistic whose window
# form is `form` (a function(m)); NA where the window is longer than
# windows_edf_wmax or alpha is out of reach of the form.
windows_edf_rows <- function(form, m, M, alpha) {
  out <- rep(NA_real_, length(m))
  for (i in seq_along(m)) {
    key <- paste(form, m[i], M[i], alpha[i])
    hit <- windows_edf_cache[[key]]
    if (!is.null(hit)) {
      out[i] <- hit
      next
    }
    if (windows_edf_size[[form]](m[i]) > windows_edf_wmax || M[i] < 1) next
    fm <- get(form, mode = "function")(m[i])
    if (alpha[i] + 2L * fm$d <= 1L) next
    out[i] <- windows_edf(fm$B, fm$d, alpha[i], M[i])
    assign(key, out[i], envir = windows_edf_cache)
  }
  out
}
