#' Exact maximum-likelihood noise fit on the raw series
#'
#' Fits the noise model to the rate series itself rather than to its Allan
#' variance: the exact Gaussian likelihood of the samples, computed by a
#' Kalman filter over the linear state-space form of each term (catalogue
#' field `statespace`: white noise `N` is measurement noise, the rate random
#' walk `K` a state with a diffuse start, the sensor's unknown bias, and a
#' Gauss-Markov term `gm` an AR(1) state started from its stationary law;
#' without `K` a constant level with a diffuse start carries the bias).
#' One likelihood costs O(n) and a fit a few hundred of them (about a second
#' at 1e5 samples).
#'
#' This is the efficient estimator: on white noise + random walk +
#' Gauss-Markov composites its errors are close to the Cramer-Rao bound
#' (bench/gmwm-mle.R). Where a term is barely visible in the record (a rate
#' random walk level with a Gauss-Markov tail at the longest tau) the
#' likelihood is flat and its maximum often sits at 0: `K = 0` then says
#' the record cannot tell the term apart, not that it is absent.
#'
#' The fit starts from [avfit()] on [allan()]'s curve (or `start`), with
#' the other amplitudes also started 10 times smaller and larger; the
#' overall scale is profiled out (Durbin & Koopman 2012, sec. 7.2). An
#' amplitude that reaches its lower limit (1e-12 of the start) is reported
#' as 0.
#'
#' @section Uncertainty:
#' Every parameter of a converged fit gets an SE or an interval
#' (`confint()`):
#' * identified parameters: the inverse of the exact expected information
#'   of [av_information()] at the estimate, in the log parameters (where it
#'   cannot be computed, the observed information: the numerical Hessian
#'   of the log-likelihood, noisy on long records). `confint()` gives Wald intervals
#'   on the log scale; `se` is the delta-method SE on the linear scale and
#'   `vcov` the covariance on that scale.
#' * an amplitude at its boundary (the likelihood is highest at 0; an
#'   estimate whose removal costs less than 0.01 in log-likelihood is set to
#'   0): no Wald SE (`NA`); `bound_upper` holds its one-sided 95% upper
#'   bound from the profile likelihood (the amplitude where the likelihood,
#'   maximised over the other parameters, has dropped by
#'   `qchisq(0.90, 1) / 2`, the boundary's half chi-square), and
#'   `confint()` gives `[0, bound_upper]`.
#' * the time constant of a Gauss-Markov term at 0 is not identified:
#'   interval `(0, Inf)`.
#' `interval` names the method used for each parameter.
#'
#' @param x The rate series (numeric vector, no missing values).
#' @param freq Sampling frequency in Hz.
#' @param terms Character vector of terms, each with a state-space form:
#'   `"N"`, `"K"`, `"gm"` (repeatable). `NULL` (the default): each term
#'   that has one, once: `c("N", "K", "gm")`.
#' @param start Optional named starting values (coefficient names as in
#'   [avfit()], e.g. `c(gm1.tc = 2)`); by default avfit()'s estimate.
#' @return An object of class `"avfit"` (see [avfit()]) whose coefficients,
#'   `se` and `vcov` are the maximum-likelihood ones; its curve parts
#'   (`data`, `chi2`, `components`) compare that model with [allan()]'s
#'   overlapping curve of `x`. Extra elements: `method = "mle"`, `loglik`
#'   (the exact log-likelihood of `x[-1]` given `x[1]`: the sensor's bias is
#'   unknown, a diffuse level, or the random walk's start when there is a
#'   `K` term), `avfit` (the curve fit it started from), `bound_upper` and
#'   `interval` (see Uncertainty).
#' @seealso [avfit()], [avsim()]
#' @export
#' @examples
#' x <- avsim(2e4, freq = 100, N = 0.01, K = 1e-3, seed = 1)
#' fit <- avmle(x, 100, c("N", "K"))
#' coef(fit)
#' fit$se
avmle <- function(x, freq, terms = NULL, start = NULL) {
  cl <- match.call()
  check_present(missing(x), "x", "a rate series")
  x <- check_values(x, min_n = 16L, arg = "x")
  freq <- check_freq(freq)
  # the default model: every entry with a state-space form, once
  terms <- check_terms(terms %||% statespace_kinds())
  lay <- coef_layout(terms)
  start <- check_named(start, "start", lay$name)
  entries <- statespace_entries(terms, "terms", "avmle() fits terms that have one")
  tau0 <- 1 / freq
  # the curve fit only starts the likelihood: its own SEs are not reported
  fit0 <- quiet_fit_warnings(avfit(allan(x, freq), terms))
  p0 <- coef(fit0)
  if (!is.null(start)) p0[names(start)] <- start
  p0 <- mle_start(p0, lay, fit0, tau0, entries)
  model <- function(p) mle_model(p, lay, entries, tau0)
  if (!is.finite(mle_loglik(x, model(p0)))) {
    abort("`freq` (", format(freq), " Hz) puts the terms' variances per sample ",
          "outside double precision; the likelihood cannot be evaluated ",
          "(give the rate in other units or the sampling frequency in Hz).",
          class = "argument")
  }
  est <- mle_optimise(x, p0, lay, model)
  est <- mle_collapse(x, est, lay, model)
  est <- mle_scoring_check(x, est, lay, model, freq)
  unc <- mle_uncertainty(x, est, lay, model, p0, freq)
  fit <- quiet_fit_warnings(avfit(fit0$input, terms, fixed = est$par))
  fit$se <- unc$se
  # (a zero amplitude's SE is NA by design: it has its bound_upper)
  fit$vcov <- unc$vcov
  fit$bound_upper <- unc$bound_upper
  fit$interval <- unc$interval
  fit$layout$fixed <- FALSE
  fit$npar <- nrow(lay)
  fit$df.residual <- fit$nobs - nrow(lay)
  fit$convergence <- est$convergence
  fit$method <- "mle"
  fit$loglik <- est$loglik
  fit$avfit <- fit0
  fit$call <- cl
  validate_avfit(fit)
}

