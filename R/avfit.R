# The noise-model fit. Internals other files may use (stable within the
# package):
#   avfit(fit, terms, start = c(gm2.tc = 30))  refits an avfit's own curve
#       with new terms; the old nonlinear estimates start the new fit.
#   fit$data     tau, m, avar, edf, fitted, z (standardized log residual)
#   fit$input    the normalised input (list: data, freq, n, type, edf_source)
#   fit$layout   one row per coefficient: name, label, kind, param, role
#                ("amp"/"nonlinear"), unit, fixed, value
#   fit$components  each term instance's AV at the data taus
#   log_bias(edf), log_sd(edf)   chi-square log bias and sd of ln AV-hat
#   edf_model(m, n, type, comp, alpha)  model EDF (see the EDF section)
#   white_corr(m, n, type)  white-noise correlation of the AV estimates
# The catalogue helpers live in terms.R (coef_layout, check_coef,
# term_basis_matrix, model_components, term_entry, term_labels).

#' Fit a noise model to an Allan variance curve
#'
#' Fits a sum of noise terms from the catalogue ([av_terms()]) to an Allan
#' variance curve by weighted least squares in the log domain, keeping
#' amplitudes non-negative and profiling the nonlinear parameters
#' (Gauss-Markov correlation times, sinusoid frequencies).
#'
#' @section Input:
#' `av` may be
#' * the result of `allan()` (one channel, or choose one with `channel`);
#'   its `freq`, `N`, `type` and `edf` are used;
#' * the result of [avar()], [avarn()] or [avari()] (columns `time`, `av`,
#'   `error`); `freq` is required, `n` is recovered from the `error` column
#'   (\eqn{1/\sqrt{2(n/m - 1)}}) when not given. avar() and avarn() are
#'   non-overlapping estimators, so `type` defaults to `"non-overlapping"`
#'   for such a table; give `type = "overlapping"` for avari() output;
#' * a plain data frame with columns `tau` (s) and `avar`, and optionally
#'   `edf`, computed elsewhere; without `edf`, give `n` and `freq` (the
#'   estimator is taken as overlapping unless `type` says otherwise);
#' * a previous `avfit` (its data are refitted with the new `terms`, its
#'   nonlinear estimates as starting values and, when its EDF came from its
#'   model, with that same EDF, so that AIC/BIC of the two fits compare).
#'
#' @section Model and estimation:
#' The expected Allan variance is \eqn{AV_j = \sum_k a_k^2 b_k(\tau_j;
#' \theta_k)} with the exact discrete term forms of [av_model()] (continuous
#' forms when `freq` is unknown). With \eqn{\nu_j} the equivalent degrees of
#' freedom of \eqn{\widehat{AV}_j}, \eqn{\ln\widehat{AV}_j} has mean
#' \eqn{\ln AV_j + \psi(\nu_j/2) - \ln(\nu_j/2)} and variance
#' \eqn{\psi'(\nu_j/2)}; the fit minimises the sum of the squared
#' standardized residuals
#' \deqn{z_j = \frac{\ln\widehat{AV}_j - \ln AV_j - [\psi(\nu_j/2) -
#'   \ln(\nu_j/2)]}{\sqrt{\psi'(\nu_j/2)}}.}
#' By default the estimates at different \eqn{\tau} are taken as
#' independent (octave-spaced points are the least correlated choice); with
#' `correlation = TRUE` the objective is the generalised
#' \eqn{r^\top\Sigma^{-1}r} with \eqn{\Sigma = D_s R D_s},
#' \eqn{D_s = \mathrm{diag}(\sqrt{\psi'(\nu_j/2)})} and \eqn{R} the exact
#' correlation of the AV estimates for white rate noise (Isserlis' theorem,
#' computed in C++ for the estimator type). It is exact for white noise and
#' an approximation otherwise; the correlation of the log estimates is taken
#' as that of the estimates.
#' For fixed nonlinear parameters the squared amplitudes \eqn{c_k = a_k^2}
#' are found by Gauss-Newton steps, each a non-negative least-squares
#' problem (C++); the nonlinear parameters are profiled on a log grid
#' (`tc` over \eqn{[\tau_{min}/4, 4\tau_{max}]}, `f0` from
#' \eqn{0.2/\tau_{max}} to the Nyquist frequency), refined by
#' one-dimensional optimisation and, with several, jointly by Nelder-Mead.
#'
#' @section EDF:
#' When the input has no `edf` column it is computed from `n`, the cluster
#' size \eqn{m = \tau f} and the fitted model: each term's EDF is that of
#' its power-law noise type (overlapping: the simple formulas of NIST SP
#' 1065 Table 5; non-overlapping: the exact Gaussian values for white FM,
#' \eqn{2M^2/(3M-1)}, and white PM, \eqn{36M^2/(70M-36)}, with \eqn{M =
#' \lfloor n/m\rfloor - 1}, Greenhall's EDF for flicker and random-walk FM),
#' and they are combined as \eqn{\nu = (\sum_k AV_k)^2 / \sum_k
#' (AV_k^2/\nu_k)}. The ramp and sinusoids are treated as deterministic.
#' The fit is iterated twice (white-FM EDF first, then the model's).
#'
#' @section Uncertainty:
#' The covariance of the free parameters is the inverse Gauss-Newton
#' information \eqn{(J^\top J)^{-1}} of the standardized residuals in the
#' reported parameterisation (amplitudes, `tc` in s, `f0` in Hz), scaled by
#' \eqn{\max(1, \chi^2/\mathrm{dof})} so that misfit widens it. For an
#' amplitude at its bound 0 the curvature is computed for \eqn{c = a^2}
#' instead and its standard error reported as \eqn{\sqrt{SE(c)}} (the
#' one-sigma upper reach of the amplitude); the `tc` or `f0` of a term whose
#' amplitude is 0 is not identified and gets `NA`. Fixed parameters have
#' zero variance.
#'
#' @param av The Allan variance curve (see Input).
#' @param terms Character vector of terms to fit (see [av_terms()]); `gm` and
#'   `sinusoid` may be repeated, e.g. `c("N", "gm", "gm")`.
#' @param n Number of samples of the record (needed for the EDF when `av`
#'   has none).
#' @param freq Sampling frequency in Hz (needed for the exact discrete
#'   forms and the EDF).
#' @param type Estimator that produced `av`: `"overlapping"` or
#'   `"non-overlapping"`.
#' @param channel For a multi-channel `allan()` result, the channel to fit.
#' @param start Optional named starting values, e.g. `c(gm1.tc = 30)`
#'   (nonlinear parameters start there instead of the grid search).
#' @param fixed Optional named values held fixed, e.g. `c(N = 0.01)`.
#' @param tau_range Optional `c(min, max)`: fit only the points with tau in
#'   this range (seconds).
#' @param bias_correct If `TRUE` (the default, right for estimated curves),
#'   the chi-square log bias \eqn{\psi(\nu/2) - \ln(\nu/2)} is removed
#'   from \eqn{\ln\widehat{AV}}; set `FALSE` to fit a noise-free
#'   theoretical curve.
#' @param correlation If `TRUE`, account for the correlation between the
#'   estimates at different tau (white-noise correlation; needs `n` and
#'   `freq`). `chi2` is then \eqn{r^\top\Sigma^{-1}r} per degree of freedom.
#' @param ... Unused.
#' @return An object of class `"avfit"`: a list with `coefficients` (named:
#'   `Q`, `N`, `B`, `K`, `R`, `gm1.sigma`, `gm1.tc`, `sinusoid1.amp`,
#'   `sinusoid1.f0`, ...), `se`, `vcov`, `chi2` (sum of squared
#'   standardized residuals per degree of freedom), `rms` (RMS relative
#'   error of the Allan deviation in percent: the measured ADEV relative to
#'   the model's,
#'   \eqn{100\sqrt{\mathrm{mean}((\sqrt{\widehat{AV}_j/AV_j} - 1)^2)}}; this
#'   direction keeps a single low estimate at the longest tau, where the EDF
#'   is near 1, from dominating),
#'   `objective`, `df.residual`, `nobs`, `terms`, `layout` (one row per
#'   coefficient: name, term label, kind, parameter, role, unit, fixed),
#'   `data` (data frame `tau`, `m`, `avar`, `edf`, `fitted`, `z`),
#'   `components` (each term's AV at the data taus), `freq`, `n`, `type`,
#'   `edf_source`, `steps` (zero-row data frame filled by `avrefine()`),
#'   `input` (the full curve before `tau_range`) and `call`.
#' @seealso [av_model()], [av_terms()], [avsim()]
#' @importFrom stats coef vcov fitted residuals confint predict logLik nobs AIC BIC
#' @export
#' @examples
#' x <- avsim(1e5, freq = 100, N = 0.01, B = 0.002, K = 1e-4, seed = 1)
#' av <- avar(x, 100)
#' fit <- avfit(av, c("N", "B", "K"), freq = 100)
#' fit
#' # a table computed elsewhere: tau, avar (and n, freq for the EDF)
#' tab <- data.frame(tau = av$time, avar = av$av)
#' coef(avfit(tab, c("N", "B", "K"), n = 1e5, freq = 100,
#'            type = "non-overlapping"))
avfit <- function(av, terms = c("N", "B", "K"), n = NULL, freq = NULL,
                  type = "overlapping", channel = NULL, start = NULL,
                  fixed = NULL, tau_range = NULL, bias_correct = TRUE,
                  correlation = FALSE, ...) {
  cl <- match.call()
  if (!isTRUE(bias_correct) && !isFALSE(bias_correct)) {
    abort("`bias_correct` must be TRUE or FALSE.")
  }
  if (!isTRUE(correlation) && !isFALSE(correlation)) {
    abort("`correlation` must be TRUE or FALSE.")
  }
  check_present(missing(av), "av", "an Allan variance curve")
  terms <- check_terms(terms)
  if (inherits(av, "avfit")) {
    if (missing(bias_correct)) bias_correct <- isTRUE(av$bias_correct)
    if (missing(correlation)) correlation <- isTRUE(av$correlation)
    # previous nonlinear estimates start the refit
    old <- av$coefficients[av$layout$role == "nonlinear"]
    old <- old[names(old) %in% coef_layout(terms)$name]
    old <- old[!names(old) %in% names(start)]
    if (length(old)) start <- c(start, old)
  }
  d <- avfit_input(av, n = n, freq = freq, type = type,
                   type_given = !missing(type), channel = channel)
  lay <- coef_layout(terms)
  start <- check_named(start, "start", lay$name)
  fixed <- check_named(fixed, "fixed", lay$name)
  lay$fixed <- lay$name %in% names(fixed)
  lay$value <- NA_real_
  lay$value[lay$fixed] <- fixed[lay$name[lay$fixed]]
  input <- d
  if (!is.null(tau_range)) {
    if (!is.numeric(tau_range) || length(tau_range) != 2L || anyNA(tau_range) ||
        tau_range[1] >= tau_range[2]) {
      abort("`tau_range` must be c(min, max) in seconds with min < max.")
    }
    keep <- d$data$tau >= tau_range[1] & d$data$tau <= tau_range[2]
    d$data <- d$data[keep, , drop = FALSE]
  }
  nfree <- sum(!lay$fixed)
  if (nrow(d$data) < nfree) {
    abort("`av` has ", nrow(d$data), " usable points, fewer than the ", nfree,
          " free parameters of terms ", paste(terms, collapse = ", "), ".")
  }
  tau0 <- if (is.null(d$freq)) NULL else 1 / d$freq
  corr <- NULL
  if (correlation) {
    if (is.null(d$freq) || is.null(d$n)) {
      abort("`correlation = TRUE` needs `n` and `freq` (the cluster sizes ",
            "and the record length).")
    }
    corr <- if (inherits(av, "avfit") && !is.null(av$corr) &&
                is.null(tau_range) && nrow(av$corr) == nrow(d$data)) {
      av$corr
    } else {
      white_corr(d$data$m, d$n, d$type)
    }
  }
  fit <- NULL
  passes <- if (d$edf_source == "model") 2L else 1L
  for (pass in seq_len(passes)) {
    if (d$edf_source == "model") {
      d$data$edf <- if (is.null(fit)) {
        edf_model(d$data$m, d$n, d$type, matrix(1, nrow(d$data), 1), 0)
      } else {
        comp <- model_components(d$data$tau, tau0, fit$layout)
        edf_model(d$data$m, d$n, d$type, comp,
                  term_alpha(fit$layout, d$data$tau))
      }
    }
    fit <- fit_core(d$data, tau0, lay, start, if (is.null(fit)) NULL else fit,
                    bias_correct, corr)
  }
  finish_fit(fit, d, input, terms, cl)
}

