#' Dynamic Allan variance: the Allan deviation over a sliding window
#'
#' Computes an Allan-family deviation in every window of a sliding set, at a
#' common grid of averaging times: a time x tau surface that shows how the
#' noise of a non-stationary sensor or clock changes (warm-up, temperature,
#' a failing part). This is the dynamic Allan variance of Galleani and
#' Tavella (IEEE Trans. UFFC 56(3), 2009), generalised to the estimators of
#' [allan()].
#'
#' @section Estimator:
#' Window \eqn{w} holds the samples `start[w]` to `start[w] + window - 1`
#' (in samples, \eqn{W} of them) and its value at cluster size \eqn{m} is
#' exactly what [allan()] with the same `type` and `input` returns for those
#' samples alone (same terms, same normalisation). Every window has the same
#' number of terms at a given \eqn{m}. The surface is evaluated from running
#' sums: one pass over the record per tau, whatever the window and step
#' (\eqn{O(N)} per tau for the whole surface, not \eqn{O(N W / step)}).
#' The types are those of [allan()] except `"total"`, whose reflected
#' extension depends on each window's ends.
#'
#' @section Defaults:
#' `window` defaults to a tenth of the record, but at least 64 samples (or
#' the whole record when shorter), and `step` to a tenth of the window (at
#' least one sample): about 91 windows. The taus are limited to what a
#' window supports: cluster sizes up to the largest with one term in a
#' window of \eqn{W} samples, as [allan()] does for a record of \eqn{W}
#' samples (e.g. \eqn{\lfloor W/2 \rfloor} for the overlapping type with rate
#' input). The longest of them rest on very few terms; their intervals say
#' so.
#'
#' @section Confidence intervals:
#' Every window has the same length, so the equivalent degrees of freedom
#' (EDF) depend only on the tau and the noise type; they come from Greenhall
#' and Riley's algorithm (PTTI 2003, the one NIST SP 1065 and Stable32 use).
#' Unless `alpha` fixes it, the noise type at each tau is read from the
#' slope \eqn{\mu} of the variance against tau between the neighbouring
#' taus, the median over all windows: \eqn{\alpha = -\mu - 1}, rounded and
#' clamped to \[-2, 2\] (\[-4, 2\] for Hadamard types). One window's own
#' slope is not used: at long tau, from a few degrees of freedom, it
#' misreads the noise type too often to choose an EDF. So where the noise
#' type itself changes over time, the intervals follow the prevailing one.
#' A slope of -2 cannot tell white from flicker phase noise except for the
#' modified type; there the smaller of the two EDFs is used. This is cruder
#' than the lag-1 autocorrelation [allan()] uses (which would cost a pass
#' per window); fix `alpha` when the noise type is known. The interval of
#' the deviation is the chi-square interval at level `conf`, as in
#' [allan()].
#'
#' @param x Numeric vector or `ts` of samples (one series), rate samples with
#'   `input = "rate"`, phase (angle, clock phase) with `input = "integrated"`.
#' @param freq Sampling frequency in Hz. Taken from `x` when it is a `ts`
#'   and `freq` is missing.
#' @param window Length of a window in seconds (rounded to whole samples);
#'   `NULL` for the default (see Defaults).
#' @param step Time between the starts of consecutive windows in seconds
#'   (rounded to whole samples, at least one); `NULL` for the default.
#' @param taus `"octave"` (default), `"decade"`, `"all"`, a whole number of
#'   points per decade, or a numeric vector of tau in seconds (wrap a single
#'   tau in [I()]), as in [allan()], within what a window supports.
#' @param type One of `"overlapping"` (default), `"standard"`, `"modified"`,
#'   `"hadamard"`, `"ohadamard"`.
#' @param input `"rate"` (default) or `"integrated"`.
#' @param conf Confidence level of the intervals, in (0, 1).
#' @param alpha `NULL` (default) to read the noise type at each tau from
#'   the slope of the curves, or a single whole number, the power-law exponent of
#'   the rate (frequency) noise to assume everywhere: 2 white phase, 1
#'   flicker phase, 0 white rate (angle/velocity random walk, white FM), -1
#'   flicker (bias instability), -2 random-walk rate; -3 and -4 for the
#'   Hadamard types only.
#' @return An object of class `allan_dynamic`, a list with `time` (centre of
#'   each window in seconds: the mean of its sample times, counted from the
#'   first sample or from `start(x)` for a ts), `start` (first sample of each
#'   window, 1-based), `tau`, `m`, `n` (terms per window at each tau), the
#'   window x tau matrices `avar`, `adev`, `lower` and `upper` (limits of
#'   `adev`), the per-tau `edf` and `alpha` (the noise exponent behind the
#'   EDF), and
#'   `freq`, `type`, `input`, `N`, `window` and `step` (in samples), `conf`,
#'   `alpha_rule` (`"slope"` or `"fixed"`). Methods: `print()`, `summary()`
#'   (per tau: the range of the deviation over time), `as.data.frame()` (long
#'   form, one row per window and tau) and `plot()` (see
#'   [plot.allan_dynamic()]).
#' @seealso [allan()] for one curve of the whole record.
#' @export
#' @examples
#' # white rate noise whose level doubles halfway
#' set.seed(1)
#' y <- c(rnorm(20000, sd = 1), rnorm(20000, sd = 2))
#' dav <- dynamic_allan(y, freq = 100, window = 40, step = 4)
#' dav
#' summary(dav)
#' plot(dav)
#' plot(dav, what = "taus", at = c(0.01, 1))
#' head(as.data.frame(dav))
dynamic_allan <- function(x, freq, window = NULL, step = NULL, taus = "octave",
                          type = "overlapping", input = "rate", conf = 0.683,
                          alpha = NULL) {
  check_present(missing(x), "x", "the samples")
  t0 <- 0
  if (stats::is.ts(x)) t0 <- stats::start(x)[1L] +
    (stats::start(x)[2L] - 1) / stats::frequency(x)
  if (missing(freq)) {
    if (!stats::is.ts(x)) {
      abort("`freq` is missing; give the sampling frequency in Hz ",
            "(or pass `x` as a ts).", class = "missing_argument")
    }
    freq <- stats::frequency(x)
  }
  freq <- check_freq(freq)
  type <- check_choice(type, dyn_types, "type")
  input <- check_choice(input, c("rate", "integrated"), "input")
  conf <- check_number(conf, "conf", 0, 1, open = TRUE)
  if ((is.matrix(x) || is.data.frame(x)) && NCOL(x) != 1L) {
    abort("`x` must be a single series; got ", describe_type(x), " with ",
          NCOL(x), " columns. Pass one column at a time.", class = "argument")
  }
  rate <- input == "rate"
  min_w <- dyn_min_window(type, rate)
  x <- check_values(x, min_n = min_w, arg = "x")
  N <- length(x)
  W <- dyn_samples(window, "window", freq, min_w, N,
                   default = max(floor(N / 10), min(N, 64L)))
  S <- dyn_samples(step, "step", freq, 1L, N,
                   default = max(1, floor(W / 10)))
  nwin <- floor((N - W) / S) + 1
  Lw <- if (rate) W + 1 else W
  maxm <- dyn_max_m(type, Lw)
  m <- dyn_taus(taus, freq, maxm)
  if (!is.null(alpha)) {
    alpha <- check_number(alpha, "alpha", min(dyn_alphas(type)), 2,
                          integer = TRUE)
  }
  nt <- allan_nterms(type, m, Lw)
  # Scaled by a power of two (exact) so that squares of data near the
  # double range neither overflow nor underflow; scaled back, and refused
  # when the variance itself cannot be represented (as in allan()).
  ex <- range_exponent(x)
  sums <- dynamic_sums_cpp(times_pow2(x, -ex), NULL, m, nt,
                           dyn_opts(type, rate, S, nwin))
  avar <- sweep(sums, 2L, dyn_norm(type, m) * nt, "/")
  avar[avar < 0] <- 0  # a sum of squares; guards the last bit only
  pos <- avar > 0
  avar[] <- times_pow2(if (rate) avar else times_freq2(avar, freq), 2 * ex)
  check_representable(avar, nonzero = pos)
  start <- (seq_len(nwin) - 1) * S
  e <- dyn_edf(type, m, Lw, avar, alpha, conf)
  dimnames(avar) <- NULL
  structure(list(
    time = t0 + (start + (W - 1) / 2) / freq, start = start + 1,
    tau = m / freq, m = as.integer(m), n = nt,
    avar = avar, adev = sqrt(avar), lower = sweep(sqrt(avar), 2L, e$lo, "*"),
    upper = sweep(sqrt(avar), 2L, e$hi, "*"), edf = e$edf, alpha = e$alpha,
    freq = freq, type = type, input = input, N = N, window = W, step = S,
    conf = conf, alpha_rule = if (is.null(alpha)) "slope" else "fixed"),
    class = "allan_dynamic")
}