# The entries of `terms`, one per term, each with its state-space form; a
# term without one is an error naming argument `arg` and what `needs` it.
statespace_entries <- function(terms, arg, needs) {
  sp <- split_term(terms)
  entries <- lapply(seq_along(terms), function(i) effect_entry(sp$kind[i], sp$variant[i]))
  none <- !vapply(entries, function(e) is.function(e$statespace), NA)
  if (any(none)) {
    abort("`", arg, "`: ", paste0("\"", unique(terms[none]), "\"", collapse = ", "),
          " has no state-space form; ", needs, " (",
          paste0("\"", statespace_kinds(), "\"", collapse = ", "), ").",
          class = "argument")
  }
  entries
}

# The kinds that have a state-space form, in canonical order.
statespace_kinds <- function() {
  vapply(entries_with("statespace"), `[[`, "", "name", USE.NAMES = FALSE)
}

# Terms' state-space parts assembled: measurement variance R, diagonal T,
# Q, P0, and the index (0-based) of the diffuse state.
mle_model <- function(p, lay, entries, tau0) {
  R <- 0
  T <- Q <- P0 <- numeric()
  for (i in seq_along(entries)) {
    rows <- lay$label == unique(lay$label)[i]
    v <- p[lay$name[rows]]
    names(v) <- lay$param[rows]
    amp <- v[lay$role[rows] == "amp"]
    nl <- v[lay$role[rows] == "nonlinear"]
    ss <- entries[[i]]$statespace(amp, nl, tau0)
    R <- R + (ss$R %||% 0)
    T <- c(T, ss$T); Q <- c(Q, ss$Q); P0 <- c(P0, ss$P0)
  }
  diffuse <- which(is.infinite(P0))
  if (!length(diffuse)) {
    # the sensor's constant bias, unknown: a diffuse level that never moves
    # (without it a bias is read as a slow Gauss-Markov process)
    T <- c(T, 1)
    Q <- c(Q, 0)
    P0 <- c(P0, Inf)
    diffuse <- length(P0)
  }
  if (length(diffuse) > 1L) {
    abort("`terms`: avmle() takes at most one term with an unknown level ",
          "(a diffuse state such as K).", class = "argument")
  }
  list(R = R, T = T, Q = Q, P0 = P0,
       diffuse = if (length(diffuse)) diffuse - 1L else -1L)
}

