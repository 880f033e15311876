#' Exact Fisher information of a record and the Cramer-Rao bound
#'
#' How precisely can a record of `n` samples at `freq` Hz tell each
#' parameter of a noise model? `av_information()` computes the exact
#' expected Fisher information of the Gaussian likelihood of the rate
#' series (the one [avmle()] maximises: the samples after the first, the
#' sensor's bias unknown) and from it the Cramer-Rao bound of every
#' parameter: the smallest standard deviation an unbiased estimator can
#' have. [av_plan()] turns it around: the record length a target precision
#' needs.
#'
#' The model is any the catalogue writes in state-space form (terms with a
#' `statespace` field: `N`, `K`, `gm`, repeatable). Differencing removes
#' the unknown level exactly (a diffuse bias or the random walk's start),
#' so the information is that of the n - 1 first differences, a stationary
#' process with a small state-space form. The information is accumulated
#' step by step from the Kalman filter (Harvey 1989, sec. 3.4.6):
#' \deqn{I_{ij} = \sum_t \frac{\partial_i F_t \partial_j F_t}{2F_t^2} +
#'   \frac{E(\partial_i v_t \partial_j v_t)}{F_t},}
#' with \eqn{F_t} and the gain deterministic (the Riccati recursion and its
#' derivative) and the covariance of the innovations' derivatives
#' propagated exactly by a linear recursion (src/information.cpp). Once the
#' filter is stationary every further sample adds the same increment, so
#' the cost is O(min(n, t*)) for the t* steps the filter takes to settle
#' (about 3e5 in the slowest case of the examples, well under a second), and
#' the information of any longer record follows in O(1). (A model without
#' `K` has differences that are not invertible and a filter that settles
#' only slowly; past 4e6 steps its last increment carries on, an
#' approximation.) The derivatives of
#' the system matrices in the log parameters are central differences of
#' closed forms (relative error about 1e-10). The tests check the result
#' against the dense \eqn{\frac12 \mathrm{tr}(\Sigma^{-1}\Sigma_i\Sigma^{-1}\Sigma_j)}
#' and against a Monte Carlo of the score.
#'
#' The bound limits unbiased estimators. Where it is large (above about
#' 50%) the large-sample picture does not hold: estimates of the barely
#' visible parameter are biased and often collapse to 0, and their RMSE
#' can be below or above the bound.
#'
#' @param model The noise model: an [avfit()] or [avmle()] fit (its
#'   coefficients and terms), or a named coefficient vector such as
#'   `c(N = 0.01, K = 2e-4, gm1.sigma = 0.02, gm1.tc = 2)`. Every term must
#'   have a state-space form and every amplitude must be positive.
#' @param n Record length in samples (at least 3).
#' @param freq Sampling frequency in Hz; for a fit, by default the fit's.
#' @return An object of class `av_information`: a list with `bound`, a data
#'   frame (`parameter`, `value`, `se`: the Cramer-Rao bound of its
#'   standard deviation, `rel_se`: the same relative to the value, the SD
#'   of the log-parameter), `information` (the Fisher information matrix of
#'   the log-parameters), `n` and `freq`.
#' @seealso [av_plan()], [avmle()]
#' @export
#' @examples
#' truth <- c(N = 0.01, K = 2e-4, gm1.sigma = 0.02, gm1.tc = 2)
#' av_information(truth, n = 1e5, freq = 100)
av_information <- function(model, n, freq = NULL) {
  check_present(missing(model), "model", "a fit or a named coefficient vector")
  check_present(missing(n), "n", "the record length in samples")
  im <- info_model(model, freq)
  n <- check_number(n, "n", lo = 3, hi = 1e15)
  n <- floor(n)
  acc <- info_accumulate(im, min(n - 1, info_cap))
  info_result(im, info_at(acc, n, extend = TRUE), n)
}