# The types with a windowed kernel: every type of allan() but "total".
dyn_types <- c("overlapping", "standard", "modified", "hadamard", "ohadamard")

# The options the windowed-sums kernel reads (src/opts-dynamic.h); type codes
# from the estimator table of src/types.h.
dyn_opts <- function(type, rate, step, nwin, threads = allanvar_threads()) {
  list(type = allan_type_code(type), rate = isTRUE(rate), step = step,
       nwin = nwin, threads = as.integer(threads))
}

# The noise exponents an estimator of difference order d resolves
# (alpha + 2 d > 1).
dyn_alphas <- function(type) {
  r <- stat_entry(type)$alpha_range
  r[1L]:r[2L]
}

# Largest cluster size with a term in L phase points (the number of terms
# at each m is allan_nterms(), R/taus.R).
dyn_max_m <- function(type, L) stat_entry(type)$max_m(L)

dyn_norm <- function(type, m) stat_entry(type)$divisor(m)

# Fewest samples a window needs for one term at m = 1.
dyn_min_window <- function(type, rate) {
  L <- stat_entry(type)$min_points
  if (rate) L - 1 else L
}

# A length in seconds as whole samples in [lo, N].
dyn_samples <- function(value, arg, freq, lo, N, default) {
  if (is.null(value)) return(as.double(min(N, default)))
  check_number(value, arg, 0, Inf, open = TRUE)
  k <- round(value * freq)
  if (k < lo || k > N) {
    abort("`", arg, "` must be between ", lo, " and ", N, " samples long (",
          format(lo / freq), " to ", format(N / freq), " s at ", format(freq),
          " Hz), not ", format(value), " s (", k, if (k == 1) " sample)."
          else " samples).", class = "argument")
  }
  as.double(k)
}

