# The joint refinement of the nonlinear parameters after the profile
# search's one-dimensional passes: Levenberg-Marquardt on the variable-
# projection problem (the amplitudes solved at each value, as the search's
# objective solves them). A step costs one amplitude solve plus one basis
# column per parameter (finite differences of the catalogue's basis, not
# of the solve), where Nelder-Mead spends dozens of solves per parameter
# to reach the same optimum.

# The model's Allan variance at nonlinear `values` (every coefficient) and
# free squared amplitudes `c` (named), and the basis it comes from.
model_av_at <- function(pr, values, c) {
  Bm <- solve_basis(pr, values, NULL)
  amp <- pr$amp
  av <- fixed_av(pr, Bm)
  free <- which(!amp$fixed)
  if (length(free)) av <- av + drop(Bm[, amp$col[free], drop = FALSE] %*% c[amp$name[free]])
  list(av = av, B = Bm)
}

# Levenberg-Marquardt from `lognl` (named log nonlinear values) within
# [lb, ub]. The Jacobian is Kaufman's: the basis's derivative at fixed
# amplitudes, projected off the span of the amplitudes that are on, so a
# step already allows for the amplitudes' own response. A parameter at a
# bound whose descent points out of it stays there for the step.
# Returns lognl, value (the objective), evals (amplitude solves) and
# converged (FALSE after `control$polish_maxit` steps: the caller goes on
# with Nelder-Mead from there).
polish_lm <- function(pr, lognl, lb, ub, control) {
  nl_names <- names(lognl)
  K <- length(lognl)
  evals <- 0L
  h <- 1e-6
  at <- function(l) {
    v <- stats::setNames(exp(l), nl_names)
    evals <<- evals + 1L
    s <- solve_amps(pr, v, control, layout = FALSE, store = NULL)
    if (!is.finite(s$objective)) return(NULL)
    values <- pr$values
    values[nl_names] <- v
    m <- model_av_at(pr, values, s$c)
    if (!all(m$av > 0)) return(NULL)
    free_amp <- which(!pr$amp$fixed)
    on <- free_amp[s$c[pr$amp$name[free_amp]] > 0]
    list(S = s$objective, c = s$c, values = values, lav = log(m$av),
         r = drop(wmul(pr$W, pr$y - log(m$av))),
         Jc = if (length(on)) wmul(pr$W, m$B[, pr$amp$col[on], drop = FALSE] / m$av))
  }
  cur <- at(lognl)
  if (is.null(cur)) return(list(lognl = lognl, value = Inf, evals = evals, converged = FALSE))
  lambda <- 1e-3
  converged <- FALSE
  for (it in seq_len(control$polish_maxit)) {
    J <- matrix(0, length(cur$r), K)
    for (k in seq_len(K)) {
      st <- if (lognl[k] + h > ub[k]) -h else h
      vals <- cur$values
      vals[nl_names[k]] <- exp(lognl[k] + st)
      avk <- model_av_at(pr, vals, cur$c)$av
      if (all(avk > 0)) J[, k] <- -drop(wmul(pr$W, log(avk) - cur$lav)) / st
    }
    if (!is.null(cur$Jc)) J <- qr.resid(qr(cur$Jc), J)
    g <- drop(crossprod(J, cur$r))
    A <- crossprod(J)
    dA <- pmax(diag(A), 1e-12 * max(diag(A), .Machine$double.xmin))
    moved <- FALSE
    repeat {
      movable <- !((lognl >= ub & g < 0) | (lognl <= lb & g > 0))
      if (!any(movable) || lambda > 1e12) break
      Mf <- (A + lambda * diag(dA, K))[movable, movable, drop = FALSE]
      df <- tryCatch(-solve(Mf, g[movable]), error = function(e) NULL)
      if (!is.null(df) && all(is.finite(df))) {
        new <- lognl
        new[movable] <- pmin(pmax(lognl[movable] + df, lb[movable]), ub[movable])
        nw <- if (any(new != lognl)) at(new)
        if (!is.null(nw) && nw$S < cur$S) {
          gain <- cur$S - nw$S
          step <- max(abs(new - lognl))
          lognl <- new
          cur <- nw
          moved <- TRUE
          lambda <- max(lambda / 3, 1e-12)
          break
        }
      }
      lambda <- lambda * 4
    }
    # no step lowers the objective (a stationary point within the bounds),
    # or the last one gained less than reltol
    if (!moved || gain <= control$reltol * (abs(cur$S) + control$reltol) || step < 1e-9) {
      converged <- TRUE
      break
    }
  }
  list(lognl = lognl, value = cur$S, evals = evals, converged = converged)
}
