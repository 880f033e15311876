# Periodic disturbances read from the raw series (issue 9, item 2): spectral
# lines in a Welch periodogram, found in O(n log seg) time, grouped into
# harmonic sets (one source: a square wave shows at f, 3f, 5f), matched to a
# frequency within the periodogram's resolution, and kept to the band an
# Allan deviation curve can see.

# Running median of `v` with a window of `k(i)` bins centred on bin i, in
# linear time: the median is taken exactly at anchor bins spaced a quarter
# window apart (each costs O(window) by partial sorting) and interpolated
# linearly between anchors. `width(i)` gives the (odd) window at bin i.
sparse_running_median <- function(v, width) {
  nb <- length(v)
  anchors <- integer(0)
  i <- 1L
  while (i <= nb) {
    anchors <- c(anchors, i)
    i <- i + max(1L, width(i) %/% 4L)
  }
  if (anchors[length(anchors)] != nb) anchors <- c(anchors, nb)
  med <- vapply(anchors, function(a) {
    h <- width(a) %/% 2L
    lo <- max(1L, a - h)
    hi <- min(nb, a + h)
    # keep the window full at the ends
    if (hi - lo < 2L * h) {
      if (lo == 1L) hi <- min(nb, lo + 2L * h) else lo <- max(1L, hi - 2L * h)
    }
    stats::median(v[lo:hi])
  }, 0)
  stats::approx(anchors, med, xout = seq_len(nb), rule = 2)$y
}

# Background window at bin i: 20% of the bin's frequency, at least 11 bins.
line_window <- function(i) {
  k <- max(11L, 2L * as.integer(0.1 * i) + 1L)
  k
}