# ---- input normalisation ----------------------------------------------------

normalize_type <- function(type) {
  if (!is.character(type) || length(type) != 1L || is.na(type)) {
    abort("`type` must be \"overlapping\" or \"non-overlapping\", not ",
          describe_type(type), ".")
  }
  t <- tolower(type)
  if (t %in% c("overlapping", "oavar", "oadev")) return("overlapping")
  if (t %in% c("non-overlapping", "nonoverlapping", "standard", "avar", "adev"))
    return("non-overlapping")
  abort("`type` must be \"overlapping\" or \"non-overlapping\" (avfit fits the ",
        "Allan variance), not ", encodeString(type, quote = '"'), ".")
}

# Returns list(data = data.frame(tau, m, avar, edf), freq, n, type, edf_source).
avfit_input <- function(av, n, freq, type, type_given, channel) {
  if (inherits(av, "avfit")) {
    d <- av$input
    if (d$edf_source == "model") {
      # keep the EDF of the fit being extended, so that the two fits'
      # likelihoods (AIC, BIC) are comparable
      tau0 <- if (is.null(d$freq)) NULL else 1 / d$freq
      comp <- model_components(d$data$tau, tau0, av$layout)
      d$data$edf <- edf_model(d$data$m, d$n, d$type, comp,
                              term_alpha(av$layout, d$data$tau))
      d$edf_source <- "previous"
    }
    return(d)
  }
  if (!is.null(freq)) freq <- check_freq(freq)
  if (!is.null(n)) n <- check_number(n, "n", lo = 2, integer = FALSE)
  edf <- NULL
  if (inherits(av, "allan")) {
    if ("channel" %in% names(av)) {
      chans <- unique(av$channel)
      if (is.null(channel)) {
        if (length(chans) > 1L) {
          abort("`av` holds ", length(chans), " channels (",
                paste(chans, collapse = ", "), "); choose one with `channel`.")
        }
        channel <- chans[1]
      }
      if (!channel %in% chans) {
        abort("`channel` must be one of ", paste(chans, collapse = ", "), ".")
      }
      av <- av[av$channel == channel, , drop = FALSE]
    }
    if (is.null(freq)) freq <- attr(av, "freq")
    if (is.null(n)) n <- attr(av, "N")
    if (!type_given && !is.null(attr(av, "type"))) type <- attr(av, "type")
    if (identical(attr(av, "input"), "integrated") && FALSE) NULL
    tau <- av$tau
    avv <- av$avar
    if ("edf" %in% names(av)) edf <- av$edf
  } else if (is.data.frame(av) && all(c("time", "av", "error") %in% names(av))) {
    if (is.null(freq)) {
      abort("`freq` is needed with an avar()/avarn()/avari() table: give the ",
            "sampling frequency in Hz.")
    }
    if (!type_given) type <- "non-overlapping"
    tau <- av$time
    avv <- av$av
    if (is.null(n)) {
      m <- round(tau * freq)
      nn <- m * (1 / (2 * av$error^2) + 1)
      nn <- nn[is.finite(nn)]
      if (!length(nn)) abort("`n` is needed: it cannot be recovered from `av$error`.")
      n <- round(stats::median(nn))
    }
  } else if (is.data.frame(av) && all(c("tau", "avar") %in% names(av))) {
    tau <- av$tau
    avv <- av$avar
    if ("edf" %in% names(av)) edf <- av$edf
  } else {
    abort("`av` must be an allan() result, an avar()/avarn()/avari() data ",
          "frame (columns time, av, error) or a data frame with columns tau ",
          "and avar, not ", describe_type(av),
          if (is.data.frame(av)) paste0(" with columns ",
                                         paste(names(av), collapse = ", ")),
          ".")
  }
  type <- normalize_type(type)
  if (!is.numeric(tau) || !is.numeric(avv)) {
    abort("`av`: the tau and Allan variance columns must be numeric.")
  }
  if (!is.null(edf) && (!is.numeric(edf) || all(is.na(edf)))) edf <- NULL
  if (is.null(edf) && (is.null(n) || is.null(freq))) {
    abort("`n` and `freq` are needed when `av` has no `edf` column: give the ",
          "number of samples and the sampling frequency in Hz.")
  }
  ok <- is.finite(tau) & tau > 0 & is.finite(avv) & avv > 0
  if (!is.null(edf)) ok <- ok & is.finite(edf) & edf > 0
  m <- if (is.null(freq)) rep(NA_real_, length(tau)) else tau * freq
  if (is.null(edf) && !is.null(n)) ok <- ok & m <= n / 2
  data <- data.frame(tau = tau[ok], m = m[ok], avar = avv[ok],
                     edf = if (is.null(edf)) NA_real_ else edf[ok])
  data <- data[order(data$tau), , drop = FALSE]
  rownames(data) <- NULL
  if (nrow(data) < 1L) abort("`av` has no usable points (positive tau and avar).")
  list(data = data, freq = freq, n = n, type = type,
       edf_source = if (is.null(edf)) "model" else "input")
}

