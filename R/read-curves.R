# Other tools' results in: allan_variance_ros' CSV curve, imu_utils' curve
# text files and yaml, a Kalibr imu.yaml. Each is read in its own
# conventions, recorded with the values, and converted to this package's
# (SI, IEEE Std 952 continuous coefficients).

#' Read the results of other Allan variance tools
#'
#' Reads the curves and parameter files written by other tools into R
#' objects in SI units, keeping each tool's conventions with the values:
#'
#' * `read_allan_variance_ros_curve()`: the `allan_variance.csv` of allan_variance_ros
#'   (ori-drs): space-separated, no header, one row per averaging time:
#'   `period acc_x acc_y acc_z gyro_x gyro_y gyro_z`, Allan *deviations*,
#'   accelerometers in m/s^2 and gyroscopes in **deg/s** (its C++ converts
#'   rad/s to deg/s with 180/pi; its analysis.py converts back for the yaml).
#' * `read_imu_utils_curve()`: imu_utils' (gaowenliang) `data_<name>_gyr_t.txt`
#'   (averaging times, s) with `data_<name>_gyr_{x,y,z}.txt` (Allan
#'   deviations in **deg/h**, converted from rad/s with its factor
#'   57.3 * 3600, not 180/pi * 3600) and the `acc` files (m/s^2); with
#'   `fitted = TRUE` its fitted curves (`data_<name>_sim_*`). Its first
#'   averaging time is one sample, so the sampling rate is `1 / tau[1]`
#'   (attribute `freq`).
#' * `read_imu_utils_yaml()`: imu_utils' `<name>_imu_param.yaml` (OpenCV
#'   yaml). Its `gyr_n`/`acc_n` are, in its current code (since May 2018),
#'   `sqrt(freq)` times the fitted Allan deviation at 1 s, a discrete-time
#'   standard deviation; the continuous white-noise coefficient N (IEEE,
#'   rad/s/sqrt(Hz)) is then `gyr_n / sqrt(freq)`. Its earlier files (the
#'   repository's 16448, A3, N3, gx4 and xsens examples) hold the fitted
#'   Allan deviation at 1 s itself, i.e. N. The file does not say which:
#'   give `curve` (its fitted curve) to decide from the numbers, or `scaled`.
#'   Its `gyr_w`/`acc_w` are the **minimum of the fitted Allan deviation**
#'   (the flat floor), not a random walk: the IEEE bias instability is
#'   `B = gyr_w / 0.664`. `avg-axis` is the mean of the three axes.
#' * `read_kalibr_yaml()`: a Kalibr `imu.yaml` (as written by Kalibr users,
#'   allan_variance_ros or [write_kalibr_yaml()]): `*_noise_density` is the
#'   continuous white-noise density N (rad/s/sqrt(Hz), m/s^2/sqrt(Hz)) and
#'   `*_random_walk` the rate random walk K (rad/s^2/sqrt(Hz),
#'   m/s^3/sqrt(Hz)). allan_variance_ros writes the mean of the axes in its
#'   older versions and the worst axis now; Kalibr's wiki says to inflate the
#'   values for real use; neither is recorded in the file.
#'
#' A curve is a data frame of class `"tool_curve"` with one row per channel
#' and averaging time; give it to [avfit()] or [as_av_curve()] with the
#' channel, the number of samples and the rate (`channel`, `n`, `freq`),
#' which these files do not hold, e.g.
#' `avfit(cv, channel = "gyro_x", n = 1e6, freq = 200)`.
#'
#' @param file Path of the file.
#' @param dir Directory holding imu_utils' `data_<name>_*.txt` files.
#' @param name The sensor name in the file names (`data_<name>_gyr_t.txt`).
#' @param fitted Read imu_utils' fitted curves (`_sim_`) instead of the
#'   measured ones.
#' @param freq Sampling rate in Hz, for the conversion of `gyr_n`/`acc_n`
#'   (`NULL`: taken from `curve`; without either the continuous N of a scaled
#'   file is `NA`).
#' @param curve Optional: the matching [read_imu_utils_curve()] result
#'   (`fitted = TRUE` best): gives `freq`, and tells whether `gyr_n` is
#'   scaled by `sqrt(freq)` (whichever of `gyr_n` and `gyr_n / sqrt(freq)`
#'   is within 5% of the curve's Allan deviation at 1 s).
#' @param scaled Whether `gyr_n`/`acc_n` are `sqrt(freq)` times N (`TRUE`,
#'   imu_utils since May 2018) or N (`FALSE`); `NULL` decides from `curve`,
#'   else assumes `TRUE`. The choice is in `attr(, "scaled")`.
#' @return `read_allan_variance_ros_curve()`, `read_imu_utils_curve()`: a `"tool_curve"` data
#'   frame with columns `channel` (`gyro_x`, ..., `accel_z`), `sensor`,
#'   `tau` (s), `adev` and `avar` (SI: rad/s, m/s^2) and `unit`, and
#'   attributes `source` (the tool), `freq` (Hz or `NULL`), `file` and
#'   `conventions` (text). `read_imu_utils_yaml()`: a data frame with one
#'   row per sensor and axis (`avg`, `x`, `y`, `z`): `sensor`, `axis`,
#'   `white` (`gyr_n`/`acc_n` as written), `floor` (`gyr_w`/`acc_w` as
#'   written), `N` (continuous, `white / sqrt(freq)`), `B` (`floor / 0.664`),
#'   `unit_N`, `unit_B`; attributes `name`, `freq`, `conventions`.
#'   `read_kalibr_yaml()`: a data frame with columns `sensor`, `term` (`N`,
#'   `K`), `key` (the yaml key), `value` and `unit`, and attributes
#'   `update_rate`, `rostopic` and `conventions`.
#' @seealso [avfit()], [write_kalibr_yaml()], [av_units()]
#' @name read_other_tools
#' @examples
#' f <- tempfile(fileext = ".csv")
#' tau <- c(0.1, 1, 10)
#' # a white-noise curve: accel N = 0.002 m/s^2/sqrt(Hz), gyro 0.01 deg/s/sqrt(Hz)
#' write.table(cbind(tau, 0.002 / sqrt(tau), 0.002 / sqrt(tau), 0.002 / sqrt(tau),
#'                   0.01 / sqrt(tau), 0.01 / sqrt(tau), 0.01 / sqrt(tau)),
#'             f, row.names = FALSE, col.names = FALSE)
#' cv <- read_allan_variance_ros_curve(f)
#' cv[cv$channel == "gyro_x", ]
#' unlink(f)
NULL

