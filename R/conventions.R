#' Conventions of other tools
#'
#' How the noise parameters of other tools relate to this package's
#' readings: white noise \eqn{N}, bias instability \eqn{B} and rate random
#' walk \eqn{K}, the continuous-time coefficients of IEEE Std 952-1997
#' (annex C) in SI, with Allan variance
#' \deqn{\sigma^2(\tau) = N^2/\tau + (2\ln 2/\pi) B^2 + K^2\tau/3.}{sigma^2(tau) = N^2/tau + (2 ln 2/pi) B^2 + K^2 tau/3.}
#' The flat floor of the Allan deviation is \eqn{\sqrt{2\ln 2/\pi}\,B =
#' 0.664 B}{sqrt(2 ln 2 / pi) B = 0.664 B}; a per-sample (discrete-time) white-noise standard deviation at
#' sampling rate \eqn{f} is \eqn{\sigma_d = N\sqrt{f}}{sigma_d = N sqrt(f)}; a per-sample bias
#' random-walk step is \eqn{\sigma_{bd} = K/\sqrt{f}}{sigma_bd = K / sqrt(f)} (see
#' [kalman_params()]). A two-sided power spectral density \eqn{N^2} is the
#' one-sided density \eqn{2N^2}: one-sided amplitudes are \eqn{\sqrt{2}}{sqrt(2)}
#' times the two-sided ones.
#'
#' | Tool | Key | This package's value | In / out |
#' |------|-----|----------------------|----------|
#' | Kalibr `imu.yaml` | `*_noise_density` | \eqn{N} (SI per sqrt(Hz)) | [read_kalibr_yaml()], [write_kalibr_yaml()] |
#' | Kalibr `imu.yaml` | `*_random_walk` | \eqn{K} (SI per s per sqrt(Hz)) | same |
#' | Kalibr `imu.yaml` | one value per sensor | worst axis (`axis = "max"`) or mean | same |
#' | OpenVINS `kalibr_imu_chain.yaml` | `imu0:` Kalibr's keys | \eqn{N}, \eqn{K} | [read_kalibr_yaml()], [write_tool_params()] |
#' | imu_utils `*_imu_param.yaml` | `gyr_n`, `acc_n` | \eqn{N\sqrt{f}}{N sqrt(f)} (ADEV at 1 s times \eqn{\sqrt{f}}{sqrt(f)}) | [read_imu_utils_yaml()], [write_tool_params()] |
#' | imu_utils | `gyr_w`, `acc_w` | \eqn{0.664 B}: the minimum ADEV, not divided by 0.664 (a bias instability floor, not a random walk) | same |
#' | imu_utils | `avg-axis` | mean of x, y, z | same |
#' | imu_utils curves | gyro in deg/h | rad/s x 57.3 x 3600 (its own 57.3) | [read_imu_utils_curve()] |
#' | VINS-Mono / VINS-Fusion | `gyr_n`, `acc_n` | \eqn{N\sqrt{f}}{N sqrt(f)}: per-sample standard deviation | [tool_params()], [write_tool_params()] |
#' | VINS-Mono / VINS-Fusion | `gyr_w`, `acc_w` | \eqn{K\sqrt{f}}{K sqrt(f)} | same |
#' | MATLAB `gyroparams`, `accelparams` | `NoiseDensity` | \eqn{N} (double-sided, MATLAB's default `NoiseType`); \eqn{\sqrt{2} N}{sqrt(2) N} single-sided | [tool_params()], [write_tool_params()] |
#' | MATLAB | `BiasInstability` | \eqn{B} (min ADEV / 0.664) | same |
#' | MATLAB | `RandomWalk` | \eqn{K}; \eqn{\sqrt{2} K}{sqrt(2) K} single-sided | same |
#' | allan_variance_ros CSV curve | gyro columns | deg/s (rad/s x 180/pi) | [read_allan_variance_ros_curve()] |
#' | allan_variance_ros `analysis.py` | white noise, random walk | \eqn{N} read at \eqn{\tau} = 1 s, \eqn{K} at \eqn{\tau} = 3 s on fixed-slope lines; bias instability = min ADEV (not / 0.664) | [read_allan_variance_ros_curve()] |
#'
#' Sources and reasons:
#' * VINS-Mono's pre-integration (`integration_base.h`) adds, per IMU
#'   sample of length dt, noise with covariance blocks (dt gyr_n)^2 (half
#'   from each mid-point sample) and (dt gyr_w)^2; against the continuous
#'   model (N^2 dt, K^2 dt per step) this makes `gyr_n` and `gyr_w`
#'   per-sample standard deviations, N sqrt(f) and K sqrt(f).
#'   Configurations that paste Kalibr's continuous values there use a
#'   different (smaller) noise; say which one a file holds.
#' * imu_utils (`src/gyr_lib`, `acc_lib`) fits its curve and writes the
#'   fitted ADEV at 1 s times sqrt(f) as `gyr_n` and the curve's
#'   minimum as `gyr_w`. Its `gyr_w` is often pasted into VINS' `gyr_w`, a
#'   random-walk parameter: the two are different quantities. Before May
#'   2018 imu_utils wrote the ADEV at 1 s without sqrt(f)
#'   ([read_imu_utils_yaml()]'s `scaled`).
#' * MATLAB's `imuSensor` reference page defines `NoiseDensity` in
#'   (rad/s)/sqrt(Hz), `BiasInstability` in rad/s and `RandomWalk` in
#'   (rad/s)*sqrt(Hz) per axis, as in its "Inertial Sensor Noise Analysis
#'   Using Allan Variance" example (N at \eqn{\tau} = 1 s, K at \eqn{\tau} =
#'   3 s, B = min / 0.664). The sqrt(2) of `"single-sided"` follows
#'   from the definition of a one-sided PSD; it has not been checked
#'   against MATLAB itself.
#'
#' @name conventions
#' @aliases allanvar_conventions
#' @seealso [tool_params()], [write_tool_params()], [write_kalibr_yaml()],
#'   [kalman_params()], [av_units()].
#' @examples
#' # N = 1e-4 rad/s/sqrt(Hz) at 200 Hz is an imu_utils / VINS gyr_n of
#' 1e-4 * sqrt(200)
#' # B = 1e-5 rad/s is an imu_utils gyr_w (the floor) of
#' 1e-5 * sqrt(2 * log(2) / pi)
NULL
