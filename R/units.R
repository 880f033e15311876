#' Units of inertial sensors and of their noise coefficients
#'
#' `av_units()` lists every unit that [read_imu()], [convert_units()],
#' [datasheet()] and the exporters understand, with its factor to SI.
#' `convert_units()` converts numbers between two units of the same kind.
#'
#' Internally everything is SI: angular rate in rad/s, acceleration in
#' m/s^2, with standard gravity g = 9.80665 m/s^2 (exact, CGPM 1901),
#' 1 deg = pi/180 rad and 1 h = 3600 s. The noise coefficients follow the
#' IEEE Std 952 convention (two-sided PSD), with u the rate unit:
#'
#' | kind | coefficient | SI, gyro | SI, accel | datasheet units |
#' |---|---|---|---|---|
#' | `rate` | B, GM sigma, sinusoid amplitude, raw samples | rad/s | m/s^2 | deg/h; ug, mg |
#' | `N` | white noise (ARW / VRW), u*sqrt(s) | rad/sqrt(s) = rad/s/sqrt(Hz) | m/s/sqrt(s) = m/s^2/sqrt(Hz) | deg/sqrt(h); m/s/sqrt(h), ug/sqrt(Hz) |
#' | `K` | rate random walk, u/sqrt(s) | rad/s/sqrt(s) = rad/s^2/sqrt(Hz) | m/s^2/sqrt(s) = m/s^3/sqrt(Hz) | deg/h/sqrt(h); m/s/h^(3/2) |
#' | `Q` | quantization, u*s | rad | m/s | deg, arcsec |
#' | `R` | rate ramp, u/s | rad/s^2 | m/s^3 | deg/h^2 |
#'
#' Spellings that denote the same SI unit (`rad/s/sqrt(Hz)` and
#' `rad/sqrt(s)`, `m/s^3/sqrt(Hz)` and `m/s^2/sqrt(s)`) have factor 1: a
#' noise density in u/sqrt(Hz) is numerically the same as u*sqrt(s).
#' Kalibr's `*_noise_density` is N and `*_random_walk` is K, both in SI.
#' Accelerometer K has no single datasheet convention; it is given in
#' m/s^3/sqrt(Hz) (Kalibr's unit) and in m/s/h^(3/2), the analogue of the
#' gyroscope's deg/h/sqrt(h).
#'
#' @param sensor Optional filter: `"gyro"` or `"accel"`.
#' @param kind Optional filter: one or more of `"rate"`, `"N"`, `"K"`,
#'   `"Q"`, `"R"`.
#' @return `av_units()`: a data frame with columns `unit`, `sensor`, `kind`,
#'   `to_si` (multiply a value in `unit` by this to get SI) and `si` (the SI
#'   unit of that kind).
#' @export
#' @examples
#' av_units("gyro", "N")
#' # 0.15 deg/sqrt(h) angle random walk in rad/s/sqrt(Hz)
#' convert_units(0.15, "deg/sqrt(h)", "rad/s/sqrt(Hz)")
#' # 1 g in m/s^2, and 10 deg/h in rad/s
#' convert_units(1, "g", "m/s^2")
#' convert_units(10, "deg/h", "rad/s")
av_units <- function(sensor = NULL, kind = NULL) {
  tab <- unit_table()
  if (!is.null(sensor)) {
    sensor <- match_sensor(sensor)
    tab <- tab[tab$sensor == sensor, ]
  }
  if (!is.null(kind)) {
    kinds <- unit_kinds()
    if (!is.character(kind) || !length(kind) || anyNA(kind) ||
        !all(kind %in% kinds)) {
      abort("`kind` must be one or more of ",
            paste0('"', kinds, '"', collapse = ", "), ", not ",
            format_value(kind), ".", class = "argument")
    }
    tab <- tab[tab$kind %in% kind, ]
  }
  tab$dim <- NULL
  rownames(tab) <- NULL
  tab
}

