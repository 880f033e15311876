# Non-stationary effects read from the raw series (issue 9, item 3): bias
# steps, an exponential warm-up and isolated spikes. They are not terms of
# the Allan variance model: each is found in the series, reported (where,
# how large) and corrected in the series only when asked. Every detector is
# O(n) or O(n log n).
#
# Red noise. A random walk or flicker wanders, and a test that assumes
# white noise sees steps everywhere. The step statistic here is the Allan
# difference itself, D = mean(after) - mean(before) over windows of tau on
# each side, whose variance under the stationary null is 2 AV(tau)
# whatever the noise; it is normalised at each scale by a robust estimate
# of that variance (the median of D^2 over the record, which a few steps
# do not move) and compared with a Bonferroni threshold over the
# effectively independent windows. A sinusoid gives a bounded D and cannot
# reach it.

# Means of consecutive blocks of b samples.
block_avg <- function(x, b) {
  b <- as.integer(b)
  if (b <= 1L) return(x)
  nb <- length(x) %/% b
  .colMeans(x[seq_len(nb * b)], b, nb)
}

# Allan differences of y at window w (blocks) for every split point i
# (mean of y[i+1..i+w] minus mean of y[i-w+1..i]), i = w..length(y)-w.
allan_differences <- function(y, w) {
  cs <- c(0, cumsum(y))
  n <- length(y)
  i <- w:(n - w)
  (cs[i + w + 1L] - 2 * cs[i + 1L] + cs[i - w + 1L]) / w
}

# Robust scale of Allan differences: sqrt(median(D^2) / median(chi2_1)).
robust_d_scale <- function(d) sqrt(stats::median(d^2) / stats::qchisq(0.5, 1))