#' Record length for a target precision
#'
#' From the exact Fisher information ([av_information()]): the number of
#' samples (and the duration) a record needs so that the Cramer-Rao bound
#' of each parameter's relative standard deviation is at most `target`,
#' found by bisection on the record length; and, when `n` is given, the
#' precision a record of that length gives.
#'
#' @inheritParams av_information
#' @param target Target relative standard deviation per parameter: one
#'   number for all, or a named vector (parameters not named are not
#'   planned). Default 0.1 (10%).
#' @param n Optional record length in samples: the bound it gives is added.
#' @param max_n The longest record searched (samples); a parameter that
#'   needs more gets `Inf`.
#' @return A data frame: `parameter`, `value`, `target`, `n_needed`
#'   (samples), `duration` (seconds), and with `n` given `rel_se` (the
#'   bound at `n`).
#' @seealso [av_information()], [imu_guidance()]
#' @export
#' @examples
#' truth <- c(N = 0.01, K = 2e-4, gm1.sigma = 0.02, gm1.tc = 2)
#' av_plan(truth, freq = 100, target = 0.2, n = 1e5)
av_plan <- function(model, freq = NULL, target = 0.1, n = NULL, max_n = 1e12) {
  check_present(missing(model), "model", "a fit or a named coefficient vector")
  im <- info_model(model, freq)
  max_n <- check_number(max_n, "max_n", lo = 10, hi = 1e15)
  if (!is.numeric(target) || !length(target) || anyNA(target) ||
      any(!is.finite(target)) || any(target <= 0)) {
    abort("`target` must be positive relative standard deviations (e.g. 0.1 ",
          "for 10%), not ", describe_type(target), ".", class = "argument")
  }
  pn <- im$names
  if (is.null(names(target))) {
    if (length(target) != 1L) {
      abort("`target` must be one number or a vector named by parameter (",
            paste(pn, collapse = ", "), ").", class = "argument")
    }
    target <- stats::setNames(rep(target, length(pn)), pn)
  } else if (!all(names(target) %in% pn)) {
    abort("`target` names parameters the model does not have: ",
          paste(setdiff(names(target), pn), collapse = ", "), "; its parameters are ",
          paste(pn, collapse = ", "), ".", class = "argument")
  }
  if (!is.null(n)) n <- floor(check_number(n, "n", lo = 3, hi = 1e15))
  # the filter settles within a few million steps unless the model has no
  # term that makes the differences invertible (no K); past the cap, the
  # last increment carries on
  cap <- min(max(c(n, max_n)), info_cap)
  acc <- info_accumulate(im, cap, keep = max(1, ceiling(cap / 2e5)))
  rel <- function(m) info_result(im, info_at(acc, m, extend = TRUE), m)$bound$rel_se
  need <- vapply(names(target), function(p) {
    j <- match(p, pn)
    ok <- function(m) isTRUE(rel(m)[j] <= target[[p]])
    if (ok(3)) return(3)
    if (!ok(max_n)) return(Inf)
    lo <- 3; hi <- max_n
    # bisection on log n to one part in 1000, then whole samples
    while (hi / lo > 1.001 && hi - lo > 1) {
      mid <- floor(sqrt(lo * hi))
      if (mid <= lo) mid <- lo + 1
      if (ok(mid)) hi <- mid else lo <- mid
    }
    hi
  }, 0)
  out <- data.frame(parameter = names(target), value = im$values[names(target)],
                    target = unname(target), n_needed = unname(need),
                    duration = unname(need) / im$freq, stringsAsFactors = FALSE)
  if (!is.null(n)) out$rel_se <- rel(n)[match(names(target), pn)]
  rownames(out) <- NULL
  out
}

#' @export
print.av_information <- function(x, ...) {
  cat(sprintf("Cramer-Rao bound of a record of %g samples at %g Hz (%s):\n",
              x$n, x$freq, format_duration(x$n / x$freq)))
  b <- x$bound
  b$rel_se <- sprintf("%.3g%%", 100 * b$rel_se)
  print(b, row.names = FALSE)
  invisible(x)
}

format_duration <- function(s) {
  if (!is.finite(s)) return("never")
  if (s >= 86400) sprintf("%.3g d", s / 86400) else if (s >= 3600)
    sprintf("%.3g h", s / 3600) else sprintf("%.4g s", s)
}