#' @rdname av_units
#' @param x Numeric values to convert.
#' @param from,to Unit names as listed by `av_units()` (for example
#'   `"deg/s"`, `"g"`, `"deg/sqrt(h)"`). They must be of the same sensor and
#'   kind; spaces are ignored, and `"m/s2"` is read as `"m/s^2"`, `"µg"` as
#'   `"ug"`.
#' @return `convert_units()`: `x` expressed in `to`.
#' @export
convert_units <- function(x, from, to) {
  if (!is.numeric(x) || is.factor(x)) {
    abort("`x` must be numeric, not ", describe_type(x), ".", class = "argument")
  }
  if (any(is.infinite(x) | is.nan(x))) {
    abort("`x` must hold finite numbers (or NA); found ",
          format(x[is.infinite(x) | is.nan(x)][1L]), ".", class = "argument")
  }
  f <- lookup_unit(from, "from")
  t <- lookup_unit(to, "to")
  if (f$sensor != t$sensor || f$kind != t$kind) {
    abort("cannot convert from \"", from, "\" (", f$sensor, " ", f$kind,
          ") to \"", to, "\" (", t$sensor, " ", t$kind, "); both units must ",
          "measure the same quantity. See av_units().", class = "units")
  }
  x * (f$to_si / t$to_si)
}


# One row per accepted spelling. Factors are written from their definitions
# so that each can be checked by hand.
unit_table <- function() {
  if (is.null(unit_cache$tab)) unit_cache$tab <- build_unit_table()
  unit_cache$tab
}

unit_cache <- new.env(parent = emptyenv())

build_unit_table <- function() {
  deg <- pi / 180
  h <- 3600
  g <- 9.80665
  u <- function(unit, sensor, kind, to_si) {
    list(unit = unit, sensor = sensor, kind = kind, to_si = to_si)
  }
  rows <- list(
    # gyro rate
    u("rad/s", "gyro", "u", 1),
    u("deg/s", "gyro", "u", deg),
    u("deg/h", "gyro", "u", deg / h),
    u("rad/h", "gyro", "u", 1 / h),
    u("mrad/s", "gyro", "u", 1e-3),
    u("rpm", "gyro", "u", 2 * pi / 60),
    # gyro white noise (angle random walk)
    u("rad/sqrt(s)", "gyro", "u*sqrt(s)", 1),
    u("rad/s/sqrt(Hz)", "gyro", "u*sqrt(s)", 1),
    u("deg/sqrt(s)", "gyro", "u*sqrt(s)", deg),
    u("deg/s/sqrt(Hz)", "gyro", "u*sqrt(s)", deg),
    u("deg/sqrt(h)", "gyro", "u*sqrt(s)", deg / sqrt(h)),
    u("deg/h/sqrt(Hz)", "gyro", "u*sqrt(s)", deg / h),
    # gyro rate random walk
    u("rad/s/sqrt(s)", "gyro", "u/sqrt(s)", 1),
    u("rad/s^2/sqrt(Hz)", "gyro", "u/sqrt(s)", 1),
    u("deg/s/sqrt(s)", "gyro", "u/sqrt(s)", deg),
    u("deg/h/sqrt(h)", "gyro", "u/sqrt(s)", deg / h / sqrt(h)),
    u("deg/h^(3/2)", "gyro", "u/sqrt(s)", deg / h^1.5),
    # gyro quantization and rate ramp
    u("rad", "gyro", "u*s", 1),
    u("deg", "gyro", "u*s", deg),
    u("arcsec", "gyro", "u*s", deg / 3600),
    u("rad/s^2", "gyro", "u/s", 1),
    u("deg/s^2", "gyro", "u/s", deg),
    u("deg/h^2", "gyro", "u/s", deg / h^2),
    # accel rate
    u("m/s^2", "accel", "u", 1),
    u("g", "accel", "u", g),
    u("mg", "accel", "u", g * 1e-3),
    u("ug", "accel", "u", g * 1e-6),
    u("m/s/h", "accel", "u", 1 / h),
    # accel white noise (velocity random walk)
    u("m/s/sqrt(s)", "accel", "u*sqrt(s)", 1),
    u("m/s^2/sqrt(Hz)", "accel", "u*sqrt(s)", 1),
    u("m/s/sqrt(h)", "accel", "u*sqrt(s)", 1 / sqrt(h)),
    u("ug/sqrt(Hz)", "accel", "u*sqrt(s)", g * 1e-6),
    u("mg/sqrt(Hz)", "accel", "u*sqrt(s)", g * 1e-3),
    u("g/sqrt(Hz)", "accel", "u*sqrt(s)", g),
    # accel rate random walk
    u("m/s^2/sqrt(s)", "accel", "u/sqrt(s)", 1),
    u("m/s^3/sqrt(Hz)", "accel", "u/sqrt(s)", 1),
    u("m/s/h^(3/2)", "accel", "u/sqrt(s)", 1 / h^1.5),
    u("ug/sqrt(s)", "accel", "u/sqrt(s)", g * 1e-6),
    u("mg/sqrt(h)", "accel", "u/sqrt(s)", g * 1e-3 / sqrt(h)),
    # accel quantization and rate ramp
    u("m/s", "accel", "u*s", 1),
    u("m/s^3", "accel", "u/s", 1),
    u("ug/s", "accel", "u/s", g * 1e-6)
  )
  dim <- vapply(rows, `[[`, "", "kind")
  tab <- data.frame(
    unit = vapply(rows, `[[`, "", "unit"),
    sensor = vapply(rows, `[[`, "", "sensor"),
    kind = vapply(dim, dim_kind, ""),
    to_si = vapply(rows, `[[`, 0, "to_si"), stringsAsFactors = FALSE)
  si <- c("gyro u" = "rad/s", "gyro u*sqrt(s)" = "rad/s/sqrt(Hz)",
          "gyro u/sqrt(s)" = "rad/s^2/sqrt(Hz)", "gyro u*s" = "rad",
          "gyro u/s" = "rad/s^2", "accel u" = "m/s^2",
          "accel u*sqrt(s)" = "m/s^2/sqrt(Hz)", "accel u/sqrt(s)" = "m/s^3/sqrt(Hz)",
          "accel u*s" = "m/s", "accel u/s" = "m/s^3")
  tab$si <- unname(si[paste(tab$sensor, dim)])
  tab$dim <- unname(dim)
  tab
}

