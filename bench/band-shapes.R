# The battery's bands (bench/battery-generators.R, g_band: white noise through a
# two-pole resonator, an AR(2)) against what the package describes them
# with (the resonance entry: a real AR(2) since session 17; a Lorentzian
# pair, the real part of a complex AR(1), before) and against the band
# removal the filter's raw-data check reads (remove_bands()). Prints, per
# band: the AV the band adds at 1 s and 10 s in units of the white noise's
# (0.01 per sample, 100 Hz), the same for the resonance entry's exact AV
# of equal variance, fr and tc (columns *_lorentz: the old form's name);
# whether bins 3-6 run widths from the band's centre exist (main before
# session 17 left the band in the series without them); and the filter
# check's lag-1 excess of the series white + band before and after the
# removal (no filter in it: 0 is right).
#
#   R_LIBS=/tmp/lib Rscript bench/band-shapes.R   (from the repository root)
suppressPackageStartupMessages(library(allanvar))
options(allanvar.threads = 1L)
ns <- asNamespace("allanvar")
freq <- 100
n <- 5e5
source("bench/battery-generators.R")
bands <- list(c(0.006, 7, 0.3), c(0.006, 12, 0.3), c(0.006, 30, 0.3),
              c(0.01, 12, 0.1), c(0.01, 18, 0.1), c(0.01, 21, 0.1))
rows <- list()
set.seed(5)
for (b in bands) {
  g <- g_band(n, b[1], b[2], b[3])
  a <- allan(g, freq, taus = I(c(1, 10)))
  lor <- ns$resonance_av(c(1, 10) * freq, 1 / freq, b[1], b[2], b[3])
  white <- 1e-4 / freq / c(1, 10)               # N^2 / tau, N = 0.01 / sqrt(freq)
  x <- rnorm(n, sd = 0.01) + g
  fb <- ns$find_bands(x, freq)
  j <- if (nrow(fb)) which.min(abs(fb$f_center - b[2])) else NA
  w <- if (is.na(j)) NA else max(fb$width[j], fb$f_to[j] - fb$f_from[j])
  window <- !is.na(j) && (fb$f_center[j] - 3 * w > 0 || fb$f_center[j] + 3 * w < freq / 2)
  r1 <- function(v) ns$filter_evidence(v, freq)$r1
  rows[[length(rows) + 1L]] <- data.frame(
    sd = b[1], fr = b[2], tc = b[3],
    av1_band = round(a$avar[1] / white[1], 3), av10_band = round(a$avar[2] / white[2], 3),
    av1_lorentz = round(lor[1] / white[1], 3), av10_lorentz = round(lor[2] / white[2], 3),
    run = if (is.na(j)) "" else sprintf("%.1f-%.1f", fb$f_from[j], fb$f_to[j]),
    window = window, r1_raw = round(r1(x), 4),
    r1_removed = round(r1(ns$remove_bands(x, freq, fb)), 4))
}
print(do.call(rbind, rows), row.names = FALSE)
