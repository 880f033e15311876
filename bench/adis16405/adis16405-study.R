# What the raw ADIS16405 recordings show, axis by axis (issue 9, phase 1):
# the sensor's filter (ACF at lags 1..16 with the slow-process level taken
# out, the periodogram's roll-off, the bandwidth it implies), spectral lines
# and harmonic sets, broad bands (resonances), bias steps, warm-up, spikes,
# and the white-noise level N read where the ADEV slope is -1/2. These
# decide which effects the catalogue needs.
#
# Reads ../shared/data (not shipped) at run time; writes only derived
# figures to bench/adis16405/adis16405-study.txt.
#   Rscript bench/adis16405/adis16405-study.R        (about 2 minutes)
pkgload::load_all(".", quiet = TRUE)
shared <- Sys.getenv("ALLANVAR_SHARED_DATA", "../shared/data")
if (!dir.exists(shared)) shared <- "/work/shared/data"
stopifnot(dir.exists(shared))
options(allanvar.threads = 1L)

# N where the ADEV slope is -1/2: local slopes between octave taus; the
# longest run of slopes within -0.5 +- 0.1 starting at tau >= 0.05 s;
# N = median of adev * sqrt(tau) there.
white_level <- function(av) {
  tau <- av$tau
  ad <- av$adev
  sl <- diff(log(ad)) / diff(log(tau))
  ok <- abs(sl + 0.5) < 0.1 & tau[-1L] >= 0.05
  if (!any(ok)) return(c(N = NA, from = NA, to = NA))
  r <- rle(ok)
  ends <- cumsum(r$lengths)
  starts <- ends - r$lengths + 1L
  k <- which(r$values)[which.max(r$lengths[r$values])]
  idx <- starts[k]:(ends[k] + 1L)
  c(N = stats::median(ad[idx] * sqrt(tau[idx])), from = tau[idx[1L]],
    to = tau[idx[length(idx)]])
}

rows <- list()
line_rows <- list()
out <- file("bench/adis16405/adis16405-study.txt", "w")
say <- function(...) {
  txt <- sprintf(...)
  cat(txt, "\n", sep = "")
  writeLines(txt, out)
}
say("# ADIS16405: what the raw data show (bench/adis16405/adis16405-study.R, %s)", format(Sys.Date()))
for (k in 1:3) {
  mat <- readRDS(file.path(shared, sprintf("adis16405_unit%d.rds", k)))
  freq <- attr(mat, "freq")
  for (axis in colnames(mat)) {
    x <- mat[, axis]
    t0 <- proc.time()[["elapsed"]]
    av <- allan(x, freq, taus = "octave")
    wl <- white_level(av)
    fe <- filter_evidence(x, freq)
    bw_ma <- if (!is.null(fe$start$ma)) filter_bandwidth(filter_spec("ma", L = fe$start$ma$L), 1 / freq) else NULL
    bw_lp1 <- if (!is.null(fe$start$lp1)) filter_bandwidth(filter_spec("lp1", fc = fe$start$lp1$fc, freq = freq), 1 / freq) else NULL
    bd <- find_bands(x, freq)
    ln <- harmonic_sets(lines_outside_bands(spectral_lines(x, freq, max_lines = 20L), bd))
    ln <- visible_lines(ln, 1 / freq, max(av$tau), freq)
    sp <- detect_spikes(x, freq)
    st <- detect_steps(remove_spikes(x, sp), freq)
    pu <- attr(st, "pulses")
    wu <- detect_warmup(remove_spikes(x, sp), freq)
    # Does filtered white noise explain the short tau? Predicted AV at
    # m = 1, 2, 4 from N (slope -1/2) and the ma filter read from the ACF,
    # over the measured AV.
    pred <- if (!is.null(fe$start$ma) && is.finite(wl[["N"]]))
      wl[["N"]]^2 * filter_av(c(1, 2, 4), filter_spec("ma", L = fe$start$ma$L), 1 / freq) else rep(NA, 3)
    meas <- av$avar[match(c(1, 2, 4), av$m)]
    el <- proc.time()[["elapsed"]] - t0
    rows[[length(rows) + 1L]] <- data.frame(
      unit = k, axis = axis, N_slope = signif(wl[["N"]], 3),
      N_tau = sprintf("%.2g-%.3g", wl[["from"]], wl[["to"]]),
      acf1 = round(fe$acf$r[1L], 3), acf2 = round(fe$acf$r[2L], 3),
      acf1_filter = round(fe$r1, 3),
      slow_level = round(fe$base, 4), filt_len = fe$length,
      psd_nyq = round(fe$psd_ratio, 2),
      ma_L = if (is.null(fe$start$ma)) NA else round(fe$start$ma$L, 3),
      f3db_ma = if (is.null(bw_ma)) NA else signif(bw_ma$f3db, 3),
      enbw_ma = if (is.null(bw_ma)) NA else signif(bw_ma$enbw, 3),
      lp1_fc = if (is.null(fe$start$lp1)) NA else signif(fe$start$lp1$fc, 3),
      av_pred_meas_m1 = round(pred[1L] / meas[1L], 3),
      av_pred_meas_m2 = round(pred[2L] / meas[2L], 3),
      av_pred_meas_m4 = round(pred[3L] / meas[3L], 3),
      lines = sum(ln$kind == "line"), bands = nrow(bd),
      band = if (nrow(bd)) sprintf("%.1f Hz w %.1f share %.2f", bd$f_center[1], bd$width[1], bd$share[1]) else "",
      spikes = nrow(sp), steps = nrow(st), pulses = nrow(pu),
      warmup = if (wu$present) sprintf("A=%.3g tc=%.0fs z=%.0f", wu$amplitude, wu$tc, wu$z) else "",
      seconds = round(el, 1), stringsAsFactors = FALSE)
    if (nrow(ln)) line_rows[[length(line_rows) + 1L]] <- cbind(unit = k, axis = axis, ln)
    if (nrow(st)) {
      say("unit%d %s steps: %s", k, axis,
          paste(sprintf("t=%.0fs size=%.3g (z=%.1f, se %.2g)", st$time, st$size, st$z, st$se),
                collapse = "; "))
    }
    if (nrow(pu)) {
      say("unit%d %s transients (opposite steps < 120 s apart): %s", k, axis,
          paste(sprintf("%.0f-%.0fs size %.3g", pu$start, pu$end, pu$size), collapse = "; "))
    }
    if (nrow(sp)) {
      say("unit%d %s spikes: %d, largest |size| %.3g at t=%.1fs", k, axis, nrow(sp),
          max(abs(sp$size)), sp$time[which.max(abs(sp$size))])
    }
  }
}
tab <- do.call(rbind, rows)
lines <- do.call(rbind, line_rows)
say("")
say("## Per axis")
writeLines(utils::capture.output(print(tab, row.names = FALSE)), out)
print(tab, row.names = FALSE)
say("")
say("## Spectral lines (Welch, resolution %.4f Hz; kind line/band; source = harmonic set)",
    attr(spectral_lines(rnorm(1e6), 100), "resolution"))
ls <- lines[, c("unit", "axis", "f0", "amp", "ratio", "kind", "source", "harmonic",
                "pattern", "visible")]
ls$f0 <- signif(ls$f0, 4)
ls$amp <- signif(ls$amp, 3)
ls$ratio <- signif(ls$ratio, 3)
writeLines(utils::capture.output(print(ls, row.names = FALSE)), out)
print(ls, row.names = FALSE)
close(out)