# Dimensions are the catalogue's parameter units, written with u, the rate
# unit: "u" (rate), "u*sqrt(s)", "u/sqrt(s)", "u*s", "u/s". The `kind` of a
# dimension is "rate" for u, else the first catalogue entry (in catalogue
# order) whose amplitude has that unit; a kind's dimension is its amplitude's
# unit. So units.R names no effect kind.
dim_kind <- function(dim) {
  if (identical(dim, "u")) return("rate")
  for (e in catalogue()) {
    p <- e$params
    if (any(p$role == "amp" & p$unit == dim)) return(e$name)
  }
  dim
}

kind_dim <- function(kind) {
  if (identical(kind, "rate") || grepl("^u", kind)) {
    return(if (identical(kind, "rate")) "u" else kind)
  }
  e <- catalogue()[[kind]]
  if (is.null(e)) return(NA_character_)
  u <- e$params$unit[e$params$role == "amp"]
  if (length(u)) u[1L] else NA_character_
}

# The kinds av_units() accepts: "rate" and the kinds of the other dimensions.
unit_kinds <- function() unique(unit_table()$kind)

# Normalise a spelling: no spaces, "s2" -> "s^2", micro sign -> u.
normalize_unit <- function(x) {
  x <- gsub("[[:space:]]", "", x)
  x <- gsub("\u00b5|\u03bc", "u", x)
  x <- gsub("s2$", "s^2", x)
  x <- gsub("s2/", "s^2/", x, fixed = TRUE)
  x <- gsub("s3/", "s^3/", x, fixed = TRUE)
  x <- sub("^(deg|rad)/sec$", "\\1/s", x)
  x <- sub("^dps$", "deg/s", x)
  x <- sub("^G$", "g", x)
  x <- sub("^m/s/s$", "m/s^2", x)
  x <- sub("^rt", "sqrt", x)
  x
}

lookup_unit <- function(unit, arg = "unit", sensor = NULL, kind = NULL) {
  if (!is.character(unit) || length(unit) != 1L || is.na(unit)) {
    abort("`", arg, "` must be a single unit name (see av_units()), not ",
          describe_type(unit), ".", class = "units")
  }
  tab <- unit_table()
  row <- tab[tab$unit == normalize_unit(unit), ]
  if (!is.null(sensor)) row <- row[row$sensor == sensor, ]
  if (!is.null(kind)) row <- row[row$kind == kind, ]
  if (nrow(row) != 1L) {
    cand <- tab$unit
    if (!is.null(sensor)) cand <- tab$unit[tab$sensor == sensor]
    if (!is.null(kind)) cand <- tab$unit[tab$unit %in% cand & tab$kind == kind]
    abort("`", arg, "` = \"", unit, "\" is not a known ",
          if (!is.null(sensor)) paste0(sensor, " "),
          if (!is.null(kind)) paste0(kind, " "), "unit; use one of ",
          paste0('"', unique(cand), '"', collapse = ", "), ".", class = "units")
  }
  as.list(row)
}