mle_loglik <- function(x, m) {
  s <- mle_kalman_sums(x, m$R, m$T, m$Q, m$P0, m$diffuse)
  -0.5 * (s[[3]] * log(2 * pi) + s[[1]] + s[[2]])
}

# Start values: an amplitude avfit() put at 0 starts where its AV is a
# tenth of the fitted curve's at the longest tau (a term just visible).
mle_start <- function(p0, lay, fit0, tau0, entries) {
  tau <- max(fit0$data$tau)
  for (i in which(lay$role == "amp" & !(p0[lay$name] > 0))) {
    e <- entries[[match(lay$label[i], unique(lay$label))]]
    rows <- lay$label == lay$label[i] & lay$role == "nonlinear"
    nl <- stats::setNames(p0[lay$name[rows]], lay$param[rows])
    b <- as.numeric(e$basis(tau, tau0, nl))[1L]
    p0[[lay$name[i]]] <- sqrt(0.1 * fit0$data$fitted[which.max(fit0$data$tau)] / b)
  }
  p0
}

# Maximises the likelihood over log parameters; every variance scales with
# the square of the amplitudes, so the first amplitude is profiled out.
mle_optimise <- function(x, p0, lay, model) {
  amp <- which(lay$role == "amp")
  ref <- amp[1L]
  free <- setdiff(seq_len(nrow(lay)), ref)
  lp0 <- log(p0)
  unpack <- function(th) {
    lp <- lp0
    lp[free] <- th
    exp(lp)
  }
  prof <- function(th) {
    m <- model(unpack(th))
    s <- mle_kalman_sums(x, m$R, m$T, m$Q, m$P0, m$diffuse)
    ll <- -0.5 * (s[[3]] * (log(2 * pi * s[[2]] / s[[3]]) + 1) + s[[1]])
    # a trial point whose variances overflow: worse than any finite one
    list(scale = s[[2]] / s[[3]], ll = if (is.finite(ll)) ll else -.Machine$double.xmax)
  }
  lower <- lp0[free] - ifelse(lay$role[free] == "amp", log(1e12), log(1e3))
  upper <- lp0[free] + ifelse(lay$role[free] == "amp", log(1e6), log(1e3))
  best <- NULL
  for (f in c(1, 0.1, 10)) {
    th <- pmin(pmax(lp0[free] + ifelse(lay$role[free] == "amp", log(f), 0), lower), upper)
    o <- stats::optim(th, function(t) -prof(t)$ll, method = "L-BFGS-B",
                      lower = lower, upper = upper, control = list(factr = 1e5))
    if (is.null(best) || o$value < best$value) best <- o
  }
  p <- unpack(best$par)
  sc <- sqrt(prof(best$par)$scale)
  p[amp] <- p[amp] * sc
  at0 <- free[lay$role[free] == "amp" & best$par <= lower + 1e-3]
  p[at0] <- 0
  list(par = stats::setNames(p, lay$name), loglik = -best$value,
       convergence = list(converged = best$convergence == 0L,
                          iterations = as.integer(best$counts[[1L]]),
                          evaluations = as.integer(best$counts[[1L]]),
                          message = best$message %||% ""))
}

# An amplitude the optimiser left just above its lower limit (the
# likelihood flat towards 0) is at the boundary: set to 0 when that costs
# less than 0.01 in log-likelihood.
mle_collapse <- function(x, est, lay, model) {
  p <- est$par
  ll <- mle_loglik(x, model(p))
  amp <- which(lay$role == "amp" & p > 0)
  for (i in amp[order(p[amp] / max(p[amp]))]) {
    if (sum(p[lay$role == "amp"] > 0) <= 1L) break
    ll0 <- mle_loglik(x, model(replace(p, i, 0)))
    if (is.finite(ll0) && ll0 >= ll - 0.01) {
      p[i] <- 0
      ll <- max(ll, ll0)
    }
  }
  est$par <- p
  est$loglik <- ll
  est
}