check_named <- function(x, arg, allowed) {
  if (is.null(x)) return(NULL)
  if (is.list(x)) x <- unlist(x)
  if (!is.numeric(x) || is.null(names(x)) || anyNA(x) || any(!is.finite(x))) {
    abort("`", arg, "` must be a named numeric vector, e.g. c(",
          allowed[1], " = 1).")
  }
  bad <- setdiff(names(x), allowed)
  if (length(bad)) {
    abort("`", arg, "` names an unknown coefficient ", bad[1],
          "; the model's coefficients are ", paste(allowed, collapse = ", "), ".")
  }
  x
}

# ---- EDF --------------------------------------------------------------------

# Power-law exponent per term instance at each tau (matrix like components);
# NA marks a deterministic term (ramp, sinusoid).
term_alpha <- function(lay, tau) {
  labs <- unique(lay$label)
  out <- matrix(NA_real_, length(tau), length(labs), dimnames = list(NULL, labs))
  for (j in seq_along(labs)) {
    kind <- lay$kind[lay$label == labs[j]][1]
    out[, j] <- switch(kind,
      Q = 2, N = 0, B = -1, K = -2, R = NA, sinusoid = NA,
      gm = {
        tc <- lay$value[lay$label == labs[j] & lay$param == "tc"]
        ifelse(tau < 0.5 * tc, -2, ifelse(tau < 3 * tc, -1, 0))
      })
  }
  out
}

