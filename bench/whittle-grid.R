# Whittle's approximation to the Cramer-Rao bound on the GMWM composites
# (N 0.01, sigma 0.02, tc 2 s, 100 Hz; K 1e-3 and 2e-4; 1e5 and 1e6
# samples) on two frequency grids for the n - 1 first differences: the
# Fourier grid 2 pi k / (n - 1) (bench/gmwm-mle.R's "whittle" row) and the
# sine grid pi k / n, whose basis diagonalises the differenced white noise
# and walk exactly. The Fourier grid starts at twice the lowest sine
# frequency, where most of K's information sits when K is weak; the exact
# bound is av_information()'s. A record for issue 25, not package code.
#
#   R CMD INSTALL --preclean . && Rscript bench/whittle-grid.R
library(allanvar)
tau0 <- 0.01
# Whittle information of the differences: 0.5 per sine frequency, 1 per
# Fourier frequency in (0, pi) (a cosine and a sine); derivatives in the
# log parameters
whittle <- function(p, n, grid) {
  nd <- n - 1
  w <- if (grid == "fourier") 2 * pi * (1:floor((nd - 1) / 2)) / nd else pi * (1:nd) / (nd + 1)
  wt <- if (grid == "fourier") 1 else 0.5
  phi <- exp(-tau0 / p[["tc"]]); R <- p[["N"]]^2 / tau0; q <- p[["K"]]^2 * tau0
  s2 <- p[["sigma"]]^2; c1 <- 2 * (1 - cos(w)); den <- 1 - 2 * phi * cos(w) + phi^2
  fw <- R * c1; fk <- q + 0 * w; fg <- s2 * (1 - phi^2) * c1 / den
  f <- fw + fk + fg
  h <- 1e-6
  gtc <- function(tc) { ph <- exp(-tau0 / tc); s2 * (1 - ph^2) * c1 / (1 - 2 * ph * cos(w) + ph^2) }
  dtc <- (gtc(p[["tc"]] * exp(h)) - gtc(p[["tc"]] * exp(-h))) / (2 * h)
  D <- cbind(2 * fw, 2 * fk, 2 * fg, dtc) / f
  I <- wt * crossprod(D)
  list(rel = sqrt(diag(solve(I))), share1 = wt * D[1, 2]^2 / I[2, 2])
}
for (K in c(1e-3, 2e-4)) for (n in c(1e5, 1e6)) {
  p <- c(N = 0.01, K = K, sigma = 0.02, tc = 2)
  a <- whittle(p, n, "fourier"); b <- whittle(p, n, "sine")
  ex <- av_information(c(N = 0.01, K = K, gm1.sigma = 0.02, gm1.tc = 2), n = n, freq = 100)
  cat(sprintf(paste("K %g, n %g: K's bound, Fourier grid %.1f%%, sine grid %.1f%%, exact %.2f%%;",
                    "share of K's sine-grid information at the lowest frequency %.0f%%\n"),
              K, n, 100 * a$rel[2], 100 * b$rel[2], 100 * ex$bound$rel_se[2], 100 * b$share1))
}
