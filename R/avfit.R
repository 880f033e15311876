# The noise-model fit: avfit(), its constructor and validator, and its
# methods. The pieces: the curve (fit-input.R), the weights of its points
# (fit-weights.R), the search (fit-search.R), the covariance
# (fit-uncertainty.R); the model itself comes from the catalogue
# (catalogue.R, coef.R).

#' Fit a noise model to an Allan variance curve
#'
#' Fits a sum of noise terms from the catalogue ([av_terms()]) to an Allan
#' variance curve by weighted least squares in the log domain, keeping
#' amplitudes non-negative and profiling the nonlinear parameters
#' (Gauss-Markov correlation times, sinusoid frequencies).
#'
#' @section Input:
#' `av` may be an [allan()] result, an [avar()]/[avarn()]/[avari()] table, a
#' plain data frame with `tau` and `avar` (and optionally `edf`), a previous
#' `avfit`, or an [as_av_curve()] result; see [as_av_curve()] for what is
#' read from each. Refitting a previous fit, `avfit(fit, terms)`, fits its
#' curve with the EDF it used (so that AIC/BIC of the two fits compare);
#' every other setting (start values, `bias_correct`, `correlation`,
#' `control`) comes from this call's arguments, nothing from the old fit.
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
#' one-dimensional optimisation and, with several, jointly by
#' Levenberg-Marquardt (see [avfit_control()]).
#'
#' @section EDF:
#' When the input has no `edf` column it is computed from `n`, the cluster
#' size \eqn{m = \tau f} and the fitted model. Each term's EDF is that of
#' its power-law noise type from the EDF engine of [allan()] (Greenhall &
#' Riley's algorithm; exact Gaussian moments for white and random-walk
#' noise at cluster sizes up to 64), so that avfit() and allan() give the
#' same EDF for the same noise. The exponents come from the catalogue:
#' Q 2, N 0, B -1, K -2, a Gauss-Markov term -2, -1 or 0 as tau is below
#' 0.5 Tc, below 3 Tc or above; the ramp and sinusoids are deterministic.
#' The terms are combined as \eqn{\nu = (\sum_k AV_k)^2 / \sum_k
#' (AV_k^2/\nu_k)}. When every noise term of the model is one of N, K, Q
#' and Gauss-Markov terms and there are several of them (or a Gauss-Markov
#' term), the EDF is instead exact for their sum (Greenhall & Riley's sum
#' over the autocovariance of the second differences, computed from each
#' term's structure function): the combination above leaves out the cross
#' terms between noises and overstates the EDF up to twofold where two
#' terms are level. The fit is iterated `edf_passes` times (see
#' [avfit_control()]; white-FM EDF first, then the model's).
#'
#' @section Uncertainty:
#' The covariance of the free parameters is the inverse Gauss-Newton
#' information \eqn{(J^\top J)^{-1}} of the standardized residuals in the
#' reported parameterisation (amplitudes, `tc` in s, `f0` in Hz), scaled by
#' \eqn{\max(1, \chi^2/\mathrm{dof})} so that misfit widens it. When the
#' points were weighed as independent (the default) and the curve carries
#' `n` and `freq`, it is the sandwich
#' \eqn{(J^\top J)^{-1} J^\top R J (J^\top J)^{-1}} with \eqn{R} the
#' correlation of the points under the fitted model (exact for sums of N,
#' K, Q and Gauss-Markov terms with the overlapping estimator), else the
#' white-noise correlation above: the estimates are those of the
#' independent weighting, their spread that of correlated points (octave
#' points share their data; without it the 95% intervals of N and K
#' covered 73-87% on simulated records). For an
#' amplitude at its bound 0 the curvature is computed for \eqn{c = a^2}
#' instead and its standard error reported as \eqn{\sqrt{SE(c)}} (the
#' one-sigma upper reach of the amplitude); the `tc` or `f0` of a term whose
#' amplitude is 0 is not identified and gets `NA`. Fixed parameters have
#' zero variance.
#'
#' @param av The Allan variance curve (see Input).
#' @param terms Character vector of terms to fit (see [av_terms()]); `gm` and
#'   `sinusoid` may be repeated, e.g. `c("N", "gm", "gm")`. `NULL` (the
#'   default) fits the datasheet model: the terms a datasheet reads, N, B
#'   and K.
#' @inheritParams as_av_curve
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
#' @param control Search settings, [avfit_control()] (or a list of its
#'   arguments).
#' @param ... Must be empty (an unknown argument is an error).
#' @return An object of class `"avfit"`: a list with `coefficients` (named:
#'   `Q`, `N`, `B`, `K`, `R`, `gm1.sigma`, `gm1.tc`, `sinusoid1.amp`,
#'   `sinusoid1.f0`, ...), `se` (`NA` for the nonlinear parameters of a
#'   term whose amplitude is 0; any other SE or coefficient that is not
#'   finite comes with a warning of class `allanvar_warning_fit_not_finite`),
#'   `vcov`, `chi2` (sum of squared
#'   standardized residuals per degree of freedom), `rms` (RMS relative
#'   error of the Allan deviation in percent: the measured ADEV relative to
#'   the model's,
#'   \eqn{100\sqrt{\mathrm{mean}((\sqrt{\widehat{AV}_j/AV_j} - 1)^2)}}; this
#'   direction keeps a single low estimate at the longest tau, where the EDF
#'   is near 1, from dominating),
#'   `objective`, `df.residual`, `nobs`, `terms`, `layout` (one row per
#'   coefficient: name, term label, kind, parameter, role, unit, fixed),
#'   `data` (data frame `tau`, `m`, `avar`, `edf`, `fitted`, `z`),
#'   `model_error` (the relative model error the weights include, 0 when
#'   the model agrees with the curve within the points' scatter; see
#'   [avfit_control()]),
#'   `components` (each term's AV at the data taus), `freq`, `n`, `type`,
#'   `edf_source`, `steps` (zero-row data frame with the columns of
#'   [avrefine()]'s steps),
#'   `input` (the full curve before `tau_range`, an [as_av_curve()] object),
#'   `convergence` (list `converged`, `iterations` (the joint refinement's evaluations
#'   with several nonlinear parameters, else Gauss-Newton steps of the last
#'   amplitude solve), `evaluations` (objective evaluations of the search)
#'   and `message`), `control` and `call`.
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
avfit <- function(av, terms = NULL, n = NULL, freq = NULL,
                  type = NULL, channel = NULL, start = NULL, fixed = NULL,
                  tau_range = NULL, bias_correct = TRUE, correlation = FALSE,
                  control = avfit_control(), ...) {
  cl <- match.call()
  check_dots_empty(...)
  check_present(missing(av), "av", "an Allan variance curve")
  fit_curve(av, terms, n, freq, type, channel, start, fixed, tau_range,
            bias_correct, correlation, control, cl)
}