# EDF of the overlapping AV for power-law noise, NIST SP 1065 Table 5 (N in
# phase points). Floored at 1.
edf_simple_oavar <- function(m, nph, alpha) {
  N <- nph
  e <- switch(as.character(alpha),
    "2" = (N + 1) * (N - 2 * m) / (2 * (N - m)),
    "1" = exp(sqrt(log((N - 1) / (2 * m)) * log((2 * m + 1) * (N - 1) / 4))),
    "0" = (3 * (N - 1) / (2 * m) - 2 * (N - 2) / N) * 4 * m^2 / (4 * m^2 + 5),
    "-1" = ifelse(m == 1, 2 * (N - 2)^2 / (2.3 * N - 4.9),
                  5 * N^2 / (4 * m * (N + 3 * m))),
    "-2" = ((N - 2) / m) * ((N - 1)^2 - 3 * m * (N - 1) + 4 * m^2) / (N - 3)^2)
  pmax(e, 1)
}

# Greenhall & Riley (2004) EDF, basic-sum form, for the non-overlapping AV
# (d = 2, S = 1, F = m); alpha in {0, -1, -2}.
edf_greenhall_noavar <- function(m, nph, alpha) {
  sw <- function(t, a) {
    at <- abs(t)
    lg <- ifelse(at > 0, log(at), 0)
    switch(as.character(a), "2" = -at, "1" = t^2 * lg, "0" = at^3,
           "-1" = t^4 * lg, "-2" = at^5)
  }
  sx <- function(t, F, a) {
    if (is.infinite(F)) return(sw(t, a + 2))
    F^2 * (2 * sw(t, a) - sw(t - 1 / F, a) - sw(t + 1 / F, a))
  }
  sz <- function(t, F, a) {
    6 * sx(t, F, a) - 4 * (sx(t - 1, F, a) + sx(t + 1, F, a)) +
      sx(t - 2, F, a) + sx(t + 2, F, a)
  }
  vapply(m, function(mm) {
    L <- 1 + 2 * mm
    M <- 1 + floor((nph - L) / mm)
    if (M < 1) return(1)
    J <- min(M, 3)
    Fp <- if (3 * mm <= 100) mm else Inf
    bs <- sz(0, Fp, alpha)^2 + (1 - J / M) * sz(J, Fp, alpha)^2
    if (J > 1) for (j in seq_len(J - 1)) bs <- bs + 2 * (1 - j / M) * sz(j, Fp, alpha)^2
    max(M * sz(0, Fp, alpha)^2 / bs, 1)
  }, 0)
}

edf_power_law <- function(m, n, type, alpha) {
  if (type == "overlapping") return(edf_simple_oavar(m, n + 1, alpha))
  M <- floor(n / m) - 1
  e <- switch(as.character(alpha),
    "2" = 36 * M^2 / (70 * M - 36),
    "1" = 36 * M^2 / (70 * M - 36),
    "0" = 2 * M^2 / (3 * M - 1),
    edf_greenhall_noavar(m, n + 1, alpha))
  pmax(e, 1)
}

# Mixture EDF: nu = (sum AV_k)^2 / sum(AV_k^2 / nu_k); alpha NA = no variance.
edf_model <- function(m, n, type, comp, alpha) {
  comp <- as.matrix(comp)
  alpha <- matrix(alpha, nrow(comp), ncol(comp))
  tot <- rowSums(comp)
  den <- numeric(nrow(comp))
  for (k in seq_len(ncol(comp))) {
    for (a in unique(stats::na.omit(alpha[, k]))) {
      i <- which(alpha[, k] == a)
      den[i] <- den[i] + comp[i, k]^2 / edf_power_law(m[i], n, type, a)
    }
  }
  e <- tot^2 / den
  e[!is.finite(e)] <- edf_power_law(m[!is.finite(e)], n, type, 0)
  # never claim more than the number of overlapping terms
  pmin(pmax(e, 1), n)
}

# ---- the fit ----------------------------------------------------------------

log_bias <- function(edf) digamma(edf / 2) - log(edf / 2)
log_sd <- function(edf) sqrt(trigamma(edf / 2))

# Profile ranges for the nonlinear parameters.
nl_range <- function(kind, tau, freq) {
  if (kind == "gm") return(c(min(tau) / 4, max(tau) * 4))
  hi <- if (is.null(freq)) 2 / min(tau) else 0.499 * freq
  c(min(0.2 / max(tau), hi / 10), hi)
}

# Correlation matrix of the AV estimates at cluster sizes m for white rate
# noise (exact Gaussian moments, C++).
white_corr <- function(m, n, type) {
  C <- avar_white_cov(as.double(round(m)), as.double(n),
                      type == "overlapping", allanvar_threads())
  d <- sqrt(diag(C))
  R <- C / outer(d, d)
  R[!is.finite(R)] <- 0
  diag(R) <- 1
  R
}