#' @rdname read_other_tools
#' @export
read_allan_variance_ros_curve <- function(file) {
  check_present(missing(file), "file", "the path of allan_variance.csv")
  check_file(file)
  tab <- tryCatch(data.table::fread(file, header = FALSE, data.table = FALSE,
                                    showProgress = FALSE, nThread = 1L),
                  error = function(e) abort("cannot read \"", basename(file), "\": ",
                                            conditionMessage(e), class = "file"))
  tab <- tab[, vapply(tab, function(v) !all(is.na(v)), logical(1)), drop = FALSE]
  if (ncol(tab) != 7L || !all(vapply(tab, is.numeric, logical(1)))) {
    abort("\"", basename(file), "\" is not an allan_variance_ros curve: expected 7 ",
          "numeric columns (period, acc x y z, gyro x y z), found ", ncol(tab), ".",
          class = "file_format")
  }
  deg <- pi / 180
  long <- curve_long(tab[[1L]], as.matrix(tab[, 2:7]),
                     c("accel_x", "accel_y", "accel_z", "gyro_x", "gyro_y", "gyro_z"),
                     to_si = c(1, 1, 1, deg, deg, deg))
  new_tool_curve(long, source = "allan_variance_ros", freq = NULL, file = file,
               conventions = c(
                 "Allan deviations (not variances), overlapping bins of 0.1 s to 1000 s",
                 "gyroscope columns in deg/s (rad/s * 180/pi), converted here with pi/180",
                 "accelerometer columns in m/s^2",
                 "analysis.py: N at tau = 1 s and K at tau = 3 s from fixed-slope lines, B = min ADEV (not / 0.664)"))
}

