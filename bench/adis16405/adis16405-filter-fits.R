# The shipped ADIS16405 Allan variance tables (data(adis16405_av)) fitted
# with the datasheet model N + B + K and with the sensor's filter in place
# of N (issue 9, phase 2 start): filter + B + K + gm, plus a resonance on
# the z gyroscopes and a sinusoid on the accelerometers (the effects the raw
# data show, bench/adis16405/adis16405-study.md). No raw data needed.
#   Rscript bench/adis16405/adis16405-filter-fits.R     (about 3 minutes)
pkgload::load_all(".", quiet = TRUE)
data(adis16405_av)
rows <- list()
for (k in 1:3) for (axis in c("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")) {
  av <- adis16405_av$av
  d <- av[av$unit == k & av$axis == axis, c("tau", "avar", "edf")]
  # N where the ADEV slope is -1/2 (as in adis16405-study.R)
  ad <- sqrt(d$avar)
  sl <- diff(log(ad)) / diff(log(d$tau))
  okk <- which(abs(sl + 0.5) < 0.1 & d$tau[-1] >= 0.05)
  n_slope <- if (length(okk)) stats::median(ad[okk] * sqrt(d$tau[okk])) else NA
  tm <- c("filter", "B", "K", "gm")
  st <- NULL
  if (axis == "gyro_z") {
    tm <- c(tm, "resonance")
    st <- c(resonance.fr = 19.8, resonance.tc = 0.1)
  }
  if (grepl("accel", axis)) {
    tm <- c(tm, "sinusoid")
    st <- c(sinusoid1.f0 = c(0.5641, 0.5663, 0.5397)[k])
  }
  t0 <- proc.time()[["elapsed"]]
  f0 <- avfit(d, terms = c("N", "B", "K"), n = 1e6, freq = 100)
  f1 <- avfit(d, terms = tm, n = 1e6, freq = 100, start = st)
  cf <- coef(f1)
  rows[[length(rows) + 1L]] <- data.frame(
    unit = k, axis = axis, chi2_NBK = round(f0$chi2, 1), N_NBK = signif(coef(f0)[["N"]], 3),
    model = paste(tm, collapse = "+"), chi2 = round(f1$chi2, 2),
    Nf = signif(cf[["filter.Nf"]], 4), N_slope = signif(n_slope, 4),
    Nf_vs_slope = round(cf[["filter.Nf"]] / n_slope - 1, 3),
    L = round(cf[["filter.L"]], 3),
    enbw_Hz = signif(filter_bandwidth(filter_spec("ma", L = cf[["filter.L"]]), 0.01)$enbw, 3),
    converged = f1$convergence$converged,
    seconds = round(proc.time()[["elapsed"]] - t0, 1))
  print(rows[[length(rows)]], row.names = FALSE)
}
tab <- do.call(rbind, rows)
print(tab, row.names = FALSE)
writeLines(utils::capture.output(print(tab, row.names = FALSE)),
           "bench/adis16405/adis16405-filter-fits.txt")
