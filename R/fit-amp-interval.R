# The confidence interval of a weakly determined amplitude of a curve fit.
#
# A curve fit's amplitude enters the Allan variance through c = amp^2,
# linearly. Where c is well determined its estimate is near-normal on the
# log scale and Wald on the log scale covers. Where it is not (a rate
# random walk seen only in the last octaves, beside a Gauss-Markov tail),
# the covariance at the estimate misleads: a record whose last points came
# out high gives a large c with a small SE, because a larger c would be
# better determined; Wald intervals covered 91.5% (weak K, 1e5 samples,
# 400 seeds), all misses such overestimates.
#
# Here the interval is a Neyman construction: c0 is in it when the
# estimate is a plausible draw under c0 (the other parameters at their
# estimates). The estimate is read off Allan variances that scatter as
# scaled chi-squares around c0 b + r (r: the other terms there), so its
# law is taken as a shifted scaled chi-square, c + s ~ (c0 + s) chi2_m / m,
# with the estimate's mean c0 and its SD under c0, SE_c(c0) (the fit's
# covariance recomputed under the tested model: sandwich, the points' EDF
# and weights). SE_c grows about linearly in c0 from SE_c(0), which gives
# the shift: s = c0 SE_c(0) / (SE_c(c0) - SE_c(0)), and m = 2 (c0 + s)^2 /
# SE_c(c0)^2. A zero shift is the plain scaled chi-square of an Allan
# variance; a large one the normal law. (Without the shift, the plain
# chi-square with nu = 2 c0^2 / SE_c(c0)^2 put its mass at 0 where nu <
# 0.1, and covered 71% on 8192-sample records.) Where the estimate's
# relative SE is small the law is normal and the interval the Wald one,
# so the construction is used only where nu at the estimate is below
# `amp_interval_nu_max`.

amp_interval_nu_max <- 100

# TRUE for the amplitudes of `object` (an avfit() curve fit, not avmle())
# named in `parm` that take the construction: free, above 0, with a finite
# SE and nu = 2 c^2 / SE_c^2 = 1 / (2 (se / amp)^2) below the limit.
amp_interval_weak <- function(object, parm) {
  if (identical(object$method, "mle") || is.null(object$input) ||
      is.null(object$input$n) || is.null(object$freq) || is.null(object$data$m)) {
    return(rep(FALSE, length(parm)))
  }
  lay <- object$layout
  i <- match(parm, lay$name)
  est <- object$coefficients[parm]
  rel <- object$se[parm] / est
  lay$role[i] == "amp" & !lay$fixed[i] & is.finite(est) & est > 0 &
    is.finite(rel) & rel > 0 & 1 / (2 * rel^2) < amp_interval_nu_max
}

# SE of c = amp^2 for amplitude `name` when it is sqrt(c0), the other
# parameters at their estimates: the covariance avfit() reports, computed
# under that model, with the points' EDF under that model (what their
# scatter would be if c0 were true).
amp_se_c <- function(object, name, c0) {
  lay <- object$layout
  i <- match(name, lay$name)
  lay$value[i] <- sqrt(c0)
  tau0 <- 1 / object$freq
  d <- object$data
  curve <- object$input
  d$edf <- edf_fit_model(d$m, curve$n, curve$type, d$tau, tau0, lay, curve$L)
  me <- object$model_error
  pr <- fit_problem(d, tau0, lay, isTRUE(object$bias_correct), object$corr,
                    model_var = if (is.null(me)) 0 else me^2)
  v <- fit_covariance(pr, curve, lay, object$chi2)[i, i]
  if (!is.finite(v) || v < 0) return(NA_real_)
  2 * sqrt(c0) * sqrt(v)
}

# The interval (amplitude units) of amplitude `name` at `level`.
amp_interval <- function(object, name, level) {
  c_hat <- object$coefficients[[name]]^2
  alpha <- (1 - level) / 2
  se0 <- amp_se_c(object, name, 1e-4 * c_hat)
  if (!is.finite(se0)) return(c(NA_real_, NA_real_))
  # SE_c at c0 = exp(lc), once per value (both ends start at the estimate)
  memo <- new.env(parent = emptyenv())
  se_at <- function(lc) {
    key <- sprintf("%.17g", lc)
    if (is.null(memo[[key]])) memo[[key]] <- amp_se_c(object, name, exp(lc))
    memo[[key]]
  }
  # the law's p-quantile under c0 = exp(lc), minus the estimate, relative
  limit <- function(lc, p) {
    c0 <- exp(lc)
    se <- se_at(lc)
    if (!is.finite(se) || se <= 0) return(NA_real_)
    if (se <= se0 * (1 + 1e-9)) {
      q <- c0 + stats::qnorm(p) * se
    } else {
      s <- c0 * se0 / (se - se0)
      m <- 2 * (c0 + s)^2 / se^2
      q <- (c0 + s) * stats::qchisq(p, m) / m - s
    }
    q / c_hat - 1
  }
  # the lower end: the c0 below which the law's upper quantile stays under
  # the estimate; the upper end: above which its lower quantile exceeds
  # it. Bracketed in quarter decades from the estimate, then solved.
  solve_end <- function(p, dir) {
    step <- dir * log(10) / 4
    a <- log(c_hat)
    fa <- limit(a, p)
    for (k in 1:24) {
      b <- a + step
      fb <- limit(b, p)
      if (!is.finite(fa) || !is.finite(fb)) return(NA_real_)
      if (sign(fb) != sign(fa)) {
        ends <- if (a < b) c(fa, fb) else c(fb, fa)
        r <- stats::uniroot(function(l) limit(l, p), sort(c(a, b)), f.lower = ends[1],
                            f.upper = ends[2], tol = 1e-4)$root
        return(exp(r))
      }
      a <- b
      fa <- fb
    }
    if (dir < 0) 0 else Inf
  }
  c(sqrt(solve_end(1 - alpha, -1)), sqrt(solve_end(alpha, 1)))
}