# avfit()'s work. `covariance = FALSE` (the loop's refits, read for their
# criterion and shares only): the reported covariance leaves out the
# sandwich (the points' model correlation, the costly part), so that its
# SEs still say which are not finite (check_fit_finite()'s warnings, which
# the loop records); complete_covariance() gives the fit the loop returns
# its full covariance.
fit_curve <- function(av, terms, n, freq, type, channel, start, fixed, tau_range,
                      bias_correct, correlation, control, cl, covariance = TRUE) {
  check_flag(bias_correct, "bias_correct")
  check_flag(correlation, "correlation")
  terms <- check_terms(terms %||% datasheet_terms())
  control <- check_control(control)
  curve <- as_av_curve(av, n = n, freq = freq, type = type, channel = channel)
  lay <- coef_layout(terms)
  start <- check_named(start, "start", lay$name)
  fixed <- check_named(fixed, "fixed", lay$name)
  lay$fixed <- lay$name %in% names(fixed)
  for (arg in c("start", "fixed")) {
    given <- get(arg)
    for (nm in names(given)) {
      # amplitudes >= 0, time constants and frequencies > 0 (as in av_model())
      v <- given[[nm]]
      role <- lay$role[lay$name == nm]
      if ((role == "amp" && v < 0) || (role == "nonlinear" && v <= 0)) {
        abort("`", arg, "`: ", nm,
              " must be ", if (role == "amp") "non-negative" else "positive",
              ", not ", format(v), ".", class = "argument")
      }
    }
  }
  # an entry measured from the raw series (a band's spectrum) cannot be
  # searched on a curve: its measured values come with it
  unmeasured <- layout_hidden(lay) & !lay$fixed
  if (any(unmeasured)) {
    kinds <- unique(lay$kind[unmeasured])
    abort("`terms`: ", paste0("\"", kinds, "\"", collapse = ", "),
          " is measured from the raw series, not fitted to a curve; let ",
          "`avrefine(fit, data = x)` propose it, or give its measured values (",
          paste(lay$name[unmeasured][seq_len(min(3, sum(unmeasured)))],
                collapse = ", "),
          if (sum(unmeasured) > 3) ", ..." else "", ") in `fixed`.",
          class = "argument")
  }
  lay$value <- NA_real_
  lay$value[lay$fixed] <- fixed[lay$name[lay$fixed]]
  keep <- rep(TRUE, nrow(curve$data))
  if (!is.null(tau_range)) {
    if (!is.numeric(tau_range) || length(tau_range) != 2L || anyNA(tau_range) ||
        tau_range[1] >= tau_range[2]) {
      abort("`tau_range` must be c(min, max) in seconds with min < max.",
            class = "argument")
    }
    keep <- curve$data$tau >= tau_range[1] & curve$data$tau <= tau_range[2]
  }
  data <- curve$data[keep, , drop = FALSE]
  rownames(data) <- NULL
  nfree <- sum(!lay$fixed)
  if (nrow(data) < nfree) {
    abort("`av` has ", nrow(data), " usable points, fewer than the ", nfree,
          " free parameters of terms ", paste(terms, collapse = ", "), ".",
          class = "curve")
  }
  tau0 <- if (is.null(curve$freq)) NULL else 1 / curve$freq
  corr <- NULL
  if (correlation) {
    if (is.null(curve$freq) || is.null(curve$n)) {
      abort("`correlation = TRUE` needs `n` and `freq` (the cluster sizes ",
            "and the record length).", class = "argument")
    }
    if (is.null(curve$corr)) {
      corr <- white_corr(data$m, curve$n, curve$type)
      # the correlation of the points is a property of the curve: kept with
      # it (all points) so that refits need not recompute it
      if (all(keep)) curve$corr <- corr
    } else {
      corr <- curve$corr[keep, keep, drop = FALSE]
    }
  }
  res <- NULL
  model_edf <- curve$edf_source == "model"
  for (pass in seq_len(if (model_edf) control$edf_passes else 1L)) {
    if (model_edf) {
      data$edf <- if (is.null(res)) {
        edf_model(data$m, curve$n, curve$type, matrix(1, nrow(data), 1), 0,
                  curve$L)
      } else {
        edf_fit_model(data$m, curve$n, curve$type, data$tau, tau0,
                      res$layout, curve$L)
      }
    }
    pr <- fit_problem(data, tau0, lay, bias_correct, corr)
    res <- fit_search(pr, start, res, control)
  }
  # An honest model-error term where the model departs from the curve
  # beyond the points' scatter (avfit_control(model_error =)): re-weighted
  # until its estimate settles.
  model_var <- 0
  if (isTRUE(control$model_error)) {
    for (it in 1:4) {
      v <- model_error_var(res, pr)
      if (v == 0 || abs(v - model_var) <= 0.05 * v) break
      model_var <- v
      pr <- fit_problem(data, tau0, lay, bias_correct, corr, model_var = model_var)
      res <- fit_search(pr, start, res, control)
    }
  }
  out <- finish_fit(res, pr, curve, terms, control, cl, covariance)
  out$model_error <- sqrt(model_var)
  out
}