#' Bias steps in a rate series (internal)
#'
#' Multi-scale search on block means (about `target_blocks` blocks): at
#' each window of 2^j blocks (up to 1/64 of the record, so that the robust
#' scale rests on at least 64 independent windows) the Allan differences at
#' every split point are standardised by their robust scale; the largest
#' |z| over scales and splits is a candidate when it exceeds the Bonferroni
#' threshold \eqn{\Phi^{-1}(1 - \alpha / (2M))}, M the number of
#' effectively independent windows (sum over scales of blocks / window),
#' and at least `min_z` (on the measured ADIS16405 records the Gaussian
#' tail gave a dozen candidates at z of 5 to 6 that the plots do not
#' support). A step is sharp: the differences over a half and a quarter of the
#' detecting window keep its size (mean ratio at least 0.65; a ramp or a
#' slow wander shrinks in proportion to the window, ratios 1/2 and 1/4, and
#' is not a step; its location is set aside and the search goes on). The time is refined to the sample by the split
#' maximising the difference of means over the window, the size is the
#' difference of the means over the window on each side at the scale where
#' the Allan variance is least (the most precise window the noise allows,
#' kept within the neighbouring steps). The step is then removed and the
#' search repeated (binary segmentation).
#'
#' Two steps of opposite sign and similar size (ratio 1/3 to 3) less than
#' `pulse_gap` seconds apart are a transient (a pulse or a shock that
#' decays), not two bias steps: they are returned in attribute `pulses`
#' (start, end, size) and left out of the steps.
#' @return data.frame `index` (first sample after the step), `time` (s from
#'   the first sample), `size` (rate unit), `se` (its standard error from
#'   the Allan variance at the window used), `z` (detection statistic),
#'   `window` (s); attributes `pulses` (data.frame `start`, `end` (s),
#'   `size`) and `rejected` (number of candidates that were not sharp).
#' @noRd
detect_steps <- function(x, freq, alpha = 0.01, max_steps = 20L,
                         target_blocks = 20000L, min_window = 4L,
                         pulse_gap = 120, min_z = 6) {
  n <- length(x)
  tau0 <- 1 / freq
  b <- max(1L, n %/% target_blocks)
  y <- block_avg(x, b)
  nb <- length(y)
  empty <- data.frame(index = integer(), time = numeric(), size = numeric(),
                      se = numeric(), z = numeric(), window = numeric())
  attr(empty, "pulses") <- data.frame(start = numeric(), end = numeric(),
                                      size = numeric())
  attr(empty, "rejected") <- 0L
  if (nb < 4L * 64L) return(empty)
  ws <- as.integer(2^(ceiling(log2(min_window)):floor(log2(nb / 64))))
  if (!length(ws)) return(empty)
  M <- sum(nb / ws)
  # On measured records the Gaussian tail is optimistic (transients,
  # changing noise levels): never below min_z.
  zc <- max(min_z, stats::qnorm(1 - alpha / (2 * M)))
  # Null scale at each window, from the series as given (robust to steps).
  scale <- vapply(ws, function(w) robust_d_scale(allan_differences(y, w)), 0)
  v <- scale^2 / 2
  wbest <- ws[which.min(v)] * b
  idx <- integer(0)
  zs <- numeric(0)
  sizes <- numeric(0)
  wins <- integer(0)
  excluded <- logical(nb)
  rejected <- 0L
  # Each step found is removed by its local size (the difference of the
  # means over the least-noisy window on each side), not by segment means:
  # under red noise a segment's mean is far from the level next to the step.
  local_size <- function(xs, at, others) {
    bounds <- sort(c(1L, others, n + 1L))
    left <- max(bounds[bounds <= at - 1L])
    right <- min(bounds[bounds > at])
    W <- max(1L, min(wbest, at - left, right - at))
    c(size = mean(xs[at:(at + W - 1L)]) - mean(xs[(at - W):(at - 1L)]), W = W)
  }
  for (k in seq_len(max_steps + 20L)) {
    if (length(idx) >= max_steps) break
    xs <- remove_steps(x, data.frame(index = idx, size = sizes))
    r <- block_avg(xs, b)
    best <- list(z = 0)
    for (j in seq_along(ws)) {
      d <- allan_differences(r, ws[j])
      d[excluded[ws[j]:(nb - ws[j])]] <- 0
      # a noiseless series (scale 0): any difference at all is a step, at
      # the largest difference
      z <- if (scale[j] > 0) d / scale[j] else ifelse(d == 0, 0, sign(d) * Inf)
      i <- which.max(abs(d))
      if (abs(z[i]) > abs(best$z)) best <- list(z = z[i], d = d[i], i = i + ws[j] - 1L, j = j)
    }
    if (abs(best$z) < zc) break
    w <- ws[best$j]
    # sharp or gradual: the differences over a half and a quarter of the
    # window keep the size of a step (ratios 1, 1) but shrink for a ramp
    # (1/2, 1/4); a step needs their mean ratio >= 0.65
    iq <- best$i
    ratios <- vapply(c(2L, 4L), function(q) {
      wq <- max(1L, w %/% q)
      if (iq < wq || iq + wq > nb) return(1)
      (sum(r[(iq + 1L):(iq + wq)]) - sum(r[(iq - wq + 1L):iq])) / wq / best$d
    }, 0)
    if (mean(ratios) < 0.65) {
      rejected <- rejected + 1L
      excluded[max(1L, best$i - 4L * w):min(nb, best$i + 4L * w)] <- TRUE
      next
    }
    # refine to the sample: split maximising |difference of window means|
    W <- w * b
    lo <- max(W + 1L, (best$i - 1L) * b + 1L)
    hi <- min(n - W + 1L, (best$i + 1L) * b + 1L)
    if (hi < lo) {
      excluded[max(1L, best$i - w):min(nb, best$i + w)] <- TRUE
      next
    }
    cs <- c(0, cumsum(xs))
    cand <- lo:hi
    dd <- (cs[cand + W] - 2 * cs[cand] + cs[cand - W]) / W
    at <- cand[which.max(abs(dd))]      # first sample after the step
    if (any(abs(idx - at) < b)) {       # the same step again: set aside
      excluded[max(1L, best$i - w):min(nb, best$i + w)] <- TRUE
      next
    }
    sz <- local_size(xs, at, idx)
    idx <- c(idx, at)
    zs <- c(zs, best$z)
    sizes <- c(sizes, sz[["size"]])
    wins <- c(wins, W)
  }
  if (!length(idx)) {
    attr(empty, "rejected") <- rejected
    return(empty)
  }
  o <- order(idx)
  idx <- idx[o]
  zs <- zs[o]
  sizes <- sizes[o]
  # final sizes, each with the other steps removed
  rows <- lapply(seq_along(idx), function(k) {
    xs <- remove_steps(x, data.frame(index = idx[-k], size = sizes[-k]))
    sz <- local_size(xs, idx[k], idx[-k])
    W <- sz[["W"]]
    # standard error: sqrt(2 AV) at the window used (interpolated in log)
    se <- sqrt(2 * exp(stats::approx(log(ws * b), log(v), log(W), rule = 2)$y))
    data.frame(index = idx[k], time = (idx[k] - 1) * tau0, size = sz[["size"]],
               se = se, z = zs[k], window = W * tau0)
  })
  out <- do.call(rbind, rows)
  # A transient whose return (or onset) is too weak for the record-wide
  # threshold: look for the opposite step within pulse_gap of each step,
  # at the Bonferroni level of that stretch alone.
  ret <- lapply(seq_len(nrow(out)), function(k) {
    step_return(x, out, k, round(pulse_gap * freq), alpha, tau0)
  })
  ret <- do.call(rbind, ret)
  out$extra <- rep(FALSE, nrow(out))
  if (!is.null(ret) && nrow(ret)) {
    ret <- ret[!duplicated(ret$index) & !ret$index %in% out$index, , drop = FALSE]
    ret$extra <- rep(TRUE, nrow(ret))
    out <- rbind(out, ret)
    out <- out[order(out$index), , drop = FALSE]
  }
  # opposite-sign pairs close together are transients
  pulse <- rep(FALSE, nrow(out))
  prow <- list()
  k <- 1L
  while (k < nrow(out)) {
    a <- out[k, ]
    c2 <- out[k + 1L, ]
    ratio <- abs(c2$size / a$size)
    # a weak partner found only near a strong step must bring the level
    # back: the two sizes cancel within their errors (else a noise dip
    # before a real step would turn the step into a transient)
    cancels <- !(a$extra || c2$extra) ||
      abs(a$size + c2$size) <= 3 * sqrt(a$se^2 + c2$se^2)
    if (sign(a$size) != sign(c2$size) && c2$time - a$time < pulse_gap &&
        !(a$extra && c2$extra) && cancels &&
        ratio > 1 / 3 && ratio < 3) {
      pulse[c(k, k + 1L)] <- TRUE
      prow[[length(prow) + 1L]] <- data.frame(start = a$time, end = c2$time,
                                              size = a$size)
      k <- k + 2L
    } else {
      k <- k + 1L
    }
  }
  # a return found below the record-wide threshold counts only as the end
  # of a transient
  steps <- out[!pulse & !out$extra, setdiff(names(out), "extra"), drop = FALSE]
  rownames(steps) <- NULL
  attr(steps, "pulses") <- if (length(prow)) do.call(rbind, prow) else attr(empty, "pulses")
  attr(steps, "rejected") <- rejected
  steps
}