# The cluster sizes asked for by `taus`, within [1, maxm].
dyn_taus <- function(taus, freq, maxm) {
  if (is.character(taus) && length(taus) == 1L && !is.na(taus) &&
      taus %in% c("octave", "decade", "all")) {
    m <- switch(taus,
      octave = 2^(0:floor(log2(maxm) + 1e-9)),
      decade = sort(as.vector(outer(c(1, 2, 4),
                                    10^(0:floor(log10(maxm) + 1e-9))))),
      all = seq_len(maxm))
    return(as.double(m[m <= maxm]))
  }
  if (!is.numeric(taus) || is.factor(taus) || length(taus) == 0L ||
      anyNA(taus) || any(!is.finite(taus)) || any(taus <= 0)) {
    abort("`taus` must be \"octave\", \"decade\", \"all\", a number of ",
          "points per decade, or a numeric vector of positive tau in ",
          "seconds; not ", if (is.character(taus) && length(taus) == 1L)
            format_value(taus) else describe_type(taus), ".",
          class = "argument")
  }
  if (length(taus) == 1L && !inherits(taus, "AsIs")) {
    k <- check_number(taus, "taus", 1, 1000, integer = TRUE)
    m <- unique(round(10^seq(0, log10(maxm), by = 1 / k)))
    return(as.double(m[m >= 1 & m <= maxm]))
  }
  m <- round(as.double(taus) * freq)
  bad <- m < 1 | m > maxm
  if (all(bad)) {
    abort("No tau in `taus` fits a window: they must lie in [",
          format(1 / freq), ", ", format(maxm / freq), "] s (cluster sizes 1 ",
          "to ", maxm, ").", class = "argument")
  }
  if (any(bad)) {
    warn(sum(bad), " of the requested tau values lie outside [",
         format(1 / freq), ", ", format(maxm / freq), "] s (what a window ",
         "supports) and were dropped.", class = "taus_dropped")
  }
  sort(unique(m[!bad]))
}