# Everything a fit reports, from the search result `res` on problem `pr`
# (`covariance`: see fit_curve()).
finish_fit <- function(res, pr, curve, terms, control, cl, covariance = TRUE) {
  lay <- res$layout
  data <- pr$data
  tau0 <- pr$tau0
  comp <- model_components(data$tau, tau0, lay, pr$plan)
  fitted <- rowSums(comp)
  z <- (pr$y - log(fitted)) / pr$s
  objective <- sum(wmul(pr$W, pr$y - log(fitted))^2)
  nfree <- sum(!lay$fixed)
  dfres <- nrow(data) - nfree
  chi2 <- if (dfres > 0) objective / dfres else NA_real_
  vc <- if (covariance) fit_covariance(pr, curve, lay, chi2) else
    fit_vcov(lay, data$tau, tau0, pr$W, chi2, pr$plan)
  data$fitted <- fitted
  data$z <- z
  input <- curve
  if (curve$edf_source == "model") input$data$edf <- NA_real_
  se <- stats::setNames(sqrt(pmax(diag(vc), 0)), lay$name)
  # a nonlinear parameter of a term whose amplitude is 0 has no value to
  # err about (its SE is NA by design, see fit_vcov())
  absent <- lay$role == "nonlinear" & is.na(diag(vc))
  check_fit_finite(stats::setNames(lay$value, lay$name), se[!absent])
  out <- new_avfit(
    coefficients = stats::setNames(lay$value, lay$name),
    se = se, vcov = vc,
    chi2 = chi2, rms = 100 * sqrt(mean((sqrt(data$avar / fitted) - 1)^2)),
    objective = objective, logdet = w_logdet(pr$W),
    df.residual = dfres, nobs = nrow(data), npar = nfree, terms = terms,
    layout = lay, data = data, components = comp, freq = curve$freq,
    n = curve$n, type = curve$type, edf_source = curve$edf_source,
    bias_correct = pr$bias_correct, correlation = !is.null(pr$corr),
    corr = pr$corr, steps = new_steps(), input = input,
    convergence = res$convergence, control = control, call = cl)
  if (!covariance) out$partial_vcov <- TRUE
  out
}

