#' Allan variance at octave cluster sizes (non-overlapping)
#'
#' Computes the non-overlapping Allan variance of a rate signal (angular rate
#' from a gyroscope, acceleration from an accelerometer, fractional frequency
#' of a clock) at cluster sizes \eqn{c = 2^i}, \eqn{i = 0, \dots, p}, exactly
#' as 'allanvar' 1.1 did: the result is `identical()` to the original's.
#'
#' With \eqn{N} samples, \eqn{p = \lfloor \log_2 \lceil (N-1)/2 \rceil \rfloor}.
#' For each cluster size the series is cut into \eqn{M = \lfloor N/c \rfloor}
#' consecutive clusters from the first sample (a trailing partial cluster is
#' dropped), and
#' \deqn{AV(c\tau_0) = \frac{1}{2(M-1)} \sum_{k=1}^{M-1} (\bar\omega_{k+1} - \bar\omega_k)^2.}
#' The `error` column is the original's percentage error of the Allan
#' deviation, \eqn{1/\sqrt{2(N/c - 1)}}.
#'
#' @section Differences from allanvar 1.1:
#' The numbers are the same, bit for bit. Unlike the original, this function
#' does not print "Calculating...", stops with a clear error on input the
#' original mishandled (fewer than 2 samples, non-numeric values, NA/NaN/Inf,
#' a multi-column matrix or data frame, a missing or non-positive `freq`),
#' and returns correct values where the original's integer sums overflowed
#' (integer input whose cluster sums exceed `.Machine$integer.max`).
#' A one-column matrix or data frame is taken as its column. For confidence
#' intervals, other estimators and any tau grid, see [allan()].
#'
#' @param values Numeric vector (or `ts`) of rate samples: angular rate,
#'   acceleration or fractional frequency. Integer counts are accepted.
#' @param freq Sampling frequency in Hz (a single positive number).
#' @return A data frame with one row per cluster size and columns
#'   `time` (cluster time \eqn{c/f} in seconds), `av` (Allan variance, in
#'   the square of the input's unit) and `error` (relative error of the
#'   Allan deviation).
#' @seealso [avarn()] for every cluster size, [avari()] for integrated input,
#'   [plotav()] to plot the result, [allan()] for the modern estimators.
#' @export
#' @examples
#' data(gyroz)
#' av <- avar(gyroz, frequency(gyroz))
#' head(av)
#' plotav(av)
avar <- function(values, freq) {
  check_present(missing(values), "values", "the rate samples")
  check_present(missing(freq), "freq", "the sampling frequency in Hz")
  values <- check_values(values, min_n = 2L)
  freq <- check_freq(freq)
  compat_range(avar_octave_exact(values, freq, allanvar_threads()), values,
               freq, function(v, f) avar_octave_exact(v, f, allanvar_threads()))
}

# allanvar 1.1's arithmetic as it is, unless it overflows (values near
# 1e300, or integrated input at a huge rate): then the same arithmetic on
# values * 2^-e at 1 Hz (exact: a power of two), scaled back by
# 2^2e freq^2 (freq^2 only for integrated input, where tau enters the
# variance). Inputs that 1.1 handles finitely keep its bits; a variance
# beyond the double range is a classed error.
compat_range <- function(res, values, freq, kernel, integrated = FALSE) {
  if (all(is.finite(res$av))) return(res)
  e <- range_exponent(values)
  r <- kernel(times_pow2(values, -e), 1)
  b <- if (integrated) floor(log2(freq)) else 0
  a <- if (integrated) freq / 2^b else 1
  res$av <- check_representable(times_pow2(r$av * a * a, 2 * e + 2 * b),
                                 what = "`values`")
  res
}
