#' Allan variance and closed-loop noise identification of three ADIS16405 IMUs
#'
#' Derived figures (no raw samples) of three static recordings of ADIS16405
#' MEMS inertial measurement units: 1,000,000 samples at 100 Hz (about 2.8
#' hours) per axis, gyroscopes in deg/s and accelerometers in g, 18 axes in
#' all. Computed by `data-raw/adis16405.R`: overlapping Allan variance at 10
#' points per decade ([allan()]), raw-data diagnostics ([avdiagnose()]), the
#' datasheet model `c("N", "B", "K")` fitted with [avfit()] and the closed
#' loop [avrefine()] run with the raw axis as `data`.
#'
#' @format A list with
#' \describe{
#'   \item{`av`}{data frame, one row per axis and tau: `unit` (1-3), `axis`
#'     (`gyro_x`, ..., `accel_z`), `sensor`, `rate_unit`, `tau` (s), `m`,
#'     `n`, `avar`, `adev`, `lower`, `upper` (68.3% limits of ADEV), `edf`.
#'     Refit with `avfit(subset(av, unit == 1 & axis == "gyro_x"), n = 1e6,
#'     freq = 100)`.}
#'   \item{`diagnostics`}{one row per axis: `n`, `freq`, `sd`, `lsb`
#'     (quantization step), `levels`, `on_grid` (fraction of samples on the
#'     grid), `sd_lsb`, `acf1` (lag-1 autocorrelation), `trend` (unit/s) and
#'     `trend_t`, `n_lines` and the strongest spectral line (`line_f0` Hz,
#'     `line_amp`, `line_ratio` over background, `line_p` Bonferroni p).}
#'   \item{`lines`}{all significant spectral lines per axis.}
#'   \item{`noise_id`}{lag-1 noise identification per axis and averaging
#'     time.}
#'   \item{`fits`}{one row per axis: `chi2_before`, `rms_before` (datasheet
#'     model), `chi2_after`, `rms_after` (refined), `n_steps`, `effects`
#'     added, `unconfirmed` (steps the raw data contradict), `final_terms`,
#'     `converged` (both fits converged), `failed_refits` (refits of the loop
#'     that failed, see `avrefine()`).}
#'   \item{`coef`}{coefficients (`value`, `se`) of the datasheet (`stage =
#'     "datasheet"`) and refined models.}
#'   \item{`steps`}{the refinement steps of every axis, with the columns of
#'     `avrefine()$steps`.}
#'   \item{`unexplained`}{the residual structure the loop left unexplained
#'     per axis, with the columns of `avrefine()$unexplained`.}
#'   \item{`check`}{the measured-data checks per axis (`bench/adis16405/adis16405-check.R`):
#'     `acf1`, `filter` (a filter term was added), `enbw` (its
#'     noise-equivalent bandwidth, Hz), `line_055` (a sinusoid at 0.5-0.6 Hz),
#'     `sinusoids` (their frequencies), `contradicted` (accepted steps the raw
#'     data contradict), `chi2`, `n_fit` (the fitted white level), `n_ref`
#'     (the white level read where the ADEV slope is -1/2), `n_err` (percent),
#'     `converged`, `unexplained` (rows), `tau_from` (first tau fitted),
#'     `effects`.}
#'   \item{`source`}{attribution.}
#' }
#' The fitted `avfit` objects themselves are in
#' `system.file("extdata", "adis16405_refine.rds", package = "allanvar")`
#' (a list by `"unitK/axis"` of `datasheet` and `refined` fits).
#' @source Department of Geomatics Engineering, University of Calgary, as
#'   published in the imudata R package (S. Guerrier, G. Bakalli et al.),
#'   licensed CC BY-NC-SA 4.0. Only derived figures are included here.
#' @usage data(adis16405_av)
#' @docType data
#' @keywords datasets
#' @examples
#' data(adis16405_av)
#' adis16405_av$fits[, c("unit", "axis", "chi2_before", "chi2_after", "effects")]
"adis16405_av"