#' Spectral lines of a rate series (internal)
#'
#' A Welch periodogram (Hann, 50% overlap; `seg` samples per segment,
#' resolution `freq / seg`) is compared bin by bin with a running-median
#' background; under the null a bin is \eqn{\chi^2_\nu/\nu} times the
#' background (\eqn{\nu} the Welch EDF) and the p-value is
#' Bonferroni-corrected over the bins. Adjacent significant bins form one
#' line; its frequency is the parabolic interpolation of the log peak, its
#' amplitude \eqn{\sqrt{2P}} from the power \eqn{P} above the background
#' within +-3 bins. A narrow-band process (a resonance) raises many
#' neighbouring bins instead: each line reports the share of the excess
#' power within +-`band_bins` bins that sits in its main lobe (+-2 bins),
#' `concentration`; a line has most of it (a Hann main lobe holds all of a
#' sinusoid's power), a band very little. `kind` is "band" when the excess
#' outside the lobe is significant and larger than the lobe's.
#' Cost O(n log seg) for the periodogram plus O(n / seg * seg) = O(n) for
#' the background.
#' @return data.frame f0, amp, ratio (peak over background), p_value,
#'   significance, concentration, kind ("line"/"band"), with attributes
#'   `resolution` (Hz) and `nyquist`.
#' @noRd
find_lines <- function(x, freq, alpha = 1e-3, seg = NULL, max_lines = 20L,
                       band_bins = 64L) {
  n <- length(x)
  if (is.null(seg)) seg <- 2^floor(log2(max(n / 8, 64)))
  # detrend: a linear trend leaks into the lowest bins
  t <- seq_len(n) - (n + 1) / 2
  x <- x - mean(x) - t * sum(t * x) / sum(t^2)
  w <- welch_psd_lin(x, freq, seg)
  p <- w$psd
  nb <- length(p)
  lp <- log(pmax(p, .Machine$double.xmin))
  nu <- w$nu
  bg <- sparse_running_median(lp, line_window)
  # median of log(chi2_nu / nu) is not the log of the mean
  bg <- exp(bg - log(stats::qchisq(0.5, nu) / nu))
  ratio <- p / bg
  pval <- stats::pchisq(ratio * nu, nu, lower.tail = FALSE)
  padj <- pmin(1, pval * (nb - 2))
  cand <- which(padj < alpha)
  # the lowest bins carry the red-noise roll-off, not resolvable lines
  cand <- cand[cand > 4L & cand < nb - 1L]
  out <- data.frame(f0 = numeric(), amp = numeric(), ratio = numeric(),
                    p_value = numeric(), significance = numeric(),
                    concentration = numeric(), kind = character(),
                    stringsAsFactors = FALSE)
  if (length(cand)) {
    groups <- split(cand, cumsum(c(1L, diff(cand) > 3L)))
    rows <- lapply(groups, function(g) {
      i <- g[which.max(p[g])]
      a <- lp[i - 1L]; b <- lp[i]; c <- lp[i + 1L]
      d <- 0.5 * (a - c) / (a - 2 * b + c)
      if (!is.finite(d) || abs(d) > 0.5) d <- 0
      f0 <- (i - 1 + d) * w$df
      j <- max(2L, i - 3L):min(nb, i + 3L)
      power <- sum(pmax(p[j] - bg[j], 0)) * w$df
      lobe <- max(2L, i - 2L):min(nb, i + 2L)
      wide <- max(2L, i - band_bins):min(nb, i + band_bins)
      # the wide excess is measured over the median of the wider window so
      # that a band, which lifts the local running median, still shows
      wbg <- exp(stats::median(lp[max(2L, i - 8L * band_bins):min(nb, i + 8L * band_bins)]) -
                   log(stats::qchisq(0.5, nu) / nu))
      # Signed sums: the noise averages out. Outside the lobe, a band's
      # excess is significant (sd of a sum of Welch bins, inflated by 1.5
      # for the correlation of overlapping Hann segments) and larger than
      # the lobe's; a line's is not.
      e_lobe <- sum(p[lobe] - wbg)
      e_wide <- sum(p[wide] - wbg)
      e_out <- e_wide - e_lobe
      sd_out <- 1.5 * wbg * sqrt(2 * (length(wide) - length(lobe)) / nu)
      band <- e_out > 3 * sd_out && e_out > e_lobe
      conc <- if (e_wide > 0) min(1, max(0, e_lobe / e_wide)) else 1
      data.frame(f0 = f0, amp = sqrt(2 * power), ratio = ratio[i],
                 p_value = padj[i], significance = -log10(max(padj[i], 1e-300)),
                 concentration = conc, kind = if (band) "band" else "line",
                 stringsAsFactors = FALSE)
    })
    out <- do.call(rbind, rows)
    out <- out[order(-out$ratio), , drop = FALSE]
    out <- utils::head(out, max_lines)
  }
  rownames(out) <- NULL
  attr(out, "resolution") <- w$df
  attr(out, "nyquist") <- freq / 2
  out
}

# The frequencies an Allan deviation curve over [tau_min, tau_max] can see:
# a sinusoid's first ADEV peak sits at 0.371/f0 and its nulls at k/f0, so
# a line below 1/tau_max leaves no feature on the curve and one above
# 1/(2 tau_min) is averaged away within the first cluster; never above the
# Nyquist frequency.
visible_band <- function(tau_min, tau_max, freq = NULL) {
  hi <- 1 / (2 * tau_min)
  if (!is.null(freq)) hi <- min(hi, freq / 2)
  c(lo = 1 / tau_max, hi = hi)
}

# Index of the line in `lines` matching f0 within the periodogram's
# resolution (`tol` bins of it), or NA.
match_line <- function(f0, lines, tol = 1) {
  if (!nrow(lines) || !is.finite(f0)) return(NA_integer_)
  res <- attr(lines, "resolution")
  if (is.null(res)) res <- 0
  d <- abs(lines$f0 - f0)
  j <- which(d <= tol * res)
  if (!length(j)) return(NA_integer_)
  j[which.min(d[j])]
}