#' @rdname read_other_tools
#' @export
read_imu_utils_curve <- function(dir, name, fitted = FALSE) {
  check_present(missing(dir), "dir", "the directory of imu_utils' data files")
  check_present(missing(name), "name", "the sensor name of the files")
  if (!is.character(dir) || length(dir) != 1L || !dir.exists(dir)) {
    abort("`dir` must be an existing directory, not ", format_value(dir), ".",
          class = "argument")
  }
  if (!is.character(name) || length(name) != 1L || is.na(name)) {
    abort("`name` must be a single sensor name, not ", describe_type(name), ".",
          class = "argument")
  }
  if (!is.logical(fitted) || length(fitted) != 1L || is.na(fitted)) {
    abort("`fitted` must be TRUE or FALSE.", class = "argument")
  }
  kind <- if (fitted) paste0(name, "_sim") else name
  one <- function(s) {
    f <- file.path(dir, sprintf("data_%s_%s_%s.txt", kind, s, c("t", "x", "y", "z")))
    miss <- f[!file.exists(f)]
    if (length(miss)) return(NULL)
    cols <- lapply(f, function(p) {
      v <- suppressWarnings(as.numeric(readLines(p, warn = FALSE)))
      v[!is.na(v)]
    })
    if (length(unique(lengths(cols))) != 1L) {
      abort("imu_utils files ", paste(basename(f), collapse = ", "),
            " do not have the same number of values.", class = "file_format")
    }
    cols
  }
  gyr <- one("gyr")
  acc <- one("acc")
  if (is.null(gyr) && is.null(acc)) {
    abort("no imu_utils curve for \"", name, "\" in ", dir, " (looked for data_",
          kind, "_gyr_t.txt and data_", kind, "_acc_t.txt).", class = "file")
  }
  parts <- list()
  # imu_utils' own factor: deg/h = rad/s * 57.3 * 3600 (src/gyr_lib/allan_gyr.cpp).
  if (!is.null(gyr)) {
    parts$g <- curve_long(gyr[[1L]], do.call(cbind, gyr[2:4]),
                          c("gyro_x", "gyro_y", "gyro_z"), rep(1 / (57.3 * 3600), 3))
  }
  if (!is.null(acc)) {
    parts$a <- curve_long(acc[[1L]], do.call(cbind, acc[2:4]),
                          c("accel_x", "accel_y", "accel_z"), rep(1, 3))
  }
  tau1 <- if (!is.null(gyr)) gyr[[1L]][1L] else acc[[1L]][1L]
  new_tool_curve(do.call(rbind, parts), source = "imu_utils", freq = 1 / tau1,
               file = file.path(dir, sprintf("data_%s_*.txt", kind)),
               conventions = c(
                 "Allan deviations; gyroscope in deg/h with imu_utils' factor 57.3 * 3600 (converted back with it)",
                 "accelerometer in m/s^2",
                 "the first averaging time is one sample: freq = 1 / tau[1]",
                 if (fitted) "fitted curves (data_*_sim_*): the model imu_utils fitted to the measured curve"))
}

