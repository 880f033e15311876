# Derived figures of the measured ADIS16405 recordings (issue 4, item 6).
#
# Reads the three static 100 Hz recordings (1e6 x 6 each; gyro deg/s,
# accel g) from ../shared/data, which are NOT shipped, and saves only derived
# figures: the overlapping Allan variance tables (10 points per decade), the
# raw-data diagnostics (quantization grid, lag-1 ACF, trend, spectral lines,
# lag-1 noise identification), the datasheet fit (N, B, K) and the closed
# loop's steps and refined coefficients.
#
# Data: Department of Geomatics Engineering, University of Calgary, as
# published in the imudata R package (S. Guerrier, G. Bakalli et al.),
# licensed CC BY-NC-SA 4.0.
#
# Run from the package root:  Rscript data-raw/adis16405.R
# (about 10 minutes on one core), or, after
#   ADIS_SAVE=/tmp/refs Rscript bench/adis16405/adis16405-check.R
# as  ADIS_REFS=/tmp/refs Rscript data-raw/adis16405.R  to reuse its fits.

pkgload::load_all(".", quiet = TRUE)

shared <- Sys.getenv("ALLANVAR_SHARED_DATA", "../shared/data")
if (!dir.exists(shared)) shared <- "/work/shared/data"
stopifnot(dir.exists(shared))
options(allanvar.threads = 1L)

units <- c(gyro = "deg/s", accel = "g")
check_rows <- list()

# check_axis(): issue 9's Done-when checks for one axis.
adis_check_define_only <- TRUE
source("bench/adis16405/adis16405-check.R")
av_rows <- list(); diag_rows <- list(); line_rows <- list()
coef_rows <- list(); step_rows <- list(); fit_rows <- list(); noise_rows <- list()
fits <- list(); unexpl_rows <- list()

for (k in 1:3) {
  m <- readRDS(file.path(shared, sprintf("adis16405_unit%d.rds", k)))
  freq <- attr(m, "freq")
  for (axis in colnames(m)) {
    t0 <- Sys.time()
    x <- m[, axis]
    sensor <- sub("_.*$", "", axis)
    id <- sprintf("unit%d/%s", k, axis)
    av <- allan(x, freq, taus = 10, type = "overlapping")
    dg <- avdiagnose(x, freq)
    # ADIS_REFS=dir reuses the fits bench/adis16405/adis16405-check.R kept
    # (ADIS_SAVE=dir there): the same calls, not run twice on a loaded machine
    saved <- file.path(Sys.getenv("ADIS_REFS", ""), sprintf("fits_%d_%s.rds", k, axis))
    if (nzchar(Sys.getenv("ADIS_REFS")) && file.exists(saved)) {
      kept <- readRDS(saved)
      fit0 <- kept$datasheet
      ref <- kept$refined
    } else {
      fit0 <- avfit(av, terms = c("N", "B", "K"))
      ref <- avrefine(fit0, data = x, max_steps = 5)
    }
    key <- data.frame(unit = k, axis = axis, sensor = sensor,
                      rate_unit = units[[sensor]], stringsAsFactors = FALSE)
    av_rows[[id]] <- cbind(key[rep(1, nrow(av)), ], as.data.frame(av)[
      c("tau", "m", "n", "avar", "adev", "lower", "upper", "edf")], row.names = NULL)
    g <- dg$grid
    top <- if (nrow(dg$lines)) dg$lines[1, ] else
      data.frame(f0 = NA, amp = NA, ratio = NA, p_value = NA, significance = NA)
    diag_rows[[id]] <- cbind(key, data.frame(
      n = dg$n, freq = freq, sd = sd(x), lsb = g$step, levels = g$levels,
      on_grid = g$on_grid, sd_lsb = g$sd_lsb, acf1 = dg$acf1,
      trend = dg$trend$slope, trend_t = dg$trend$t, n_lines = nrow(dg$lines),
      line_f0 = top$f0, line_amp = top$amp, line_ratio = top$ratio,
      line_p = top$p_value))
    if (nrow(dg$lines)) line_rows[[id]] <- cbind(key[rep(1, nrow(dg$lines)), ],
                                                 dg$lines, row.names = NULL)
    noise_rows[[id]] <- cbind(key[rep(1, nrow(dg$noise_id)), ], dg$noise_id,
                              row.names = NULL)
    for (stage in c("datasheet", "refined")) {
      f <- if (stage == "datasheet") fit0 else ref
      coef_rows[[paste(id, stage)]] <- cbind(key[rep(1, length(coef(f))), ],
        data.frame(stage = stage, name = names(coef(f)), value = unname(coef(f)),
                   se = unname(f$se[names(coef(f))]), stringsAsFactors = FALSE),
        row.names = NULL)
    }
    st <- ref$steps
    if (nrow(st)) step_rows[[id]] <- cbind(key[rep(1, nrow(st)), ],
                                           step = seq_len(nrow(st)), st, row.names = NULL)
    fit_rows[[id]] <- cbind(key, data.frame(
      chi2_before = fit0$chi2, rms_before = fit0$rms,
      chi2_after = ref$chi2, rms_after = ref$rms, n_steps = nrow(st),
      effects = if (nrow(st)) paste(st$effect, collapse = ", ") else "",
      unconfirmed = sum(isFALSE(st$confirmed) | st$confirmed %in% FALSE),
      final_terms = paste(ref$terms, collapse = ","),
      converged = fit0$convergence$converged && ref$convergence$converged,
      failed_refits = NROW(ref$refine$failures),
      stringsAsFactors = FALSE))
    un <- ref$unexplained
    if (NROW(un)) unexpl_rows[[id]] <- cbind(key[rep(1, nrow(un)), ], un, row.names = NULL)
    fits[[id]] <- list(datasheet = fit0, refined = ref)
    check_rows[[id]] <- cbind(key, check_axis(x, freq, av, dg, ref))
    cat(sprintf("%-14s chi2 %8.1f -> %7.2f  rms %5.1f%% -> %5.1f%%  [%s]  %.0f s\n", id,
                fit0$chi2, ref$chi2, fit0$rms, ref$rms,
                fit_rows[[id]]$effects, as.numeric(Sys.time() - t0, units = "secs")))
  }
}