# Whitening matrix W with ||W r||^2 = r' Sigma^-1 r, Sigma = diag(s) R diag(s).
whitening <- function(s, corr) {
  if (is.null(corr)) return(diag(1 / s, length(s)))
  Sig <- corr * outer(s, s)
  U <- tryCatch(chol(Sig), error = function(e) NULL)
  # nearly coincident taus can make Sigma numerically singular: add a ridge
  ridge <- 1e-10
  while (is.null(U) && ridge < 1e-2) {
    U <- tryCatch(chol(Sig + diag(ridge * s^2, length(s))),
                  error = function(e) NULL)
    ridge <- ridge * 100
  }
  if (is.null(U)) return(diag(1 / s, length(s)))
  t(backsolve(U, diag(length(s))))
}

# Solve for the amplitudes at given nonlinear values; returns list with c
# (named by free amp label), objective.
# `off`: labels of term instances left out (amplitude 0) for this solve.
solve_amps <- function(data, tau0, lay, nlv, y, W, cstart = NULL, off_labels = NULL) {
  lay2 <- lay
  lay2$value[lay2$role == "nonlinear" & !lay2$fixed] <- nlv
  Bm <- term_basis_matrix(data$tau, tau0, lay2)
  amp <- lay2[lay2$role == "amp", , drop = FALSE]
  freeamp <- amp$label[!amp$fixed & !amp$label %in% off_labels]
  off <- numeric(nrow(data))
  for (i in which(amp$fixed)) off <- off + amp$value[i]^2 * Bm[, amp$label[i]]
  Bf <- Bm[, freeamp, drop = FALSE]
  if (is.null(cstart)) cstart <- numeric(length(freeamp))
  if (length(freeamp) == 0L) {
    av <- off
    obj <- if (all(av > 0)) sum((W %*% (y - log(av)))^2) else Inf
    return(list(c = numeric(0), objective = obj, layout = lay2))
  }
  r <- avfit_log_nnls(Bf, off, y, W, cstart, 100L, 1e-12)
  cc <- stats::setNames(numeric(sum(!amp$fixed)), amp$label[!amp$fixed])
  cc[freeamp] <- r$c
  list(c = cc, objective = r$objective, layout = lay2)
}

fit_core <- function(data, tau0, lay, start, prev, bias_correct = TRUE,
                     corr = NULL) {
  y <- log(data$avar) - if (bias_correct) log_bias(data$edf) else 0
  s <- log_sd(data$edf)
  W <- whitening(s, corr)
  freq <- if (is.null(tau0)) NULL else 1 / tau0
  nlrows <- which(lay$role == "nonlinear" & !lay$fixed)
  nlv <- numeric(length(nlrows))
  names(nlv) <- lay$name[nlrows]
  obj <- function(lognl, off_labels = NULL) {
    solve_amps(data, tau0, lay, exp(lognl), y, W, off_labels = off_labels)$objective
  }
  if (length(nlrows)) {
    ranges <- lapply(nlrows, function(i) nl_range(lay$kind[i], data$tau, freq))
    # initial values: previous pass, start, or grid centre
    for (k in seq_along(nlrows)) {
      nm <- lay$name[nlrows[k]]
      nlv[k] <- if (!is.null(prev)) prev$layout$value[prev$layout$name == nm] else
        if (!is.null(start) && nm %in% names(start)) start[[nm]] else
          sqrt(prod(ranges[[k]]))
    }
    # a parameter with a start (given, or from the previous pass) is refined
    # locally; the others are searched on the grid first
    has_start <- names(nlv) %in% names(start)
    search <- function(order) {
      lognl <- log(nlv)
      cycles <- if (length(nlrows) > 1L) 2L else 1L
      for (cy in seq_len(cycles)) {
        for (pos in seq_along(order)) {
          k <- order[pos]
          # first cycle: terms not searched yet stay out of the model (greedy)
          later <- if (cy == 1L) {
            j <- order[seq_along(order) > pos]
            lay$label[nlrows[j[!has_start[j]]]]
          } else NULL
          f1 <- function(v) { l <- lognl; l[k] <- v; obj(l, later) }
          if (cy > 1L || !is.null(prev)) {
            lo <- lognl[k] - log(1.5); hi <- lognl[k] + log(1.5)
          } else {
            # a start value: a short grid over start / 4 .. start * 4;
            # otherwise the whole range
            ng <- if (has_start[k]) 13L else
              if (lay$kind[nlrows[k]] == "sinusoid") 120L else 40L
            g <- if (has_start[k]) lognl[k] + seq(-log(4), log(4), length.out = ng) else
              seq(log(ranges[[k]][1]), log(ranges[[k]][2]), length.out = ng)
            vals <- vapply(g, f1, 0)
            i <- which.min(vals)
            lo <- g[max(i - 1L, 1L)]; hi <- g[min(i + 1L, ng)]
            lognl[k] <- g[i]
          }
          o <- stats::optimize(f1, c(lo, hi), tol = 1e-7)
          if (o$objective <= f1(lognl[k])) lognl[k] <- o$minimum
        }
      }
      if (length(nlrows) > 1L) {
        o <- stats::optim(lognl, obj, method = "Nelder-Mead",
                          control = list(reltol = 1e-10, maxit = 400))
        if (o$value <= obj(lognl)) lognl <- o$par
      }
      list(lognl = lognl, value = obj(lognl))
    }
    # The greedy search depends on the order in which the terms enter; with
    # several unstarted nonlinear terms try each rotation of the order (and
    # its reverse) and keep the best objective.
    K <- length(nlrows)
    orders <- list(seq_len(K))
    if (is.null(prev) && sum(!has_start) > 1L) {
      rot <- lapply(seq_len(K) - 1L, function(r) (seq_len(K) + r - 1L) %% K + 1L)
      orders <- unique(c(rot, lapply(rot, rev)))
      if (length(orders) > 6L) orders <- orders[seq_len(6L)]
    }
    best <- NULL
    for (ord in orders) {
      r <- search(ord)
      if (is.null(best) || r$value < best$value) best <- r
    }
    lognl <- best$lognl
    nlv[] <- exp(lognl)
  }
  sol <- solve_amps(data, tau0, lay, nlv, y, W)
  lay2 <- sol$layout
  amprows <- which(lay2$role == "amp" & !lay2$fixed)
  lay2$value[amprows] <- sqrt(pmax(sol$c[lay2$label[amprows]], 0))
  list(layout = lay2, objective = sol$objective, y = y, s = s, W = W,
       corr = corr, data = data, tau0 = tau0, bias_correct = bias_correct)
}