match_sensor <- function(sensor, arg = "sensor") {
  if (!is.character(sensor) || length(sensor) != 1L ||
      !sensor %in% c("gyro", "accel")) {
    abort("`", arg, "` must be \"gyro\" or \"accel\", not ",
          format_value(sensor), ".", class = "argument")
  }
  sensor
}

# Datasheet units of each dimension, by sensor: what datasheet() shows
# beside SI. More than one where the field uses several.
datasheet_units <- function(sensor) {
  if (identical(sensor, "gyro")) {
    list("u*sqrt(s)" = "deg/sqrt(h)", "u" = "deg/h", "u/sqrt(s)" = "deg/h/sqrt(h)")
  } else if (identical(sensor, "accel")) {
    list("u*sqrt(s)" = c("m/s/sqrt(h)", "ug/sqrt(Hz)"), "u" = c("ug", "mg"),
         "u/sqrt(s)" = "m/s/h^(3/2)")
  } else {
    list()
  }
}

# The SI unit of `kind` ("rate", a catalogue kind or a dimension such as
# "u*sqrt(s)") for `sensor`; for an unknown sensor (NA) the dimension itself,
# with u the input's rate unit.
si_unit <- function(sensor, kind) {
  dim <- kind_dim(kind)
  if (is.na(sensor)) return(dim)
  tab <- unit_table()
  tab$si[tab$sensor == sensor & tab$dim == dim][1L]
}

# Units checked on the data (read_imu(), imu_record()). Accelerometers: a
# static record shows gravity, |mean a| = 1 g = 9.80665 m/s^2 (CGPM 1901),
# so three axes tell their unit. Returns the (possibly detected) units and a
# table of what was checked.
gravity_units <- c("m/s^2" = 9.80665, "g" = 1, "mg" = 1000)

check_imu_units <- function(x, sensors, units, freq, assumed, units_source,
                            source, quiet = FALSE) {
  ch <- colnames(x)
  src <- rep(if (assumed) "assumed" else units_source, length(ch))
  evidence <- rep(NA_character_, length(ch))
  warning_text <- rep("", length(ch))
  acc <- which(sensors == "accel")
  said <- NULL
  if (length(acc) == 3L) {
    u <- unique(units[acc])
    r <- sqrt(sum(colMeans(x)[acc]^2))   # colMeans(x): no copy of columns
    hit <- names(gravity_units)[abs(r / gravity_units - 1) <= 0.1]
    if (length(u) == 1L && is.finite(r)) {
      evidence[acc] <- sprintf("|mean a| = %.5g %s on 3 axes", r, u)
      if (length(hit) && hit != u) {
        if (assumed) {
          units[acc] <- hit
          src[acc] <- "gravity"
          evidence[acc] <- sprintf("|mean a| = %.5g %s on 3 axes (gravity)", r, hit)
          said <- sprintf("accelerometers read as %s: their mean has norm %.5g, gravity in %s",
                          hit, r, hit)
        } else {
          warn(source, ": the accelerometers' mean has norm ", format(signif(r, 5)),
               " ", u, ", which is gravity in ", hit, ", not in ", u,
               " (1 g = 9.80665 m/s^2 on a static record); the samples look like ",
               hit, ": give units = c(accel = \"", hit, "\") if so.",
               class = "accel_units")
          evidence[acc] <- paste0(evidence[acc], ": looks like ", hit)
          warning_text[acc] <- sprintf(
            "units suspect: the accelerometers' mean norm %.5g %s is gravity in %s", r, u, hit)
        }
      } else if (length(hit)) {
        if (assumed) {
          src[acc] <- "gravity"
          said <- sprintf("accelerometers in %s, as gravity confirms (|mean a| = %.5g)",
                          hit, r)
        }
        evidence[acc] <- paste0(evidence[acc], " (gravity)")
      }
    }
  }
  if (assumed && !quiet) {
    message(basename(source), ": no units given; assuming rad/s for ",
            "gyroscopes", if (is.null(said)) " and m/s^2 for accelerometers",
            " (set `units`)", if (!is.null(said)) paste0("; ", said), ".")
  } else if (!is.null(said) && any(src == "gravity" & units != "m/s^2")) {
    message(basename(source), ": ", said, ".")
  }
  list(units = units,
       checks = data.frame(channel = ch, sensor = unname(sensors),
                           unit = unname(units), source = src,
                           evidence = evidence, warning = warning_text,
                           stringsAsFactors = FALSE))
}

