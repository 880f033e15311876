#' allanvar: Allan variance analysis of inertial sensors and clocks
#'
#' The compatibility functions [avar()], [avarn()], [avari()] and [plotav()]
#' return exactly what 'allanvar' 1.1 returned, computed by C++ kernels.
#'
#' @keywords internal
#' @useDynLib allanvar, .registration = TRUE
#' @importFrom Rcpp sourceCpp
"_PACKAGE"