# The step of opposite sign within `gap` samples after (or before) step k
# of `steps`, the other steps removed: at windows from the step's own up to
# gap / 4 (octaves), the split maximising the opposite difference of means
# over the window on each side, never reaching across step k; kept when its
# z (the step's standard error scaled as white noise to the window) exceeds
# the Bonferroni threshold over that stretch and those windows (at least
# 3). NULL when there is none.
step_return <- function(x, steps, k, gap, alpha, tau0) {
  n <- length(x)
  at <- steps$index[k]
  if (!is.finite(steps$se[k]) || steps$se[k] <= 0) return(NULL)
  W0 <- max(1L, as.integer(round(steps$window[k] / tau0)))
  Ws <- unique(pmin(W0 * 2L^(0:8), max(W0, gap %/% 4L)))
  xs <- remove_steps(x, steps[-k, c("index", "size"), drop = FALSE])
  cs <- c(0, cumsum(xs))
  best <- NULL
  M <- 0
  for (W in Ws) {
    cand <- c(max(1L, at - gap):(at - W), (at + W):min(n, at + gap))
    cand <- cand[cand >= W + 1L & cand <= n - W + 1L & abs(cand - at) >= W]
    if (!length(cand)) next
    M <- M + length(cand) / W
    d <- (cs[cand + W] - 2 * cs[cand] + cs[cand - W]) / W
    se <- steps$se[k] * sqrt(W0 / W)
    z <- -sign(steps$size[k]) * d / se
    j <- which.max(z)
    if (length(j) && is.finite(z[j]) && (is.null(best) || z[j] > best$zo)) {
      best <- list(zo = z[j], i = cand[j], d = d[j], se = se, W = W)
    }
  }
  if (is.null(best)) return(NULL)
  zc <- max(3, stats::qnorm(1 - alpha / (2 * max(1, M))))
  if (!is.finite(best$se) || best$se <= 0 || best$zo < zc) return(NULL)
  data.frame(index = best$i, time = (best$i - 1) * tau0, size = best$d,
             se = best$se, z = best$d / best$se, window = best$W * tau0)
}