bind <- function(l) { out <- do.call(rbind, l); rownames(out) <- NULL; out }
check <- bind(check_rows)
writeLines(capture.output({
  cat("Issue 9 Done-when checks on the 18 ADIS16405 axes (from N, B, K, raw data given)\n\n")
  print(transform(check, acf1 = round(acf1, 3), enbw = round(enbw, 1),
                  chi2 = round(chi2, 2), n_fit = signif(n_fit, 4),
                  n_ref = signif(n_ref, 4), n_err = round(n_err, 1)),
        row.names = FALSE)
  bw <- tapply(check$enbw, check$sensor, function(v) diff(range(v, na.rm = TRUE)) /
                 mean(v, na.rm = TRUE) * 100)
  cat("\nENBW spread per sensor type (range / mean, %):\n"); print(round(bw, 1))
}), "bench/adis16405/adis16405-check-summary.txt")
adis16405_av <- list(
  av = bind(av_rows), diagnostics = bind(diag_rows), lines = bind(line_rows),
  noise_id = bind(noise_rows), fits = bind(fit_rows), coef = bind(coef_rows),
  steps = bind(step_rows), unexplained = bind(unexpl_rows), check = check,
  source = paste("ADIS16405 static recordings, 3 units x 6 axes, 100 Hz, 1e6",
                 "samples each. Department of Geomatics Engineering, University",
                 "of Calgary, via the imudata R package; CC BY-NC-SA 4.0."))
# Drop the parts the fits do not need to keep the file small, and never
# ship the recordings: no series pass may carry the data (its `x`; fits
# saved by older code kept it).
slim <- function(f) {
  f$call <- NULL
  if (!is.null(f$series)) f$series$x <- NULL
  f
}
fits <- lapply(fits, function(p) lapply(p, slim))

dir.create("data", showWarnings = FALSE)
save(adis16405_av, file = "data/adis16405_av.rda", compress = "xz")
dir.create("inst/extdata", recursive = TRUE, showWarnings = FALSE)
saveRDS(fits, "inst/extdata/adis16405_refine.rds", compress = "xz")
print(adis16405_av$fits[, c("unit", "axis", "chi2_before", "chi2_after",
                            "rms_before", "rms_after", "effects")])