# The full covariance (and SEs) of a fit finish_fit() gave a partial one;
# any other fit is returned as it is. The problem is rebuilt from the fit's
# own points, EDF and layout, as the fit's last pass had it (the loop's
# refits carry no model-error term).
complete_covariance <- function(fit) {
  if (!isTRUE(fit$partial_vcov)) return(fit)
  lay <- fit$layout
  data <- fit$data[, setdiff(names(fit$data), c("fitted", "z")), drop = FALSE]
  tau0 <- if (is.null(fit$freq)) NULL else 1 / fit$freq
  pr <- fit_problem(data, tau0, lay, fit$bias_correct, fit$corr)
  vc <- fit_covariance(pr, fit$input, lay, fit$chi2)
  fit$vcov <- vc
  fit$se <- stats::setNames(sqrt(pmax(diag(vc), 0)), lay$name)
  fit$partial_vcov <- NULL
  fit
}

# The covariance a fit of layout `lay` on problem `pr` reports (the
# sandwich with the points' correlation where the weighting left it out),
# scaled by its chi2 per dof; also R/fit-amp-interval.R's under a tested
# value.
fit_covariance <- function(pr, curve, lay, chi2) {
  fit_vcov(lay, pr$data$tau, pr$tau0, pr$W, chi2, pr$plan,
           corr = sandwich_corr(pr, curve, lay))
}

# The correlation of the fitted points that the weighting left out, when
# the fit treated them as independent and the curve says how they were
# made (n and freq): under the fitted model itself where every stochastic
# term has an exact structure function (N, K, Q, Gauss-Markov; overlapping
# estimator), else the white-noise correlation `correlation = TRUE` uses;
# NULL otherwise. Left out above `sandwich_max_points` points (the J x J
# matrix; such dense grids come from `taus = "all"`).
sandwich_max_points <- 2000L
sandwich_corr <- function(pr, curve, lay) {
  if (!is.null(pr$corr) || is.null(curve$n) || is.null(curve$freq)) return(NULL)
  m <- pr$data$m
  if (is.null(m) || length(m) < 2L || length(m) > sandwich_max_points) return(NULL)
  R <- model_corr(m, curve$n, curve$type, pr$data$tau, pr$tau0, lay,
                  curve$L %||% (curve$n + 1))
  if (!is.null(R)) return(R)
  if (!is.null(curve$corr) && nrow(curve$corr) == nrow(curve$data)) {
    keep <- match(pr$data$tau, curve$data$tau)
    if (!anyNA(keep)) return(curve$corr[keep, keep, drop = FALSE])
  }
  white_corr(m, curve$n, curve$type)
}

