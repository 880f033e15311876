# The spectrum of a raw rate series, in one place: the Welch periodogram,
# the running-median backgrounds, spectral lines (significant bins, their
# harmonic sets, the band an Allan deviation curve can see, matching within
# the resolution, removal from the series) and broad bands (a resonance's
# bump: detection, fit of the resonance's PSD, removal). Periodic disturbances and
# narrow-band processes are read here for the catalogue's sinusoid,
# resonance and band entries (R/effect-*.R).

# ---- Welch periodogram --------------------------------------------------------

# Welch periodogram (Hann, 50% overlap, segments demeaned), one-sided PSD
# in u^2/Hz, in O(n log seg): the segments' squared transforms summed in
# C++ (welch_sums(), src/evidence.cpp: two real segments per complex
# transform, one pair in memory at a time). `detrend`: take the
# least-squares line out of x first (a linear trend leaks into the lowest
# bins). Default `seg`: an eighth of the record, a power of 2, at least 64.
welch_psd <- function(x, freq, seg = NULL, detrend = TRUE) {
  n <- length(x)
  if (is.null(seg)) seg <- 2^floor(log2(max(n / 8, 64)))
  seg <- as.integer(min(seg, 2^floor(log2(n))))
  x <- if (detrend) detrend_linear(x) else as.double(x)
  hop <- seg %/% 2L
  starts <- seq.int(1L, n - seg + 1L, by = hop)
  win <- 0.5 - 0.5 * cos(2 * pi * (seq_len(seg) - 1) / seg)
  U <- sum(win^2)
  half <- seg %/% 2L + 1L
  acc <- welch_sums(x, starts, win)
  k <- length(starts)
  p <- acc / k / (freq * U)
  p[2:(half - 1L)] <- 2 * p[2:(half - 1L)]
  # Welch EDF for Hann with 50% overlap (Percival & Walden): about 1.89 K
  # for many segments.
  nu <- 2 * k / (1 + 2 * 0.167^2 * (k - 1) / k)
  list(f = (seq_len(half) - 1) * freq / seg, psd = p, nu = nu, seg = seg,
       df = freq / seg, k = k)
}

# The Welch PSD of the centred series, not detrended: what find_bands() and
# measure_band() read (`welch` arguments, so that one avrefine() call makes
# it once: raw_welch()).
centred_welch <- function(x, freq, seg) welch_psd(x - mean(x), freq, seg, detrend = FALSE)

# ---- backgrounds ----------------------------------------------------------------

