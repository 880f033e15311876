# The uncertainty of a fit: the covariance of the free parameters from the
# Gauss-Newton information of the standardized log residuals, in the
# reported parameterisation (amplitudes; nonlinear parameters in their own
# units), scaled by max(1, chi2/dof). A fit that weighed correlated points
# as independent gets the sandwich covariance with their correlation: the
# estimate is unchanged, its spread is not (octave points of one record
# share most of their data, and ignoring it gave 95% intervals that
# covered 78-87%).

# Jacobian of ln AV with respect to the free parameters (amplitudes, or c =
# a^2 for amplitudes at 0; nonlinear parameters in their own units).
jacobian_lnav <- function(lay, tau, tau0, plan = model_plan(lay)) {
  values <- stats::setNames(lay$value, lay$name)
  Bm <- plan_basis(plan, tau, tau0, values)
  comp <- basis_components(Bm, plan, values)
  tot <- rowSums(comp)
  free <- which(!lay$fixed)
  Jm <- matrix(0, length(tau), length(free),
               dimnames = list(NULL, lay$name[free]))
  at_zero <- logical(length(free))
  for (k in seq_along(free)) {
    i <- free[k]
    if (lay$role[i] == "amp") {
      a <- lay$value[i]
      b <- Bm[, lay$name[i]]
      if (a > 0) {
        Jm[, k] <- 2 * a * b / tot
      } else {
        Jm[, k] <- b / tot
        at_zero[k] <- TRUE
      }
    } else {
      h <- 1e-5
      # ln AV with this value moved: only its own term's column changes
      j <- which(vapply(plan, function(p) lay$name[i] %in% p$nl, NA))
      p <- plan[[j]]
      moved <- function(v) {
        vals <- values
        vals[i] <- v
        b <- stored_basis(p$entry, tau, tau0, stats::setNames(vals[p$nl], p$nl_param))
        cm <- comp
        cm[, j] <- matrix(b, length(tau)) %*% (vals[p$amp]^2)
        log(rowSums(cm))
      }
      dp <- moved(lay$value[i] * exp(h))
      dm <- moved(lay$value[i] * exp(-h))
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
  # no free parameter (every coefficient fixed): nothing to invert
  if (!length(A)) return(A)
  # a Jacobian that overflowed (taus or AVs near the limits of double,
  # e.g. freq = 1e300): no covariance rather than an error from eigen()
  if (!all(is.finite(A))) return(matrix(NA_real_, nrow(A), ncol(A)))
  e <- eigen((A + t(A)) / 2, symmetric = TRUE)
  d <- e$values
  keep <- d > max(d) * 1e-12
  if (!any(keep)) return(matrix(NA_real_, nrow(A), ncol(A)))
  e$vectors[, keep, drop = FALSE] %*% (t(e$vectors[, keep, drop = FALSE]) / d[keep])
}

# Covariance matrix (all coefficients; fixed ones 0) of a fit with layout
# `lay` at the taus `tau`, whitening W and chi2 per dof `chi2`; `corr`, when
# given, the correlation of the points that a diagonal W left out
# (sandwich: A^-1 J'W R W J A^-1 with A = J'W W J). An
# amplitude at its bound 0 gets sqrt(SE(c)) as its standard error and no
# covariance; a nonlinear parameter of a term whose amplitudes are all 0 is
# not identified (NA).
fit_vcov <- function(lay, tau, tau0, W, chi2, plan = model_plan(lay), corr = NULL) {
  jj <- jacobian_lnav(lay, tau, tau0, plan)
  Js <- -wmul(W, jj$J)
  Ainv <- pinv(crossprod(Js))
  V <- if (is.null(corr)) Ainv else Ainv %*% crossprod(Js, corr %*% Js) %*% Ainv
  V <- V * max(1, if (is.na(chi2)) 1 else chi2)
  vc <- matrix(0, nrow(lay), nrow(lay), dimnames = list(lay$name, lay$name))
  fn <- lay$name[jj$free]
  vfree <- V
  dimnames(vfree) <- list(fn, fn)
  if (any(jj$at_zero)) {
    zn <- fn[jj$at_zero]
    sez <- sqrt(sqrt(pmax(diag(V)[jj$at_zero], 0)))
    vfree[zn, ] <- 0
    vfree[, zn] <- 0
    diag(vfree)[match(zn, fn)] <- sez^2
  }
  vc[fn, fn] <- vfree
  for (i in which(lay$role == "nonlinear" & !lay$fixed)) {
    a <- lay$value[lay$label == lay$label[i] & lay$role == "amp"]
    if (!any(a > 0)) {
      vc[i, ] <- vc[, i] <- NA_real_
    }
  }
  vc
}