# Gyroscopes: white noise N from the Allan deviation at about 1 s (N = ADEV
# sqrt(tau) where white noise dominates; IEEE Std 952 Annex C). Real gyros
# span about 1e-4 deg/sqrt(h) (navigation grade) to a few deg/sqrt(h)
# (consumer MEMS); outside 1e-5..60 the unit is almost surely wrong.
gyro_noise_range <- c(1e-5, 60)
# A static gyro reads its bias plus Earth's rate (7.3e-5 rad/s): MEMS biases
# reach a few deg/s, never 1 rad/s (57 deg/s).
gyro_mean_limit <- 1

check_gyro_noise <- function(x, sensors, units, freq, checks, source,
                             assumed = FALSE) {
  gy <- which(sensors == "gyro")
  if (!length(gy)) return(checks)
  to_dph <- 180 / pi * 60
  n <- nrow(x)
  m <- max(1L, min(as.integer(round(freq)), n %/% 10L))
  k <- n %/% m
  if (k < 10L) return(checks)
  msgs <- character()
  means <- colMeans(x)
  for (j in gy) {
    av <- col_block_avar(x, j, m)
    N <- sqrt(av * m / freq) * to_dph
    if (!is.finite(N) || N == 0) next
    mean_rate <- abs(means[[j]])
    checks$evidence[j] <- sprintf("N ~ %.3g deg/sqrt(h) from ADEV at %.3g s; |mean| %.3g rad/s",
                                  N, m / freq, mean_rate)
    if (N > gyro_noise_range[2L] || N < gyro_noise_range[1L] ||
        mean_rate > gyro_mean_limit) {
      cur <- lookup_unit(units[[j]], sensor = "gyro", kind = "rate")$to_si
      cand <- c("deg/s", "rad/s", "deg/h", "mrad/s")
      f <- vapply(cand, function(u) lookup_unit(u, sensor = "gyro", kind = "rate")$to_si, 0)
      alt <- N * f / cur
      ok <- cand[alt >= 1e-4 & alt <= 30 & cand != units[[j]]]
      checks$evidence[j] <- paste0(checks$evidence[j], ": implausible")
      checks$warning[j] <- sprintf(
        "units suspect: white noise N ~ %.3g deg/sqrt(h)%s as %s, outside what real gyros show",
        N, if (mean_rate > gyro_mean_limit) sprintf(" and mean %.3g rad/s", mean_rate) else "",
        units[[j]])
      msgs <- c(msgs, sprintf("%s: white noise N ~ %.3g deg/sqrt(h)%s if the samples are %s%s",
                              colnames(x)[j], N,
                              if (mean_rate > gyro_mean_limit)
                                sprintf(" and a mean rate of %.3g rad/s", mean_rate) else "",
                              units[[j]],
                              if (length(ok)) sprintf("; as %s it would be %.3g", ok[1L],
                                                      alt[match(ok[1L], cand)]) else ""))
      attr(msgs, "alt") <- c(attr(msgs, "alt"), if (length(ok)) ok[1L])
    }
  }
  if (length(msgs)) {
    alt <- attr(msgs, "alt")
    warn(source, ": the gyroscope units look wrong (real gyros span ",
         gyro_noise_range[1L], " to ", gyro_noise_range[2L],
         " deg/sqrt(h) of white noise, and a static one reads less than ",
         gyro_mean_limit, " rad/s):\n", paste0("  - ", msgs, collapse = "\n"),
         if (length(alt)) paste0("\nGive units = c(gyro = \"", alt[1L], "\") ",
                                 "(CLI: --gyro-units ", alt[1L], ") if they are ",
                                 alt[1L], "."),
         class = "gyro_units")
  }
  checks
}

# The unit checks that failed in an analysis' record: one row per channel
# with its warning (none for a record without checks).
unit_warnings <- function(a) {
  uc <- a$record$unit_checks
  if (is.null(uc) || is.null(uc$warning)) {
    return(data.frame(channel = character(), warning = character()))
  }
  uc <- uc[nzchar(uc$warning), , drop = FALSE]
  data.frame(channel = uc$channel, warning = uc$warning, stringsAsFactors = FALSE)
}

# The failed unit checks of one channel as one text ("" when none).
channel_unit_warning <- function(uw, channel) {
  paste(uw$warning[uw$channel == channel], collapse = "; ")
}

# The failed unit checks as comment lines for a written file ("" prefix).
unit_warning_lines <- function(a) {
  w <- unit_warnings(a)
  if (!nrow(w)) return(character())
  c("WARNING: the units failed their checks; the values below are wrong if the units are:",
    sprintf("WARNING:   %s: %s", w$channel, w$warning))
}
