# Compare allan()'s further statistics (TDEV, MTOT, TTOT, HTOT, Theo1,
# TheoH, MTIE, TIE rms) with every Stable32 run in the test suites of the
# Python packages allantools (github.com/aewallin/allantools, tests/) and
# allantoolkit (gitlab/github amv213/allantoolkit, tests/assets/).
#
# The reference data are not part of this repository (their licences are
# not ours): point ALLANVAR_PEER_DATA at one or more checkouts (separated by
# ":"), e.g.
#   git -C <mirror> archive HEAD tests | tar -x -C /tmp/allantools
#   ALLANVAR_PEER_DATA=/tmp/allantools:/tmp/allantoolkit \
#     Rscript tools/check-stable32-types.R
# ALLANVAR_NOISE_ID=stable32 (or coverage) sets options(allanvar.noise_id)
# (R/taus.R noise_id_rules(), src/noise_id.h). Counts on allantools' and
# allantoolkit's suites: 334 of 351 rows' limits by default, 342 with
# "stable32", 318 "coverage".
# Run from the repository root (it loads the package with pkgload) or with
# allanvar installed. tests/testthat/test-types-stable32.R runs it when the
# variable is set.
#
# A value matches when allan()'s value rounded to the printed significant
# digits equals the printed value (a last-digit tie, |difference| within
# 0.5001 units, counts as a match); the count of terms is compared where
# Stable32 prints it; a confidence limit "agrees" when it lies within 25% of
# Stable32's half-width of Stable32's limit.

# Rows of a Stable32 result table: every line whose first field is a number.
read_stable32 <- function(path) {
  lines <- readLines(path, warn = FALSE)
  lines <- trimws(lines)
  lines <- lines[nzchar(lines) & !startsWith(lines, "#")]
  f <- strsplit(lines, "[[:space:]]+")
  num <- vapply(f, function(z) !is.na(suppressWarnings(as.numeric(z[1]))), TRUE)
  f <- f[num]
  w <- lengths(f)
  f <- f[w == stats::median(w)]
  m <- do.call(rbind, lapply(f, as.numeric))
  list(values = m, digits = do.call(rbind, lapply(f, function(z) {
    vapply(z, function(s) nchar(gsub("[^0-9]", "", sub("e.*$", "", s))), 1L)
  })))
}

read_series <- function(path) {
  con <- if (grepl("\\.gz$", path)) gzfile(path) else file(path)
  on.exit(close(con))
  lines <- readLines(con, warn = FALSE)
  lines <- trimws(lines)
  lines <- lines[nzchar(lines) & !startsWith(lines, "#")]
  vapply(strsplit(lines, "[[:space:]]+"), function(z) as.numeric(z[length(z)]),
         1)
}

