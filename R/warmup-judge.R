# The warm-up's judge: a likelihood ratio in which the block means without
# a warm-up and the block means with one each fit their own noise model.
# detect_warmup() finds T with the noise fitted after taking the warm-up
# out (else Gauss-Markov components would explain the warm-up), but that
# fit cannot judge the warm-up: the exponential takes a random walk's
# excursion with it, the walk's variance comes out at half its value or less
# and the excursion looks significant (z of 8 on white noise plus a random
# walk). Under the likelihood ratio the null model keeps its own noise.

# Maximum-likelihood noise model of the block means `y` with the columns
# of `X` (or none) as regressors by GLS: the variances of warmup_noise()'s
# components (random walk and AR(1) at time constants 4^k blocks, as
# ratios to the white, which the likelihood's scale takes), started from
# each model of `starts` (the best start kept). Returns the log-likelihood
# (the first innovation, the diffuse level's, dropped), the model and the
# GLS coefficients.
warmup_ml <- function(y, X, starts) {
  nb <- length(y)
  phis <- exp(-1 / 4^(0:floor(log(nb / 4, 4))))
  Y <- cbind(y, if (!is.null(X)) as.matrix(X))
  storage.mode(Y) <- "double"
  # (src/warmup_ml.cpp: the filter, the GLS and the likelihood in one call)
  fit <- function(th) {
    q <- exp(th[1L])
    s <- exp(th[-1L])
    r <- warmup_gls_ll(Y, q, phis, s)
    rss <- r$rss
    n <- r$n
    # the scale concentrated out: c = rss / n
    list(ll = r$ll, model = list(h = rss / n, q = q * rss / n, phi = phis, s = s * rss / n),
         beta = r$beta)
  }
  nll <- function(th) {
    v <- warmup_gls_ll(Y, exp(th[1L]), phis, exp(th[-1L]))$ll
    if (is.finite(v)) -v else 1e300
  }
  best <- NULL
  for (st in starts) {
    # components a start leaves out enter at 1e-6 of the white (a log
    # scale does not reach 0)
    s0 <- numeric(length(phis))
    j <- match(st$phi, phis)
    s0[j[!is.na(j)]] <- st$s[!is.na(j)]
    th0 <- log(pmax(c(st$q, s0) / st$h, 1e-6))
    o <- stats::optim(th0, nll, method = "L-BFGS-B", lower = -30, upper = 30)
    if (is.null(best) || o$value < best$value) best <- o
  }
  out <- fit(best$par)
  out$par <- best$par
  out
}

# Each exponential of `tcs` judged given the others: z = sqrt of twice
# the log-likelihood it adds (the noise refitted by ML on both sides), and
# whether it explains the block means better than a straight line `ramp`
# in its place. `expo(tc)`: the block means of exp(-t / T); `starts`:
# noise models to start from. The likelihood has local maxima (a slow
# Gauss-Markov or the random walk can take the same wander): every model
# starts from `starts` and from every other model's optimum, in two sweeps,
# so that the null and the alternatives are maximised alike. Returns
# data.frame `amplitude` (y's units, from the fit with every exponential),
# `tc`, `z`, `beats_line`.
warmup_judge <- function(y, tcs, expo, starts, ramp) {
  k <- length(tcs)
  E <- vapply(tcs, expo, numeric(length(y)))
  # the regressors of each model: the null, all exponentials, each
  # exponential's others alone, and the line in each exponential's place
  others <- if (k > 1L) seq_len(k) else integer()
  regs <- c(list(NULL, E), lapply(others, function(i) E[, -i, drop = FALSE]),
            lapply(seq_len(k), function(i) cbind(E[, -i, drop = FALSE], ramp)))
  fits <- vector("list", length(regs))
  tried <- vector("list", length(regs))
  pool <- starts
  for (sweep in 1:2) {
    for (f in seq_along(regs)) {
      new <- setdiff(seq_along(pool), tried[[f]])
      if (!length(new)) next
      r <- warmup_ml(y, regs[[f]], pool[new])
      tried[[f]] <- c(tried[[f]], new)
      if (is.null(fits[[f]]) || r$ll > fits[[f]]$ll) {
        fits[[f]] <- r
        pool[[length(pool) + 1L]] <- r$model
      }
    }
  }
  ll <- vapply(fits, `[[`, 0, "ll")
  full <- fits[[2L]]
  rows <- lapply(seq_len(k), function(i) {
    rest <- ll[if (k > 1L) 2L + i else 1L]
    data.frame(amplitude = full$beta[i], tc = tcs[i],
               z = sqrt(max(0, 2 * (full$ll - rest))),
               beats_line = full$ll > ll[2L + length(others) + i])
  })
  do.call(rbind, rows)
}