# Jacobian of ln AV with respect to the free parameters (amplitudes, or c for
# amplitudes at 0; nonlinear parameters in their own units).
jacobian_lnav <- function(fit) {
  lay <- fit$layout
  tau <- fit$data$tau
  tau0 <- fit$tau0
  comp <- model_components(tau, tau0, lay)
  tot <- rowSums(comp)
  free <- which(!lay$fixed)
  Jm <- matrix(0, length(tau), length(free),
               dimnames = list(NULL, lay$name[free]))
  at_zero <- logical(length(free))
  for (k in seq_along(free)) {
    i <- free[k]
    if (lay$role[i] == "amp") {
      a <- lay$value[i]
      b <- comp[, lay$label[i]] / max(a^2, .Machine$double.xmin)
      if (a > 0) {
        Jm[, k] <- 2 * a * b / tot
      } else {
        lay1 <- lay; lay1$value[i] <- 1
        b <- model_components(tau, tau0, lay1)[, lay$label[i]]
        Jm[, k] <- b / tot
        at_zero[k] <- TRUE
      }
    } else {
      h <- 1e-5
      lp <- lay; lp$value[i] <- lay$value[i] * exp(h)
      lm <- lay; lm$value[i] <- lay$value[i] * exp(-h)
      dp <- log(rowSums(model_components(tau, tau0, lp)))
      dm <- log(rowSums(model_components(tau, tau0, lm)))
      Jm[, k] <- (dp - dm) / (2 * h) / lay$value[i]
    }
  }
  list(J = Jm, at_zero = at_zero, free = free)
}

# Pseudo-inverse of a symmetric PSD matrix, equilibrated first: parameters
# differ by many orders of magnitude (c = K^2 ~ 1e-8 next to tc ~ 10 s).
pinv <- function(A) {
  dg <- sqrt(pmax(diag(A), 0))
  dg[dg == 0] <- 1
  As <- A / outer(dg, dg)
  pinv_raw(As) / outer(dg, dg)
}

pinv_raw <- function(A) {
  e <- eigen((A + t(A)) / 2, symmetric = TRUE)
  d <- e$values
  keep <- d > max(d) * 1e-12
  if (!any(keep)) return(matrix(NA_real_, nrow(A), ncol(A)))
  e$vectors[, keep, drop = FALSE] %*% (t(e$vectors[, keep, drop = FALSE]) / d[keep])
}

finish_fit <- function(fit, d, input, terms, cl) {
  lay <- fit$layout
  data <- fit$data
  tau0 <- fit$tau0
  comp <- model_components(data$tau, tau0, lay)
  fitted <- rowSums(comp)
  z <- (fit$y - log(fitted)) / fit$s
  objective <- sum((fit$W %*% (fit$y - log(fitted)))^2)
  nfree <- sum(!lay$fixed)
  dfres <- nrow(data) - nfree
  chi2 <- if (dfres > 0) objective / dfres else NA_real_
  rms <- 100 * sqrt(mean((sqrt(data$avar / fitted) - 1)^2))
  coef <- stats::setNames(lay$value, lay$name)
  # covariance
  jj <- jacobian_lnav(fit)
  Js <- -fit$W %*% jj$J
  V <- pinv(crossprod(Js)) * max(1, if (is.na(chi2)) 1 else chi2)
  vc <- matrix(0, nrow(lay), nrow(lay), dimnames = list(lay$name, lay$name))
  se <- stats::setNames(numeric(nrow(lay)), lay$name)
  fn <- lay$name[jj$free]
  vfree <- V
  dimnames(vfree) <- list(fn, fn)
  if (any(jj$at_zero)) {
    zn <- fn[jj$at_zero]
    # SE of a zero amplitude: sqrt(SE(c)); no covariance reported
    sez <- sqrt(sqrt(pmax(diag(V)[jj$at_zero], 0)))
    vfree[zn, ] <- 0
    vfree[, zn] <- 0
    diag(vfree)[match(zn, fn)] <- sez^2
  }
  vc[fn, fn] <- vfree
  # a nonlinear parameter of a term whose amplitude is 0 is not identified
  for (i in which(lay$role == "nonlinear" & !lay$fixed)) {
    a <- lay$value[lay$label == lay$label[i] & lay$role == "amp"]
    if (!(a > 0)) {
      vc[i, ] <- vc[, i] <- NA_real_
    }
  }
  se[] <- sqrt(pmax(diag(vc), 0))
  data$fitted <- fitted
  data$z <- z
  steps <- data.frame(effect = character(0), tau_from = numeric(0),
                      tau_to = numeric(0), evidence = character(0),
                      chi2_before = numeric(0), chi2_after = numeric(0),
                      rms_before = numeric(0), rms_after = numeric(0),
                      stringsAsFactors = FALSE)
  input$data$edf <- if (d$edf_source == "model") NA_real_ else input$data$edf
  structure(list(
    coefficients = coef, se = se, vcov = vc, chi2 = chi2, rms = rms,
    objective = objective, logdet = -2 * sum(log(diag(fit$W))),
    df.residual = dfres, nobs = nrow(data),
    npar = nfree, terms = terms, layout = lay, data = data,
    components = comp, freq = d$freq, n = d$n, type = d$type,
    edf_source = d$edf_source, bias_correct = fit$bias_correct,
    correlation = !is.null(fit$corr), corr = fit$corr, steps = steps,
    input = input, call = cl),
    class = "avfit")
}

# ---- methods ----------------------------------------------------------------