# The parameters the likelihood identifies: amplitudes above 0 and the
# nonlinear parameters of terms whose amplitude is above 0.
mle_identified <- function(par, lay) {
  zero_lab <- lay$label[lay$role == "amp" & par == 0]
  !(lay$label %in% zero_lab & lay$role == "nonlinear") & !(lay$role == "amp" & par == 0)
}

# L-BFGS-B on numerical gradients of a sum over 1e6 samples often ends in
# a failed line search at the maximum (the log-likelihood's last digits are
# rounding). Such a stop is checked by Fisher-scoring steps from there
# (the exact expected information at the stop, central-difference
# gradient; at most five, each halved until it gains), and the fit counts as
# converged when the gain a further step predicts, g'I^-1 g / 2, is below
# 1e-3 log-likelihood units.
mle_scoring_check <- function(x, est, lay, model, freq, tol = 1e-3) {
  if (isTRUE(est$convergence$converged)) return(est)
  par <- est$par
  ok <- mle_identified(par, lay)
  f <- function(lp) mle_loglik(x, model(replace(par, ok, exp(lp))))
  # the scoring direction and the gain it predicts at lp
  direction <- function(lp) {
    V <- mle_inverse(tryCatch(av_information(replace(par, ok, exp(lp))[ok], n = length(x),
                                             freq = freq)$information,
                              allanvar_error = function(e) NULL))
    if (is.null(V)) return(NULL)
    h <- 1e-3
    g <- vapply(seq_along(lp), function(j) {
      e <- replace(numeric(length(lp)), j, h)
      (f(lp + e) - f(lp - e)) / (2 * h)
    }, 0)
    d <- as.numeric(V %*% g)
    list(d = d, gain = sum(g * d) / 2)
  }
  lp <- log(par[ok])
  dir <- direction(lp)
  # a few steps at most, each halved until it gains
  for (step in 1:5) {
    if (is.null(dir) || !is.finite(dir$gain) || dir$gain < tol) break
    moved <- FALSE
    for (half in 0:5) {
      lp1 <- lp + dir$d / 2^half
      ll1 <- f(lp1)
      if (is.finite(ll1) && ll1 > est$loglik) { moved <- TRUE; break }
    }
    if (!moved) break
    lp <- lp1
    est$par <- replace(par, ok, exp(lp))
    est$loglik <- ll1
    dir <- direction(lp)
  }
  if (!is.null(dir) && is.finite(dir$gain) && dir$gain < tol) {
    est$convergence$converged <- TRUE
    est$convergence$message <- sprintf(
      "%s; Fisher scoring from the stop: a further step would gain %.1e in log-likelihood, at the maximum",
      est$convergence$message, dir$gain)
  }
  est
}

# Uncertainty of every parameter. Identified parameters: the inverse of the
# exact expected information of av_information() at the estimate, in the
# log parameters (where it cannot be had, the observed information: the
# numerical Hessian), so Wald intervals on the log scale
# (`se` is the delta-method SE on the linear scale). An amplitude at 0: no
# Wald SE, a one-sided 95% upper bound from the profile likelihood
# (2 * drop = qchisq(0.90, 1), the boundary's half chi-square). The
# nonlinear parameters of a term at 0: not identified, interval (0, Inf).
mle_uncertainty <- function(x, est, lay, model, p0, freq) {
  par <- est$par
  k <- nrow(lay)
  ok <- mle_identified(par, lay)
  # the exact expected information first: the numerical Hessian of a sum
  # over 1e6 samples is noisy (95% intervals for a weak K covered 84% at
  # 1e6 samples, 98.5% at 1e5; with the expected information 94.1% and
  # 97.1%, bench/README.md)
  I <- tryCatch(av_information(par[ok], n = length(x), freq = freq)$information,
                allanvar_error = function(e) NULL)
  V <- mle_inverse(I)
  source <- "expected"
  if (is.null(V)) {
    nll <- function(lp) {
      v <- -mle_loglik(x, model(replace(par, ok, exp(lp))))
      if (is.finite(v)) v else .Machine$double.xmax
    }
    lp <- log(par[ok])
    H <- tryCatch(stats::optimHess(lp, nll, control = list(ndeps = rep(1e-3, length(lp)))),
                  error = function(e) NULL)
    V <- mle_inverse(H)
    source <- "observed"
  }
  vc <- matrix(NA_real_, k, k, dimnames = list(lay$name, lay$name))
  se <- stats::setNames(rep(NA_real_, k), lay$name)
  interval <- stats::setNames(rep("not identified", k), lay$name)
  if (!is.null(V)) {
    vc[ok, ok] <- V * outer(par[ok], par[ok])
    se[ok] <- par[ok] * sqrt(diag(V))
    interval[ok] <- paste0("Wald, log scale (", source, " information)")
  }
  bound <- stats::setNames(rep(NA_real_, k), lay$name)
  for (i in which(lay$role == "amp" & par == 0)) {
    bound[i] <- mle_profile_upper(x, par, i, ok, lay, model, p0, est$loglik)
    interval[i] <- "one-sided, profile likelihood"
  }
  list(se = se, vcov = vc, bound_upper = bound, interval = interval)
}

