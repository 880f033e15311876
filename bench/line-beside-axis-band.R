# A line added beside a measured accelerometer's own ~10 Hz band (the
# ADIS16405 records of ../shared/data, never shipped): on each of the 9
# accelerometer axes a line 5-15% below or above 9.9 Hz at 0.3-0.6 x the
# axis's white sd (seed 4301 unless given). Each case runs the loop as analyze_imu()
# does per axis, with and without the line, and prints: the line named
# (within 3%), N against the run without it, the band or resonance centres
# of both runs, and their terms. Another seed draws other lines.
#   R_LIBS=/tmp/lib Rscript bench/line-beside-axis-band.R [data dir] [seed]
args <- commandArgs(TRUE)
dir <- if (length(args)) args[1] else "../shared/data"
seed <- if (length(args) > 1L) as.integer(args[2]) else 4301L
suppressMessages(library(allanvar))
options(allanvar.threads = 1L)
run <- function(x, freq) {
  r <- suppressWarnings(suppressMessages(avrefine(avfit(allan(x, freq), terms = c("N", "B", "K")), data = x)))
  cf <- coef(r)
  list(r = r, N = unname(cf[grepl("^N$|^filter[^.]*\\.Nf$", names(cf))][1L]),
       f0 = cf[grepl("^sinusoid[0-9]+\\.f0$", names(cf))],
       band = cf[grepl("resonance[0-9]\\.fr$|band[0-9]\\.f_c$", names(cf))])
}
set.seed(seed)
k <- 0; named <- 0; nok <- 0; same_band <- 0
for (u in 1:3) for (ax in c("accel_x", "accel_y", "accel_z")) {
  m <- readRDS(file.path(dir, sprintf("adis16405_unit%d.rds", u)))
  b <- as.numeric(m[, ax]); freq <- attr(m, "freq"); s <- sd(diff(b)) / sqrt(2)
  f0 <- round(9.9 * (1 + sample(c(-1, 1), 1) * runif(1, 0.05, 0.15)), 2)
  a <- round(runif(1, 0.3, 0.6), 2)
  x <- b + a * s * sin(2 * pi * f0 * seq_along(b) / freq + runif(1, 0, 2 * pi))
  r0 <- run(b, freq); r1 <- run(x, freq)
  nm <- any(abs(r1$f0 / f0 - 1) < 0.03); dn <- 100 * (r1$N / r0$N - 1)
  sb <- length(r0$band) == length(r1$band) && (length(r0$band) == 0 || all(abs(sort(r1$band) / sort(r0$band) - 1) < 0.05))
  k <- k + 1; named <- named + nm; nok <- nok + (abs(dn) <= 5); same_band <- same_band + sb
  cat(sprintf("unit %d %s + %.2f Hz (%.2f sd): named %s | N %+.1f%% | band %s -> %s | terms %s -> %s\n", u, ax, f0, a, nm, dn,
      paste(signif(r0$band, 4), collapse = ","), paste(signif(r1$band, 4), collapse = ","),
      paste(r0$r$terms, collapse = "+"), paste(r1$r$terms, collapse = "+")))
}
cat("named", named, "/", k, " N within 5%", nok, " bands as without (5%)", same_band, "\n")