# The model of av_information()/av_plan(): coefficient values, terms,
# catalogue entries, layout and freq, checked once.
info_model <- function(model, freq) {
  if (inherits(model, "avfit")) {
    cf <- model$coefficients
    if (is.null(freq)) freq <- model$freq
    if (is.null(freq)) {
      abort("`freq` is missing and the fit does not carry its sampling ",
            "frequency; give `freq` in Hz.", class = "missing_argument")
    }
    lay <- model$layout
    lay$value <- cf[lay$name]
  } else {
    lay <- check_coef(model, "model")
    check_present(is.null(freq), "freq", "the sampling frequency in Hz")
  }
  freq <- check_freq(freq)
  terms <- layout_terms(lay)
  entries <- statespace_entries(terms, "model",
    "the exact information is defined for models of terms that have one")
  v <- stats::setNames(lay$value, lay$name)
  if (any(!is.finite(v)) || any(v <= 0)) {
    bad <- lay$name[!is.finite(v) | v <= 0]
    abort("`model`: every parameter must be positive and finite for its ",
          "information; ", paste(bad, collapse = ", "), " ",
          if (length(bad) > 1) "are" else "is", " not (drop a term at 0 from the model).",
          class = "argument")
  }
  list(values = v, names = lay$name, lay = lay, entries = entries, freq = freq,
       tau0 = 1 / freq)
}

# The state-space form of the first differences d_t = y_t - y_{t-1} of the
# model's rate, t = 2..n: every stationary state s (and the white
# measurement noise) enters as s_t - s_{t-1}, so it becomes the pair
# (s_t, s_{t-1}); the diffuse level (a random walk or a constant bias)
# leaves only its innovation, white measurement noise H of d.
info_system <- function(p, im) {
  m <- mle_model(p, im$lay, im$entries, im$tau0)
  dif <- m$diffuse + 1L
  if (m$T[dif] != 1) {
    abort("`model`: the diffuse state must be a level (transition 1).",
          class = "argument")
  }
  st <- setdiff(seq_along(m$T), dif)
  Tv <- c(m$T[st], 0)          # the white noise as a state with T = 0
  Qv <- c(m$Q[st], m$R)
  P0 <- c(m$P0[st], m$R)
  k <- length(Tv)
  s <- 2L * k
  if (s > 16L) {
    abort("`model`: the exact information takes at most 7 stationary terms ",
          "(Gauss-Markov), not ", k - 1L, ".", class = "argument")
  }
  Tm <- Qm <- P <- matrix(0, s, s)
  for (i in seq_len(k)) {
    a <- 2L * i - 1L; b <- a + 1L
    Tm[a, a] <- Tv[i]; Tm[b, a] <- 1
    Qm[a, a] <- Qv[i]
    # (s_2, s_1): var s_1 = P0, s_2 = T s_1 + eta
    P[a, a] <- Tv[i]^2 * P0[i] + Qv[i]; P[a, b] <- P[b, a] <- Tv[i] * P0[i]
    P[b, b] <- P0[i]
  }
  list(T = Tm, Q = Qm, H = m$Q[dif], P = P, Z = rep(c(1, -1), k))
}

# Steps of the filter at most: it settles long before in models with K;
# without K (the differences not invertible) it settles only slowly, and
# past the cap the last increment carries on.
info_cap <- 4e6

# The filter of the differences (src/information.cpp) at the parameters,
# with the system's derivatives in the log parameters by central
# differences of the closed-form system matrices. Runs until the
# information increment is stationary or `steps` differences are taken;
# keeps the cumulative information every `keep` steps.
info_accumulate <- function(im, steps, keep = steps, h = 1e-5) {
  p0 <- im$values
  sys <- info_system(p0, im)
  deriv <- lapply(seq_along(p0), function(j) {
    up <- info_system(replace(p0, j, p0[[j]] * exp(h)), im)
    dn <- info_system(replace(p0, j, p0[[j]] * exp(-h)), im)
    list(T = (up$T - dn$T) / (2 * h), Q = (up$Q - dn$Q) / (2 * h),
         P1 = (up$P - dn$P) / (2 * h), H = (up$H - dn$H) / (2 * h))
  })
  # T entries that do not depend on a parameter are exact zeros
  deriv <- lapply(deriv, function(d) { d$T[abs(d$T) < 1e-12] <- 0; d })
  r <- info_kalman(list(T = sys$T, Q = sys$Q, P1 = sys$P, Z = sys$Z, H = sys$H),
                   deriv, list(max_steps = max(1, steps), tol = 1e-12, every = 25,
                               keep = max(1, keep)))
  r$np <- length(p0)
  r
}