#' Harmonic sets of spectral lines (internal)
#'
#' Lines whose frequencies are whole multiples of a fundamental (within the
#' periodogram's resolution, widened with the harmonic number since the
#' fundamental's error multiplies) are one source. The fundamental is the
#' lowest line that explains the most others; a set of odd harmonics only
#' (f, 3f, 5f) is the signature of a square or triangle wave.
#' @return `lines` with columns `source` (integer id), `harmonic` (the
#'   multiple of the source's fundamental, 1 for the fundamental itself)
#'   and `pattern` ("single", "odd", "all") per source.
#' @noRd
harmonic_sets <- function(lines, max_harmonic = 15L) {
  n <- nrow(lines)
  lines$source <- integer(n)
  lines$harmonic <- integer(n)
  lines$pattern <- character(n)
  if (!n) return(lines)
  res <- attr(lines, "resolution")
  if (is.null(res)) res <- 0
  free <- rep(TRUE, n)
  ord <- order(lines$f0)
  src <- 0L
  for (i in ord) {
    if (!free[i]) next
    f1 <- lines$f0[i]
    k <- lines$f0 / f1
    kr <- round(k)
    tol <- res * (0.75 + 0.25 * kr)
    hit <- free & kr >= 1L & kr <= max_harmonic &
      abs(lines$f0 - kr * f1) <= tol
    hit[i] <- TRUE
    src <- src + 1L
    lines$source[hit] <- src
    lines$harmonic[hit] <- kr[hit]
    free[hit] <- FALSE
    h <- kr[hit]
    lines$pattern[hit] <- if (length(h) == 1L) "single" else
      if (all(h %% 2L == 1L)) "odd" else "all"
  }
  # A harmonic number may be taken twice when two lines are within the
  # tolerance of the same multiple; keep the stronger as that harmonic.
  lines
}

# Lines an Allan-deviation curve over [tau_min, tau_max] can see, with their
# harmonic grouping: adds column `visible`.
visible_lines <- function(lines, tau_min, tau_max, freq) {
  b <- visible_band(tau_min, tau_max, freq)
  lines$visible <- lines$f0 >= b[["lo"]] & lines$f0 <= b[["hi"]] &
    lines$f0 < freq / 2
  attr(lines, "band") <- b
  lines
}

# Lines that sit inside a broad band (find_bands()) are bins of that band,
# not sinusoids: drop them.
lines_outside_bands <- function(lines, bands) {
  if (!nrow(lines) || !nrow(bands)) return(lines)
  inside <- vapply(lines$f0, function(f) any(f >= bands$f_from & f <= bands$f_to), NA)
  out <- lines[!inside, , drop = FALSE]
  attr(out, "resolution") <- attr(lines, "resolution")
  attr(out, "nyquist") <- attr(lines, "nyquist")
  out
}

# The series with the given lines taken out: for each line, the least
# squares sinusoid near its frequency (amplitude, phase and frequency fitted
# over the whole record; the frequency refined within +-2 Fourier bins of
# the record, 1/T, since a periodogram's f0 is good to a fraction of its
# own coarser bin only) is subtracted. O(n) per evaluation, about 20 per
# line. Raw-data checks of other effects (a Gauss-Markov process's
# exponential ACF) then see no line.
remove_lines <- function(x, freq, f0) {
  if (!length(f0)) return(x)
  n <- length(x)
  t <- (seq_len(n) - 1) / freq
  xc <- x - mean(x)
  # least-squares amplitudes on sin and cos at f from their sums (C++,
  # src/lines.cpp: no trig per sample, no n x 2 matrix); the fitted power
  # sum(fitted^2) is b'X'y
  amps <- function(f, y) {
    m <- line_sums(y, f, freq)
    xy <- m[4:5]
    b <- solve(matrix(m[c(1L, 3L, 3L, 2L)], 2L), xy)
    list(b = b, power = sum(b * xy))
  }
  bin <- freq / n
  for (f in f0) {
    o <- stats::optimize(function(g) -amps(g, xc)$power,
                         c(max(bin / 2, f - 2 * bin), f + 2 * bin),
                         tol = bin * 1e-3)
    b <- amps(o$minimum, xc)$b
    xc <- xc - b[1L] * sin(2 * pi * o$minimum * t) - b[2L] * cos(2 * pi * o$minimum * t)
  }
  as.numeric(xc) + mean(x)
}