# The reference runs: data file, its kind and tau0, the result files with
# the allan() type and debias setting they were made with.
stable32_type_cases <- function() {
  at <- function(...) file.path("tests", ...)
  kit <- function(...) file.path("tests", "assets", ...)
  sr <- function(kind, file) {
    grid <- c("decade", "many", "octave")
    out <- list()
    for (g in grid) {
      for (ty in c("tdev", "mtotdev", "ttotdev", "htotdev", "theoh", "mtie",
                   "tierms")) {
        out[[length(out) + 1L]] <- list(file = kit("Sr87", kind, g,
                                                   paste0(ty, ".txt")),
                                        type = ty, grid = g)
      }
    }
    out[[length(out) + 1L]] <- list(file = kit("Sr87", kind, "fastu", "mtie.txt"),
                                    type = "mtie", grid = "fast")
    out
  }
  list(
    list(data = at("phasedat", "PHASE.DAT"), kind = "phase", tau0 = 1,
         runs = list(
           list(file = at("phasedat", "phase_dat_tdev.txt"), type = "tdev"),
           list(file = at("phasedat", "phase_dat_tdev_octave.txt"), type = "tdev"),
           list(file = at("phasedat", "phase_dat_mtie.txt"), type = "mtie"),
           list(file = at("phasedat", "phase_dat_tierms.txt"), type = "tierms"),
           list(file = at("phasedat", "phase_dat_mtotdev.txt"), type = "mtotdev",
                debias = TRUE, note = "Stable32 1.53, bias-corrected"),
           list(file = at("phasedat", "phase_dat_mtotdev_octave.txt"),
                type = "mtotdev"),
           list(file = at("phasedat", "phase_dat_mtotdev_decade.txt"),
                type = "mtotdev"),
           list(file = at("phasedat", "phase_dat_mtotdev_octave_alpha0.txt"),
                type = "mtotdev"),
           list(file = at("phasedat", "phase_dat_ttotdev_octave.txt"),
                type = "ttotdev"),
           list(file = at("phasedat", "phase_dat_ttotdev_decade.txt"),
                type = "ttotdev"),
           list(file = at("phasedat", "phase_dat_ttotdev_all.txt"),
                type = "ttotdev"),
           list(file = at("phasedat", "phase_dat_htotdev_octave.txt"),
                type = "htotdev"),
           list(file = at("phasedat", "phase_dat_htotdev_octave_nobias.txt"),
                type = "htotdev"),
           list(file = at("phasedat", "phase_dat_theo1_alpha0.txt"),
                type = "theo1"),
           list(file = at("phasedat", "phase_dat_theo1_alpha0_decade.txt"),
                type = "theo1"))),
    list(data = at("Cs5071A", "5071A_phase.txt.gz"), kind = "phase", tau0 = 1,
         runs = lapply(c("tdev_all", "tdev_decade", "mtie_all", "mtie_decade",
                         "mtie_fast", "tierms_all", "tierms_decade"),
                       function(f) list(file = at("Cs5071A", paste0(f, ".txt")),
                                        type = sub("_.*$", "", f)))),
    list(data = at("Keysight53230A_ti_noise_floor", "tic_phase.txt"),
         kind = "phase", tau0 = 1,
         runs = list(
           list(file = at("Keysight53230A_ti_noise_floor", "tic_tdev.txt"),
                type = "tdev"),
           list(file = at("Keysight53230A_ti_noise_floor", "tic_tierms.txt"),
                type = "tierms"))),
    list(data = at("gps", "gps_1pps_phase_data.txt.gz"), kind = "phase",
         tau0 = 1, runs = list(list(file = at("gps", "stable32_TDEV_octave.txt"),
                                    type = "tdev"))),
    list(data = at("ocxo", "ocxo_frequency.txt"), kind = "freq", tau0 = 1,
         scale = 1e7,
         runs = list(list(file = at("ocxo", "tdev_octave.txt"), type = "tdev",
                          loose = TRUE),
                     list(file = at("ocxo", "stable32_tdev_alltau.txt"),
                          type = "tdev"))),
    list(data = at("pink_frequency", "pink_frequency.txt"), kind = "freq",
         tau0 = 42, runs = list(list(file = at("pink_frequency", "tdev.txt"),
                                     type = "tdev"))),
    list(data = kit("Sr87", "phase", "phase_data.txt"), kind = "phase",
         tau0 = 2.5, runs = sr("phase")),
    list(data = kit("Sr87", "phase0", "phase0_data.txt"), kind = "phase",
         tau0 = 2.5, runs = sr("phase0")),
    list(data = kit("Sr87", "freq", "freq_data.txt"), kind = "freq",
         tau0 = 2.5, runs = sr("freq"))
  )
}