# EDF and noise exponent at each tau, and the factors of the chi-square
# limits. Every window has the same length, so both depend on tau only; the
# noise type is the median over the windows of the local slope (one
# window's slope at long tau, from a few degrees of freedom, misreads it
# too often to choose an EDF).
dyn_edf <- function(type, m, L, avar, alpha, conf) {
  alphas <- dyn_alphas(type)
  tab <- dyn_edf_table(type, m, L, alphas)
  tab[!is.finite(tab) | tab <= 0] <- NA
  nt <- length(m)
  if (!is.null(alpha)) {
    a <- rep(as.integer(alpha), nt)
  } else {
    a <- round(-dyn_slope(avar, m) - 1)
    a[!is.finite(a)] <- 0
    a <- as.integer(pmin(pmax(a, min(alphas)), 2))
    if (!stat_entry(type)$modified) {
      # white and flicker phase noise share the slope (the modified
      # statistic's tells them apart): the smaller EDF
      pick <- ifelse(is.na(tab[, "1"]) | tab[, "2"] <= tab[, "1"], 2L, 1L)
      a[a >= 1L] <- pick[a >= 1L]
    }
  }
  e <- tab[cbind(seq_len(nt), a - min(alphas) + 1L)]
  # where a noise type has no EDF (too few terms), white rate noise's
  w0 <- tab[, as.character(0L)]
  e[is.na(e)] <- w0[is.na(e)]
  p <- (1 - conf) / 2
  list(edf = e, alpha = a, lo = sqrt(e / stats::qchisq(1 - p, e)),
       hi = sqrt(e / stats::qchisq(p, e)))
}

# EDF of a window at each tau under each candidate noise type (columns named
# by alpha), from the package's one EDF engine (src/edf.cpp through
# allan_edf_direct(): exact Gaussian moments for white and random-walk rate
# noise at small m, Greenhall & Riley elsewhere). Every window has L phase
# points, so one table serves all windows.
dyn_edf_table <- function(type, m, L, alphas) {
  n <- allan_nterms(type, m, L)
  tab <- vapply(alphas, function(a) {
    e <- rep(NA_real_, length(m))
    ok <- n >= 1
    if (any(ok)) {
      e[ok] <- allan_edf_direct(type, m[ok], n[ok], L,
                                rep(as.integer(a), sum(ok)))
    }
    e
  }, numeric(length(m)))
  matrix(tab, length(m), length(alphas),
         dimnames = list(NULL, as.character(alphas)))
}