# Running median of `v` with an odd window `width[i]` centred on each bin
# i, the background of a log periodogram (lines: octave_background();
# bands: spectral_bands()).
# * `exact = TRUE`: every bin's window median, by stats::runmed() over each
#   run of bins sharing a window (the run and two windows either side, so
#   its values are those of a runmed() of the whole vector), with Tukey's
#   end rule (runmed()'s "median") at the vector's ends in O(k log k) by
#   smooth_ends(): O(n log k) in all for windows constant over octaves.
# * `exact = FALSE`: the median exactly at anchor bins a quarter window
#   apart (each by partial sorting, O(window)), linear in between, the
#   window held full against the ends: O(n) in all for a window that grows
#   with every bin, where a run per window would cost O(n k).
running_median <- function(v, width, exact = TRUE) {
  nb <- length(v)
  if (exact) {
    # runmed() takes an odd window shorter than the vector
    width <- pmin(width, 2L * ((nb - 1L) %/% 2L) - 1L)
    out <- rep(NA_real_, nb)
    r <- rle(width)
    his <- cumsum(r$lengths)
    los <- his - r$lengths + 1L
    for (j in seq_along(los)) {
      k <- r$values[j]
      from <- max(1L, los[j] - 2L * k)
      to <- min(nb, his[j] + 2L * k)
      rm <- stats::runmed(v[from:to], k, endrule = "keep")
      rm <- smooth_ends(rm, k, left = from == 1L, right = to == nb)
      out[los[j]:his[j]] <- rm[(los[j]:his[j]) - from + 1L]
    }
    return(out)
  }
  anchors <- integer(0)
  i <- 1L
  while (i <= nb) {
    anchors <- c(anchors, i)
    i <- i + max(1L, width[i] %/% 4L)
  }
  if (anchors[length(anchors)] != nb) anchors <- c(anchors, nb)
  med <- vapply(anchors, function(a) {
    h <- width[a] %/% 2L
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

# Background of a log periodogram for line detection: a running median
# with a window ~20% of the frequency, constant over each octave band of
# bins (at least 11 bins).
octave_background <- function(lp) {
  nb <- length(lp)
  lo <- 2^(findInterval(seq_len(nb), 2^(0:floor(log2(nb)))) - 1L)
  running_median(lp, as.integer(pmax(11, 2 * floor(0.1 * lo) + 1)))
}

# stats::smoothEnds(y, k) (Tukey's end-point rule, the runmed() end rule
# "median") at the chosen ends, in O(k log k) instead of O(k^2): the medians
# of the growing windows y[1:j] (j = 3, 5, ..., k - 2) come from one sort
# and a linked list from which the window's elements are removed, longest
# window first, moving the median pointer by a step or two each time.
smooth_ends <- function(y, k, left = TRUE, right = TRUE) {
  k2 <- as.integer(k) %/% 2L
  n <- length(y)
  if (k2 < 1L) return(y)
  sm <- y
  med3 <- function(a, b, c) sort(c(a, b, c))[2L]
  if (k2 >= 2L) {
    J <- 2L * k2 - 1L
    if (left) sm[2:k2] <- growing_medians(y[seq_len(J)])
    if (right) sm[n - (2:k2) + 1L] <- growing_medians(y[n - seq_len(J) + 1L])
  }
  if (left) sm[1L] <- med3(y[1L], sm[2L], sm[2L] - 2L * (sm[3L] - sm[2L]))
  if (right) sm[n] <- med3(y[n], sm[n - 1L], sm[n - 1L] - 2L * (sm[n - 2L] - sm[n - 1L]))
  sm
}

# Medians of e[1:j] for j = 3, 5, ..., length(e) (odd), in that order.
growing_medians <- function(e) {
  J <- length(e)
  o <- order(e)
  rk <- integer(J)
  rk[o] <- seq_len(J)
  nxt <- c(seq_len(J - 1L) + 1L, NA_integer_)
  prv <- c(NA_integer_, seq_len(J - 1L))
  m <- (J + 1L) %/% 2L
  lower <- m - 1L
  out <- numeric((J - 1L) %/% 2L)
  out[length(out)] <- e[o[m]]
  L <- J
  while (L > 3L) {
    for (x in c(rk[L], rk[L - 1L])) {
      if (x < m) {
        lower <- lower - 1L
      } else if (x == m) {
        if (!is.na(nxt[m])) m <- nxt[m] else {
          m <- prv[m]
          lower <- lower - 1L
        }
      }
      p <- prv[x]
      q <- nxt[x]
      if (!is.na(p)) nxt[p] <- q
      if (!is.na(q)) prv[q] <- p
    }
    L <- L - 2L
    target <- (L - 1L) %/% 2L
    while (lower > target) { m <- prv[m]; lower <- lower - 1L }
    while (lower < target) { m <- nxt[m]; lower <- lower + 1L }
    out[(L - 1L) %/% 2L] <- e[o[m]]
  }
  out
}

# ---- lines ------------------------------------------------------------------------

# The series pass and the loop's raw-data diagnostics read the same record
# one after the other: its lines and their least-squares sinusoids (0.2 s
# of a 1e6-sample axis) are kept for the last record, under everything
# they depend on.
record_store <- new.env(parent = emptyenv())
remember_record <- function(what, key, make) {
  hit <- record_store[[what]]
  if (!is.null(hit) && identical(hit$key, key)) return(hit$value)
  value <- make()
  record_store[[what]] <- list(key = key, value = value)
  value
}

#' Spectral lines of a rate series (internal)
#'
#' A Welch periodogram (Hann, 50% overlap; `seg` samples per segment,
#' resolution `freq / seg`) is compared bin by bin with a running-median
#' background (octave_background()); under the null a bin is
#' \eqn{\chi^2_\nu/\nu} times the background (\eqn{\nu} the Welch EDF)
#' and the p-value is Bonferroni-corrected over the bins. Adjacent
#' significant bins form one line when their highest bin is a peak (no
#' neighbour above it: else they are the flank of red noise rolling off
#' below the bins searched); its frequency is the parabolic
#' interpolation of the log peak, its amplitude \eqn{\sqrt{2P}} from the
#' power \eqn{P} above the background within +-3 bins. A narrow-band
#' process (a resonance) raises many neighbouring bins instead: each line
#' reports the share of the excess power within +-`band_bins` bins that
#' sits in its main lobe (+-2 bins), `concentration`; a line has most of it
#' (a Hann main lobe holds all of a sinusoid's power), a band very little.
#' `kind` is "band" when the excess outside the lobe is significant and
#' larger than the lobe's. The `max_lines` strongest are kept.
#' @return data.frame f0, amp, ratio (peak over background), p_value,
#'   significance, concentration, kind ("line"/"band"), with attributes
#'   `resolution` (Hz) and `nyquist`.
#' @noRd
spectral_lines <- function(x, freq, alpha = 1e-3, seg = NULL, max_lines = 24L,
                           band_bins = 64L) {
  remember_record("lines", list(x, freq, alpha, seg, max_lines, band_bins),
                  function() find_lines(x, freq, alpha, seg, max_lines, band_bins))
}

find_lines <- function(x, freq, alpha, seg, max_lines, band_bins) {
  w <- welch_psd(x, freq, seg)
  p <- w$psd
  nb <- length(p)
  lp <- log(p)
  nu <- w$nu
  # Median of log(chi2_nu/nu) differs from log of the mean.
  bg <- exp(octave_background(lp) - log(stats::qchisq(0.5, nu) / nu))
  ratio <- p / bg
  pval <- stats::pchisq(ratio * nu, nu, lower.tail = FALSE)
  padj <- pmin(1, pval * (nb - 2))
  cand <- which(padj < alpha)
  # The lowest bins carry the red-noise roll-off, not resolvable lines.
  cand <- cand[cand > 4 & cand < nb - 1]
  lines <- data.frame(f0 = numeric(), amp = numeric(), ratio = numeric(),
                      p_value = numeric(), significance = numeric(),
                      concentration = numeric(), kind = character(),
                      stringsAsFactors = FALSE)
  if (length(cand)) {
    groups <- split(cand, cumsum(c(1, diff(cand) > 3)))
    rows <- lapply(groups, function(g) {
      i <- g[which.max(p[g])]
      # A line is a peak of the periodogram: a group whose highest bin has
      # a higher neighbour is the flank of something below the bins
      # searched (a Gauss-Markov corner and a random walk, flat over the
      # first five bins, read as a "line" at the first bin allowed, 2.5 x
      # the falling background, p = 4e-5).
      if (p[i] < p[i - 1L] || p[i] < p[i + 1L]) return(NULL)
      # Parabolic interpolation of the log peak for a sub-bin f0.
      a <- lp[i - 1L]; b <- lp[i]; c <- lp[i + 1L]
      d <- 0.5 * (a - c) / (a - 2 * b + c)
      if (!is.finite(d) || abs(d) > 0.5) d <- 0
      f0 <- (i - 1 + d) * w$df
      j <- max(2L, i - 3L):min(nb, i + 3L)
      power <- sum(pmax(p[j] - bg[j], 0)) * w$df
      sh <- line_shape(p, lp, i, nu, band_bins)
      data.frame(f0 = f0, amp = sqrt(2 * power), ratio = ratio[i],
                 p_value = padj[i], significance = -log10(max(padj[i], 1e-300)),
                 concentration = sh$concentration, kind = sh$kind,
                 stringsAsFactors = FALSE)
    })
    rows <- rows[!vapply(rows, is.null, NA)]
    if (length(rows)) {
      lines <- do.call(rbind, rows)
      lines <- lines[order(-lines$ratio), , drop = FALSE]
      lines <- utils::head(lines, max_lines)
    }
  }
  rownames(lines) <- NULL
  attr(lines, "resolution") <- w$df
  attr(lines, "nyquist") <- freq / 2
  lines
}

# Is the peak at bin i a line or the top of a band? The excess over the
# median of a wide window (a band lifts the local running median, so that
# one is not used) in the main lobe (+-2 bins) against the excess within
# +-band_bins. Signed sums: the noise averages out. Outside the lobe, a
# band's excess is significant (sd of a sum of Welch bins, inflated by 1.5
# for the correlation of overlapping Hann segments) and larger than the
# lobe's; a line's is not.
line_shape <- function(p, lp, i, nu, band_bins) {
  nb <- length(p)
  lobe <- max(2L, i - 2L):min(nb, i + 2L)
  wide <- max(2L, i - band_bins):min(nb, i + band_bins)
  wbg <- exp(stats::median(lp[max(2L, i - 8L * band_bins):min(nb, i + 8L * band_bins)]) -
               log(stats::qchisq(0.5, nu) / nu))
  e_lobe <- sum(p[lobe] - wbg)
  e_wide <- sum(p[wide] - wbg)
  e_out <- e_wide - e_lobe
  sd_out <- 1.5 * wbg * sqrt(2 * (length(wide) - length(lobe)) / nu)
  band <- e_out > 3 * sd_out && e_out > e_lobe
  list(concentration = if (e_wide > 0) min(1, max(0, e_lobe / e_wide)) else 1,
       kind = if (band) "band" else "line")
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
# resolution (`tol` bins of it), or NA: the nearest, or with `pick =
# "strongest"` the one standing highest above its background.
match_line <- function(f0, lines, tol = 1, pick = c("nearest", "strongest")) {
  # (match.arg() cost more than the rest: the callers name a choice)
  if (!(identical(pick, "strongest") || identical(pick, "nearest"))) pick <- match.arg(pick)
  if (!nrow(lines) || !is.finite(f0)) return(NA_integer_)
  res <- attr(lines, "resolution")
  if (is.null(res)) res <- 0
  d <- abs(lines$f0 - f0)
  j <- which(d <= tol * res)
  if (!length(j)) return(NA_integer_)
  if (pick == "strongest") j[which.max(lines$ratio[j])] else j[which.min(d[j])]
}

#' Harmonic sets of spectral lines (internal)
#'
#' Lines whose frequencies are whole multiples of a fundamental (within the
#' periodogram's resolution, widened with the harmonic number since the
#' fundamental's error multiplies, up to 3 bins) are one source, up to
#' the 50th harmonic (a square wave's reach the Nyquist frequency). The fundamental is the
#' lowest line that explains the most others; a set of odd harmonics only
#' (f, 3f, 5f) is the signature of a square or triangle wave.
#' @return `lines` with columns `source` (integer id), `harmonic` (the
#'   multiple of the source's fundamental, 1 for the fundamental itself)
#'   and `pattern` ("single", "odd", "all") per source.
#' @noRd
harmonic_sets <- function(lines, max_harmonic = 50L) {
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
    # at most 3 bins: a square wave's 45th harmonic sits within 0.01 bin of
    # 45 f1, and wider windows would take unrelated lines
    tol <- res * pmin(0.75 + 0.25 * kr, 3)
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

# Lines an Allan-deviation curve over [tau_min, tau_max] can see (the
# sinusoid entry's proposals): adds column `visible`.
visible_lines <- function(lines, tau_min, tau_max, freq) {
  b <- visible_band(tau_min, tau_max, freq)
  lines$visible <- lines$f0 >= b[["lo"]] & lines$f0 <= b[["hi"]] &
    lines$f0 < freq / 2
  attr(lines, "visible_band") <- b
  lines
}

# Lines that sit inside a broad band (find_bands()) are bins of that band,
# not sinusoids: drop them, unless the record's own resolution shows a line
# there on top of the band (find_bands()' attribute "lines").
lines_outside_bands <- function(lines, bands) {
  if (!nrow(lines) || !nrow(bands)) return(lines)
  on_band <- attr(bands, "lines") %||% numeric()
  res <- attr(lines, "resolution") %||% 0
  inside <- vapply(lines$f0, function(f) {
    any(f >= bands$f_from & f <= bands$f_to) && !any(abs(on_band - f) <= 1.5 * res)
  }, NA)
  out <- lines[!inside, , drop = FALSE]
  attr(out, "resolution") <- attr(lines, "resolution")
  attr(out, "nyquist") <- attr(lines, "nyquist")
  out
}

# The broad bands of find_bands(), read again without the lines that sit
# where a band is read (band_reach_lines(): on it, at the record's
# resolution, or in its background): such a line is a sinusoid, and read
# as part of the band, or of its background, it moved the band's fit (an
# 8.97 Hz line on the flank of an accelerometer's 9.8 Hz resonance: FWHM
# 0.9 -> 2.2 Hz, centre 9.69 Hz), so that a resonance or band fitted to it
# took the line's place in the model. `lines`: the raw series' lines
# (avdiagnose()'s); the lines taken out are in attribute "lines" (lines on
# a band, which lines_outside_bands() keeps).
bands_without_lines <- function(x, freq, lines, welch = centred_welch) {
  b <- find_bands(x, freq, welch = welch)
  on <- attr(b, "lines") %||% numeric()
  near <- if (NROW(lines)) band_reach_lines(b, lines_outside_bands(lines, b), freq) else numeric()
  # a line on a band that the raw lines do not list, by find_bands()' own reading
  res <- attr(lines, "resolution") %||% 0
  near <- c(near, on[!vapply(on, function(f) any(abs(near - f) <= 1.5 * res), NA)])
  if (!length(near)) return(b)
  out <- find_bands(remove_lines(x, freq, near), freq)
  # (a band read without a line can grow over it: the line stays a line)
  attr(out, "lines") <- sort(unique(c(near, attr(out, "lines"))))
  out
}

# How far either side of each band of `bands` measure_band() reads its
# background: the band's width, at least 4 Welch bins of width `df`.
band_reach <- function(bands, df) pmax(bands$f_to - bands$f_from, 4 * df)

# Which of the frequencies `f` lie on a band's run of `bands` or within
# `wd` (per band) either side of it.
near_band_runs <- function(bands, f, wd) {
  vapply(f, function(x) any(x >= bands$f_from - wd & x <= bands$f_to + wd), NA)
}

# The frequencies of `lines` (rows with f0; those lines_outside_bands()
# keeps) that sit where a band of `bands` is measured (measure_band(): the
# band and its background either side, band_reach() at Welch segments of
# `seg` samples).
band_reach_lines <- function(bands, lines, freq, seg = 512L) {
  if (!NROW(bands) || !NROW(lines)) return(numeric())
  lines$f0[near_band_runs(bands, lines$f0, band_reach(bands, freq / seg))]
}

# Which of the frequencies `f` lie on a band of `bands` or within twice its
# width (FWHM; at least 4 bins of the bands' resolution) of its run, where
# the band's shape still has a tenth of its peak power or more and the
# curve can trade it for a line's (a line 1 Hz, 1.5 FWHM, from a measured
# accelerometer's 9.84 Hz resonance took its power). Not a broad band's
# whole background reach: a line 5 Hz below such a run is apart from it.
by_band_shape <- function(bands, f) {
  if (!NROW(bands)) return(logical(length(f)))
  near_band_runs(bands, f, pmax(2 * bands$width, 4 * (attr(bands, "resolution") %||% 0)))
}

# The series without the lines of `lines` (the lines part) where a band of
# `bands` is measured (band_reach_lines()), each its least-squares sinusoid
# over the record; `x` itself when there are none.
without_lines_on_bands <- function(x, freq, bands, lines) {
  near <- band_reach_lines(bands, lines, freq)
  if (!length(near)) x else remove_lines(x, freq, near)
}

# The series with the given lines taken out: for each line, the least
# squares sinusoid near its frequency (amplitude, phase and frequency fitted
# over the whole record; the frequency refined within +-2 Fourier bins of
# the record, 1/T, since a periodogram's f0 is good to a fraction of its
# own coarser bin only; to 0.02 bin, where what a frequency error leaves
# is 0.1% of the line's power) is subtracted. One O(n) pass per line (its
# block moments) and one to take it out. Raw-data checks of other effects
# (a Gauss-Markov process's exponential ACF) then see no line.
remove_lines <- function(x, freq, f0) {
  subtract_line_fits(x, freq, record_line_fits(x, freq, f0))
}

# The least-squares sinusoids of remove_lines(), one row per line in the
# order given, each fitted to the series with the lines before it taken
# out: `f0` (as given), `f` (refined), `s`, `c` (the sin and cos
# coefficients) and `amp`. A line that holds one frequency over the whole
# record has all its power in that sinusoid (`amp` is the Welch line's);
# a line whose frequency wanders keeps a fraction of it (0.1-0.65 on the
# ADIS16405 accelerometers' own lines).
#
# Each row depends only on the lines before it, so the fits of the last
# record are kept and a request whose lines begin as the kept ones did
# reuses those rows (the loop asks for the series pass's lines less those
# inside a band, usually the last ones: 0.35 s of a 1e6-sample axis).
record_line_fits <- function(x, freq, f0) {
  hit <- record_store[["fits"]]
  same <- !is.null(hit) && identical(hit$key, list(x, freq))
  done <- NULL
  if (same) {
    k <- common_prefix(hit$value$f0, f0)
    done <- hit$value[seq_len(k), , drop = FALSE]
    rownames(done) <- NULL
    if (k == length(f0)) return(done)
  }
  fits <- fit_lines(x, freq, f0, done)
  # the longer table stays: a shorter request is its prefix again
  if (!same || nrow(fits) >= nrow(hit$value)) {
    record_store[["fits"]] <- list(key = list(x, freq), value = fits)
  }
  fits
}

# How many leading elements `a` and `b` share.
common_prefix <- function(a, b) {
  k <- min(length(a), length(b))
  same <- a[seq_len(k)] == b[seq_len(k)]
  if (all(same)) k else which.min(same) - 1L
}

# `done`: the fits of the first nrow(done) lines of `f0`, made before (by
# this function, on the same series), taken out and kept as they are.
fit_lines <- function(x, freq, f0, done = NULL) {
  fits <- data.frame(f0 = numeric(), f = numeric(), s = numeric(), c = numeric(),
                     amp = numeric())
  if (!length(f0)) return(fits)
  n <- length(x)
  # least-squares amplitudes on sin and cos at f from their sums, the
  # fitted power sum(fitted^2) being b'X'y; the sums near a line from its
  # block moments (C++, src/lines.cpp: one pass over the record per line,
  # then O(n / 800) per frequency tried)
  amps <- function(f, mom) {
    m <- line_sums_near(mom, f)
    xy <- m[4:5]
    b <- solve(matrix(m[c(1L, 3L, 3L, 2L)], 2L), xy)
    list(b = b, power = sum(b * xy))
  }
  bin <- freq / n
  rows <- vector("list", length(f0))
  for (k in seq_len(NROW(done))) rows[[k]] <- done[k, , drop = FALSE]
  # (the lines done taken out again, or found taken out: line_chain())
  same <- NULL
  if (NROW(done)) {
    ch <- line_chain(x, freq, done, x - mean(x))
    xc <- ch$xc
    same <- ch$same
  } else {
    xc <- x - mean(x)
  }
  taken <- NROW(done)
  for (k in seq_along(f0)[seq_along(f0) > NROW(done)]) {
    f <- f0[k]
    mom <- line_moments(xc, f, freq, 2 * bin)
    o <- stats::optimize(function(g) -amps(g, mom)$power,
                         c(max(bin / 2, f - 2 * bin), f + 2 * bin),
                         tol = bin * 0.02)
    b <- amps(o$minimum, mom)$b
    rows[[k]] <- data.frame(f0 = f, f = o$minimum, s = b[1L], c = b[2L],
                            amp = sqrt(sum(b^2)))
    # the next line is fitted with this one out
    if (k < length(f0)) {
      xc <- line_subtract(xc, o$minimum, freq, b[1L], b[2L])
      taken <- k
    }
  }
  out <- do.call(rbind, rows)
  rownames(out) <- NULL
  if (taken > NROW(done)) {
    line_chain_keep(x, freq, out[seq_len(taken), , drop = FALSE], xc, same)
  }
  out
}

# x - mean(x) less the sinusoids (f, s, c) of the rows of `fits`, one by
# one in their order (line_subtract()), as fit_lines() and
# subtract_line_fits() take them out. The last such chain made on a record
# is kept (record_store): the loop's diagnostics take out the lines the
# series pass fitted on the same record, and a chain that begins with the
# kept one goes on from it (the same operations, so the same values).
# `xc`: x - mean(x), as the caller made it (not evaluated when the kept
# chain is used). Returns list(xc, same): `same`, whether the kept chain
# is of this record (for line_chain_keep()).
line_chain <- function(x, freq, fits, xc) {
  hit <- record_store[["chain"]]
  # (one comparison of the record per call: identical() reads 1e6 values
  # one by one unless they are the same object)
  same <- !is.null(hit) && identical(hit$key, list(x, freq))
  k0 <- 0L
  if (same) {
    j <- length(hit$fits$f)
    if (j <= nrow(fits) && identical(hit$fits$f, fits$f[seq_len(j)]) &&
        identical(hit$fits$s, fits$s[seq_len(j)]) &&
        identical(hit$fits$c, fits$c[seq_len(j)])) {
      xc <- hit$xc
      k0 <- j
    }
  }
  for (k in seq_len(nrow(fits))[seq_len(nrow(fits)) > k0]) {
    xc <- line_subtract(xc, fits$f[k], freq, fits$s[k], fits$c[k])
  }
  if (nrow(fits) > k0) line_chain_keep(x, freq, fits, xc, same)
  list(xc = xc, same = same)
}

# Keep the chain `fits` -> `xc` of record x; `same`: whether the kept one
# is of this record (NULL: not known). A shorter chain on the same record
# (a subset of its lines) does not replace a longer one.
line_chain_keep <- function(x, freq, fits, xc, same = NULL) {
  hit <- record_store[["chain"]]
  if (is.null(same)) same <- !is.null(hit) && identical(hit$key, list(x, freq))
  if (same && length(hit$fits$f) > nrow(fits)) return(invisible(NULL))
  record_store[["chain"]] <- list(key = list(x, freq),
                                  fits = list(f = fits$f, s = fits$s, c = fits$c),
                                  xc = xc)
  invisible(NULL)
}

# A line is sharp (one frequency over the whole record) when its
# least-squares sinusoid over the record holds at least this share of the
# Welch line's amplitude: 0.99-1.06 for a square wave's harmonics,
# 0.1-0.65 for the ADIS16405 accelerometers' own lines, whose frequency
# wanders.
line_sharp_share <- 0.8
# Which lines are sharp, from their record and Welch amplitudes (FALSE
# where the record's is unknown).
is_sharp <- function(record_amp, amp) {
  !is.na(record_amp) & record_amp >= line_sharp_share * amp
}

# The series less its sharp lines, for the detectors of steps, transients,
# spikes and warm-up: a periodic component is none of those, and what it
# leaves in window means is noise to them (a 0.48 Hz line moved a step's
# read size by 26% and its time by 1 s). A wandering line is left in: a
# single sinusoid takes out a part of it only.
without_sharp_lines <- function(x, freq) {
  lines <- spectral_lines(x, freq)
  if (!nrow(lines)) return(x)
  fits <- record_line_fits(x, freq, lines$f0)
  sharp <- is_sharp(fits$amp, lines$amp)
  if (!any(sharp)) return(x)
  subtract_line_fits(x, freq, fits[sharp, , drop = FALSE])
}

# `x` less the sinusoids of record_line_fits() (its mean kept).
subtract_line_fits <- function(x, freq, fits) {
  if (!nrow(fits)) return(x)
  # xc - s sin(2 pi f t) - c cos(2 pi f t), t = (0..n-1) / freq (C++),
  # line by line (line_chain())
  xc <- line_chain(x, freq, fits, x - mean(x))$xc
  as.numeric(xc) + mean(x)
}

# ---- the record's own resolution ---------------------------------------------------

# One-sided periodogram (u^2/Hz) of the whole record: resolution 1/T, the
# finest the data have. A Blackman-Harris (4-term) taper keeps a line's
# power in its main lobe (+-4 bins) with side lobes 92 dB down, so however
# strong a line is, its power does not leak into the bins around it.
# Zero-padded to a power of two (record_fft_size()); `res` is the record's
# resolution freq / n, `df` the bin spacing.
record_periodogram <- function(x, freq) {
  n <- length(x)
  tp <- record_taper(n)
  w <- tp$w
  np <- record_fft_size(n)
  X <- real_fft_cpp(detrend_linear(x) * w, np)
  half <- length(X)
  # Mod(X)^2 / (freq * w2), bins 2..half - 1 doubled (C++, src/bands.cpp)
  p <- bin_power_cpp(X, freq * tp$w2, FALSE)
  list(f = (seq_len(half) - 1) * freq / np, psd = p, df = freq / np,
       res = freq / n, lobe = ceiling(4 * np / n) + 1L)
}

# The transforms of a whole record (record_periodogram(), remove_bands())
# run on it zero-padded to a power of two, two samples per complex point,
# by the package's FFT (src/real_fft.cpp: 1e6 points in about half
# the time of R's fft(), which is also quadratic in a large prime factor).
record_fft_size <- function(n) 2^max(2, ceiling(log2(n)))

# The taper of record_periodogram() for n samples and its sum of squares.
# Its cosines cost more than the record's FFT, and the loop reads records
# of one length axis after axis: the last length's taper is kept.
taper_store <- new.env(parent = emptyenv())
record_taper <- function(n) {
  if (!identical(taper_store$n, n)) {
    k <- 2 * pi * (seq_len(n) - 1) / n
    w <- 0.35875 - 0.48829 * cos(k) + 0.14128 * cos(2 * k) - 0.01168 * cos(3 * k)
    taper_store$w <- w
    taper_store$w2 <- sum(w^2)
    taper_store$n <- n
  }
  list(w = taper_store$w, w2 = taper_store$w2)
}

# What a peak region [f_lo, f_hi] of a coarser spectrum holds at the
# record's own resolution (`rp`, record_periodogram()): lines, a band, or
# both. Lines: bins standing above the local running median (101 bins; a
# bin is exponential about its mean, whose median is log 2 of it) beyond
# the exponential tail at false-alarm rate `alpha` over the region, in
# groups no wider than the taper's main lobe. Band: the excess over `bg`
# (the background PSD, a function of f) outside the lines' lobes is
# significant (5 sd of a sum of bins whose taper correlates them over its
# 2-bin noise bandwidth) and at least a tenth of the lines' excess (else it
# may be the lines' own shoulder or an error of the background), or, when
# `far` (Hz) is given, significant by itself beyond `far` of every line,
# where no line's shoulder reaches (a measured accelerometer's band, 9% of
# a strong line's power 0.7 Hz beside it, stood 11-18 sd out there and was
# lost). Returns list(lines = frequencies, line_power, band = logical,
# band_power, rest_ratio = the excess outside the lines' lobes over the
# background there).
record_peak_shape <- function(rp, f_lo, f_hi, bg, alpha = 1e-3, far = NULL) {
  nb <- length(rp$psd)
  i_lo <- max(2L, floor(f_lo / rp$df) + 1L)
  i_hi <- min(nb - 1L, ceiling(f_hi / rp$df) + 1L)
  none <- list(lines = numeric(), line_power = numeric(), band = TRUE,
               band_power = NA_real_, rest_ratio = NA_real_)
  if (i_hi - i_lo < 4L) return(none)
  h <- 50L
  ext <- max(1L, i_lo - h):min(nb, i_hi + h)
  p <- rp$psd[ext]
  loc <- stats::runmed(p, 2L * h + 1L, endrule = "median") / log(2)
  reg <- (i_lo:i_hi) - ext[1L] + 1L
  thr <- log(length(reg) / alpha)
  hot <- reg[p[reg] > thr * loc[reg]]
  lines <- numeric()
  lpow <- numeric()
  lobe <- rp$lobe
  masked <- rep(FALSE, length(p))
  b <- bg(rp$f[ext])
  if (length(hot)) {
    groups <- split(hot, cumsum(c(1, diff(hot) > 2L)))
    for (g in groups) {
      if (diff(range(g)) > 2L * lobe) next       # wider than a line: band bins
      i <- g[which.max(p[g])]
      a <- log(p[i - 1L]); c <- log(p[i + 1L]); m <- log(p[i])
      d <- 0.5 * (a - c) / (a - 2 * m + c)
      if (!is.finite(d) || abs(d) > 0.5) d <- 0
      lines <- c(lines, rp$f[ext[i]] + d * rp$df)
      j <- max(1L, min(g) - lobe):min(length(p), max(g) + lobe)
      lpow <- c(lpow, sum(pmax(p[j] - b[j], 0)) * rp$df)
      masked[j] <- TRUE
    }
  }
  rest <- reg[!masked[reg]]
  if (!length(lines)) return(none)
  e_rest <- sum(p[rest] - b[rest])
  significant <- function(k) length(k) > 0L && sum(p[k] - b[k]) > 5 * sqrt(2 * sum(b[k]^2))
  beyond <- if (is.null(far)) integer()
    else rest[rowSums(abs(outer(rp$f[ext[rest]], lines, "-")) <= far) == 0]
  band <- significant(rest) && (e_rest * rp$df > 0.1 * sum(lpow) || significant(beyond))
  list(lines = lines, line_power = lpow, band = band,
       band_power = max(e_rest, 0) * rp$df,
       rest_ratio = if (length(rest)) e_rest / sum(b[rest]) else NA_real_)
}

# Does a Welch run (bins `j`) that holds the record's lines `lines` still
# stand out over the background `bg` (the bins' test `stands_out`, at least
# `min_bins` in a row) once those lines are taken out of `x`? Lines at
# 1.89-5.04 Hz (a sawtooth's harmonics on a measured accelerometer) made
# a run of 1.56-5.27 Hz, and the spectrum between them stood 4.4% above
# the background read across the run: 6 sd over its 38818 bins, but within
# that background's own error (its flanks stood 1-15% above it), and no
# run without the lines.
line_free_run <- function(x, freq, seg, lines, j, bg, stands_out, min_bins) {
  p <- centred_welch(remove_lines(x, freq, lines), freq, seg)$psd
  r <- rle(stands_out(p[j] / bg[j]))
  any(r$values & r$lengths >= min_bins)
}

# ---- bands ------------------------------------------------------------------------

#' Spectral bands of a rate series (internal)
#'
#' Narrow-band processes found at a coarse resolution (`seg` samples per
#' Welch segment, default 512). Pass 1: bins standing above a wide (about
#' an octave) running-median background significantly (the Welch
#' estimate's chi-square with its EDF, false-alarm rate `alpha` over the
#' bins searched), in contiguous runs of at least `min_bins` bins. Pass 2: those runs, widened by their own width on each side, are
#' masked and the background is re-read from the bins around them (a band
#' lifts the median of its own window). Each band is then described by the
#' resonance model fitted to the excess over the background by least
#' squares (relative to the background): centre `f_center`, `tc` (its
#' FWHM is about 1/(pi tc), given as `width`), `power` (its variance,
#' sigma^2) and `share` of the series' variance. A run none of whose bins
#' stands out at that rate over the background re-read beside the fits
#' plus the other bands' fitted PSD is dropped. A run that two resonances
#' fit better but that stays one (their centres closer than the sum of
#' their widths) with the excess dipping between them also carries the two (`pair_fr1`, `pair_tc1`,
#' `pair_power1`, `pair_fr2`, ...; NA otherwise).
#' Cost O(n log seg).
#' @noRd
find_bands <- function(x, freq, seg = 512L, min_bins = 3L, alpha = 1e-3,
                       welch = centred_welch) {
  n <- length(x)
  tau0 <- 1 / freq
  seg <- as.integer(min(seg, 2^floor(log2(n / 8))))
  w <- welch(x, freq, seg)
  p <- w$psd
  nb <- length(p)
  lp <- log(pmax(p, .Machine$double.xmin))
  corr <- log(stats::qchisq(0.5, w$nu) / w$nu)
  octave <- function(i) 2L * as.integer(pmax(8, 0.35 * i)) + 1L
  edge <- octave(1L) %/% 2L + 1L
  # bins whose ratio to a background is significant against the Welch
  # estimate's chi-square (EDF nu), with a false-alarm rate alpha over the
  # nb bins searched (Bonferroni); no fixed power ratio (a weak band over a
  # long record is still a band)
  stands_out <- function(ratio) {
    ratio > 1 & stats::pchisq(ratio * w$nu, w$nu, lower.tail = FALSE) * nb < alpha
  }
  runs <- function(bg) {
    ratio <- p / bg
    hot <- stands_out(ratio)
    # only where the background window is centred: at the low end it slides
    # up in frequency and under-reads a falling spectrum (RW, GM, roll-off)
    hot[seq_len(min(nb, edge))] <- FALSE
    # one band is one run: a gap between hot runs shorter than min_bins, or
    # than a quarter of the wider neighbour (a broad band's tail broken up
    # by the noise), is closed, so one band is not fitted as two
    r <- rle(hot)
    nr <- length(r$values)
    nbr <- pmax(c(0L, r$lengths[-nr]), c(r$lengths[-1L], 0L))
    gap <- !r$values & (r$lengths < min_bins | 4L * r$lengths < nbr) &
      seq_len(nr) > 1L & seq_len(nr) < nr
    r$values[gap] <- TRUE
    r <- rle(inverse.rle(r))
    ends <- cumsum(r$lengths)
    starts <- ends - r$lengths + 1L
    keep <- which(r$values & r$lengths >= min_bins)
    list(from = starts[keep], to = ends[keep], ratio = ratio)
  }
  bg <- exp(running_median(lp, octave(seq_len(nb)), exact = FALSE) - corr)
  r1 <- runs(bg)
  if (length(r1$from)) {
    mask <- rep(FALSE, nb)
    for (k in seq_along(r1$from)) {
      wd <- r1$to[k] - r1$from[k] + 1L
      mask[max(1L, r1$from[k] - wd):min(nb, r1$to[k] + wd)] <- TRUE
    }
    keep <- which(!mask)
    if (length(keep) > 10L) {
      bg2 <- exp(running_median(lp[keep], octave(seq_along(keep)), exact = FALSE) - corr)
      bg <- exp(stats::approx(keep, log(bg2), xout = seq_len(nb), rule = 2)$y)
    }
  }
  r2 <- split_valleys(runs(bg), p, bg, w$nu, min_bins)
  # A run may be a line (or a few) that the coarse segments smear over
  # several bins: at the record's own resolution a line stays within the
  # taper's lobe and a band does not. Runs holding lines only are not
  # bands; the lines found on top of a band are kept as lines. A run the
  # lines made must also stand out without them (line_free_run()).
  on_band <- list()
  if (length(r2$from)) {
    rp <- record_periodogram(x, freq)
    lbg <- log(bg)
    bgf <- function(f) exp(stats::approx(w$f, lbg, xout = f, rule = 2)$y)
    keep <- logical(length(r2$from))
    on <- numeric()
    for (k in seq_along(r2$from)) {
      sh <- record_peak_shape(rp, w$f[r2$from[k]] - w$df, w$f[r2$to[k]] + w$df,
                              bgf, alpha, far = w$df)
      if (sh$band && length(sh$lines)) {
        sh$band <- line_free_run(x, freq, seg, sh$lines, r2$from[k]:r2$to[k], bg,
                                 stands_out, min_bins)
      }
      keep[k] <- sh$band
      if (sh$band) on_band[[length(on_band) + 1L]] <- sh$lines
      if (sh$band && isTRUE(sum(sh$line_power) > sh$band_power)) on <- c(on, sh$lines)
    }
    r2$from <- r2$from[keep]
    r2$to <- r2$to[keep]
    # A band under lines that carry more power than it does is measured
    # without them: fitted with their power, it is centred on the line (a
    # 2.05 Hz line over a run that also held a sensor's wandering 1.6-1.7
    # Hz lines: FWHM 0.22 Hz, 5% of the variance, the line's power; it
    # backed a resonance of tc 2620 s, a pure tone, in the line's place).
    # Weaker lines stay in the band's measure (a square wave's harmonics on
    # a resonance, which the loop does not add one by one).
    if (length(on)) {
      w <- welch(remove_lines(x, freq, on), freq, seg)
      p <- w$psd
    }
  }
  total <- stats::var(x)
  make_regs <- function(r2) lapply(seq_along(r2$from), function(k) {
    j <- r2$from[k]:r2$to[k]
    wd <- length(j)
    # the fit region stops short of the neighbouring bands (else a weak
    # band's fit slides onto a strong neighbour)
    lo <- if (k > 1L) r2$to[k - 1L] + 1L else 2L
    hi <- if (k < length(r2$from)) r2$from[k + 1L] - 1L else nb
    list(j = j, reg = max(2L, lo, r2$from[k] - 2L * wd):min(nb, hi, r2$to[k] + 2L * wd))
  })
  regs <- make_regs(r2)
  # a fit whose centre leaves its run has slid onto a neighbour
  in_run <- function(ft, g) ft$fr >= w$f[g$j[1L]] && ft$fr <= w$f[g$j[length(g$j)]]
  # the one-sided PSD of fitted bands on the Welch grid
  fitted_psd <- function(fs) {
    M <- 0
    for (ft in fs) M <- M + 2 * resonance_psd(w$f, tau0, ft$sigma, ft$fr, ft$tc)
    M
  }
  fits <- lapply(regs, function(g) {
    ex <- pmax(p[g$j] - bg[g$j], 0)
    fc <- sum(w$f[g$j] * ex) / sum(ex)
    sdf <- sqrt(sum((w$f[g$j] - fc)^2 * ex) / sum(ex))
    ft <- fit_resonance_psd(w$f[g$reg], p[g$reg] - bg[g$reg], bg[g$reg], tau0,
                            fc, sum(ex) * w$df, max(sdf, w$df))
    # (a 4 Hz band's onto a 0.54 Hz line in the fit region: centre -0.52
    # Hz); the run's moments describe the band instead
    if (in_run(ft, g)) ft else
      list(sigma = sqrt(sum(ex) * w$df), fr = fc, tc = 1 / (2 * pi * max(sdf, w$df)))
  })
  # The background's running median still holds the bands' skirts (a
  # resonance's PSD falls as f^-4 away from f_r and lifts the whole
  # spectrum by a few percent), and where pass 2's mask reaches 0 Hz it is
  # extended flat from above the band (under a falling spectrum, too low):
  # the fits took part of each band for background, or background for
  # band (power 6-16% low on the battery's simulated bands, 27% high on a
  # band added to unit 1 gyro_x). Twice: the background re-read from the
  # spectrum with the fitted bands taken off, masking only the runs
  # themselves (the flanks and skirts are in the fitted PSD), and the bands
  # refitted on it from their fits.
  reread <- function() {
    if (!length(fits)) return()
    mask <- rep(FALSE, nb)
    for (k in seq_along(r2$from)) mask[r2$from[k]:r2$to[k]] <- TRUE
    keep <- which(!mask)
    for (it in seq_len(if (length(keep) > 10L) 2L else 0L)) {
      M <- fitted_psd(fits)
      lq <- log(pmax(p - M, .Machine$double.xmin))
      bg2 <- exp(running_median(lq[keep], octave(seq_along(keep)), exact = FALSE) - corr)
      bg <<- exp(stats::approx(keep, log(bg2), xout = seq_len(nb), rule = 2)$y)
      # a refit whose centre leaves its run (a weak run beside a strong
      # band sliding onto the other's flank) keeps its fit
      fits <<- lapply(seq_along(regs), function(k) {
        g <- regs[[k]]
        ft <- fit_resonance_psd(w$f[g$reg], p[g$reg] - bg[g$reg], bg[g$reg], tau0, start = fits[[k]])
        if (in_run(ft, g)) ft else fits[[k]]
      })
    }
  }
  reread()
  # Two bands whose flanks meet with no valley split_valleys() could cut
  # (a 10 Hz resonance of 0.85 x the background on the skirt of a 7.1 Hz
  # band of 4.5 x: one run of 1.8-10.7 Hz, one band fitted at 7.1 Hz, the
  # resonance lost) are two when two resonances fit the run's excess
  # better than one beyond the false-alarm level and are distinct: further
  # apart than the sum of their widths (closer, they make one bump on the
  # Allan curve, which a measured band of the whole run describes; a 22 Hz
  # band split from a z gyro's own 20 Hz one left two pieces the loop
  # could not add one by one), each wider than a Welch bin (the measured
  # axes' own bands, not of the AR(2) shape, fit two overlapping resonances
  # better too) and each side's peak a quarter above the background plus
  # the other's fitted PSD (as the skirt check below: the background under
  # a broad run is read to 10-20%; a strong band added to a measured gyro
  # left a second "resonance" on its flank standing 10-19% above, 1.8 x as
  # wide; a weaker one narrower than the stronger, which that error cannot
  # make, need only clear the false-alarm level: an accelerometer's own
  # 9.84 Hz resonance stood 19% above a 7.9 Hz band's skirt), the
  # weaker no more than twice as wide as the stronger (a broad excess beside
  # a band is the background's curvature under the run, read by a median
  # interpolated across it: a second-order low-pass's roll-off left one of
  # FWHM 4.7 Hz beside a 15 Hz resonance of 1.2 Hz). The run is cut where
  # the upper one takes over (or a half-width below the upper one's centre
  # when it never does). Judged on the background re-read beside the
  # fits (the first, read with a run and its flanks masked, leaves a strong
  # band's skirts as excess), which is read again beside the split bands.
  # Two such resonances closer than the sum of their widths stay one run
  # (one measured band), but when the excess dips between them the pair is
  # kept with it (`pairs`): the loop may describe the run
  # as two resonances, each measured here (a band added at 8.1 Hz beside
  # an axis's own 9.86 Hz resonance, one run of 3-11.8 Hz: the resonance
  # fitted to the run sat at 8.14 Hz and the curve was left with chi2/dof
  # 25.7).
  n_runs <- length(regs)
  pairs <- vector("list", length(regs))
  k <- 1L
  while (k <= length(regs)) {
    g <- regs[[k]]
    pf <- if (length(g$j) >= 2L * min_bins + 1L) {
      band_pair_fit(g$j, g$reg, fits[[k]], w$f, p, bg, tau0, w$nu)
    }
    wd <- if (!is.null(pf$fits)) vapply(pf$fits, function(ft) 1 / (pi * ft$tc), 0)
    pw <- if (!is.null(pf$fits)) vapply(pf$fits, function(ft) ft$sigma^2, 0)
    # (a weaker one narrower than the stronger need only stand out: see above)
    narrow <- !is.null(wd) && wd[which.min(pw)] < wd[which.max(pw)]
    two <- !is.null(pf) && !is.na(pf$cut) &&
      (if (narrow) stands_out(1 + pf$stand) else pf$stand > 0.25) &&
      wd[which.min(pw)] <= 2 * wd[which.max(pw)] &&
      pf$chi2_one - pf$chi2_two > stats::qchisq(1 - alpha, 3L) &&
      all(wd >= w$df) &&
      pf$cut > min_bins && length(g$j) - pf$cut + 1L >= min_bins
    if (!(two && pf$apart)) {
      if (two && pf$resolved) pairs[k] <- list(pf$fits)
      k <- k + 1L
      next
    }
    at <- g$j[pf$cut]
    r2$from <- append(r2$from, at, after = k)
    r2$to <- append(r2$to, r2$to[k], after = k)
    r2$to[k] <- at - 1L
    fits <- append(fits, pf$fits[2L], after = k)
    fits[[k]] <- pf$fits[[1L]]
    pairs <- append(pairs, list(NULL), after = k)
    ln <- on_band[[k]] %||% numeric()
    on_band <- append(on_band, list(ln[ln >= w$f[at]]), after = k)
    on_band[[k]] <- ln[ln < w$f[at]]
    regs <- make_regs(r2)
    k <- k + 2L
  }
  if (length(regs) > n_runs) reread()
  # A run that holds lines beside a rest read as band power, cut at a
  # valley from a neighbouring run, may hold no band of its own: its rest
  # is the neighbour's skirt, which the running median left out (a 6.1 Hz
  # line on the low skirt of an 11.2 Hz resonance was read as a band of
  # FWHM 0.16 Hz carrying the line's power). It is judged again over the
  # background plus the neighbours' fitted PSD, and must stand above it by
  # more than that background's own error (a quarter: a skirt's slice
  # stood 12-20% above the running median).
  if (length(fits) > 1L) {
    skirt <- vapply(on_band, length, 0L) > 0L
    for (k in which(skirt)) {
      nb_lo <- k > 1L && r2$from[k] - r2$to[k - 1L] <= 2L
      nb_hi <- k < length(fits) && r2$from[k + 1L] - r2$to[k] <= 2L
      # a piece stronger than each neighbour it borders is no skirt of theirs
      # (a 9.9 Hz band cut from a stretch of background 8% high at 7.6 Hz)
      nbr <- c(if (nb_lo) k - 1L, if (nb_hi) k + 1L)
      if (!length(nbr) || fits[[k]]$sigma > max(vapply(fits[nbr], `[[`, 0, "sigma"))) {
        skirt[k] <- FALSE
        next
      }
      lm <- log(bg + fitted_psd(fits[-k]))
      sh <- record_peak_shape(rp, w$f[r2$from[k]] - w$df, w$f[r2$to[k]] + w$df,
                              function(f) exp(stats::approx(w$f, lm, xout = f, rule = 2)$y),
                              alpha)
      skirt[k] <- !isTRUE(sh$band) || !isTRUE(sh$rest_ratio > 0.25)
    }
    if (any(skirt)) {
      r2$from <- r2$from[!skirt]
      r2$to <- r2$to[!skirt]
      regs <- regs[!skirt]
      fits <- fits[!skirt]
      pairs <- pairs[!skirt]
      on_band <- on_band[!skirt]
    }
  }
  # Runs were found against the first background (a running median, and
  # across masked runs an interpolation) and a strong band's skirt can lift
  # a stretch of it above that (a 12.5 Hz "band" beside a 20.8 Hz one of
  # 0.5 x the white sd); judged again over the background re-read beside
  # the fits plus the other bands' fitted PSD, a run none of whose bins
  # stands out at the false-alarm level is no band.
  if (length(fits)) {
    stands <- vapply(seq_along(regs), function(k) {
      j <- regs[[k]]$j
      any(stands_out(p[j] / (bg[j] + if (length(fits) > 1L) fitted_psd(fits[-k])[j] else 0)))
    }, NA)
    if (!all(stands)) {
      r2$from <- r2$from[stands]
      r2$to <- r2$to[stands]
      regs <- make_regs(r2)
      fits <- fits[stands]
      pairs <- pairs[stands]
      on_band <- on_band[stands]
      reread()
    }
  }
  on_band <- unlist(on_band)
  if (is.null(on_band)) on_band <- numeric()
  rows <- lapply(seq_along(regs), function(k) {
    j <- regs[[k]]$j
    fit <- fits[[k]]
    pr <- pairs[[k]]
    pv <- function(i, what) if (is.null(pr)) NA_real_ else pr[[i]][[what]]
    data.frame(f_center = fit$fr, f_from = w$f[j[1L]], f_to = w$f[j[length(j)]],
               width = 1 / (pi * fit$tc), tc = fit$tc, power = fit$sigma^2,
               share = fit$sigma^2 / total, peak_ratio = max(r2$ratio[j]),
               pair_fr1 = pv(1L, "fr"), pair_tc1 = pv(1L, "tc"), pair_power1 = pv(1L, "sigma")^2,
               pair_fr2 = pv(2L, "fr"), pair_tc2 = pv(2L, "tc"), pair_power2 = pv(2L, "sigma")^2)
  })
  out <- if (length(rows)) do.call(rbind, rows) else
    data.frame(f_center = numeric(), f_from = numeric(), f_to = numeric(),
               width = numeric(), tc = numeric(), power = numeric(),
               share = numeric(), peak_ratio = numeric(),
               pair_fr1 = numeric(), pair_tc1 = numeric(), pair_power1 = numeric(),
               pair_fr2 = numeric(), pair_tc2 = numeric(), pair_power2 = numeric())
  attr(out, "resolution") <- w$df
  attr(out, "lines") <- on_band
  out
}

# Two bands side by side make one run of significant bins when their
# flanks meet; where the excess over the background (smoothed over 5 bins)
# has a valley between two peaks that each stand at least half the
# background above it, dropping below half the lower peak by more than 5
# of its standard errors, the run is cut at the valley's deepest bin, each
# side keeping at least `min_bins` bins (a wiggle on one band's flank, or
# an error of the background under it, is not a second band). `r`: runs
# (list(from, to, ratio)), `p`, `bg`: the Welch PSD and its background,
# `nu`: the Welch EDF.
split_valleys <- function(r, p, bg, nu, min_bins) {
  if (!length(r$from)) return(r)
  from <- integer()
  to <- integer()
  for (k in seq_along(r$from)) {
    j <- r$from[k]:r$to[k]
    cuts <- integer()
    if (length(j) >= 2L * min_bins + 1L) {
      ex <- p[j] - bg[j]
      sm <- as.numeric(stats::filter(ex, rep(1 / 5, 5), sides = 2))
      sm[is.na(sm)] <- ex[is.na(sm)]
      # standard error of a 5-bin mean of Welch bins (chi-square with EDF
      # nu; 1.5 for the overlap of the segments)
      se <- 1.5 * bg[j] * sqrt(2 / nu) / sqrt(5)
      pk <- which(vapply(seq_along(sm), function(i) {
        sm[i] == max(sm[max(1L, i - 3L):min(length(sm), i + 3L)])
      }, NA) & sm > 5 * se & sm > 0.5 * bg[j])
      last <- if (length(pk)) pk[1L] else NA_integer_
      for (q in pk[-1L]) {
        v <- last + which.min(sm[last:q]) - 1L
        low <- min(sm[last], sm[q])
        if (sm[v] < 0.5 * low && low - sm[v] > 5 * se[v] &&
            v - max(c(0L, cuts)) > min_bins && length(j) - v >= min_bins) {
          cuts <- c(cuts, v)
          last <- q
        } else if (sm[q] > sm[last]) {
          last <- q
        }
      }
    }
    edges <- c(0L, cuts, length(j))
    for (e in seq_len(length(edges) - 1L)) {
      # the valley bin belongs to neither side
      lo <- edges[e] + 1L
      hi <- if (e < length(edges) - 1L) edges[e + 1L] - 1L else edges[e + 1L]
      from <- c(from, j[lo])
      to <- c(to, j[hi])
    }
  }
  r$from <- from
  r$to <- to
  r
}

# Least-squares fit of the resonance's one-sided PSD (2 x two-sided, the
# AR(2) form of R/resonance.R) to the excess `ex` over a background `bg` at
# frequencies f, relative to the background; starts from the band's
# moments (centre fc, variance power, sd sdf about fc) or from a previous
# fit `start`.
fit_resonance_psd <- function(f, ex, bg, tau0, fc, power, sdf, start = NULL) {
  # sum(((ex - 2 * resonance_psd(f, tau0, exp(q[1L]), q[2L], exp(q[3L]))) /
  # bg)^2) in C++, the same values
  f <- as.double(f)
  obj <- function(q) resonance_fit_obj_cpp(q, f, ex, bg, tau0)
  q0 <- if (is.null(start)) c(log(sqrt(power)), fc, log(1 / (2 * pi * sdf))) else
    c(log(start$sigma), start$fr, log(start$tc))
  o <- stats::optim(q0, obj, control = list(maxit = 500L, reltol = 1e-10))
  list(sigma = exp(o$par[1L]), fr = o$par[2L], tc = exp(o$par[3L]))
}

# Two bands whose flanks meet with no valley deep enough for
# split_valleys() (a weak resonance on a strong band's skirt) are told
# apart by their shape: the excess over the background in region `reg`
# (Welch bins; run `j` within it) is fitted by one resonance (`fit1`) and
# by two, the second started at the largest excess the first leaves in
# the run. The chi-square of each (the bins' scatter (bg + M)^2 / nu,
# inflated 1.5^2 for the overlapping segments) is returned with the two
# fits, the bin of `j` where the second takes over from the first (NA
# unless both centres are in the run), `apart` (the centres further apart
# than the sum of their widths), `resolved` (the excess dips between them)
# and `stand`: how far the weaker side's peak stands
# above the background plus the other's fitted PSD, relative to them.
band_pair_fit <- function(j, reg, fit1, f, p, bg, tau0, nu) {
  one <- function(ft, ff) 2 * resonance_psd(ff, tau0, ft$sigma, ft$fr, ft$tc)
  # a resonance from its log sigma, fr and log tc
  unpack <- function(q) list(sigma = exp(q[1L]), fr = q[2L], tc = exp(q[3L]))
  chi2 <- function(M) sum(((p[reg] - bg[reg] - M) / (bg[reg] + M))^2) * nu / 1.5^2
  M1 <- one(fit1, f[reg])
  out <- list(chi2_one = chi2(M1), chi2_two = NA_real_, cut = NA_integer_)
  res <- p[j] - bg[j] - one(fit1, f[j])
  hw1 <- 1 / (2 * pi * fit1$tc)
  far <- abs(f[j] - fit1$fr) > hw1
  if (!any(far & res > 0)) return(out)
  i2 <- which(far)[which.max(res[far])]
  near <- abs(f[j] - f[j[i2]]) <= hw1
  pow2 <- sum(pmax(res[near], 0)) * (f[2L] - f[1L])
  if (!(pow2 > 0)) return(out)
  ex <- p[reg] - bg[reg]
  model <- function(q) one(unpack(q[1:3]), f[reg]) + one(unpack(q[4:6]), f[reg])
  # sum(((ex - model(q)) / bg[reg])^2) in C++, the same values
  fr <- f[reg]
  bgr <- bg[reg]
  obj <- function(q) resonance_fit_obj_cpp(q, fr, ex, bgr, tau0)
  q0 <- c(log(fit1$sigma), fit1$fr, log(fit1$tc), log(sqrt(pow2)), f[j[i2]], log(fit1$tc))
  o <- stats::optim(q0, obj, control = list(maxit = 2000L, reltol = 1e-10))
  a <- unpack(o$par[1:3])
  b <- unpack(o$par[4:6])
  if (a$fr > b$fr) { t <- a; a <- b; b <- t }
  out$chi2_two <- chi2(model(o$par))
  out$fits <- list(a, b)
  inside <- function(ft) ft$fr >= f[j[1L]] && ft$fr <= f[j[length(j)]]
  if (!inside(a) || !inside(b)) return(out)
  out$apart <- b$fr - a$fr > 1 / (pi * a$tc) + 1 / (pi * b$tc)
  # two peaks: the excess (over 3 bins) dips between the centres to 10%
  # below the lower of its values at them (a skewed band, which two
  # resonances fit better too, falls from its one peak without a dip)
  ex <- p[j] - bg[j]
  sm <- as.numeric(stats::filter(ex, rep(1 / 3, 3), sides = 2))
  sm[is.na(sm)] <- ex[is.na(sm)]
  ia <- which.min(abs(f[j] - a$fr))
  ib <- which.min(abs(f[j] - b$fr))
  out$resolved <- ib - ia >= 2L && min(sm[(ia + 1L):(ib - 1L)]) < 0.9 * min(sm[ia], sm[ib])
  # where the upper one takes over, between the centres
  between <- which(f[j] > a$fr & f[j] < b$fr)
  if (!length(between)) return(out)
  over <- between[one(b, f[j[between]]) >= one(a, f[j[between]])]
  # a weak resonance on a strong one's skirt may never take over: its side
  # starts a half-width below its centre
  if (!length(over)) over <- between[f[j[between]] >= b$fr - 1 / (2 * pi * b$tc)]
  if (!length(over)) return(out)
  out$cut <- over[1L]
  # how far each side's peak stands above the background plus the other's
  # fitted PSD (relative)
  lo <- j[seq_len(out$cut - 1L)]
  hi <- j[out$cut:length(j)]
  stand <- function(i, other) max((p[i] - bg[i] - one(other, f[i])) / (bg[i] + one(other, f[i])))
  out$stand <- min(stand(lo, b), stand(hi, a))
  out
}

# The series with each broad band of find_bands() brought down to its
# background: every FFT bin is scaled by sqrt(B / (B + M(f))), where M is
# the band's fitted resonance PSD (one-sided, the AR(2) form, skirt
# included; no higher than the smoothed spectrum's excess over B) and B(f)
# the background PSD under it (band_background()), so that the expected
# power of each bin becomes the background's. Phases are kept, so the white
# noise and the filter's roll-off under the band stay; only the band's
# excess goes. Used for the raw-data checks of the other effects (the
# filter's short-lag ACF, a Gauss-Markov ACF), which a resonance disturbs.
remove_bands <- function(x, freq, bands) {
  if (is.null(bands) || !nrow(bands)) return(x)
  n <- length(x)
  m <- mean(x)
  tau0 <- 1 / freq
  # zero-padded (record_fft_size()); the pad is filtered and dropped
  np <- record_fft_size(n)
  X <- real_fft_cpp(x - m, np)
  h <- length(X)
  fh <- (seq_len(h) - 1) * freq / np
  # 2 * Mod(X)^2 / (n * freq) (C++, src/bands.cpp)
  Ph <- bin_power_cpp(X, n * freq, TRUE)
  in_run <- rep(FALSE, h)
  for (j in seq_len(nrow(bands))) {
    in_run[bins_between(fh, bands$f_from[j], bands$f_to[j])] <- TRUE
  }
  # the bands' gains multiply; each band's background is read on the
  # series with the bands before it taken out
  G <- 1
  for (k in seq_len(nrow(bands))) {
    b <- bands[k, ]
    M <- 2 * resonance_psd(fh, tau0, sqrt(b$power), b$f_center, b$tc)
    # the power the spectrum shows, Ph * G^2, smoothed over the Welch
    # resolution (freq / 512: a centred running mean, in C++), and
    # the band's fitted PSD no higher than its excess over the background
    # B: a measured band that falls faster than the fitted form (the ADIS
    # z gyros' below 20 Hz) loses no more than it has
    S <- bin_mean_cpp(Ph, G, max(1L, np %/% 512L))
    B <- band_background(fh, b, in_run, S, M)
    if (is.null(B)) {
      warn("no background bins for the band at ", format(signif(b$f_center, 4)),
           " Hz: left in the series", class = "band_kept")
      next
    }
    # G * sqrt(B / (B + pmin(M, pmax(S - B, 0))))
    G <- band_gain_cpp(G, B, M, S)
  }
  if (length(G) == 1L) return(x)
  real_ifft_cpp(X * G, np, n) / np + m
}

# The bins of increasing frequencies `fh` within [lo, hi] (`lo_open`,
# `hi_open`: that end excluded), by binary search: the `fh >= lo & fh <=
# hi` of the whole grid (none for an NA end).
bins_between <- function(fh, lo, hi, lo_open = FALSE, hi_open = FALSE) {
  if (is.na(lo) || is.na(hi)) return(integer(0))
  # the number of bins below v (or at most v): the last bin that is
  below <- function(v, strict) {
    a <- 0L
    b <- length(fh)
    while (a < b) {
      mid <- (a + b + 1L) %/% 2L
      if (if (strict) fh[mid] < v else fh[mid] <= v) a <- mid else b <- mid - 1L
    }
    a
  }
  from <- below(lo, !lo_open) + 1L
  to <- below(hi, hi_open)
  if (from <= to) from:to else integer(0)
}

# The background PSD under band `b` (a row of find_bands()) at every bin
# fh (0..Nyquist), from R = S - pmin(M, S), the smoothed spectrum `S` with
# the band's fitted PSD `M` taken off (read at the bins used only),
# outside every band's run (`other`, logical over fh): its
# medians just below and just above the run (one run width, or 3 fitted
# FWHM if wider, on each side; a median, as a window reaching 0 Hz holds
# the random walk's few huge bins), linear in f between them, flat beyond;
# from one side if the other has no bins (a run reaching 0 Hz or Nyquist,
# the ADIS z gyros' 20 Hz bands at 100 Hz); else the median of all bins
# outside the runs farther than one FWHM. A background that slopes under
# the band (a filter's roll-off) is followed. NULL if no bin or a median <= 0.
band_background <- function(fh, b, other, S, M) {
  w <- max(b$f_to - b$f_from, 3 * b$width)
  # `i`: the bins a side reads before those in a run are dropped
  side <- function(i) {
    i <- i[!other[i]]
    if (!length(i)) return(NULL)
    v <- stats::median(S[i] - pmin(M[i], S[i]))
    if (!is.finite(v) || v <= 0) return(NULL)
    c(f = mean(fh[i]), v = v)
  }
  lo <- side(bins_between(fh, b$f_from - w, b$f_from, hi_open = TRUE))
  hi <- side(bins_between(fh, b$f_to, b$f_to + w, lo_open = TRUE))
  if (is.null(lo) && is.null(hi)) {
    one <- side(which(abs(fh - b$f_center) > b$width))
    if (is.null(one)) return(NULL)
    return(rep(one[["v"]], length(fh)))
  }
  if (is.null(lo) || is.null(hi)) {
    return(rep((if (is.null(lo)) hi else lo)[["v"]], length(fh)))
  }
  stats::approx(c(lo[["f"]], hi[["f"]]), c(lo[["v"]], hi[["v"]]), xout = fh, rule = 2)$y
}