# Compare one result file; a data frame with one row per compared value.
# Types with a noise-dependent bias correction are computed raw and
# compared both raw and corrected with the noise type Stable32 printed (the
# runs differ: Stable32 1.53 corrected MTOT and TTOT, 1.60 did not); the
# convention that matches more rows is the file's. A TheoH table is
# compared column by column: its Allan part with the overlapping AVAR, its
# Theo1 column with allan(type = "theobr").
check_stable32_run <- function(x, tau0, kind, run, path) {
  tab <- read_stable32(path)
  v <- tab$values
  if (is.null(v) || !nrow(v)) return(NULL)
  dg <- tab$digits
  type <- run$type
  input <- if (kind == "phase") "integrated" else "rate"
  freq <- 1 / tau0
  af <- v[, 1]
  row <- function(type, af, n_s32, n, s32, ours, digits, lo_s32, hi_s32, lo,
                  hi, alpha_s32, alpha, convention = "") {
    data.frame(file = path, type = type, af = af, n_s32 = n_s32, n = n,
               s32 = s32, ours = ours, digits = digits, lo_s32 = lo_s32,
               hi_s32 = hi_s32, lo = lo, hi = hi, alpha_s32 = alpha_s32,
               alpha = alpha, convention = convention,
               L = if (kind == "phase") length(x) else length(x) + 1)
  }
  if (ncol(v) == 8L) {
    # TheoH: AF, tau, #, TheoH tau, sigma, Theo1 dev, min, max
    out <- list()
    ia <- which(v[, 5] > 0)
    if (length(ia)) {
      a <- allan(x, freq, taus = I(af[ia] * tau0), type = "overlapping",
                 input = input)
      i <- match(af[ia], a$m)
      lim <- v[ia, 6] == 0
      out[[1]] <- row("theoh/avar", af[ia], v[ia, 3], a$n[i], v[ia, 5],
                      a$adev[i], dg[ia, 5], ifelse(lim, v[ia, 7], NA),
                      ifelse(lim, v[ia, 8], NA), a$lower[i], a$upper[i], NA,
                      a$alpha[i])
    }
    it <- which(v[, 6] > 0)
    if (length(it)) {
      a <- allan(x, freq, taus = I(0.75 * af[it] * tau0), type = "theobr",
                 input = input)
      i <- match(af[it], a$m)
      out[[2]] <- row("theoh/theobr", af[it], NA, NA, v[it, 6], a$adev[i],
                      dg[it, 6], v[it, 7], v[it, 8], a$lower[i], a$upper[i],
                      NA, a$alpha[i])
    }
    out <- do.call(rbind, out)
    out$lo_a <- out$hi_a <- NA_real_
    return(out)
  }
  taus <- if (type == "theo1") 0.75 * af * tau0 else af * tau0
  has_bias <- type %in% c("mtotdev", "ttotdev", "htotdev", "theo1")
  a <- allan(x, freq, taus = I(taus), type = type, input = input,
             debias = FALSE)
  i <- match(af, a$m)
  four <- ncol(v) == 4L
  dev_col <- if (four) 4L else 6L
  ours <- a$adev[i]
  lo <- a$lower[i]
  hi <- a$upper[i]
  conv <- ""
  if (has_bias) {
    f <- sqrt(debias_factor(type, v[, 4], af))
    unit <- 10^(floor(log10(abs(v[, dev_col]))) - (dg[, dev_col] - 1))
    raw_ok <- sum(abs(ours - v[, dev_col]) <= 0.5001 * unit, na.rm = TRUE)
    cor_ok <- sum(abs(ours * f - v[, dev_col]) <= 0.5001 * unit, na.rm = TRUE)
    if (cor_ok > raw_ok) {
      ours <- ours * f
      lo <- lo * f
      hi <- hi * f
      conv <- "corrected"
    } else {
      conv <- "raw"
    }
  }
  ns32 <- v[, 3]
  if (type == "mtie" && length(unique(ns32)) == 1L) ns32 <- NA  # record length
  out <- row(type, af, ns32, a$n[i], v[, dev_col], ours, dg[, dev_col],
             if (four) NA else v[, 5], if (four) NA else v[, 7], lo, hi,
             if (four) NA else v[, 4], a$alpha[i], conv)
  # the limits again with Stable32's noise type: tests the EDF formulas
  # apart from the noise identification
  out$lo_a <- out$hi_a <- NA_real_
  if (!four && !type %in% c("mtie", "tierms")) {
    L <- if (input == "rate") length(x) + 1 else length(x)
    al <- as.integer(v[, 4])
    e <- if (type == "tdev") {
      allan_edf_direct("modified", af, L - 3 * af + 1, L, al)
    } else {
      extra_edf(type, af, L, al, a$n[i])
    }
    ci <- allan_ci(ours^2, e, 0.683)
    out$lo_a <- ci$lower
    out$hi_a <- ci$upper
  }
  if (isTRUE(run$loose)) out$loose <- TRUE
  out
}

