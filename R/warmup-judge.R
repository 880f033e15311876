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

# The steps of `times` (s) judged beside the warm-ups of `tcs` (s) by the
# same likelihood: each step within `reach` time constants of the slowest
# warm-up (where the two trade: a step bends the exponential, and the
# exponential's misfit reads as a step) gets z = sqrt of twice the
# log-likelihood it adds to the block means given the warm-ups and the
# other steps, the noise refitted by maximum likelihood on both sides and
# the slowest warm-up's time constant refitted on both sides; NA beyond the
# reach. The step detector reads windows from a few seconds to minutes;
# the likelihood reads block means of two lengths (1000 and 4000 blocks:
# 10 s and 2.5 s at 1e6 samples of 100 Hz) and a step stands at the
# larger z: a sharp step shows on the fine blocks, a level move the
# detector read over half a minute on the coarse ones. (On a measured
# accelerometer the axis's own level drop at 272 s, z 5.8 to the step
# detector, crossed its threshold once an added warm-up was taken out and
# then bent the warm-up's time constant from 121 s to 95 s: z 3.2 on the
# coarse blocks and 3.1 on the fine. Unit 3 accel_z's own drop at 466 s,
# z 7.5 to the detector with or without an added warm-up: 5.1 and 4.6. A
# simulated step of 11 x ADEV(10 s) at 527 s beside a warm-up of 783 s:
# 4.7 and 6.9. The margins are thin: a level move and a step differ by
# about one unit of z here.)
steps_beside_warmup_z <- function(x, freq, times, tcs, reach = 5,
                                  blocks = c(1000L, 4000L)) {
  z <- rep(NA_real_, length(times))
  near <- which(times < reach * max(tcs))
  if (!length(near) || !length(tcs)) return(z)
  for (nb in blocks) {
    # a finer read only for the steps that do not stand yet
    open <- near[is.na(z[near]) | z[near] <= warmup_z_level]
    if (!length(open)) break
    zb <- steps_lr_z(x, freq, times, tcs, open, nb)
    z[open] <- pmax(z[open], zb[open], na.rm = TRUE)
  }
  z
}

# The likelihood ratio z of each step of `near` on about `target_blocks`
# block means (steps_beside_warmup_z()); NA where the blocks are too few.
steps_lr_z <- function(x, freq, times, tcs, near, target_blocks) {
  z <- rep(NA_real_, length(times))
  tau0 <- 1 / freq
  # (the whole record: the noise model read on the warm-up's span alone,
  # ten time constants, took a measured axis's own step below the level)
  b <- max(1L, length(x) %/% target_blocks)
  y <- block_avg(x, b)
  nb <- length(y)
  if (nb < 64L) return(z)
  dt <- b * tau0
  s <- max(abs(y))
  if (!is.finite(s) || s == 0) return(z)
  y <- y / s
  t_start <- (seq_len(nb) - 1) * dt
  # a step's share of each block (the block holding its edge in part)
  S <- vapply(times, function(t0) pmin(1, pmax(0, (t_start + dt - t0) / dt)), numeric(nb))
  expo <- block_expo(nb, b, tau0)
  slow <- which.max(tcs)
  E_rest <- vapply(tcs[-slow], expo, numeric(nb))
  # each fit starts from the last fit's noise model (neighbouring time
  # constants and regressors: a few iterations instead of a hundred)
  pool <- new.env()
  pool$start <- warmup_noise(y, dt)
  # the log-likelihood with the steps `keep`, the slow time constant refitted
  ll <- function(keep) {
    f <- function(ltc) {
      r <- warmup_ml(y, cbind(expo(exp(ltc)), E_rest, S[, keep, drop = FALSE]),
                     list(pool$start))
      pool$start <- r$model
      r$ll
    }
    lt <- log(tcs[slow])
    stats::optimize(f, c(lt - log(4), lt + log(4)), maximum = TRUE, tol = 0.05)$objective
  }
  all <- seq_along(times)
  l_all <- ll(all)
  for (i in near) z[i] <- sqrt(max(0, 2 * (l_all - ll(all[-i]))))
  z
}
