# Shared by bench/line-beside-sim-band.R and bench/band-beside-line-sweep.R
# (sourced from the repository root): their record (5e5 samples at 100 Hz,
# one thread), a two-pole band of unit sd (own generator, stats::filter),
# and the loop's run as analyze_imu() makes it, read for its terms, N,
# lines and band.
suppressMessages(library(allanvar))
options(allanvar.threads = 1L)
freq <- 100
n <- 5e5
t <- seq_len(n) / freq
ar2_unit <- function(fr, tc, burn = 2000L) {
  r <- exp(-1 / (freq * tc))
  z <- as.numeric(stats::filter(rnorm(n + burn), c(2 * r * cos(2 * pi * fr / freq), -r^2),
                                method = "recursive"))[-seq_len(burn)]
  z / stats::sd(z)
}
run <- function(x) {
  r <- suppressWarnings(suppressMessages(avrefine(avfit(allan(x, freq), terms = c("N", "B", "K")), data = x)))
  cf <- coef(r)
  list(terms = paste(r$terms, collapse = "+"),
       N = unname(cf[grepl("^N$|^filter[^.]*\\.Nf$", names(cf))][1L]),
       f0 = cf[grepl("^sinusoid[0-9]+\\.f0$", names(cf))],
       amp = cf[grepl("^sinusoid[0-9]+\\.amp$", names(cf))],
       band = cf[grepl("^resonance[0-9]+\\.fr$|^band[0-9]+\\.f_c$", names(cf))])
}