#' Methods for noise-model fits
#'
#' Accessors and displays for [avfit()] results.
#'
#' `residuals()` returns the standardized log residuals \eqn{z_j} (see
#' [avfit()]; `type = "log"` gives \eqn{\ln\widehat{AV}_j - \ln AV_j} minus
#' the chi-square log bias, `type = "relative"` gives
#' \eqn{\sqrt{\widehat{AV}_j/AV_j} - 1}, the relative ADEV error).
#' `confint()` gives Wald intervals: for amplitudes on the linear scale,
#' truncated at 0; for `tc` and `f0` on the log scale.
#' `logLik()` is the Gaussian log-likelihood of \eqn{\ln\widehat{AV}_j}
#' (bias-corrected) with variances \eqn{\psi'(\nu_j/2)} (and the
#' white-noise correlation when the fit used `correlation = TRUE`); its `df` is the
#' number of free parameters and `nobs` the number of points, so AIC() and
#' BIC() work. Compare models by AIC/BIC only on the same points with the same
#' EDF: when the EDF is derived from the model (input without `edf`), refit
#' the candidate from the first fit, `avfit(fit, terms)`, or pass its
#' `fit$data$edf` as an `edf` column.
#'
#' @param object,x An `avfit` object.
#' @param parm Coefficients for `confint()` (names or indices; default all).
#' @param level Confidence level.
#' @param type For `residuals()`: `"standardized"`, `"log"` or `"relative"`.
#'   For `predict()`: `"avar"` or `"adev"`.
#' @param newdata For `predict()`: a vector of tau (s) or a data frame with a
#'   `tau` column; default the fitted taus.
#' @param by_term For `predict()`: return each term's contribution.
#' @param terms For `plot()`: draw each term's curve.
#' @param residuals For `plot()`: add the residual panel.
#' @param ... Further arguments (for `plot()`, passed to the main
#'   `plot.default()` call).
#' @return `coef()` a named vector; `vcov()` a matrix; `confint()` a matrix
#'   with lower and upper columns; `fitted()`, `residuals()` and
#'   `predict()` numeric vectors (a matrix with `by_term = TRUE`);
#'   `logLik()` a `logLik` object; `summary()` an object of class
#'   `summary.avfit` with a coefficient table (estimate, SE, CI, unit);
#'   `print()` and `plot()` return `x` invisibly.
#' @name avfit-methods
#' @examples
#' x <- avsim(1e5, freq = 100, N = 0.01, K = 1e-3, seed = 2)
#' fit <- avfit(avar(x, 100), c("N", "K"), freq = 100)
#' coef(fit)
#' confint(fit)
#' AIC(fit)
#' predict(fit, c(1, 10, 100), type = "adev")
#' summary(fit)
#' plot(fit)
NULL

#' @rdname avfit-methods
#' @export
coef.avfit <- function(object, ...) object$coefficients

#' @rdname avfit-methods
#' @export
vcov.avfit <- function(object, ...) object$vcov

#' @rdname avfit-methods
#' @export
fitted.avfit <- function(object, ...) object$data$fitted

#' @rdname avfit-methods
#' @export
residuals.avfit <- function(object, type = c("standardized", "log", "relative"),
                            ...) {
  type <- match.arg(type)
  d <- object$data
  switch(type,
    standardized = d$z,
    log = log(d$avar) - log(d$fitted) -
      if (isFALSE(object$bias_correct)) 0 else log_bias(d$edf),
    relative = sqrt(d$avar / d$fitted) - 1)
}

#' @rdname avfit-methods
#' @export
confint.avfit <- function(object, parm, level = 0.95, ...) {
  cf <- object$coefficients
  se <- object$se
  if (missing(parm)) parm <- names(cf)
  if (is.numeric(parm)) parm <- names(cf)[parm]
  if (!all(parm %in% names(cf))) {
    abort("`parm` must name coefficients of the fit: ",
          paste(names(cf), collapse = ", "), ".")
  }
  level <- check_number(level, "level", lo = 0, hi = 1, open = TRUE)
  zq <- stats::qnorm((1 + level) / 2)
  lay <- object$layout
  role <- lay$role[match(parm, lay$name)]
  est <- cf[parm]
  s <- se[parm]
  lo <- ifelse(role == "amp", pmax(est - zq * s, 0), est * exp(-zq * s / est))
  hi <- ifelse(role == "amp", est + zq * s, est * exp(zq * s / est))
  pct <- paste(format(100 * c((1 - level) / 2, (1 + level) / 2), trim = TRUE,
                      digits = 3), "%")
  out <- cbind(lo, hi)
  dimnames(out) <- list(parm, pct)
  out
}

#' @rdname avfit-methods
#' @export
predict.avfit <- function(object, newdata = NULL, type = c("avar", "adev"),
                          by_term = FALSE, ...) {
  type <- match.arg(type)
  tau <- if (is.null(newdata)) object$data$tau else
    if (is.data.frame(newdata)) newdata$tau else newdata
  if (!is.numeric(tau) || !length(tau) || anyNA(tau) || any(tau <= 0)) {
    abort("`newdata` must be positive tau values in seconds (a vector or a ",
          "data frame with a `tau` column).")
  }
  tau0 <- if (is.null(object$freq)) NULL else 1 / object$freq
  comp <- model_components(tau, tau0, object$layout)
  out <- if (by_term) comp else rowSums(comp)
  if (type == "adev") sqrt(out) else out
}

#' @rdname avfit-methods
#' @export
logLik.avfit <- function(object, ...) {
  d <- object$data
  s <- log_sd(d$edf)
  # -1/2 [J ln(2 pi) + ln det Sigma + r' Sigma^-1 r], Sigma = diag(s) R diag(s)
  ldet <- if (!is.null(object$logdet)) object$logdet else 2 * sum(log(s))
  ll <- -0.5 * (length(s) * log(2 * pi) + ldet + object$objective)
  structure(ll, df = object$npar, nobs = object$nobs, class = "logLik")
}

#' @rdname avfit-methods
#' @export
nobs.avfit <- function(object, ...) object$nobs