# Information of n samples (n - 1 differences) from an accumulation: the
# kept step at or below, the stationary increment beyond the last, linear
# between kept steps.
info_at <- function(acc, n, extend = FALSE) {
  d <- n - 1
  k <- length(acc$at)
  last <- acc$at[k]
  I <- if (d >= last) {
    inc <- acc$stationary
    if (d > last && is.null(inc)) {
      if (!extend || k < 2) stop("internal: information not run far enough")
      inc <- (acc$cum[, k] - acc$cum[, k - 1]) / (last - acc$at[k - 1])
    }
    acc$cum[, k] + if (d > last) (d - last) * as.vector(inc) else 0
  } else {
    j <- findInterval(d, acc$at)
    lo <- if (j == 0) 0 else acc$at[j]
    clo <- if (j == 0) 0 else acc$cum[, j]
    clo + (d - lo) / (acc$at[j + 1] - lo) * (acc$cum[, j + 1] - clo)
  }
  matrix(I, acc$np, acc$np)
}

info_result <- function(im, I, n) {
  dimnames(I) <- list(im$names, im$names)
  if (!all(is.finite(I))) {
    abort("The Fisher information of this model is not finite at `freq` = ",
          format(im$freq), " Hz and `n` = ", format(n), ": the rate or the ",
          "record puts its terms beyond double precision.", class = "argument")
  }
  # inverted on the unit diagonal: parameters whose information differs by
  # 20 orders (N and K of a 1000-sample record at 1 MHz) made solve()
  # call the matrix singular and every bound Inf
  d <- sqrt(diag(I))
  V <- if (all(d > 0)) {
    tryCatch(solve(I / outer(d, d)) / outer(d, d), error = function(e) NULL)
  }
  rel <- if (is.null(V)) rep(Inf, length(im$names)) else sqrt(pmax(diag(V), 0))
  bound <- data.frame(parameter = im$names, value = unname(im$values),
                      se = unname(im$values * rel), rel_se = unname(rel),
                      stringsAsFactors = FALSE)
  structure(list(bound = bound, information = I, n = n, freq = im$freq),
            class = "av_information")
}

# Seconds of record for the Cramer-Rao bound of `param`'s relative SD to
# reach `target`, for the model of the coefficients `coef` with the values
# `set` put in (added or replaced). NA when the model has a term at a
# positive value without a state-space form (flicker B, quantization, ...):
# leaving it out would make the answer optimistic. Terms at 0 are left out.
# Used by imu_guidance().
plan_record_length <- function(coef, freq, set, param, target, max_n = 1e12) {
  coef <- coef[setdiff(names(coef), names(set))]
  coef <- c(coef, set)
  lay <- tryCatch(check_coef(coef), error = function(e) NULL)
  if (is.null(lay) || !is.finite(freq) || freq <= 0) return(NA_real_)
  sp <- split_term(layout_terms(lay))
  has_ss <- vapply(seq_along(sp$kind), function(i) {
    is.function(effect_entry(sp$kind[i], sp$variant[i])$statespace)
  }, NA)
  labels <- unique(lay$label)
  ok_label <- has_ss & vapply(labels, function(l) {
    v <- lay$value[lay$label == l]
    all(is.finite(v) & v > 0)
  }, NA)
  positive <- vapply(labels, function(l) any(lay$value[lay$label == l & lay$role == "amp"] > 0), NA)
  if (any(positive & !has_ss)) return(NA_real_)
  keep <- lay$label %in% labels[ok_label]
  if (!param %in% lay$name[keep]) return(NA_real_)
  model <- stats::setNames(lay$value[keep], lay$name[keep])
  pl <- tryCatch(av_plan(model, freq = freq, target = stats::setNames(target, param),
                         max_n = max_n),
                 allanvar_error = function(e) NULL)
  if (is.null(pl)) NA_real_ else pl$duration
}