#' @rdname read_other_tools
#' @export
read_imu_utils_yaml <- function(file, freq = NULL, curve = NULL, scaled = NULL) {
  check_present(missing(file), "file", "the path of an imu_utils *_imu_param.yaml")
  y <- read_yaml_file(file)
  if (!is.null(curve) && !inherits(curve, "tool_curve")) {
    abort("`curve` must be a read_imu_utils_curve() result, not ",
          describe_type(curve), ".", class = "argument")
  }
  if (is.null(freq) && !is.null(curve)) freq <- attr(curve, "freq")
  if (!is.null(freq)) freq <- check_freq(freq)
  if (!is.null(scaled) && (!is.logical(scaled) || length(scaled) != 1L || is.na(scaled))) {
    abort("`scaled` must be TRUE, FALSE or NULL.", class = "argument")
  }
  how <- if (is.null(scaled)) "assumed (current imu_utils)" else "given"
  rows <- list()
  for (s in c("Gyr", "Acc")) {
    blk <- y[[s]]
    if (is.null(blk)) next
    pre <- tolower(s)
    for (ax in c("avg-axis", "x-axis", "y-axis", "z-axis")) {
      v <- blk[[ax]]
      if (is.null(v)) next
      w <- as.numeric(v[[paste0(pre, "_n")]])
      fl <- as.numeric(v[[paste0(pre, "_w")]])
      gyro <- s == "Gyr"
      rows[[length(rows) + 1L]] <- data.frame(
        sensor = if (gyro) "gyro" else "accel", axis = sub("-axis", "", ax),
        white = w, floor = fl, N = NA_real_,
        B = fl / 0.664,
        unit_N = if (gyro) "rad/s/sqrt(Hz)" else "m/s^2/sqrt(Hz)",
        unit_B = if (gyro) "rad/s" else "m/s^2", stringsAsFactors = FALSE)
    }
  }
  if (!length(rows)) {
    abort("\"", basename(file), "\" has no Gyr or Acc block: not an imu_utils ",
          "parameter file.", class = "file_format")
  }
  out <- do.call(rbind, rows)
  if (is.null(scaled) && !is.null(curve) && !is.null(freq)) {
    # Compare with the curve at 1 s, on the axes both hold.
    a1 <- vapply(seq_len(nrow(out)), function(i) {
      ch <- paste0(out$sensor[i], "_", out$axis[i])
      d <- curve[curve$channel == ch, ]
      if (nrow(d) < 2L) return(NA_real_)
      exp(stats::approx(log(d$tau), log(d$adev), xout = 0)$y)
    }, 0)
    r <- stats::median(out$white / a1, na.rm = TRUE)
    if (is.finite(r) && abs(r - 1) < 0.05) {
      scaled <- FALSE
    } else if (is.finite(r) && abs(r / sqrt(freq) - 1) < 0.05) {
      scaled <- TRUE
    }
    if (!is.null(scaled)) how <- sprintf("from the curve (white / ADEV(1 s) = %.4g)", r)
  }
  if (is.null(scaled)) scaled <- TRUE
  out$N <- if (!scaled) out$white else if (is.null(freq)) NA_real_ else
    out$white / sqrt(freq)
  attr(out, "name") <- y$name
  attr(out, "freq") <- freq
  attr(out, "scaled") <- scaled
  attr(out, "scaled_source") <- how
  attr(out, "conventions") <- c(
    if (scaled) "white (gyr_n, acc_n) = sqrt(freq) * fitted ADEV at tau = 1 s, a discrete-time sigma: N = white / sqrt(freq)"
    else "white (gyr_n, acc_n) = fitted ADEV at tau = 1 s (imu_utils before May 2018): N = white",
    "floor (gyr_w, acc_w) = minimum of the fitted ADEV (not a random walk): IEEE B = floor / 0.664",
    "avg = mean of the three axes; units rad/s and m/s^2 (57.3 deg/rad)")
  out
}

