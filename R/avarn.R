#' Allan variance at every cluster size (non-overlapping)
#'
#' The non-overlapping Allan variance of a rate signal at every cluster size
#' \eqn{c = 1, \dots, \lceil (N-1)/2 \rceil}, as in 'allanvar' 1.1.
#'
#' With `exact = TRUE` (the default) the result is `identical()` to the
#' original's: every cluster sum is formed as R's `sum()` forms it, which
#' costs \eqn{O(N^2)} operations (shared between up to
#' `getOption("allanvar.threads", 2)` threads). With `exact = FALSE` the same
#' rows come from [allan()]'s prefix-sum engine in \eqn{O(N \log N)}: the
#' structure is identical and the values agree to about \eqn{10^{-12}}
#' relative, the path to take for large \eqn{N}.
#'
#' @inheritSection avar Differences from allanvar 1.1
#' @inheritParams avar
#' @param exact `TRUE` (default) for results bit-identical to 'allanvar' 1.1;
#'   `FALSE` for the fast prefix-sum path.
#' @return A data frame with one row per cluster size and columns `time`,
#'   `av` and `error`, as for [avar()].
#' @seealso [avar()], [avari()], [plotav()], [allan()].
#' @export
#' @examples
#' data(gyroz)
#' av <- avarn(gyroz[1:1000], frequency(gyroz))
#' nrow(av)
#' plotav(av)
avarn <- function(values, freq, exact = TRUE) {
  check_present(missing(values), "values", "the rate samples")
  check_present(missing(freq), "freq", "the sampling frequency in Hz")
  values <- check_values(values, min_n = 2L)
  freq <- check_freq(freq)
  if (!is.logical(exact) || length(exact) != 1L || is.na(exact)) {
    abort("`exact` must be TRUE or FALSE, not ", describe_type(exact), ".")
  }
  if (exact) {
    return(avarn_all_exact(values, freq, allanvar_threads()))
  }
  avarn_fast(values, freq)
}

# The O(N log N) path for avarn(exact = FALSE): allan()'s non-overlapping
# kernel (compensated prefix sums) at every cluster size, no noise id or EDF.
avarn_fast <- function(values, freq) {
  N <- length(values)
  cs <- seq_len(ceiling((N - 1) / 2))
  nterms <- allan_nterms("standard", cs, N + 1)
  res <- allan_sums_cpp(values, N, cs, nterms, numeric(0),
                        allan_opts("standard", rate = TRUE))
  data.frame(time = cs * (1 / freq), av = res$sums[, 1] / (2 * cs^2 * nterms),
             error = 1 / sqrt(2 * ((N / cs) - 1)))
}
