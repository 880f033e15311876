#' Simulated one-axis gyroscope output (allanvar 1.1's example data)
#'
#' `gyroz` is the example series of 'allanvar' 1.1, unchanged: the output of a
#' simulated one-axis gyroscope in rad/s, with a clear angle random walk and
#' rate random walk. `gyroz_long` is the longer series from the same
#' simulation (the first 10,000 samples are `gyroz`).
#'
#' As in 'allanvar' 1.1 the data are loaded with [utils::data()]:
#' `data(gyroz)` gives the 10,000-sample series and, for code written for
#' the original, `data(gyroz_complete)` defines an object named `gyroz` that
#' holds the 65,536-sample series (`data(gyroz_long)` gives the same series
#' under its own name).
#'
#' @format `gyroz`: a [ts] of 10,000 angular rate samples (rad/s) at
#'   97.65625 Hz (sample period 10.24 ms), starting at time 1.
#'   `gyroz_long`: a [ts] of 65,536 samples, same rate and start.
#' @source Simulated by J. Hidalgo Carrio for 'allanvar' 1.1 (GPL-2); not
#'   from a real sensor.
#' @examples
#' data(gyroz)
#' frequency(gyroz)
#' length(gyroz)
#' data(gyroz_long)
#' identical(as.numeric(gyroz_long[1:10000]), as.numeric(gyroz))
#' @name gyroz
#' @aliases gyroz_long gyroz_complete
#' @docType data
#' @keywords datasets
NULL