mle_inverse <- function(H) {
  if (is.null(H) || !all(is.finite(H))) return(NULL)
  ch <- tryCatch(chol((H + t(H)) / 2), error = function(e) NULL)
  if (is.null(ch)) return(NULL)
  V <- chol2inv(ch)
  dimnames(V) <- dimnames(H)
  V
}

# One-sided 95% upper bound of the amplitude `i` at 0: the a > 0 where the
# log-likelihood, maximised over the other identified parameters (and the
# term's own nonlinear ones), has dropped by qchisq(0.90, 1) / 2.
mle_profile_upper <- function(x, par, i, ok, lay, model, p0, llmax) {
  drop <- stats::qchisq(0.90, 1) / 2
  own <- lay$label == lay$label[i] & lay$role == "nonlinear"
  free <- ok | own
  start <- par
  start[own] <- p0[own]
  lp_start <- log(start[free])
  box <- c(-1, 1) * log(1e3)
  lp_warm <- lp_start
  # each profile point starts from the last one's nuisance parameters
  prof <- function(la) {
    f <- function(lp) {
      v <- -mle_loglik(x, model(replace(replace(par, free, exp(lp)), i, exp(la))))
      if (is.finite(v)) v else .Machine$double.xmax
    }
    run <- function(from) {
      tryCatch(stats::optim(from, f, method = "L-BFGS-B",
                            lower = lp_start + box[1], upper = lp_start + box[2],
                            control = list(maxit = 300, factr = 1e3)),
               error = function(e) NULL)
    }
    o <- run(lp_warm)
    if (is.null(o)) return(NA_real_)
    # L-BFGS-B on numerical gradients can stop early (a failed line search
    # or a stale curvature memory); a restart from where it stopped goes on
    for (r in 1:3) {
      o2 <- run(o$par)
      if (is.null(o2) || o2$value >= o$value - 1e-6) break
      o <- o2
    }
    lp_warm <<- o$par
    -o$value
  }
  # negative while the profile is within `drop` of the maximum
  g <- function(la) llmax - prof(la) - drop
  # bracket: from a tenth of the start upwards by decades
  ref <- if (p0[i] > 0) p0[i] else max(par[lay$role == "amp"])
  lo <- log(ref) - log(1e4)
  hi <- log(ref) - log(10)
  glo <- g(lo)
  if (!is.finite(glo)) return(NA_real_)
  if (glo > 0) return(exp(lo))
  for (step in 1:10) {
    gh <- g(hi)
    if (!is.finite(gh)) return(NA_real_)
    if (gh > 0) break
    lo <- hi; glo <- gh
    hi <- hi + log(10)
  }
  if (!(gh > 0)) return(Inf)
  exp(stats::uniroot(g, c(lo, hi), f.lower = glo, f.upper = gh, tol = 0.01)$root)
}

# `expr` without the warnings of fits whose SEs are not reported.
quiet_fit_warnings <- function(expr) {
  withCallingHandlers(expr, allanvar_warning_fit_not_finite = function(w)
    invokeRestart("muffleWarning"))
}