# The series with the steps removed: each step's size subtracted from every
# sample after it (the level before the first step is kept).
remove_steps <- function(x, steps) {
  if (!nrow(steps)) return(x)
  adj <- numeric(length(x))
  for (k in seq_len(nrow(steps))) {
    i <- steps$index[k]
    adj[i:length(x)] <- adj[i:length(x)] + steps$size[k]
  }
  x - adj
}

#' Exponential warm-up (internal)
#'
#' A warm-up is a decaying offset at the start, y = c + A exp(-t / T). On a
#' log grid of T (from `min_tc` to a quarter of the record), c and A are
#' fitted by linear least squares to the block means over the first 6 T
#' only (over the whole record a random walk's wander would be read as the
#' exponential), and the amplitude is judged by
#' z = |A| (1 - e^-1)^2 / sqrt(2 AV(T)): the numerator is the Allan
#' difference the exponential makes between the first two windows of
#' length T, the denominator the noise of that difference (the robust Allan
#' variance of the series at T), so red noise is accounted for as in
#' detect_steps(). T is the grid value of largest z, refined by least
#' squares over its window. Present when z exceeds `z_level`.
#' @return list `present`, `amplitude` (rate unit, the offset at t = 0),
#'   `tc` (s), `z`, `level` (the settled level c).
#' @noRd
detect_warmup <- function(x, freq, z_level = 5, target_blocks = 5000L,
                          min_tc = NULL) {
  n <- length(x)
  tau0 <- 1 / freq
  b <- max(1L, n %/% target_blocks)
  y <- block_avg(x, b)
  nb <- length(y)
  dt <- b * tau0
  t <- (seq_len(nb) - 0.5) * dt
  if (is.null(min_tc)) min_tc <- 4 * dt
  max_tc <- n * tau0 / 4
  none <- list(present = FALSE, amplitude = 0, tc = NA_real_, z = 0,
               level = mean(x))
  if (max_tc <= min_tc || nb < 32L) return(none)
  # a constant series has no warm-up (and no noise to judge one by)
  if (max(x) == min(x)) return(none)
  fit_at <- function(tc, span) {
    k <- seq_len(min(nb, max(8L, ceiling(span / dt))))
    X <- cbind(1, exp(-t[k] / tc))
    f <- stats::lm.fit(X, y[k])
    list(A = unname(f$coefficients[2L]), c = unname(f$coefficients[1L]),
         rss = sum(f$residuals^2))
  }
  noise <- function(tc) {
    bw <- max(1L, round(tc / dt))
    d <- if (nb > 2L * bw + 10L) allan_differences(y, bw) else numeric(0)
    if (length(d) > 10L) robust_d_scale(d) else stats::sd(y) * sqrt(2)
  }
  grid <- exp(seq(log(min_tc), log(max_tc), length.out = 60L))
  zg <- vapply(grid, function(tc) {
    abs(fit_at(tc, 6 * tc)$A) * (1 - exp(-1))^2 / noise(tc)
  }, 0)
  tc <- grid[which.max(zg)]
  # least squares over the window 6 T, the window following T (a fixed
  # point within a few passes)
  for (pass in 1:4) {
    span <- 6 * tc
    o <- stats::optimize(function(lt) fit_at(exp(lt), span)$rss,
                         log(tc) + c(-1, 1))
    if (abs(o$minimum - log(tc)) < 0.01) {
      tc <- exp(o$minimum)
      break
    }
    tc <- exp(o$minimum)
  }
  tc <- min(max(tc, min_tc), max_tc)
  f <- fit_at(tc, 6 * tc)
  z <- abs(f$A) * (1 - exp(-1))^2 / noise(tc)
  list(present = is.finite(z) && z > z_level, amplitude = f$A, tc = tc, z = z,
       level = f$c)
}