# Coefficients or standard errors that are not finite are never returned
# without a word: a classed warning names them and says why.
check_fit_finite <- function(coef, se) {
  bad_c <- names(coef)[!is.finite(coef)]
  bad_s <- setdiff(names(se)[!is.finite(se)], bad_c)
  if (length(bad_c)) {
    warn("the fit left ", paste(bad_c, collapse = ", "), " not finite: the curve ",
         "does not determine ", if (length(bad_c) > 1L) "them" else "it",
         " (too few points or degrees of freedom for these terms); drop the ",
         "term or give a longer curve.", class = "fit_not_finite")
  }
  if (length(bad_s)) {
    warn("no finite standard error for ", paste(bad_s, collapse = ", "),
         ": the fit is flat in ", if (length(bad_s) > 1L) "these directions" else "this direction",
         " (the curve does not determine ", if (length(bad_s) > 1L) "them" else "it",
         ").", class = "fit_not_finite")
  }
  invisible()
}

#' Construct and validate an avfit object (internal)
#'
#' `new_avfit()` builds the object from its named parts and validates it;
#' `validate_avfit()` checks the invariants every avfit method relies on.
#' @noRd
new_avfit <- function(..., class = character()) {
  x <- structure(list(...), class = c(class, "avfit"))
  validate_avfit(x)
}

validate_avfit <- function(x, arg = NULL) {
  bad <- function(...) abort(if (is.null(arg)) "Invalid avfit object: " else
    paste0("`", arg, "` is not a valid avfit() result: "), ..., class = "avfit")
  need <- c("coefficients", "se", "vcov", "chi2", "rms", "objective",
            "df.residual", "nobs", "npar", "terms", "layout", "data",
            "components", "type", "edf_source", "steps", "input",
            "convergence")
  miss <- setdiff(need, names(x))
  if (length(miss)) bad("missing ", paste(miss, collapse = ", "), ".")
  lay <- x$layout
  if (!identical(names(x$coefficients), lay$name)) {
    bad("the coefficient names do not match the layout.")
  }
  if (!identical(dim(x$vcov), rep(nrow(lay), 2L))) bad("vcov has the wrong size.")
  if (!all(c("tau", "m", "avar", "edf", "fitted", "z") %in% names(x$data))) {
    bad("`data` lacks columns.")
  }
  if (nrow(x$data) != x$nobs) bad("nobs does not match the data.")
  validate_steps(x$steps)
  cv <- x$convergence
  if (!is.list(cv) || !is.logical(cv$converged) || length(cv$converged) != 1L ||
      !is.character(cv$message)) {
    bad("`convergence` must hold converged, iterations and message.")
  }
  x
}

# Named numeric `start` / `fixed` values, naming coefficients of the model.
check_named <- function(x, arg, allowed) {
  if (is.null(x)) return(NULL)
  if (is.list(x)) x <- unlist(x)
  if (!is.numeric(x) || is.null(names(x)) || anyNA(x) || any(!is.finite(x))) {
    abort("`", arg, "` must be a named numeric vector, e.g. c(",
          allowed[1], " = 1).", class = "argument")
  }
  bad <- setdiff(names(x), allowed)
  if (length(bad)) {
    abort("`", arg, "` names an unknown coefficient ", bad[1],
          "; the model's coefficients are ", paste(allowed, collapse = ", "), ".",
          class = "argument")
  }
  x
}

check_flag <- function(x, arg) {
  if (!isTRUE(x) && !isFALSE(x)) {
    abort("`", arg, "` must be TRUE or FALSE.", class = "argument")
  }
  x
}

