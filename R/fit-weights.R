# How the fit weighs the points of a curve: the equivalent degrees of
# freedom (EDF) of each AV estimate under the model, the chi-square bias and
# spread of ln AV-hat, the white-noise correlation between points and the
# whitening matrix built from them.
#
# The EDF of the model's N, K, Q and Gauss-Markov terms is exact for their
# sum (edf_fit_model(), src/avfit.cpp: Greenhall & Riley's sum over the
# autocovariance of the second differences). Any other stochastic term
# gets the EDF of its power-law exponent (catalogue `edf_alpha`) from the
# one EDF engine of allan() (src/edf.cpp through allan_edf_direct() in
# R/edf.R), combined as nu = (sum_k AV_k)^2 / sum_k (AV_k^2 / nu_k);
# deterministic terms (alpha NA) add no variance.

log_bias <- function(edf) digamma(edf / 2) - log(edf / 2)
log_sd <- function(edf) sqrt(trigamma(edf / 2))

# The catalogue entry of avfit's `type` (its "non-overlapping" is the
# standard estimator); engine_type(): the name the EDF engine knows.
fit_stat <- function(type) {
  stat_entry(if (identical(type, "non-overlapping")) "standard" else type)
}
engine_type <- function(type) fit_stat(type)$name

# EDF of the AV estimates at cluster sizes m (rounded to whole samples) for
# power-law noise of rate-PSD exponent `alpha` (one value): n samples, L
# phase points (n + 1 for rate input). NA where the estimator has no term.
edf_power_law <- function(m, n, type, alpha, L = n + 1) {
  et <- engine_type(type)
  mm <- pmax(round(m), 1)
  nt <- allan_nterms(et, mm, L)
  out <- rep(NA_real_, length(m))
  ok <- is.finite(nt) & nt >= 1
  if (any(ok)) {
    out[ok] <- allan_edf_direct(et, mm[ok], nt[ok], L,
                                rep(as.integer(alpha), sum(ok)))
  }
  out
}

# Mixture EDF of a model: `comp` the per-instance AV (matrix, one column per
# instance), `alpha` their exponents (matrix of the same shape, or a
# scalar); nu = (sum AV_k)^2 / sum(AV_k^2 / nu_k). Floored at 1 and never
# more than the number of samples.
edf_model <- function(m, n, type, comp, alpha, L = n + 1) {
  comp <- as.matrix(comp)
  alpha <- matrix(alpha, nrow(comp), ncol(comp))
  tot <- rowSums(comp)
  den <- numeric(nrow(comp))
  for (k in seq_len(ncol(comp))) {
    for (a in unique(stats::na.omit(alpha[, k]))) {
      i <- which(alpha[, k] == a)
      den[i] <- den[i] + comp[i, k]^2 / edf_power_law(m[i], n, type, a, L)
    }
  }
  e <- tot^2 / den
  # a model of deterministic terms only: white-noise EDF
  bad <- !is.finite(e)
  if (any(bad)) e[bad] <- edf_power_law(m[bad], n, type, 0, L)
  pmin(pmax(e, 1), n)
}

# EDF of a fitted model's AV estimates at the data taus: `lay` the layout
# with values. When every stochastic term says how it enters the exact EDF
# (the catalogue's `exact_edf`: white, random-walk and white-phase
# structure functions, AR(1) parts) and there is more than one of them or
# one that is not a power law, the EDF is exact for their sum (Greenhall &
# Riley 2003, cross terms included; the per-term combination overstates it
# up to twofold where two terms are level); deterministic terms (ramp,
# sinusoids) add to the AV only. Otherwise (a flicker or filter term, a
# single power-law noise, which the engine of allan() already gives, or no
# tau0) edf_model().
edf_fit_model <- function(m, n, type, tau, tau0, lay, L = n + 1) {
  plan <- model_plan(lay)
  comp <- model_components(tau, tau0, lay, plan)
  alpha <- model_alpha(tau, tau0, lay, plan)
  ex <- exact_model(plan, comp, alpha, lay, tau0)
  if (is.null(ex) || !(ex$stochastic > 1L || !ex$power_law)) {
    return(edf_model(m, n, type, comp, alpha, L))
  }
  exact <- ex$exact
  parts <- ex$parts
  mm <- pmax(round(m), 1)
  nu_g <- avfit_exact_edf(as.double(mm),
                          as.double(allan_nterms(engine_type(type), mm, L)),
                          fit_stat(type)$overlapping,
                          parts$shape, parts$coef, parts$phi)
  av_g <- rowSums(comp[, exact, drop = FALSE])
  e <- rowSums(comp)^2 / (av_g^2 / nu_g)
  bad <- !(is.finite(e) & e > 0)
  if (any(bad)) {
    e[bad] <- edf_model(m[bad], n, type, comp[bad, , drop = FALSE],
                        alpha[bad, , drop = FALSE], L)
  }
  pmin(pmax(e, 1), n)
}

