# Non-stationary effects read from the raw series: bias steps, an
# exponential warm-up and isolated spikes. They are not terms of the Allan
# variance model: each is found in the series, reported (where,
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
  # (x itself where the blocks cover it: the same values without a copy)
  .colMeans(if (nb * b == length(x)) x else x[seq_len(nb * b)], b, nb)
}

# Exact block means (nb blocks of b samples, tau0 apart) of exp(-t / tc),
# t from the first sample: a function of tc.
block_expo <- function(nb, b, tau0) {
  dt <- b * tau0
  function(tc) {
    exp(-(seq_len(nb) - 1) * dt / tc) * (1 - exp(-tau0 * b / tc)) /
      (b * (1 - exp(-tau0 / tc)))
  }
}

# Allan differences of y at window w (blocks) for every split point i
# (mean of y[i+1..i+w] minus mean of y[i-w+1..i]), i = w..length(y)-w.
# (`cs`: c(0, cumsum(y)), when the caller has it for several w)
allan_differences <- function(y, w, cs = c(0, cumsum(y))) {
  n <- length(y)
  i <- w:(n - w)
  (cs[i + w + 1L] - 2 * cs[i + 1L] + cs[i - w + 1L]) / w
}

# Robust scale of Allan differences: sqrt(median(D^2) / median(chi2_1)).
# (the median by selection in src/series.cpp; stats::median() where d has a
# NaN or is empty)
robust_d_scale <- function(d) {
  m <- median_of_squares(d)
  if (is.na(m)) m <- stats::median(d^2)
  sqrt(m / stats::qchisq(0.5, 1))
}

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
#' detecting window, the largest within that shorter window of the split,
#' keep its size (mean ratio at least 0.65; a ramp or a
#' slow wander shrinks in proportion to the window, ratios 1/2 and 1/4, and
#' is not a step; its location is set aside and the search goes on). The time is refined to the sample by the split
#' maximising the difference of means over the window, the size is the
#' difference of the means over the window on each side at the scale where
#' the Allan variance is least (the most precise window the noise allows,
#' kept within the neighbouring steps) when the level over it keeps the
#' size read over the detecting window (within 2 combined standard errors),
#' else over the detecting window (a short excursion is read at its own
#' scale, which an added continuous effect does not move). The step is
#' then removed and the search repeated (binary segmentation).
#'
#' Two steps of opposite sign and similar size (ratio 1/3 to 3) less than
#' `pulse_gap` seconds apart are a transient (a pulse or a shock that
#' decays), not two bias steps: they are returned in attribute `pulses`
#' (start, end, size) and left out of the steps. Pairs of two steps found at
#' the record-wide threshold are formed first (sizes unlike: only when the
#' level comes back, pulse_returns()); a step is then paired with a weaker
#' return (step_return()) of similar size only when the level comes back.
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
  cy <- c(0, cumsum(y))
  scale <- vapply(ws, function(w) robust_d_scale(allan_differences(y, w, cy)), 0)
  v <- scale^2 / 2
  wbest <- ws[which.min(v)] * b
  # standard error of a difference of means over W samples on each side:
  # sqrt(2 AV) at W (interpolated in log)
  se_at <- function(W) sqrt(2 * exp(stats::approx(log(ws * b), log(v), log(W), rule = 2)$y))
  idx <- integer(0)
  zs <- numeric(0)
  sizes <- numeric(0)
  wins <- integer(0)
  excluded <- logical(nb)
  rejected <- 0L
  # Each step found is removed by its local size (the difference of the
  # means over a window on each side), not by segment means: under red
  # noise a segment's mean is far from the level next to the step. The
  # window is the least-noisy one (the most precise read), kept within the
  # neighbouring steps, when the level over it keeps the size read over the
  # detecting window (the two reads agree within 2 combined standard
  # errors); else the detecting one. A short excursion read over a longer
  # window is no longer the feature that was detected (on the measured
  # accelerometers excursions of 5-15 s read as steps of 1 standard error),
  # and the least-noisy window moves when an added continuous effect (a
  # Gauss-Markov term) reshapes the Allan variance: the read must not.
  # (lv: the steps' levels, step_levels(); only the 2 W samples read)
  local_size <- function(lv, at, others, Wd) {
    bounds <- sort(c(1L, others, n + 1L))
    left <- max(bounds[bounds <= at - 1L])
    right <- min(bounds[bounds > at])
    read <- function(Wc) {
      W <- max(1L, min(Wc, at - left, right - at))
      xw <- steps_window(x, lv, at - W, at + W - 1L)
      c(size = mean(xw[W + seq_len(W)]) - mean(xw[seq_len(W)]), W = W)
    }
    sd <- read(Wd)
    sb <- read(wbest)
    if (sb[["W"]] == sd[["W"]]) return(sb)
    agree <- abs(sb[["size"]] - sd[["size"]]) <=
      2 * sqrt(se_at(sb[["W"]])^2 + se_at(sd[["W"]])^2)
    if (isTRUE(agree)) sb else sd
  }
  done <- -1L
  for (k in seq_len(max_steps + 20L)) {
    if (length(idx) >= max_steps) break
    # a candidate set aside leaves the steps as they were: the series and
    # its block means are made again only when a step was added
    if (done != length(idx)) {
      lv <- step_levels(data.frame(index = idx, size = sizes), n)
      r <- steps_block_means(x, lv, b, nb)
      cr <- c(0, cumsum(r))            # shared by every window below
      done <- length(idx)
    }
    best <- list(z = 0)
    for (j in seq_along(ws)) {
      # the largest |Allan difference| at window ws[j] outside the excluded
      # splits (src/series.cpp: allan_differences()' arithmetic, the first
      # of equal ones as which.max(), without the vectors)
      m <- steps_largest_difference(cr, ws[j], excluded)
      i <- m[[1L]]
      d <- m[[2L]]
      # a noiseless series (scale 0): any difference at all is a step, at
      # the largest difference
      z <- if (scale[j] > 0) d / scale[j] else if (d == 0) 0 else sign(d) * Inf
      if (abs(z) > abs(best$z)) best <- list(z = z, d = d, i = i + ws[j] - 1L, j = j)
    }
    if (abs(best$z) < zc) break
    w <- ws[best$j]
    # sharp or gradual: the differences over a half and a quarter of the
    # window keep the size of a step (ratios 1, 1) but shrink for a ramp
    # (1/2, 1/4); a step needs their mean ratio >= 0.65. Each is the
    # largest within a shorter window of the split: the split of the long
    # window is loose by a few blocks, and read at it alone the ratios of
    # one measured step went from 0.67, 0.49 (a ramp) to 0.83, 0.64 (a
    # step) when a line far above the block rate moved it by 2 blocks.
    # (Along a ramp the shorter difference is its 1/2 or 1/4 everywhere.)
    iq <- best$i
    ratios <- vapply(c(2L, 4L), function(q) {
      wq <- max(1L, w %/% q)
      lo <- max(wq, iq - wq)
      hi <- min(nb - wq, iq + wq)
      if (lo > hi) return(1)
      max(split_differences(cr, (lo:hi) + 1L, wq) / best$d)
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
    # c(0, cumsum(xs)) at lo - W .. hi + W only
    cs <- steps_prefix(x, lv, lo - W, hi + W)
    cand <- lo:hi
    p <- cand - (lo - W) + 1L           # their places in cs
    dd <- split_differences(cs, p, W)
    at <- cand[which.max(abs(dd))]      # first sample after the step
    if (any(abs(idx - at) < b)) {       # the same step again: set aside
      excluded[max(1L, best$i - w):min(nb, best$i + w)] <- TRUE
      next
    }
    sz <- local_size(lv, at, idx, W)
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
  wins <- wins[o]
  # final sizes, each with the other steps removed
  rows <- lapply(seq_along(idx), function(k) {
    lv <- step_levels(data.frame(index = idx[-k], size = sizes[-k]), n)
    sz <- local_size(lv, idx[k], idx[-k], wins[k])
    W <- sz[["W"]]
    # standard error: sqrt(2 AV) at the window used
    se <- se_at(W)
    data.frame(index = idx[k], time = (idx[k] - 1) * tau0, size = sz[["size"]],
               se = se, z = zs[k], window = W * tau0)
  })
  out <- do.call(rbind, rows)
  # A transient whose return (or onset) is too weak for the record-wide
  # threshold: look for the opposite step within pulse_gap of each step,
  # at the Bonferroni level of that stretch alone.
  ret <- lapply(seq_len(nrow(out)), function(k) {
    step_return(x, out, k, round(pulse_gap * freq), alpha, tau0, ws[1L] * b, se_at)
  })
  ret <- do.call(rbind, ret)
  out$extra <- rep(FALSE, nrow(out))
  if (!is.null(ret) && nrow(ret)) {
    ret <- ret[!duplicated(ret$index) & !ret$index %in% out$index, , drop = FALSE]
    ret$extra <- rep(TRUE, nrow(ret))
    out <- rbind(out, ret)
    out <- out[order(out$index), , drop = FALSE]
  }
  # Opposite-sign pairs close together are transients: first the pairs of
  # two steps each found at the record-wide threshold, then a step no such
  # pair took with a weak return (else a weak return beside a pulse takes
  # one of its steps and leaves the other a lone step).
  pulse <- rep(FALSE, nrow(out))
  prow <- list()
  cs_all <- NULL
  for (weak in c(FALSE, TRUE)) {
    # (the first round sees the supported steps only: a weak return found
    # between them must not keep them apart)
    free <- which(!pulse & (weak | !out$extra))
    k <- 1L
    while (k < length(free)) {
      ia <- free[k]
      ic <- free[k + 1L]
      a <- out[ia, ]
      c2 <- out[ic, ]
      ratio <- abs(c2$size / a$size)
      both <- !(a$extra || c2$extra)
      near <- sign(a$size) != sign(c2$size) && c2$time - a$time < pulse_gap &&
        (both || (weak && !(a$extra && c2$extra)))
      similar <- ratio > 1 / 3 && ratio < 3
      # A weak partner must be of similar size and bring the level back
      # (else a noise dip before a real step would turn the step into a
      # transient). Two supported steps are a pulse when their sizes are
      # similar or, where they are not, when the level comes back: each
      # size is read over the least-noisy window between them, which can
      # be short (an added Gauss-Markov term moves it), and a size ratio
      # of 0.31 split a pulse whose level came back into two steps.
      ok <- near && (similar || both)
      if (ok && !(both && similar)) {
        # c(0, cumsum()) of the series with every step found removed, once
        if (is.null(cs_all)) cs_all <- c(0, cumsum(remove_steps(x, out[c("index", "size")])))
        ok <- pulse_returns(cs_all, a, c2, tau0)
      }
      if (ok) {
        pulse[c(ia, ic)] <- TRUE
        prow[[length(prow) + 1L]] <- data.frame(start = a$time, end = c2$time,
                                                size = a$size)
        k <- k + 2L
      } else {
        k <- k + 1L
      }
    }
  }
  if (length(prow)) {
    prow <- do.call(rbind, prow)
    prow <- prow[order(prow$start), , drop = FALSE]
    rownames(prow) <- NULL
  }
  # a return found below the record-wide threshold counts only as the end
  # of a transient
  steps <- out[!pulse & !out$extra, setdiff(names(out), "extra"), drop = FALSE]
  rownames(steps) <- NULL
  attr(steps, "pulses") <- if (length(prow)) prow else attr(empty, "pulses")
  attr(steps, "rejected") <- rejected
  steps
}

# The difference of the means of the W samples after and the W before
# each split: `cs` a c(0, cumsum()) of the series (or a slice of it), `p`
# the positions in cs of the sums up to each split.
split_differences <- function(cs, p, W) (cs[p + W] - 2 * cs[p] + cs[p - W]) / W

# Does the level come back across a pulse from step `a` to step `c2` (rows
# of detect_steps()' table)? The level after the return less the level
# before the onset (means over the shorter of their windows, the `others`
# steps removed) must be within 3 of the same difference's standard
# deviations at that gap everywhere in the record (robust scale: a few
# pulses do not move it), and nearer the level before than the level
# during the pulse (half the pulse's size, the mean of its two steps'):
# else the level mostly stays and the first is a step. Across a gap the
# difference carries the wander the series has at that lag (a random walk,
# a Gauss-Markov term), which the steps' own errors (adjacent windows) do
# not: the return of a pulse in such noise was refused as not cancelling.
pulse_returns <- function(cs, a, c2, tau0) {
  n <- length(cs) - 1L
  i0 <- a$index
  i1 <- c2$index
  G <- i1 - i0
  W <- as.integer(round(min(a$window, c2$window) / tau0))
  W <- max(1L, min(W, i0 - 1L, n - i1 + 1L))
  if (G < 1L || i0 - W < 1L || i1 + W - 1L > n) return(FALSE)
  # `cs` has every step removed, these two too: their sizes added back
  # (removal is linear in the levels; the others stay removed)
  net <- (cs[i1 + W] - cs[i1]) / W - (cs[i0] - cs[i0 - W]) / W + a$size + c2$size
  # the record's difference at that gap, every W / 8 samples (neighbours
  # closer than that share most of their samples)
  i <- seq.int(W + 1L, n - G - W + 1L, by = max(1L, W %/% 8L))
  if (length(i) < 64L) return(FALSE)
  sc <- robust_d_scale((cs[i + G + W] - cs[i + G]) / W - (cs[i] - cs[i - W]) / W)
  is.finite(sc) && abs(net) <= 3 * sc && abs(net) <= abs(a$size - c2$size) / 4
}

# detect_steps() of a series within one series pass (detect_series()
# opens and closes it): the steps and the transients both read it, and
# where no step was found they read it of the same series (then the
# second is the first's result; identical() input, identical output).
series_pass_memo <- new.env(parent = emptyenv())
series_pass_open <- function() {
  series_pass_memo$open <- TRUE
  series_pass_memo$steps <- NULL
}
series_pass_close <- function() {
  series_pass_memo$open <- FALSE
  series_pass_memo$steps <- NULL
}
pass_steps <- function(x, freq) {
  m <- series_pass_memo$steps
  if (!is.null(m) && identical(m$freq, freq) && identical(m$x, x)) return(m$result)
  r <- detect_steps(x, freq)
  if (isTRUE(series_pass_memo$open)) {
    series_pass_memo$steps <- list(x = x, freq = freq, result = r)
  }
  r
}

# The step of opposite sign within `gap` samples after (or before) step k
# of `steps`, the other steps removed: at windows (octaves) from half the
# step's own (that window at most gap / 4, the search's least `W_min`
# samples at least) up to gap / 4, the split maximising the
# opposite difference of means over the window on each side, never
# reaching across step k; kept when its z (over sqrt(2 AV) at the window,
# `se_at()`) exceeds the Bonferroni threshold over that stretch and those
# windows (at least 3). NULL when there is none. (From the step's own
# window up, a return closer than it, or any return of a step whose size
# was read over a window longer than the gap, had no window that could see
# it: an added Gauss-Markov term that moved the windows turned a transient
# into a lone step. From a quarter of it, noise returns of a bias step in
# white noise made it a transient three times as often: 12 in 400, 4.)
step_return <- function(x, steps, k, gap, alpha, tau0, W_min, se_at) {
  n <- length(x)
  at <- steps$index[k]
  if (!is.finite(steps$se[k]) || steps$se[k] <= 0) return(NULL)
  W_top <- max(1L, gap %/% 4L)
  W0 <- min(max(1L, as.integer(round(steps$window[k] / tau0))), W_top)
  W1 <- max(as.integer(W_min), W0 %/% 2L, 1L)
  Ws <- unique(pmin(W1 * 2L^(0:12), max(W1, W_top)))
  lv <- step_levels(steps[-k, c("index", "size"), drop = FALSE], n)
  # c(0, cumsum(xs)) only where the windows below read it (every
  # candidate lies within max(gap, W) of the step)
  reach <- max(gap, max(Ws)) + max(Ws)
  c0 <- max(1L, at - reach)
  cs <- steps_prefix(x, lv, c0, min(n + 1L, at + reach))
  best <- NULL
  M <- 0
  for (W in Ws) {
    cand <- c(max(1L, at - gap):(at - W), (at + W):min(n, at + gap))
    cand <- cand[cand >= W + 1L & cand <= n - W + 1L & abs(cand - at) >= W]
    if (!length(cand)) next
    M <- M + length(cand) / W
    p <- cand - c0 + 1L
    d <- split_differences(cs, p, W)
    se <- se_at(W)
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
  n <- length(x)
  lv <- step_levels(steps, n)
  if (is.null(lv$at)) return(x - lv$shift)
  x - rep.int(lv$level, diff(c(1L, lv$at, n + 1L)))
}

# What remove_steps() subtracts: the sizes summed at their indices, then
# their cumulative sum (cumsum() of the sparse jumps only: the zeros
# between them add nothing, so the levels are those of the cumsum() of the
# full jump series) held constant from each index on: `at` (sorted step
# indices) and `level` (length(at) + 1 values, the first 0). Indices that
# are not samples: `shift`, the full jump series' cumsum, as before.
step_levels <- function(steps, n) {
  at <- sort(unique(steps$index))
  if (any(at < 1 | at > n | at != floor(at))) {
    jump <- numeric(n)
    for (k in seq_len(nrow(steps))) {
      i <- steps$index[k]
      jump[i] <- jump[i] + steps$size[k]
    }
    return(list(shift = cumsum(jump)))
  }
  jump <- numeric(length(at))
  for (k in seq_len(nrow(steps))) {
    i <- match(steps$index[k], at)
    jump[i] <- jump[i] + steps$size[k]
  }
  list(at = as.integer(at), level = c(0, cumsum(jump)))
}

# x with the steps of `lv` (step_levels()) removed, read in place: samples
# from..to, block means (block_avg()), c(0, cumsum())[lo:hi]. The same
# values as from remove_steps()' copy (src/series.cpp), without the copy.
steps_window <- function(x, lv, from, to) {
  i <- from:to
  if (is.null(lv$at)) return(x[i] - lv$shift[i])
  x[i] - lv$level[findInterval(i, lv$at) + 1L]
}
steps_block_means <- function(x, lv, b, nb) {
  if (is.null(lv$at)) return(block_avg(x - lv$shift, b))
  shifted_block_means(x, lv$at, lv$level, max(1L, as.integer(b)), nb)
}
steps_prefix <- function(x, lv, lo, hi) {
  if (is.null(lv$at)) return(c(0, cumsum(x - lv$shift))[lo:hi])
  shifted_prefix(x, lv$at, lv$level, lo, hi)
}

# The level at which the warm-up's likelihood names one; steps beside a
# warm-up are judged at the same level.
warmup_z_level <- 5

#' Exponential warm-up (internal)
#'
#' A warm-up is a decaying offset at the start, y = c + A exp(-t / T). It
#' is estimated by generalised least squares on about `target_blocks`
#' block means with the series' own noise model: white noise at the block
#' scale, a random walk and Gauss-Markov components on a fixed grid of time
#' constants (a flicker floor or the bumps of a real sensor), their
#' variances fitted by NNLS to the Allan variance of the block means
#' (`warmup_noise()`; the sensor's filter and quantization are inside a
#' block and count as white). The Kalman filter of that model (level
#' diffuse: the intercept c) whitens the block means and the exponential of
#' every T on a log grid from 2 blocks to 40% of the record in one pass; T
#' maximises the profile likelihood, refined by a parabola in log T. The
#' noise model is fitted again with the warm-up found taken out (else its
#' Gauss-Markov components would explain the warm-up) until T settles.
#' The profile's z (the GLS estimate of A over its standard error) only
#' screens: its noise was fitted with the warm-up out, which takes a random
#' walk's variance with it. The warm-up is judged by warmup_judge(): z =
#' sqrt(2 log LR), the block means with and without the exponential each
#' fitting their own noise model by maximum likelihood; present when z
#' exceeds `z_level`. A second exponential (an added warm-up on an axis
#' that has one of its own) is looked for with the first in the
#' regression, judged given the first, and kept when it also passes and
#' the time constants are at least a factor 2 apart. An exponential is kept
#' only when it explains the block means better than a straight line (a
#' rate ramp) in its place (by likelihood, each fitting its noise), and
#' when its time constant lies inside the grid (a profile still rising at
#' 40% of the record is a random walk's wander). `amplitude`: the GLS
#' amplitude under the judge's noise model.
#' @return list `present`, `amplitude` (rate unit, the offset at t = 0),
#'   `tc` (s), `z`, `level` (the settled level c; `NA` from the GLS
#'   fit), and `all`: a data.frame (`amplitude`, `tc`, `z`, `tc_lower`,
#'   `tc_upper`: the 95% interval of tc, warmup_tc_interval()) of every
#'   exponential found (none, one or two), strongest first.
#' @noRd
detect_warmup <- function(x, freq, z_level = warmup_z_level, target_blocks = 1000L,
                          min_tc = NULL, max_iter = 4L) {
  n <- length(x)
  tau0 <- 1 / freq
  b <- max(1L, n %/% target_blocks)
  y <- block_avg(x, b)
  nb <- length(y)
  dt <- b * tau0
  # fitted in units of the largest block mean: the GLS's variances would
  # overflow for values beyond about 1e150 (amplitudes scaled back below)
  s <- max(abs(y))
  if (!is.finite(s) || s == 0) s <- 1
  y <- y / s
  none <- list(present = FALSE, amplitude = 0, tc = NA_real_, z = 0,
               level = mean(x),
               all = data.frame(amplitude = numeric(), tc = numeric(), z = numeric(),
                                tc_lower = numeric(), tc_upper = numeric()))
  if (is.null(min_tc)) min_tc <- 2 * dt
  max_tc <- 0.4 * nb * dt
  # a constant series has no warm-up (and no noise to judge one by)
  if (max_tc <= min_tc || nb < 64L || max(x) == min(x)) return(none)
  grid <- exp(seq(log(min_tc), log(max_tc), by = 0.07))
  expo <- block_expo(nb, b, tau0)
  X <- vapply(grid, expo, numeric(nb))
  fixed <- NULL                      # regressors already found
  found <- data.frame(amplitude = numeric(), tc = numeric(), z = numeric())
  for (round in 1:2) {
    tc <- NA_real_
    clean <- y
    if (!is.null(fixed)) clean <- y - fixed$X %*% fixed$A
    for (it in seq_len(max_iter)) {
      model <- warmup_noise(clean, dt)
      # after the first pass, only the grid near the current T
      near <- if (is.finite(tc)) which(abs(log(grid / tc)) <= 0.6) else seq_along(grid)
      prof <- warmup_profile(y, X[, near, drop = FALSE], grid[near], model, fixed$X)
      tc_new <- prof$tc
      done <- is.finite(tc) && abs(log(tc_new / tc)) < 0.02
      tc <- tc_new
      # take the warm-up (and any found before) out before fitting the noise again
      clean <- y - prof$fitted
      if (done) break
    }
    if (!is.finite(prof$z) || abs(prof$z) <= z_level) break
    if (nrow(found) && abs(log(tc / found$tc[1L])) < log(2)) break
    found <- rbind(found, data.frame(amplitude = prof$A, tc = tc, z = abs(prof$z)))
    if (nrow(found) == 2L) {
      # each again given the other, alternately (the first was found with
      # the second left in)
      for (pass in 1:3) {
        for (i in 1:2) {
          o <- 3L - i
          near <- which(abs(log(grid / found$tc[i])) <= 1)
          pi <- warmup_profile(y, X[, near, drop = FALSE], grid[near], model,
                               matrix(expo(found$tc[o]), nb))
          if (!is.finite(pi$z) || abs(log(pi$tc / found$tc[o])) < log(2)) next
          found[i, ] <- data.frame(amplitude = pi$A, tc = pi$tc, z = abs(pi$z))
          found$amplitude[o] <- pi$A_fixed
        }
      }
      break
    }
    fixed <- list(X = matrix(expo(tc), nb), A = prof$A)
  }
  # The profile's z rests on noise fitted with the warm-up out (optimistic:
  # it screens). The judge is the likelihood ratio with the noise refitted
  # on both sides (warmup_judge()), each exponential given the others; one
  # that fails leaves the rest judged again without it.
  # A rate ramp (the catalogue's R) is a straight line in the rate, and a
  # slow exponential over a record fits much of a line (or of a random
  # walk's drift): an exponential is a warm-up only when it explains the
  # block means better than a straight line in its place, beside the other
  # exponential found. Both have one free amplitude; a long warm-up's
  # curvature makes its own fit the better one.
  # A profile still rising at the longest time constant the grid allows
  # (40% of the record) resolves no decay: a random walk's wander over
  # the record, not a warm-up (a warm-up of up to 30% peaks inside).
  lr_z <- 0
  if (nrow(found)) {
    ramp <- matrix(seq(-1, 1, length.out = nb), nb)
    starts <- list(warmup_noise(y, dt), model)
    found <- found[found$tc < grid[length(grid)] * (1 - 1e-9), , drop = FALSE]
    while (nrow(found)) {
      j <- warmup_judge(y, found$tc, expo, starts, ramp)
      lr_z <- max(j$z)
      ok <- j$z > z_level & j$beats_line
      if (all(ok)) {
        found <- j[, c("amplitude", "tc", "z")]
        break
      }
      found <- found[ok, , drop = FALSE]
    }
  }
  if (!nrow(found)) {
    none$z <- if (lr_z > 0) lr_z else if (exists("prof")) abs(prof$z) else 0
    none$tc <- if (exists("prof")) prof$tc else NA_real_
    none$amplitude <- if (exists("prof")) prof$A * s else 0
    return(none)
  }
  found$amplitude <- found$amplitude * s
  ci <- warmup_tc_interval(y, found$tc, expo, starts)
  found$tc_lower <- ci[1L, ]
  found$tc_upper <- ci[2L, ]
  found <- found[order(-found$z), , drop = FALSE]
  rownames(found) <- NULL
  list(present = TRUE, amplitude = found$amplitude[1L], tc = found$tc[1L],
       z = found$z[1L], level = NA_real_, all = found)
}

# The 95% interval of each time constant of `tcs` (the others held), by
# the profile likelihood of warmup_ml() (its noise refitted at each point)
# read as a parabola in log T through T e^-h, T and T e^h: a 2 x 2
# matrix, lower and upper by column; NA where the likelihood has no
# curvature there. (The battery's misses of 25-30% on a measured axis and
# a simulated sensor were 2.1 standard errors out.)
warmup_tc_interval <- function(y, tcs, expo, starts, h = 0.15) {
  vapply(seq_along(tcs), function(i) {
    ll <- vapply(c(-h, 0, h), function(d) {
      tc <- tcs
      tc[i] <- tcs[i] * exp(d)
      warmup_ml(y, vapply(tc, expo, numeric(length(y))), starts)$ll
    }, 0)
    a <- (ll[1L] + ll[3L] - 2 * ll[2L]) / (2 * h^2)
    if (!is.finite(a) || a >= 0) return(c(NA_real_, NA_real_))
    top <- (ll[1L] - ll[3L]) / (4 * h * a)        # the parabola's peak, in log T
    half <- stats::qnorm(0.975) / sqrt(-2 * a)
    tcs[i] * exp(top + c(-half, half))
  }, numeric(2))
}

# The block means' noise model for the warm-up's GLS: white (variance h per
# block), a random walk (increment variance q per block) and AR(1)
# components (the block means of Gauss-Markov processes) at time constants
# 4^k blocks, variances by NNLS on the overlapping Allan variance of the
# block means at octave m, each point weighted by its relative precision
# (about sqrt(nb / m)).
warmup_noise <- function(y, dt) {
  nb <- length(y)
  ms <- 2^(0:floor(log2(nb / 4)))
  cs <- c(0, cumsum(y - mean(y)))
  av <- vapply(ms, function(m) {
    i <- seq_len(nb - 2 * m + 1)
    d <- cs[i + 2 * m] - 2 * cs[i + m] + cs[i]
    mean(d^2) / (2 * m^2)
  }, 0)
  tcs <- 4^(0:floor(log(nb / 4, 4)))             # in blocks
  phis <- exp(-1 / tcs)
  # AV at m of an AR(1) of unit variance: (4 V(m) - V(2m)) / (2 m^2), V(n)
  # the variance of the sum of n consecutive values
  V <- function(n, p) n * (1 + p) / (1 - p) - 2 * p * (1 - p^n) / (1 - p)^2
  B <- cbind(1 / ms, (2 * ms^2 + 1) / (6 * ms),
             vapply(phis, function(p) (4 * V(ms, p) - V(2 * ms, p)) / (2 * ms^2),
                    numeric(length(ms))))
  ok <- av > 0
  w <- sqrt(nb / ms[ok]) / av[ok]
  coef <- if (any(ok)) avfit_nnls(B[ok, , drop = FALSE] * w, w * av[ok]) else
    c(stats::var(y), rep(0, ncol(B) - 1L))
  coef <- pmax(as.numeric(coef), 0)
  if (!(coef[1L] > 0)) coef[1L] <- max(av[1L], .Machine$double.eps) * 1e-3
  # A random walk the fit set to 0 still wanders: one realisation's long-m
  # points can lie low, and a model without the walk would read its wander
  # as a slow exponential. The walk is at least what the two longest m
  # leave over the other components.
  top <- utils::tail(which(ok), 2L)
  rest <- as.numeric(B[top, -2L, drop = FALSE] %*% coef[-2L])
  coef[2L] <- max(coef[2L], (av[top] - rest) / B[top, 2L], 0)
  keep <- which(coef[-(1:2)] > 0)
  list(h = coef[1L], q = coef[2L], phi = phis[keep], s = coef[-(1:2)][keep],
       dt = dt)
}

# Standardised innovations of the columns of Y under `model`: one Kalman
# filter (the gains do not depend on the data) over a diffuse level (random
# walk of increment variance q: the intercept), AR(1) states and white
# noise h. The first row (the diffuse start) is dropped.
warmup_whiten <- function(Y, model) {
  Y <- as.matrix(Y)
  storage.mode(Y) <- "double"
  # (src/warmup_kalman.h: the filter as the R loop it replaced ran it, and
  # the log-determinant warmup_ml() needs in attribute "logdet")
  warmup_whiten_cpp(Y, model$h, model$q, as.double(model$phi), as.double(model$s))
}

# Profile of the warm-up's time constant: GLS of the block means on each
# column of X (with the columns `fixed`, exponentials found before, in the
# regression), the T of largest explained sum of squares refined by a
# parabola in log T, and its amplitude and z.
warmup_profile <- function(y, X, grid, model, fixed = NULL) {
  E <- warmup_whiten(cbind(y, fixed, X), model)
  ey <- E[, 1L]
  nf <- if (is.null(fixed)) 0L else ncol(fixed)
  ef <- if (nf) E[, 1L + seq_len(nf), drop = FALSE] else NULL
  EX <- E[, -seq_len(1L + nf), drop = FALSE]
  if (nf) {
    # project the fixed regressors out of y and of every candidate
    qf <- qr(ef)
    ey <- qr.resid(qf, ey)
    EX <- qr.resid(qf, EX)
  }
  sxx <- colSums(EX^2)
  sxy <- colSums(EX * ey)
  gain <- ifelse(sxx > 0, sxy^2 / sxx, 0)
  k <- which.max(gain)
  lt <- log(grid[k])
  if (k > 1L && k < length(grid)) {
    g <- gain[(k - 1L):(k + 1L)]
    den <- g[1L] - 2 * g[2L] + g[3L]
    h <- diff(log(grid[1:2]))
    if (den < 0) lt <- lt + h * 0.5 * (g[1L] - g[3L]) / den
  }
  tc <- exp(lt)
  # the refined T's column, interpolated in log T (columns are smooth in T)
  j <- k
  wgt <- 0
  if (lt != log(grid[k])) {
    j <- if (lt > log(grid[k])) k + 1L else k - 1L
    wgt <- (lt - log(grid[k])) / (log(grid[j]) - log(grid[k]))
  }
  ex <- (1 - wgt) * EX[, k] + wgt * EX[, j]
  xt <- (1 - wgt) * X[, k] + wgt * X[, j]
  A <- sum(ex * ey) / sum(ex^2)
  res <- ey - A * ex
  s2 <- sum(res^2) / max(1, length(res) - 2L - nf)
  z <- A * sqrt(sum(ex^2)) / sqrt(max(s2, .Machine$double.eps))
  A_fixed <- numeric(0)
  fitted <- A * xt
  if (nf) {
    A_fixed <- qr.coef(qr(E[, 1L + seq_len(nf), drop = FALSE]), E[, 1L] - A * ex)
    fitted <- fitted + fixed %*% A_fixed
  }
  list(best = k, tc = tc, A = A, z = z, fitted = as.numeric(fitted),
       A_fixed = if (nf) unname(A_fixed[1L]) else NA_real_)
}

# Scale of a residual robust to a few outliers and to coarse quantization
# (where the MAD can be 0): the root mean square of the central 99%
# (values beyond the 0.5% and 99.5% quantiles dropped), corrected to a
# standard deviation for Gaussian data.
robust_scale <- function(r, trim = 0.005) {
  zq <- stats::qnorm(1 - trim)
  # variance of a standard normal truncated to [-zq, zq]
  vt <- 1 - 2 * zq * stats::dnorm(zq) / (1 - 2 * trim)
  # the ranks stats::quantile(type = 1) reads (n p, or the next when n p is
  # not whole), found by selection (src/series.cpp; a sort of 1e6 values
  # and R's copies cost 0.1 s a call); R's own path where r has a NaN or
  # an infinite sum
  n <- length(r)
  np <- n * c(trim, 1 - trim)
  j <- floor(np)
  k <- pmin(pmax(j + (np > j), 1), n)
  v <- if (n) trimmed_mean_square(r, k[1L], k[2L]) else NA_real_
  if (!is.na(v)) return(sqrt(v / vt))
  q <- stats::quantile(r, c(trim, 1 - trim), names = FALSE, type = 1)
  keep <- r[r >= q[1L] & r <= q[2L]]
  sqrt(mean((keep - mean(keep))^2) / vt)
}

#' Isolated spikes (internal)
#'
#' A spike is an additive outlier of the series' own noise model: an
#' AR(`p`) model fitted by Burg to the winsorised series less its slow
#' part (spike_slow_part(); its first 2e5 samples) carries the sensor's
#' filter, its lines (a line near Nyquist is two AR roots) and the colour
#' of the noise, and the additive-outlier
#' statistic (Fox 1972; Chang, Tiao and Chen 1988) of every sample,
#' w = sum_j pi_j e(t + j) / sum pi_j^2 over its standard error (the
#' innovations' robust scale), is compared with the Gaussian Bonferroni
#' level over the record (at least `min_z`), or beyond what the series'
#' own heavy-tailed noise reaches over the record where its body is not
#' Gaussian (spike_tail_level()), moved clear of the candidates' own |z|
#' (stable_level(): a scale moved 2% by an added effect must not move the
#' count); a neighbour of an outlier is
#' a spike only beyond what the outlier lends it (spike_distinct()).
#' Judged on the running median's residual instead, a line near Nyquist of
#' the white noise's amplitude raised the scale 20% and took 85% of the
#' count away. On the measured accelerometers the outliers' sizes are a
#' heavy-tailed continuum (the count above z falls about as z^-7): a scale
#' 2% larger moved about 10% of them below a level inside it, so they are
#' the noise's tail, not spikes; what spikes left in do to N is
#' series_reading_bias()'s.
#' @return data.frame `index`, `time` (s), `value` (the sample), `size`
#'   (its excess over the running median of `k` samples), `z`; attribute
#'   `threshold` (in robust sd).
#' @noRd
detect_spikes <- function(x, freq, alpha = 0.01, k = 7L, min_z = 6, p = 20L,
                          level_margin = 0.03) {
  n <- length(x)
  med <- spike_runmed(x, k)
  r <- x - med
  s <- robust_scale(r)
  empty <- data.frame(index = integer(), time = numeric(), value = numeric(),
                      size = numeric(), z = numeric())
  attr(empty, "threshold") <- Inf
  if (!(s > 0) || n <= 4L * p) return(empty)
  # the model is fitted where the outliers are clipped (4 robust sd from
  # the running median); the statistic reads the series without its slow
  # part (spike_slow_part())
  w <- seq_len(min(n, 200000L))
  slow <- spike_slow_part(x, 50L * p + 1L)
  z <- spike_ao_z(x - slow, med[w] + pmax(pmin(r[w], 4 * s), -4 * s) - slow[w], p)
  if (is.null(z)) return(empty)
  zc <- max(min_z, stats::qnorm(1 - alpha / (2 * n)),
            spike_tail_level(z, alpha))
  # the level moved clear of the candidates (stable_level()), which are
  # looked for down to the least level it can choose
  lo <- zc / (1 + level_margin)
  big <- if (n < .Machine$integer.max) which_abs_above(z, lo) else which(abs(z) > lo)
  zc <- stable_level(z[spike_distinct(z, big, lo, attr(z, "pi"))], zc,
                     margin = level_margin)
  big <- big[abs(z[big]) > zc]
  i <- spike_distinct(z, big, zc, attr(z, "pi"))
  out <- data.frame(index = i, time = (i - 1) / freq, value = x[i], size = r[i],
                    z = z[i])
  attr(out, "threshold") <- zc
  out
}

# The slow part of x: its centred moving mean over L samples (fewer at the
# ends). A spike is judged against the local noise, the AR model's p lags;
# a slow process (a Gauss-Markov drift, a warm-up, a random walk) left in
# reshapes the statistic's body and so the tail level: on a measured
# accelerometer a 20 s GM added moved that level from 10.1 to 9.8 sd and the
# count from 3 to 5, with no sample's z moved by more than 0.5%. Over
# L = 50 p + 1 samples the mean leaves the p lags the model whitens alone,
# and a spike moves it by 1/L of its size.
# (src/series.cpp; in R, cumsum and four index vectors of n cost 0.09 s an
# axis)
spike_slow_part <- function(x, L) centred_moving_mean(as.double(x), as.double(L %/% 2L))

# stats::runmed(x, k, endrule = "median"): the window medians in
# src/series.cpp (runmed's Turlach cost 0.04 s an axis), the ends by
# runmed's own smoothEnds(); runmed itself where x has a NaN or is short.
spike_runmed <- function(x, k) {
  k <- as.integer(k)
  med <- if (length(x) > 2L * k && k %% 2L == 1L) running_median_keep(x, k)
  if (length(med) != length(x)) {
    return(stats::runmed(x, k, endrule = "median", algorithm = "Turlach"))
  }
  med <- stats::smoothEnds(med, k)
  attr(med, "k") <- k
  med
}

# The level the series' own noise reaches over the record: a Student t
# fitted to the body of z, the Bonferroni quantile of it. Its degrees of
# freedom from B = the mean of |z| between its 95% and 99% quantiles
# (by rank) over z's robust scale (robust_scale()): 2.20 for Gaussian z.
# Means over ranks, not quantiles: quantization of 1-2 steps to the sd
# makes |z| coarse (its median 20% off). Outliers in the top 1% leave B
# alone (with the band at 99-99.9%, 200 outliers of 15 sd in 1e5 samples
# read as a heavy tail and went unnamed). The measured accelerometers' AO
# statistics have heavy tails throughout (their 99% quantile of |z| over
# its median 3.98-4.46, Gaussian 3.82; counts beyond 4, 5 and 6 sd fall
# about as z^-6.5): a level inside that continuum moved the count 4-14%
# when the scale moved 2%; beyond it (7-12.5 sd there) the count is a few
# and moves by at most 2. 0 where the body is Gaussian or the record short
# (< 1e4 values).
spike_tail_level <- function(z, alpha) {
  z <- drop_zeros(z)                 # z[z != 0] (src/series.cpp)
  n <- length(z)
  if (n < 1e4) return(0)
  S <- robust_scale(z)
  if (!(S > 0)) return(0)
  # the ranks 95-99% of |z| in order: a selection places that band, which
  # alone is then sorted (src/series.cpp; a full sort of 1e6 cost 0.17 s an
  # axis, R's partial sort and copies 0.05 s)
  lo <- ceiling(0.95 * n)
  hi <- floor(0.99 * n)
  B <- abs_rank_band_mean(z, lo, hi)
  if (is.na(B)) B <- mean(sort(sort(abs(z), partial = c(lo, hi))[seq.int(lo, hi)]))
  B <- B / S
  tab <- spike_t_table()
  if (B <= tab$B[length(tab$B)]) return(0)  # Gaussian or lighter
  lnu <- stats::approx(tab$B, log(tab$nu), B, rule = 2)$y
  k <- stats::approx(log(tab$nu), tab$S, lnu)$y
  S / k * stats::qt(1 - alpha / (2 * n), exp(lnu))
}

# B and the robust scale S of a unit Student t (spike_tail_level()) on a
# grid of degrees of freedom, decreasing in B; computed once a session.
spike_t_table <- function() {
  if (!is.null(spike_t_cache$tab)) return(spike_t_cache$tab)
  zq <- stats::qnorm(0.995)
  vt <- 1 - 2 * zq * stats::dnorm(zq) / 0.99  # as robust_scale()
  nu <- exp(seq(log(2.5), log(1e4), length.out = 60L))
  v <- vapply(nu, function(d) {
    c0 <- stats::qt(0.975, d)
    c1 <- stats::qt(0.995, d)
    s2 <- 2 * stats::integrate(function(t) t^2 * stats::dt(t, d), 0, c1)$value / 0.99
    band <- 2 * stats::integrate(function(t) t * stats::dt(t, d), c0, c1)$value / 0.04
    c(band / sqrt(s2 / vt), sqrt(s2 / vt))
  }, numeric(2))
  spike_t_cache$tab <- list(nu = nu, B = v[1L, ], S = v[2L, ])
  spike_t_cache$tab
}
spike_t_cache <- new.env(parent = emptyenv())

# The additive-outlier z of every sample of x under an AR(p) model fitted
# by Burg to `xw` (the winsorised start); 0 within 2 p of the ends, where
# the statistic lacks its neighbours. NULL when the innovations have no
# scale.
spike_ao_z <- function(x, xw, p = 20L) {
  n <- length(x)
  # scaled by a power of two (exact): the filters' squares of data near
  # 1e300 overflow
  top <- max(abs(xw))
  if (!is.finite(top) || !(top > 0)) return(NULL)
  sc <- 2^floor(log2(top))
  xw <- xw / sc
  mu <- mean(xw)
  # Burg's AR(p) as ar.burg(aic = FALSE, demean = FALSE) gives it, numeric(0)
  # where ar.burg() stops, and the filters as stats::filter(sides = 1)
  # computes them (src/series.cpp: the same operations in their order)
  ar <- spike_burg(xw - mu, p)
  if (!all(is.finite(ar))) ar <- numeric(0)
  pi <- c(1, -ar)
  p <- length(pi) - 1L
  ew <- ar_filter(xw - mu, pi, FALSE)
  se <- robust_scale(ew[-seq_len(p)])
  if (!isTRUE(se > 0)) return(NULL)
  # innovations e(t) = pi(B) x, then sum_j pi_j e(t + j) (the filter run
  # backwards); where the model has an order, in one C++ pass (the same
  # operations without five n-value temporaries)
  denom <- sqrt(sum(pi^2)) * se
  if (p >= 1L && n > 4L * p) {
    a <- spike_ao_values(x, sc, mu, pi, denom)
  } else {
    x <- x / sc
    e <- ar_filter(x - mu, pi, FALSE)
    e[seq_len(p)] <- 0
    a <- ar_filter(e, pi, TRUE)
    a[is.na(a)] <- 0
    a[c(seq_len(2L * p), seq.int(max(1L, n - 2L * p + 1L), n))] <- 0
    a <- a / denom
  }
  attr(a, "pi") <- pi                 # (structure() copied the 1e6 values)
  a
}

# An outlier raises its neighbours' statistic too, by its own z times the
# correlation of the two estimates (sum_j pi_j pi_(j+d) / sum pi_j^2 at d
# samples): the candidates `i`, largest first, each kept when its z less
# what the outliers kept before lend it still exceeds zc.
spike_distinct <- function(z, i, zc, pi) {
  if (length(i) < 2L) return(i)
  p <- length(pi) - 1L
  rho <- vapply(0:p, function(d) sum(pi[seq_len(p + 1L - d)] * pi[seq_len(p + 1L - d) + d]), 0) /
    sum(pi^2)
  i <- i[order(-abs(z[i]))]
  keep <- logical(length(i))
  for (k in seq_along(i)) {
    near <- which(keep & abs(i - i[k]) <= p)
    lent <- sum(z[i[near]] * rho[abs(i[near] - i[k]) + 1L])
    keep[k] <- abs(z[i[k]] - lent) > zc
  }
  sort(i[keep])
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
