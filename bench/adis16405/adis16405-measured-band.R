# Evaluation (issue 9, adis3): is the ~20 Hz band of the ADIS16405 z gyros
# described by its own measured spectrum where the Lorentzian resonance
# fails (unit 3: chi2/dof 4.8)? For each z gyro the loop's final model is
# refitted with the resonance replaced by a "measured band" term: its
# spectrum IS the Welch estimate over the band minus the background (read
# on the flanks, quadratic and linear in f: their spread is the
# background's systematic uncertainty), its AV the exact discrete AV
# transfer function applied to it,
#   AV(m) = 2 sum_j S1_j int_bin sin^4(pi f m tau0) df / (m sin(pi f_j tau0))^2
# (one-sided S1; each bin integrated in closed form, the denominator at the
# bin centre). Nothing is fitted but an optional scale, reported against
# the band power's uncertainty. A scratch entry is registered for the fit
# only; this is an evaluation, not a catalogue entry.
#
# Run from the package root (installed build, fast):
#   ADIS_LIB=/tmp/libadis Rscript bench/adis16405/adis16405-measured-band.R
# Output: bench/adis16405/adis16405-measured-band.txt

lib <- Sys.getenv("ADIS_LIB", "")
if (nzchar(lib)) library(allanvar, lib.loc = lib) else pkgload::load_all(".", quiet = TRUE)
list2env(as.list(asNamespace("allanvar"), all.names = TRUE), globalenv())
shared <- Sys.getenv("ALLANVAR_SHARED_DATA", "/work/shared/data")
options(allanvar.threads = 1L)

F4 <- function(x) 3 * x / 8 - sin(2 * x) / 4 + sin(4 * x) / 32
measured_band <- function(x, freq, b, seg = 512L, degree = 2L) {
  w <- welch_psd(x - mean(x), freq, seg, detrend = FALSE)
  wd <- b$f_to - b$f_from
  fl <- (w$f > b$f_from - wd & w$f < b$f_from) |
    (w$f > b$f_to & w$f < min(b$f_to + wd, 0.49 * freq))
  fit <- stats::lm(log(w$psd[fl]) ~ poly(w$f[fl], degree, raw = TRUE))
  inb <- w$f >= b$f_from & w$f <= b$f_to
  bg <- exp(drop(cbind(1, poly(w$f[inb], degree, raw = TRUE)) %*% stats::coef(fit)))
  list(f = w$f[inb], S = pmax(w$psd[inb] - bg, 0), df = w$df, nu = w$nu,
       bg = sum(bg) * w$df)
}
band_av <- function(mm, tau0, mb) vapply(mm, function(m) {
  a <- pi * m * tau0
  I <- (F4(a * (mb$f + mb$df / 2)) - F4(a * (mb$f - mb$df / 2))) / a
  2 * sum(mb$S * I / (m * sin(pi * mb$f * tau0))^2)
}, 0)

out <- "bench/adis16405/adis16405-measured-band.txt"
cat("Measured-band evaluation on the ADIS16405 z gyros (", format(Sys.time(), "%Y-%m-%d"), ")\n",
    sep = "", file = out)
for (k in 1:3) {
  m <- readRDS(file.path(shared, sprintf("adis16405_unit%d.rds", k)))
  freq <- attr(m, "freq"); tau0 <- 1 / freq
  x <- m[, "gyro_z"]; rm(m)
  av <- allan(x, freq, taus = 10, type = "overlapping")
  ref <- suppressMessages(avrefine(avfit(av, terms = c("N", "B", "K")), data = x, max_steps = 5))
  bands <- find_bands(x, freq)
  b <- bands[which.max(bands$power), ]
  mb <- measured_band(x, freq, b)
  mb1 <- measured_band(x, freq, b, degree = 1L)
  p2 <- sum(mb$S) * mb$df; p1 <- sum(mb1$S) * mb1$df
  # band power uncertainty: the bins' chi-square and the background's spread
  sd_rel <- sqrt(2 / (mb$nu * length(mb$f)) + ((p1 - p2) / p2)^2)
  e <- effect_resonance()
  e$name <- "mband"; e$title <- "measured band (evaluation)"
  e$params <- effect_param("amp", "amp", "1", "square root of the band's scale")
  e$basis <- function(tau, tau0_, nl) band_av(pmax(round(tau / tau0), 1), tau0, mb)
  e[c("nl_range", "nl_bounds", "propose", "evidence", "peak_tau", "acf", "describe")] <- list(NULL)
  e$sim <- function(n, tau0, amp, nl) rep(0, n)
  register_effect(e, replace = TRUE)
  terms <- c(setdiff(ref$terms, "resonance"), "mband")
  nl <- stats::coef(ref)[ref$layout$role == "nonlinear"]
  nl <- nl[!grepl("^resonance", names(nl))]
  fixed <- ref$refine$fixed
  g1 <- avfit(ref, terms = terms, start = nl, fixed = c(fixed, mband.amp = 1))
  gs <- avfit(ref, terms = terms, start = nl, fixed = fixed)
  enbw <- function(f) {
    cf <- stats::coef(f); L <- cf[grep("^filter\\.L$", names(cf))]
    if (length(L)) filter_bandwidth(filter_spec_of("ma", list(L = L), tau0), tau0)$enbw else NA
  }
  scale <- stats::coef(gs)[["mband.amp"]]^2
  cat(sprintf(paste0("\nunit %d gyro_z: band %.2f-%.2f Hz (%d bins), measured power %.4g",
                     " (linear background %.4g; Lorentzian fit %.4g), rel. uncertainty %.2f%%\n",
                     "  loop model %-40s chi2/dof %.2f  filter ENBW %.1f Hz\n",
                     "  measured band, scale 1       %-26s chi2/dof %.2f  filter ENBW %.1f Hz\n",
                     "  measured band, scale free    %-26s chi2/dof %.2f  ENBW %.1f Hz, scale %.4f (|log| = %.1f uncertainties)\n"),
              k, b$f_from, b$f_to, length(mb$f), p2, p1, b$power, 100 * sd_rel,
              paste(ref$terms, collapse = " "), ref$chi2, enbw(ref),
              paste(terms, collapse = " "), g1$chi2, enbw(g1),
              "", gs$chi2, enbw(gs), scale, abs(log(scale)) / sd_rel),
      file = out, append = TRUE)
}
cat(readLines(out), sep = "\n")