# The model as structure-function parts, when every live stochastic term
# declares how it enters (the catalogue's `exact_edf`) and tau0 is known:
# list(parts, exact (which plan entries), stochastic (how many live
# stochastic terms), power_law (all of them power laws)); else NULL.
exact_model <- function(plan, comp, alpha, lay, tau0) {
  exact <- vapply(plan, function(p) is.function(p$entry$exact_edf), NA)
  power_law <- vapply(plan, function(p) is.finite(p$entry$psd_alpha), NA)
  # AVs beyond double precision (a rate of 1e-300 Hz): no exact form
  if (is.null(tau0) || !all(is.finite(comp))) return(NULL)
  stoch <- colSums(comp) > 0 & colSums(!is.na(alpha)) > 0
  if (!any(stoch) || !all(exact[stoch])) return(NULL)
  list(parts = exact_edf_parts(plan[exact], stats::setNames(lay$value, lay$name), tau0),
       exact = exact, stochastic = sum(stoch), power_law = all(power_law[stoch]))
}

# The structure-function parts the terms of `plan` declare (each entry's
# exact_edf(amp, nl, tau0)), as the kernel's shape codes, coefficients and
# AR(1) poles.
exact_edf_parts <- function(plan, values, tau0) {
  shapes <- c("linear", "cubic", "step", "ar1")
  parts <- unlist(lapply(plan, function(p) {
    nl <- if (length(p$nl)) stats::setNames(values[p$nl], p$nl_param) else NULL
    p$entry$exact_edf(values[p$amp], nl, tau0)
  }), recursive = FALSE)
  list(shape = match(vapply(parts, `[[`, "", "shape"), shapes) - 1L,
       coef = vapply(parts, function(q) as.double(q$coef), 0),
       phi = vapply(parts, function(q) as.double(q$phi %||% 0), 0))
}

# Correlation matrix of the overlapping AV estimates at cluster sizes m
# under the fitted model (layout `lay`), when every stochastic term has an
# exact structure function (exact_model()); NULL otherwise.
model_corr <- function(m, n, type, tau, tau0, lay, L = n + 1) {
  if (!identical(fit_stat(type)$name, "overlapping")) return(NULL)
  plan <- model_plan(lay)
  ex <- exact_model(plan, model_components(tau, tau0, lay, plan),
                    model_alpha(tau, tau0, lay, plan), lay, tau0)
  if (is.null(ex)) return(NULL)
  mm <- pmax(round(m), 1)
  R <- avfit_model_corr(as.double(mm), as.double(allan_nterms("overlapping", mm, L)),
                        ex$parts$shape, ex$parts$coef, ex$parts$phi)
  if (anyNA(R)) return(NULL)
  R
}

# Correlation matrix of the AV estimates at cluster sizes m for white rate
# noise (exact Gaussian moments, C++).
white_corr <- function(m, n, type) {
  C <- avar_white_cov(as.double(round(m)), as.double(n),
                      fit_stat(type)$overlapping, allanvar_threads())
  d <- sqrt(diag(C))
  R <- C / outer(d, d)
  R[!is.finite(R)] <- 0
  diag(R) <- 1
  R
}

# Whitening matrix W with ||W r||^2 = r' Sigma^-1 r, Sigma = diag(s) R diag(s).
# Independent points: W is diagonal and is kept as its diagonal, a
# one-column matrix (a dense J x J diagonal is 800 MB at J = 10,000); apply
# it with wmul(), which src/avfit.cpp mirrors.
whitening <- function(s, corr) {
  if (is.null(corr)) return(matrix(1 / s, ncol = 1L))
  Sig <- corr * outer(s, s)
  U <- chol_or_null(Sig)
  # nearly coincident taus can make Sigma numerically singular: add a ridge
  ridge <- 1e-10
  while (is.null(U) && ridge < 1e-2) {
    U <- chol_or_null(Sig + diag(ridge * s^2, length(s)))
    ridge <- ridge * 100
  }
  if (is.null(U)) return(diag(1 / s, length(s)))
  t(backsolve(U, diag(length(s))))
}

# W %*% v for a whitening matrix or a diagonal one kept as a column.
wmul <- function(W, v) {
  v <- as.matrix(v)
  if (ncol(W) == 1L && nrow(W) == nrow(v) && nrow(v) > 1L) W[, 1L] * v else W %*% v
}

# log-determinant term of the whitening: -2 sum log diag(W).
w_logdet <- function(W) {
  d <- if (ncol(W) == 1L && nrow(W) > 1L) W[, 1L] else diag(W)
  -2 * sum(log(d))
}

# Cholesky factor, or NULL when the matrix is not numerically positive
# definite (the caller then regularises).
chol_or_null <- function(A) {
  tryCatch(chol(A), error = function(e) NULL)
}