#' @rdname avfit-methods
#' @export
print.avfit <- function(x, ...) {
  cat("Allan variance noise-model fit:", paste(x$terms, collapse = " + "), "\n")
  cat(sprintf("%d points, tau %.3g to %.3g s, %s estimator, EDF from %s\n",
              x$nobs, min(x$data$tau), max(x$data$tau), x$type,
              switch(x$edf_source, input = "the input", model = "the model",
                     previous = "the previous fit's model")))
  tab <- data.frame(estimate = signif(x$coefficients, 4),
                    se = signif(x$se, 3), unit = x$layout$unit)
  print(tab)
  cat(sprintf("chi2/dof = %.3g (dof %d), RMS ADEV error = %.3g %%\n",
              x$chi2, x$df.residual, x$rms))
  if (nrow(x$steps)) cat(nrow(x$steps), "refinement step(s); see $steps\n")
  invisible(x)
}

#' @rdname avfit-methods
#' @export
summary.avfit <- function(object, level = 0.95, ...) {
  ci <- confint(object, level = level)
  lay <- object$layout
  words <- vapply(seq_len(nrow(lay)), function(i) {
    e <- term_entry(lay$kind[i])
    unname(e$words[lay$param[i]])
  }, "")
  tab <- data.frame(estimate = object$coefficients, se = object$se,
                    lower = ci[, 1], upper = ci[, 2], unit = lay$unit,
                    meaning = words, fixed = lay$fixed,
                    stringsAsFactors = FALSE)
  rownames(tab) <- lay$name
  structure(list(coefficients = tab, chi2 = object$chi2, rms = object$rms,
                 df.residual = object$df.residual, nobs = object$nobs,
                 logLik = logLik(object), AIC = stats::AIC(object),
                 BIC = stats::BIC(object), level = level, steps = object$steps,
                 terms = object$terms, type = object$type),
            class = "summary.avfit")
}

#' @rdname avfit-methods
#' @export
print.summary.avfit <- function(x, ...) {
  cat("Allan variance noise-model fit:", paste(x$terms, collapse = " + "), "\n\n")
  tab <- x$coefficients
  out <- data.frame(Estimate = signif(tab$estimate, 4),
                    `Std.Error` = signif(tab$se, 3),
                    lower = signif(tab$lower, 4), upper = signif(tab$upper, 4),
                    Unit = paste0(tab$unit, " (", tab$meaning, ")"),
                    check.names = FALSE)
  rownames(out) <- rownames(tab)
  names(out)[3:4] <- paste0(c("lower ", "upper "), format(100 * x$level), "%")
  print(out, right = FALSE)
  cat("\n\"u\" is the input's rate unit (e.g. deg/s or m/s^2).\n")
  cat(sprintf("chi2/dof = %.4g on %d dof; RMS relative ADEV error = %.3g %%\n",
              x$chi2, x$df.residual, x$rms))
  cat(sprintf("logLik = %.4g, AIC = %.4g, BIC = %.4g (%d points)\n",
              as.numeric(x$logLik), x$AIC, x$BIC, x$nobs))
  if (nrow(x$steps)) {
    cat("\nRefinement steps:\n")
    print(x$steps)
  }
  invisible(x)
}

#' @rdname avfit-methods
#' @export
plot.avfit <- function(x, terms = TRUE, residuals = TRUE, ...) {
  d <- x$data
  op <- graphics::par(no.readonly = TRUE)
  on.exit(graphics::par(op))
  if (residuals) {
    graphics::layout(matrix(1:2, 2), heights = c(3, 1.3))
    graphics::par(mar = c(0.5, 4.5, 2, 1), oma = c(3.5, 0, 0, 0))
  }
  # 68.3% chi-square limits of ADEV from the EDF
  lo <- sqrt(d$avar * d$edf / stats::qchisq(0.8415, d$edf))
  hi <- sqrt(d$avar * d$edf / stats::qchisq(0.1585, d$edf))
  tt <- exp(seq(log(min(d$tau)), log(max(d$tau)), length.out = 300))
  tt <- sort(unique(c(tt, d$tau)))
  comp <- predict(x, tt, by_term = TRUE)
  tot <- rowSums(comp)
  yl <- range(c(lo, hi, sqrt(tot)), finite = TRUE)
  # room below the data for the terms' curves (down to half their peak)
  yl[1] <- max(min(yl[1], 0.5 * apply(sqrt(comp), 2, max)), yl[2] * 1e-4)
  graphics::plot(d$tau, sqrt(d$avar), log = "xy", ylim = yl, pch = 19,
                 cex = 0.7, xlab = if (residuals) "" else "tau [s]",
                 ylab = "Allan deviation", xaxt = if (residuals) "n" else "s",
                 main = paste("avfit:", paste(x$terms, collapse = " + ")), ...)
  if (residuals) graphics::axis(1, labels = FALSE)
  graphics::arrows(d$tau, lo, d$tau, hi, angle = 90, code = 3,
                   length = 0.02, col = "grey40")
  cols <- grDevices::hcl.colors(max(ncol(comp), 2), "Dark 3")
  if (terms) {
    for (k in seq_len(ncol(comp))) {
      v <- sqrt(comp[, k])
      v[v < yl[1] / 10] <- NA
      graphics::lines(tt, v, lty = 2, col = cols[k])
    }
  }
  graphics::lines(tt, sqrt(tot), lwd = 2)
  graphics::legend("topright", bty = "n", cex = 0.8,
                   legend = c("data", "model", if (terms) colnames(comp)),
                   lty = c(NA, 1, if (terms) rep(2, ncol(comp))),
                   pch = c(19, NA, if (terms) rep(NA, ncol(comp))),
                   lwd = c(NA, 2, if (terms) rep(1, ncol(comp))),
                   col = c("black", "black", if (terms) cols[seq_len(ncol(comp))]))
  if (residuals) {
    graphics::par(mar = c(0.5, 4.5, 0.5, 1))
    zr <- max(3, abs(d$z), na.rm = TRUE)
    graphics::plot(d$tau, d$z, log = "x", ylim = c(-zr, zr), pch = 19,
                   cex = 0.7, xlab = "", ylab = "z")
    graphics::abline(h = 0)
    graphics::abline(h = c(-2, 2), lty = 3)
    graphics::mtext("tau [s]", side = 1, line = 2.2, outer = TRUE)
  }
  invisible(x)
}
