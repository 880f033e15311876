# Names of earlier releases kept for one release: each warns once per call
# (.Deprecated()) and calls the function that replaced it.

#' Deprecated names
#'
#' These names of allanvar 2.0's development versions are kept for one
#' release and will be removed: each warns and calls the function that
#' replaced it.
#'
#' * `filter_params()` is [kalman_params()] (the parameters of a Kalman
#'   filter; the old name read like the sensor's own filter, an effect of
#'   the noise model);
#' * `read_avr_curve()` is [read_allan_variance_ros_curve()] (the tool is
#'   named in full, as in the other readers of tools' results);
#' * `series_effects()` is [detect_series_effects()] (a verb: it detects,
#'   and removes when asked; the class of its result stays
#'   `"series_effects"`).
#'
#' @param ... Passed to the new function.
#' @return What the new function returns.
#' @keywords internal
#' @name allanvar-deprecated
#' @examples
#' suppressWarnings(filter_params(c(N = 1e-3, K = 1e-5), dt = 0.01))
NULL

#' @rdname allanvar-deprecated
#' @export
filter_params <- function(...) {
  .Deprecated("kalman_params", package = "allanvar")
  kalman_params(...)
}

#' @rdname allanvar-deprecated
#' @export
read_avr_curve <- function(...) {
  .Deprecated("read_allan_variance_ros_curve", package = "allanvar")
  read_allan_variance_ros_curve(...)
}

#' @rdname allanvar-deprecated
#' @export
series_effects <- function(...) {
  .Deprecated("detect_series_effects", package = "allanvar")
  detect_series_effects(...)
}
