# Shared by test-signatures.R and test-trace.R. References: the continuous IEEE 952 AV
# forms (vignette("noise-terms")), written out here independently of the
# package's catalogue, and series with known construction.

av_ref <- function(tau, Q = 0, N = 0, B = 0, K = 0, R = 0, gm = NULL, sn = NULL) {
  av <- 3 * Q^2 / tau^2 + N^2 / tau + 2 * log(2) / pi * B^2 + K^2 * tau / 3 +
    R^2 * tau^2 / 2
  if (!is.null(gm)) {
    x <- tau / gm$tc
    av <- av + gm$sigma^2 / x^2 * (2 * x - 3 + 4 * exp(-x) - exp(-2 * x))
  }
  if (!is.null(sn)) {
    av <- av + sn$amp^2 * sin(pi * sn$f0 * tau)^4 / (pi * sn$f0 * tau)^2
  }
  av
}

# Standardized residuals of a model that lacks one effect: log-domain
# difference over its sd sqrt(2 / edf), with a rough overlapping-AV edf.
z_missing <- function(tau, full, model, n = 1e6, freq = 100) {
  edf <- pmax(1.5 * n / (tau * freq) , 2)
  (log(full) - log(model)) / sqrt(2 / edf)
}