# Median over the windows of the slope of log(avar) against log(tau), from
# the neighbouring taus (one-sided at the ends); NA with a single tau.
dyn_slope <- function(avar, m) {
  nt <- length(m)
  if (nt < 2L) return(NA_real_)
  la <- suppressWarnings(log(avar))
  la[!is.finite(la)] <- NA
  lo <- pmax(seq_len(nt) - 1L, 1L)
  hi <- pmin(seq_len(nt) + 1L, nt)
  mu <- (la[, hi, drop = FALSE] - la[, lo, drop = FALSE]) /
    rep(log(m[hi]) - log(m[lo]), each = nrow(la))
  apply(mu, 2L, stats::median, na.rm = TRUE)
}

#' @export
print.allan_dynamic <- function(x, digits = 3, ...) {
  cat(dyn_header(x), "\n", sep = "")
  nw <- length(x$time)
  rows <- unique(round(seq(1, nw, length.out = min(nw, 5L))))
  tab <- t(x$adev[rows, , drop = FALSE])
  tab <- signif(tab, digits)
  dimnames(tab) <- list(paste0("tau=", signif(x$tau, 4)),
                        paste0("t=", signif(x$time[rows], 4)))
  cat("adev at ", length(rows), " of ", nw, " window centres (s):\n", sep = "")
  print(tab, ...)
  invisible(x)
}

dyn_header <- function(x) {
  sprintf(paste0("<allan_dynamic> %s deviation of %s input: N = %s at %s Hz;",
                 " %d windows of %s samples (%s s) every %s samples (%s s); %d taus",
                 " from %s to %s s; %s%% intervals"),
          x$type, x$input, format(x$N, big.mark = ","), format(x$freq),
          length(x$time), format(x$window, big.mark = ","),
          format(x$window / x$freq), format(x$step, big.mark = ","),
          format(x$step / x$freq), length(x$tau), format(signif(min(x$tau), 4)),
          format(signif(max(x$tau), 4)), format(100 * x$conf))
}

#' @export
summary.allan_dynamic <- function(object, ...) {
  a <- object$adev
  imin <- apply(a, 2L, which.min)
  imax <- apply(a, 2L, which.max)
  d <- data.frame(
    tau = object$tau, n = object$n,
    adev_min = apply(a, 2L, min), adev_median = apply(a, 2L, stats::median),
    adev_max = apply(a, 2L, max),
    ratio = apply(a, 2L, max) / apply(a, 2L, min),
    time_min = object$time[imin], time_max = object$time[imax],
    edf = object$edf, alpha = object$alpha)
  structure(d, header = dyn_header(object),
            class = c("summary.allan_dynamic", "data.frame"))
}

#' @export
print.summary.allan_dynamic <- function(x, digits = 4, ...) {
  print_summary_table(x, digits, ...)
}

#' @export
as.data.frame.allan_dynamic <- function(x, ...) {
  nw <- length(x$time)
  nt <- length(x$tau)
  # window-major: all taus of the first window, then the next
  cell <- function(v) as.vector(t(v))
  data.frame(time = rep(x$time, each = nt), start = rep(x$start, each = nt),
             tau = rep(x$tau, nw), m = rep(x$m, nw), n = rep(x$n, nw),
             avar = cell(x$avar), adev = cell(x$adev),
             lower = cell(x$lower), upper = cell(x$upper),
             edf = rep(x$edf, nw), alpha = rep(x$alpha, nw))
}