check_stable32_types <- function(roots = strsplit(Sys.getenv("ALLANVAR_PEER_DATA"),
                                                  ":", fixed = TRUE)[[1]],
                                 verbose = TRUE) {
  roots <- roots[nzchar(roots) & dir.exists(roots)]
  found <- function(rel) {
    for (r in roots) if (file.exists(file.path(r, rel))) return(file.path(r, rel))
    NULL
  }
  rows <- list()
  for (cs in stable32_type_cases()) {
    dpath <- found(cs$data)
    if (is.null(dpath)) next
    x <- read_series(dpath)
    if (!is.null(cs$scale)) x <- x / cs$scale - 1
    for (run in cs$runs) {
      rpath <- found(run$file)
      if (is.null(rpath)) next
      r <- tryCatch(check_stable32_run(x, cs$tau0, cs$kind, run, rpath),
                    error = function(e) {
                      message(rpath, ": ", conditionMessage(e))
                      NULL
                    })
      if (!is.null(r)) {
        r$grid <- if (is.null(run$grid)) "" else run$grid
        rows[[length(rows) + 1L]] <- r
      }
    }
  }
  if (!length(rows)) return(invisible(NULL))
  rows <- lapply(rows, function(r) {
    if (is.null(r$loose)) r$loose <- FALSE
    r
  })
  d <- do.call(rbind, rows)
  ok_s32 <- is.finite(d$s32) & d$s32 > 0
  unit <- 10^(floor(log10(abs(d$s32))) - (d$digits - 1))
  u <- abs(d$ours - d$s32) / unit
  d$value_ok <- ok_s32 & !is.na(d$ours) & u <= 0.5 + 1e-9
  # last-digit ties: within 0.51 of a unit (Stable32 rounds a few of these
  # the other way)
  d$value_tie <- ok_s32 & !is.na(d$ours) & !d$value_ok & u <= 0.51
  # Stable32 prints Theo1's count with 5 digits, and the record length as
  # the count of its non-"fast" MTIE runs
  tol <- ifelse(d$type == "theo1", 0.5 * 10^(floor(log10(pmax(1, d$n_s32))) - 4),
                0)
  d$n_ok <- is.na(d$n_s32) | d$n_s32 == 0 |
    (!is.na(d$n) & abs(d$n - d$n_s32) <= tol + 1e-9)
  lim <- ok_s32 & is.finite(d$lo_s32) & d$lo_s32 > 0 & is.finite(d$hi_s32)
  d$lim_ok <- NA
  d$lim_ok[lim] <- abs(d$lo[lim] - d$lo_s32[lim]) <=
    0.25 * (d$s32[lim] - d$lo_s32[lim]) &
    abs(d$hi[lim] - d$hi_s32[lim]) <= 0.25 * (d$hi_s32[lim] - d$s32[lim])
  d$lim_ok[lim & is.na(d$lim_ok)] <- FALSE
  d$lim_a_ok <- NA
  la <- lim & is.finite(d$lo_a)
  d$lim_a_ok[la] <- abs(d$lo_a[la] - d$lo_s32[la]) <=
    0.25 * (d$s32[la] - d$lo_s32[la]) &
    abs(d$hi_a[la] - d$hi_s32[la]) <= 0.25 * (d$hi_s32[la] - d$s32[la])
  if (verbose) {
    grp <- paste(d$file, d$type)
    s <- do.call(rbind, lapply(split(seq_len(nrow(d)), factor(grp, unique(grp))),
                               function(i) {
      data.frame(file = sub(".*/tests/", "", d$file[i[1]]), type = d$type[i[1]],
                 alpha = sum(d$alpha[i] == d$alpha_s32[i], na.rm = TRUE),
                 rows = length(i),
                 conv = d$convention[i[1]],
                 values = sum(d$value_ok[i]), ties = sum(d$value_tie[i]),
                 of = sum(ok_s32[i]),
                 n_ok = sum(d$n_ok[i]),
                 limits = sum(d$lim_ok[i], na.rm = TRUE),
                 of_limits = sum(!is.na(d$lim_ok[i])),
                 lim_s32_alpha = sum(d$lim_a_ok[i], na.rm = TRUE),
                 max_rel = signif(max(abs(d$ours[i] / d$s32[i] - 1)[ok_s32[i]],
                                      na.rm = TRUE), 2))
    }))
    print(s, row.names = FALSE)
    s$loose <- NULL
    st <- !d$loose
    cat(sprintf(paste0(
      "values: %d of %d match to the printed digits, %d more are last-digit ",
      "ties (within 0.51 of a unit); counts: %d of %d; noise type as ",
      "Stable32: %d of %d; limits within 25%% of the half-width: %d of %d ",
      "(%d of %d with Stable32's noise type)\n"),
      sum(d$value_ok[st]), sum(ok_s32[st]), sum(d$value_tie[st]),
      sum(d$n_ok[st]), sum(st), sum(d$alpha == d$alpha_s32 & st, na.rm = TRUE),
      sum(!is.na(d$alpha_s32) & st), sum(d$lim_ok[st], na.rm = TRUE),
      sum(!is.na(d$lim_ok[st])), sum(d$lim_a_ok[st], na.rm = TRUE),
      sum(!is.na(d$lim_a_ok[st]))))
    if (any(d$loose)) {
      cat("Not counted (reference made from differently normalised data; ",
          "allantools checks it at 2e-3 only): ",
          paste(unique(sub(".*/tests/", "", d$file[d$loose])), collapse = ", "),
          "\n", sep = "")
    }
  }
  invisible(d)
}

if (sys.nframe() == 0L) {
  # ALLANVAR_NOISE_ID: the noise-identification rules (default, stable32,
  # coverage)
  if (nzchar(Sys.getenv("ALLANVAR_NOISE_ID"))) {
    options(allanvar.noise_id = Sys.getenv("ALLANVAR_NOISE_ID"))
  }
  if (file.exists("DESCRIPTION") && requireNamespace("pkgload", quietly = TRUE)) {
    pkgload::load_all(quiet = TRUE)
  } else {
    # an installed build: the internals the checks call (debias_factor(),
    # allan_edf_direct()) on the search path too
    library(allanvar)
    attach(asNamespace("allanvar"), name = "allanvar_internals",
           warn.conflicts = FALSE)
  }
  d <- check_stable32_types()
  if (is.null(d)) {
    cat("No reference data found: set ALLANVAR_PEER_DATA to allantools/",
        "allantoolkit checkouts.\n", sep = "")
  }
}
