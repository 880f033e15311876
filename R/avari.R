#' Allan variance of integrated input at octave cluster sizes (overlapping)
#'
#' The overlapping Allan variance computed from an integrated signal (angle
#' from a gyroscope, velocity from an accelerometer, phase of a clock), at
#' cluster sizes \eqn{c = 2^i}, \eqn{i = 0, \dots, p-1}, exactly as
#' 'allanvar' 1.1 did:
#' \deqn{AV(T) = \frac{1}{2T^2(N-2c)} \sum_{k=1}^{N-2c} (\theta_{k+2c} - 2\theta_{k+c} + \theta_k)^2,}
#' with \eqn{T = c/f}.
#'
#' @inheritSection avar Differences from allanvar 1.1
#' @param values Numeric vector (or `ts`) of integrated samples (angle,
#'   velocity or phase), at least 4 of them. Integer counts are accepted.
#' @inheritParams avar
#' @return A data frame with one row per cluster size and columns `time`,
#'   `av` and `error`, as for [avar()].
#' @seealso [avar()], [avarn()], [plotav()], [allan()] with
#'   `input = "integrated"`.
#' @export
#' @examples
#' data(gyroz)
#' angle <- cumsum(gyroz) / frequency(gyroz)
#' av <- avari(angle, frequency(gyroz))
#' plotav(av)
avari <- function(values, freq) {
  check_present(missing(values), "values", "the integrated samples")
  check_present(missing(freq), "freq", "the sampling frequency in Hz")
  values <- check_values(values, min_n = 4L)
  freq <- check_freq(freq)
  compat_range(avari_octave_exact(values, freq), values, freq,
               avari_octave_exact, integrated = TRUE)
}