#' @rdname read_other_tools
#' @export
read_kalibr_yaml <- function(file) {
  check_present(missing(file), "file", "the path of a Kalibr imu.yaml")
  y <- read_yaml_file(file)
  # OpenVINS' kalibr_imu_chain.yaml nests the same keys under imu0
  if (is.list(y) && is.list(y$imu0) && !"gyroscope_noise_density" %in% names(y)) {
    y <- y$imu0
  }
  keys <- c(gyroscope_noise_density = "gyro.N", gyroscope_random_walk = "gyro.K",
            accelerometer_noise_density = "accel.N", accelerometer_random_walk = "accel.K")
  have <- names(keys)[names(keys) %in% names(y)]
  if (!length(have)) {
    abort("\"", basename(file), "\" has none of the Kalibr keys (",
          paste(names(keys), collapse = ", "), ").", class = "file_format")
  }
  val <- vapply(have, function(k) {
    v <- suppressWarnings(as.numeric(y[[k]]))
    if (length(v) != 1L) NA_real_ else v
  }, 0)
  bad <- !is.finite(val) | val < 0
  if (any(bad)) {
    k <- have[bad][1L]
    abort("\"", basename(file), "\": `", k, "` must be a single non-negative ",
          "finite number, not ", format_value(y[[k]]), ".", class = "file_format")
  }
  sk <- strsplit(keys[have], ".", fixed = TRUE)
  sensor <- vapply(sk, `[`, "", 1L)
  term <- vapply(sk, `[`, "", 2L)
  out <- data.frame(sensor = sensor, term = term, key = have, value = unname(val),
                    unit = unname(mapply(si_unit, sensor, term)),
                    stringsAsFactors = FALSE)
  rownames(out) <- NULL
  attr(out, "update_rate") <- if (is.null(y$update_rate)) NULL else as.numeric(y$update_rate)
  attr(out, "rostopic") <- y$rostopic
  attr(out, "conventions") <- c(
    "*_noise_density: continuous white-noise density N (IEEE), SI per sqrt(Hz)",
    "*_random_walk: rate random walk K (IEEE), SI per sqrt(s)",
    "whether a value is one axis, the worst or the mean of the axes is not recorded")
  out
}

# Long table of curves: one row per channel and tau, SI values.
curve_long <- function(tau, dev, channels, to_si) {
  n <- length(tau)
  sensor <- ifelse(startsWith(channels, "gyro"), "gyro", "accel")
  adev <- as.vector(sweep(as.matrix(dev), 2L, to_si, `*`))
  data.frame(channel = rep(channels, each = n), sensor = rep(sensor, each = n),
             tau = rep(as.numeric(tau), length(channels)), adev = adev, avar = adev^2,
             unit = rep(ifelse(sensor == "gyro", "rad/s", "m/s^2"), each = n),
             stringsAsFactors = FALSE)
}

new_tool_curve <- function(d, source, freq, file, conventions) {
  rownames(d) <- NULL
  d <- d[is.finite(d$tau) & d$tau > 0 & is.finite(d$adev), , drop = FALSE]
  attr(d, "source") <- source
  attr(d, "freq") <- freq
  attr(d, "file") <- file
  attr(d, "conventions") <- conventions
  class(d) <- c("tool_curve", "data.frame")
  d
}

#' @export
print.tool_curve <- function(x, ...) {
  ch <- unique(x$channel)
  cat(sprintf("<tool_curve> from %s: %d channel(s) (%s), %d averaging times from %.3g s to %.3g s\n",
              attr(x, "source"), length(ch), paste(ch, collapse = ", "),
              length(unique(x$tau)), min(x$tau), max(x$tau)))
  if (!is.null(attr(x, "freq"))) cat(sprintf("  sampling rate %.6g Hz\n", attr(x, "freq")))
  cat(paste0("  - ", attr(x, "conventions"), "\n"), sep = "")
  print(utils::head(as.data.frame(x)), ...)
  invisible(x)
}

read_yaml_file <- function(file) {
  check_file(file)
  if (!requireNamespace("yaml", quietly = TRUE)) {
    abort("reading \"", basename(file), "\" needs the 'yaml' package; install it ",
          "(Debian: r-cran-yaml).", class = "dependency")
  }
  txt <- readLines(file, warn = FALSE)
  txt <- txt[!grepl("^%YAML", txt)]          # OpenCV's "%YAML:1.0" directive
  tryCatch(yaml::yaml.load(paste(txt, collapse = "\n")),
           error = function(e) abort("\"", basename(file), "\" is not valid YAML: ",
                                     conditionMessage(e), class = "file_format"))
}