#' Plot a dynamic Allan deviation
#'
#' @param x An `allan_dynamic` object from [dynamic_allan()].
#' @param what `"surface"` (default): the deviation as an image over window
#'   centre time (x) and tau (y, log scale), coloured by
#'   \eqn{\log_{10}} of the deviation, with a colour key; `"windows"`: the
#'   deviation against tau (log-log) for a few windows, with their
#'   intervals; `"taus"`: the deviation against time for a few taus, with
#'   their intervals.
#' @param at For `"windows"`, times (s) of the windows to draw (the nearest
#'   window centre is taken); for `"taus"`, the taus (s). `NULL` for five
#'   spread over the range.
#' @param col Colours: the palette of the image, or the colours of the lines.
#' @param contour For `"surface"`, add contour lines of the deviation.
#' @param main,xlab,ylab Titles; `NULL` for defaults.
#' @param ... Passed to the underlying `image()` or `plot()` call.
#' @return `x`, invisibly.
#' @export
#' @examples
#' set.seed(2)
#' y <- c(rnorm(5000), rnorm(5000, sd = 3))
#' dav <- dynamic_allan(y, freq = 10, window = 200, step = 20)
#' plot(dav)
#' plot(dav, what = "windows")
plot.allan_dynamic <- function(x, what = "surface", at = NULL, col = NULL,
                               contour = FALSE, main = NULL, xlab = NULL,
                               ylab = NULL, ...) {
  what <- check_choice(what, c("surface", "windows", "taus"), "what")
  dev_name <- stat_entry(x$type)$ylab
  if (what == "surface") {
    dyn_plot_surface(x, col, contour, main, xlab, ylab, dev_name, ...)
  } else {
    dyn_plot_lines(x, what, at, col, main, xlab, ylab, dev_name, ...)
  }
  invisible(x)
}

dyn_palette <- function(n) {
  grDevices::colorRampPalette(c("#440154", "#3B528B", "#21908C", "#5DC863",
                                "#FDE725"))(n)
}

dyn_plot_surface <- function(x, col, contour, main, xlab, ylab, dev_name,
                             ...) {
  z <- x$adev
  z[!(is.finite(z) & z > 0)] <- NA
  z <- log10(z)
  if (is.null(col)) col <- dyn_palette(64)
  zr <- range(z, finite = TRUE)
  if (!all(is.finite(zr))) zr <- c(0, 1)
  if (diff(zr) == 0) zr <- zr + c(-0.5, 0.5)
  ly <- log10(x$tau)
  op <- graphics::par(mar = pmax(graphics::par("mar"), c(5.1, 4.6, 4.1, 6.5)))
  on.exit(graphics::par(op))
  tx <- x$time
  if (length(tx) == 1L) tx <- tx + c(-0.5, 0.5) * x$window / x$freq
  if (length(ly) == 1L) ly <- ly + c(-0.15, 0.15)
  zz <- z
  if (nrow(zz) != length(tx)) zz <- zz[c(1, 1), , drop = FALSE]
  if (ncol(zz) != length(ly)) zz <- zz[, c(1, 1), drop = FALSE]
  graphics::image(tx, ly, zz, col = col, zlim = zr, axes = FALSE,
                  xlab = if (is.null(xlab)) "time of window centre (s)" else xlab,
                  ylab = if (is.null(ylab)) "tau (s)" else ylab,
                  main = if (is.null(main)) paste("dynamic", dev_name) else main,
                  ...)
  graphics::axis(1)
  yt <- seq(floor(min(ly)), ceiling(max(ly)))
  graphics::axis(2, at = yt, labels = formatC(10^yt, format = "g"), las = 1)
  graphics::box()
  if (contour && nrow(zz) > 1L && ncol(zz) > 1L) {
    v <- dyn_key_values(zr)
    graphics::contour(tx, ly, zz, add = TRUE, col = "grey20", labcex = 0.6,
                      levels = log10(v), labels = formatC(v, format = "g"))
  }
  dyn_colour_key(zr, col, dev_name)
}

# A vertical colour key in the right margin, ticks at 1-2-5 values (or
# decades when the range is wide).
dyn_colour_key <- function(zr, col, dev_name) {
  usr <- graphics::par("usr")
  cx <- graphics::grconvertX(c(1.03, 1.07), "npc", "user")
  br <- seq(usr[3], usr[4], length.out = length(col) + 1L)
  op <- graphics::par(xpd = NA)
  on.exit(graphics::par(op))
  graphics::rect(cx[1], br[-length(br)], cx[2], br[-1L], col = col,
                 border = NA)
  graphics::rect(cx[1], usr[3], cx[2], usr[4], border = "black")
  v <- dyn_key_values(zr)
  ty <- usr[3] + (log10(v) - zr[1]) / diff(zr) * (usr[4] - usr[3])
  graphics::segments(cx[2], ty, cx[2] + 0.3 * diff(cx), ty)
  graphics::text(cx[2] + 0.45 * diff(cx), ty, formatC(v, format = "g"),
                 adj = 0, cex = 0.7)
  graphics::mtext(dev_name, side = 4, line = 5.2, cex = 0.8)
}