# Scale of a residual robust to a few outliers and to coarse quantization
# (where the MAD can be 0): the root mean square of the central 99%
# (values beyond the 0.5% and 99.5% quantiles dropped), corrected to a
# standard deviation for Gaussian data.
robust_scale <- function(r, trim = 0.005) {
  q <- stats::quantile(r, c(trim, 1 - trim), names = FALSE, type = 1)
  keep <- r[r >= q[1L] & r <= q[2L]]
  zq <- stats::qnorm(1 - trim)
  # variance of a standard normal truncated to [-zq, zq]
  vt <- 1 - 2 * zq * stats::dnorm(zq) / (1 - 2 * trim)
  sqrt(mean((keep - mean(keep))^2) / vt)
}

#' Isolated spikes (internal)
#'
#' A spike stands out from its neighbours: the residual from a running
#' median of `k` samples is compared with its robust scale, and samples
#' beyond \eqn{\Phi^{-1}(1 - \alpha / (2n))} scales (Bonferroni over the
#' record, at least `min_z`) are spikes. Runs of flagged samples shorter than
#' k/2 are one spike each.
#' @return data.frame `index`, `time` (s), `value` (the sample), `size`
#'   (its excess over the running median), `z`.
#' @noRd
detect_spikes <- function(x, freq, alpha = 0.01, k = 7L, min_z = 6) {
  n <- length(x)
  med <- stats::runmed(x, k, endrule = "median", algorithm = "Turlach")
  r <- x - med
  s <- robust_scale(r)
  zc <- max(min_z, stats::qnorm(1 - alpha / (2 * n)))
  if (!(s > 0)) {
    return(data.frame(index = integer(), time = numeric(), value = numeric(),
                      size = numeric(), z = numeric()))
  }
  z <- r / s
  i <- which(abs(z) > zc)
  data.frame(index = i, time = (i - 1) / freq, value = x[i], size = r[i],
             z = z[i])
}

# The series with spikes replaced by the running median around them.
remove_spikes <- function(x, spikes, k = 7L) {
  if (!nrow(spikes)) return(x)
  x[spikes$index] <- x[spikes$index] - spikes$size
  x
}

# Allan deviation with and without an effect: the relative error an
# uncorrected effect makes at each tau (octave taus of allan()).
adev_before_after <- function(x, corrected, freq) {
  a <- allan(x, freq)
  b <- allan(corrected, freq, taus = a$tau)
  data.frame(tau = a$tau, adev_raw = a$adev, adev_corrected = b$adev,
             change = a$adev / b$adev - 1)
}