check_dots_empty <- function(...) {
  if (...length()) {
    nm <- names(list(...))
    what <- if (is.null(nm) || !nzchar(nm[1])) "an unnamed argument" else
      paste0("`", nm[1], "`")
    abort("Unknown argument: ", what, " is not an argument of this function.",
          class = "argument")
  }
  invisible(TRUE)
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
#' `confint()` gives Wald intervals on the log scale, except for a weakly
#' determined amplitude of a curve fit (its variance coefficient c = amp^2
#' has nu = 2 c^2 / SE(c)^2 below 100): there a value c0 is in the interval
#' when the estimate lies between the (1 -+ level)/2 quantiles of its law
#' under c0, a shifted scaled chi-square with mean c0 and the SD the fit's
#' covariance gives under c0 (a Neyman construction; Wald intervals at the
#' estimate were too short for estimates that came out high). For an amplitude at
#' 0 a one-sided interval `[0, upper]` (from the profile likelihood for
#' [avmle()] fits, at level 0.95; for curve fits from the quadratic
#' approximation of the objective in the variance coefficient c = amp^2,
#' c <= qnorm(level) SE(c)); for the time constant of a term at 0, `(0, Inf)`
#' (not identified).
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
#' @param type For `residuals()`: `"standardized"` (default), `"log"` or
#'   `"relative"`. For `predict()`: `"avar"` (default) or `"adev"`.
#' @param newdata For `predict()`: a vector of tau (s) or a data frame with a
#'   `tau` column; default the fitted taus.
#' @param by_term For `predict()`: return each term's contribution.
#' @param terms For `plot()`: draw each term's curve.
#' @param residuals For `plot()`: add the residual panel.
#' @param unit For `plot()`: the rate unit of the curve, for the y axis;
#'   `NULL` for the unit the curve carried, else "u".
#' @param ... Further arguments (for `plot()`, passed to the main
#'   `plot.default()` call).
#' @return `coef()` a named vector; `vcov()` a matrix; `confint()` a matrix
#'   with lower and upper columns; `fitted()`, `residuals()` and
#'   `predict()` numeric vectors (a matrix with `by_term = TRUE`);
#'   `logLik()` a `logLik` object; `summary()` an object of class
#'   `summary.avfit` with a coefficient table (estimate, SE, CI, unit,
#'   meaning, fixed, and hidden: measured values the printed tables leave
#'   out, such as a measured band's spectrum);
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
residuals.avfit <- function(object, type = "standardized", ...) {
  type <- check_choice(type, c("standardized", "log", "relative"), "type")
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
  if (!(is.character(parm) || is.numeric(parm)) || is.object(parm)) {
    abort("`parm` must be coefficient names or indices, not ", describe_type(parm),
          ".", class = "argument")
  }
  if (is.numeric(parm)) parm <- names(cf)[parm]
  if (!all(parm %in% names(cf))) {
    abort("`parm` must name coefficients of the fit: ",
          paste(names(cf), collapse = ", "), ".", class = "argument")
  }
  level <- check_number(level, "level", lo = 0, hi = 1, open = TRUE)
  zq <- stats::qnorm((1 + level) / 2)
  lay <- object$layout
  role <- lay$role[match(parm, lay$name)]
  est <- cf[parm]
  s <- se[parm]
  # Wald on the log scale; an amplitude at 0: one-sided [0, upper], from
  # the profile likelihood where the fit has it (avmle(), at 95%), else
  # from the quadratic approximation of the objective in c = amp^2 (whose
  # SE is se^2): c <= qnorm(level) se^2; a nonlinear parameter whose term
  # is at 0 is not identified: (0, Inf)
  zero <- role == "amp" & est == 0
  lo <- est * exp(-zq * s / est)
  hi <- est * exp(zq * s / est)
  bu <- object$bound_upper
  bu <- if (is.null(bu)) rep(NA_real_, length(parm)) else unname(bu[parm])
  lo[zero] <- 0
  hi[zero] <- ifelse(is.finite(bu[zero]), if (abs(level - 0.95) < 1e-12) bu[zero] else NA_real_,
                     sqrt(stats::qnorm(level)) * s[zero])
  lab <- lay$label[match(parm, lay$name)]
  dead <- role == "nonlinear" & lab %in% lay$label[lay$role == "amp" & cf[lay$name] == 0] &
    !is.finite(s)
  lo[dead] <- 0
  hi[dead] <- Inf
  # a weakly determined amplitude of a curve fit: the Neyman construction
  # of R/fit-amp-interval.R instead of Wald
  for (k in which(amp_interval_weak(object, parm))) {
    ab <- amp_interval(object, parm[k], level)
    if (all(!is.na(ab))) {
      lo[k] <- ab[1]
      hi[k] <- ab[2]
    }
  }
  pct <- paste(format(100 * c((1 - level) / 2, (1 + level) / 2), trim = TRUE,
                      digits = 3), "%")
  out <- cbind(lo, hi)
  dimnames(out) <- list(parm, pct)
  out
}

#' @rdname avfit-methods
#' @export
predict.avfit <- function(object, newdata = NULL, type = "avar",
                          by_term = FALSE, ...) {
  type <- check_choice(type, c("avar", "adev"), "type")
  tau <- if (is.null(newdata)) object$data$tau else
    if (is.data.frame(newdata)) newdata$tau else newdata
  if (!is.numeric(tau) || !length(tau) || anyNA(tau) || any(tau <= 0) ||
      any(!is.finite(tau))) {
    abort("`newdata` must be positive tau values in seconds (a vector or a ",
          "data frame with a `tau` column).", class = "argument")
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
                    se = signif(x$se, 3), unit = unit_label(x$layout$unit, x))
  hid <- layout_hidden(x$layout)
  print(tab[!hid, , drop = FALSE])
  note_hidden(hid)
  cat(sprintf("chi2/dof = %.3g (dof %d), RMS ADEV error = %.3g %%\n",
              x$chi2, x$df.residual, x$rms))
  if (isTRUE(x$model_error > 0)) {
    cat(sprintf(paste0("The model departs from the curve beyond its points' scatter: ",
                       "weights include a model error of %.3g%% (relative AV); ",
                       "see the residuals (z).\n"), 100 * x$model_error))
  }
  if (nrow(x$steps)) cat(nrow(x$steps), "refinement step(s); see $steps\n")
  print_convergence(x$convergence)
  invisible(x)
}

# Rows of a fit's layout that hold measured values an entry carries for its
# own use (a measured band's spectrum): left out of the printed tables.
# coef_layout() records them; layouts saved before it did are looked up.
layout_hidden <- function(lay) {
  if (!is.null(lay$hidden)) return(lay$hidden %in% TRUE)
  vapply(seq_len(nrow(lay)), function(i) {
    p <- effect_entry(lay$kind[i], lay$variant[i])$params
    isTRUE(p$hidden[p$name == lay$param[i]])
  }, logical(1))
}

note_hidden <- function(hid) {
  if (any(hid)) {
    cat(sum(hid), "measured value(s) of the model not shown; see coef()\n")
  }
}

# A fit that did not converge says so (nothing is printed when it did).
print_convergence <- function(cv) {
  if (!is.null(cv) && !isTRUE(cv$converged)) {
    cat("The fit did NOT converge: ", cv$message,
        ". Raise the limits in avfit_control().\n", sep = "")
  }
  invisible(cv)
}

#' @rdname avfit-methods
#' @export
summary.avfit <- function(object, level = 0.95, ...) {
  ci <- confint(object, level = level)
  lay <- object$layout
  words <- vapply(seq_len(nrow(lay)), function(i) {
    p <- effect_entry(lay$kind[i], lay$variant[i])$params
    p$meaning[p$name == lay$param[i]]
  }, "")
  tab <- data.frame(estimate = object$coefficients, se = object$se,
                    lower = ci[, 1], upper = ci[, 2],
                    unit = unit_label(lay$unit, object),
                    meaning = words, fixed = lay$fixed,
                    hidden = layout_hidden(lay), stringsAsFactors = FALSE)
  rownames(tab) <- lay$name
  structure(list(coefficients = tab, chi2 = object$chi2, rms = object$rms,
                 df.residual = object$df.residual, nobs = object$nobs,
                 logLik = logLik(object), AIC = stats::AIC(object),
                 BIC = stats::BIC(object), level = level, steps = object$steps,
                 terms = object$terms, type = object$type,
                 convergence = object$convergence,
                 rate_unit = fit_unit(object)),
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
  hid <- if (is.null(tab$hidden)) rep(FALSE, nrow(out)) else tab$hidden
  print(out[!hid, , drop = FALSE], right = FALSE)
  note_hidden(hid)
  if (is.null(x$rate_unit)) {
    cat("\n\"u\" is the input's rate unit (e.g. deg/s or m/s^2).\n")
  }
  cat(sprintf("chi2/dof = %.4g on %d dof; RMS relative ADEV error = %.3g %%\n",
              x$chi2, x$df.residual, x$rms))
  cat(sprintf("logLik = %.4g, AIC = %.4g, BIC = %.4g (%d points)\n",
              as.numeric(x$logLik), x$AIC, x$BIC, x$nobs))
  print_convergence(x$convergence)
  if (nrow(x$steps)) {
    cat("\nRefinement steps:\n")
    print(x$steps)
  }
  invisible(x)
}

#' @rdname avfit-methods
#' @export
plot.avfit <- function(x, terms = TRUE, residuals = TRUE, unit = NULL, ...) {
  d <- x$data
  unit <- fit_unit(x, unit)
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
  cols <- grDevices::hcl.colors(max(ncol(comp), 2), "Dark 3")
  labs <- colnames(comp)
  # an oscillating term (a sinusoid's lobes) is drawn as its upper
  # envelope: dashes along every lobe would hide the model
  wavy <- apply(sqrt(comp), 2, n_peaks) > 2L
  labs[wavy] <- paste(labs[wavy], "(envelope)")
  leg <- list(legend = c("data", "model", if (terms) labs),
              lty = c(NA, 1, if (terms) rep(2, ncol(comp))),
              pch = c(19, NA, if (terms) rep(NA, ncol(comp))),
              lwd = c(NA, 2, if (terms) rep(1, ncol(comp))),
              col = c("black", "black", if (terms) cols[seq_len(ncol(comp))]))
  reserve_legend(leg, cex = 0.8)
  graphics::plot(d$tau, sqrt(d$avar), log = "xy", ylim = yl, pch = 19,
                 cex = 0.7, xlab = if (residuals) "" else "tau [s]",
                 ylab = if (is.null(unit)) "Allan deviation [u]" else
                   sprintf("Allan deviation [%s]", unit),
                 xaxt = if (residuals) "n" else "s",
                 main = paste("avfit:", paste(x$terms, collapse = " + ")), ...)
  if (residuals) graphics::axis(1, labels = FALSE)
  # error bars only where they have a length (arrows() warns otherwise)
  bar <- is.finite(lo) & is.finite(hi) & hi > lo * (1 + 1e-3)
  if (any(bar)) {
    graphics::arrows(d$tau[bar], lo[bar], d$tau[bar], hi[bar], angle = 90,
                     code = 3, length = 0.02, col = "grey40")
  }
  if (terms) {
    for (k in seq_len(ncol(comp))) {
      v <- sqrt(comp[, k])
      if (wavy[k]) v <- rev(cummax(rev(v)))
      v[v < yl[1] / 10] <- NA
      graphics::lines(tt, v, lty = 2, col = grDevices::adjustcolor(cols[k], 0.8))
    }
  }
  graphics::lines(tt, sqrt(tot), lwd = 2)
  legend_beside(leg, cex = 0.8)
  if (residuals) {
    graphics::par(mar = c(0.5, 4.5, 0.5, graphics::par("mar")[4L]))
    zr <- max(3, abs(d$z), na.rm = TRUE)
    graphics::plot(d$tau, d$z, log = "x", ylim = c(-zr, zr), pch = 19,
                   cex = 0.7, xlab = "", ylab = "z")
    graphics::abline(h = 0)
    graphics::abline(h = c(-2, 2), lty = 3)
    graphics::mtext("tau [s]", side = 1, line = 2.2, outer = TRUE)
  }
  invisible(x)
}