# Round deviations within the log10 range zr: 1-2-5 values, or decades.
dyn_key_values <- function(zr) {
  k <- seq(floor(zr[1]), ceiling(zr[2]))
  inside <- function(v) v[log10(v) >= zr[1] - 1e-9 & log10(v) <= zr[2] + 1e-9]
  v <- inside(as.vector(outer(c(1, 2, 5), 10^k)))
  if (length(v) > 8L || length(v) < 2L) {
    dec <- inside(10^k)
    if (length(dec) >= 2L) v <- dec
  }
  if (length(v) < 2L) v <- signif(10^zr, 2)
  v
}

dyn_plot_lines <- function(x, what, at, col, main, xlab, ylab, dev_name,
                           ...) {
  windows <- what == "windows"
  pos <- if (windows) x$time else x$tau
  if (is.null(at)) {
    pick <- unique(round(seq(1, length(pos), length.out = min(5L,
                                                              length(pos)))))
  } else {
    if (!is.numeric(at) || length(at) == 0L || anyNA(at)) {
      abort("`at` must be a numeric vector of ",
            if (windows) "times" else "taus", " in seconds, not ",
            describe_type(at), ".", class = "argument")
    }
    pick <- unique(vapply(at, function(a) {
      if (windows) which.min(abs(pos - a)) else which.min(abs(log(pos / a)))
    }, 1L))
  }
  if (is.null(col)) {
    col <- c("black", "#D55E00", "#0072B2", "#009E73", "#CC79A7", "#E69F00",
             "#56B4E9", "#999999")
  }
  col <- rep_len(col, length(pick))
  xs <- if (windows) x$tau else x$time
  get <- function(v, k) if (windows) v[k, ] else v[, k]
  all_v <- unlist(lapply(pick, function(k) {
    c(get(x$adev, k), get(x$lower, k), get(x$upper, k))
  }))
  yl <- range(all_v[is.finite(all_v) & all_v > 0])
  if (!all(is.finite(yl))) yl <- c(1, 10)
  lab <- if (windows) paste0("t = ", signif(x$time[pick], 4), " s")
         else paste0("tau = ", signif(x$tau[pick], 4), " s")
  leg <- list(legend = lab, col = col, lty = 1, pch = 20)
  op <- reserve_legend(leg, cex = 0.8)
  on.exit(graphics::par(op))
  graphics::plot(range(xs), yl, type = "n", log = if (windows) "xy" else "y",
                 xlab = if (!is.null(xlab)) xlab else if (windows) "tau (s)"
                   else "time of window centre (s)",
                 ylab = if (is.null(ylab)) dev_name else ylab,
                 main = if (is.null(main)) paste("dynamic", dev_name) else main,
                 ...)
  graphics::grid(equilogs = FALSE)
  for (i in seq_along(pick)) {
    k <- pick[i]
    yv <- get(x$adev, k)
    ok <- is.finite(yv) & yv > 0
    graphics::lines(xs[ok], yv[ok], type = "b", pch = 20, col = col[i])
    lo <- get(x$lower, k)
    hi <- get(x$upper, k)
    bar <- ok & is.finite(lo) & lo > 0 & is.finite(hi) & hi > lo
    if (any(bar)) {
      graphics::arrows(xs[bar], lo[bar], xs[bar], hi[bar], angle = 90,
                       code = 3, length = 0.02, col = col[i])
    }
  }
  legend_beside(leg, cex = 0.8)
}
