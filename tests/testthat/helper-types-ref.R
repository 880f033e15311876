# Plain R evaluations of the further statistics, written from their
# definitions (NIST SP 1065 eqs. 15, 27-30, 33; Vernotte et al. 2016 for
# PDEV) for phase x (L points, tau0 = 1), as the reference for the C++
# kernels. Slow on purpose: each term is formed as the definition says.

# NBS14's frequency data (NIST SP 1065 p. 107) and its phase, which is
# Stable32's PHASE.DAT.
nbs14_freq <- function() {
  n <- numeric(1000)
  n[1] <- 1234567890
  for (i in 2:1000) n[i] <- (16807 * n[i - 1]) %% 2147483647
  n / 2147483647
}

nbs14_phase <- function() {
  y <- nbs14_freq()
  c(0, cumsum(y - mean(y)))
}

with_threads <- function(n, expr) {
  old <- options(allanvar.threads = n)
  on.exit(options(old))
  expr
}

ref_window_total <- function(s, m, hadamard) {
  n3 <- 3 * m
  h <- floor(n3 / 2)
  slope <- (mean(s[(n3 - h + 1):n3]) - mean(s[1:h])) / (n3 - h)
  s0 <- s - slope * (0:(n3 - 1))
  e <- c(rev(s0), s0, rev(s0))          # even reflection at both ends
  E <- c(0, cumsum(e))
  j <- 1:(6 * m)
  d <- (E[j + 3 * m] - 3 * E[j + 2 * m] + 3 * E[j + m] - E[j]) / m
  mean(d^2) / if (hadamard) 6 else 1
}

ref_mtotvar <- function(x, m) {
  n <- length(x) - 3 * m + 1
  q <- vapply(seq_len(n), function(i) {
    ref_window_total(x[i:(i + 3 * m - 1)], m, FALSE)
  }, 0)
  sum(q) / (2 * m^2 * n)
}

ref_htotvar <- function(x, m) {
  y <- diff(x)
  if (m == 1) {  # the overlapping Hadamard variance (SP 1065 sec. 5.2.14)
    d <- y[3:length(y)] - 2 * y[2:(length(y) - 1)] + y[1:(length(y) - 2)]
    return(mean(d^2) / 6)
  }
  n <- length(y) - 3 * m + 1
  q <- vapply(seq_len(n), function(i) {
    ref_window_total(y[i:(i + 3 * m - 1)], m, TRUE)
  }, 0)
  mean(q)
}

ref_theo1 <- function(x, m) {
  N <- length(x)
  k <- m / 2
  i <- 1:(N - m)
  acc <- 0
  for (d in 0:(k - 1)) {
    acc <- acc + sum((x[i] - x[i - d + k] + x[i + m] - x[i + d + k])^2) / (k - d)
  }
  acc / (0.75 * (N - m) * m^2)
}

ref_oavar <- function(x, m) {
  N <- length(x)
  d <- x[(1 + 2 * m):N] - 2 * x[(1 + m):(N - m)] + x[1:(N - 2 * m)]
  sum(d^2) / (2 * (N - 2 * m) * m^2)
}

ref_theobr_factor <- function(x, n = floor(length(x) / 6 - 3)) {
  mean(vapply(0:n, function(i) ref_oavar(x, 9 + 3 * i) / ref_theo1(x, 12 + 4 * i),
              0))
}

ref_pvar <- function(x, m) {
  N <- length(x)
  if (m == 1) return(ref_oavar(x, 1))
  M <- N - 2 * m
  w <- (m - 1) / 2 - 0:(m - 1)
  s <- vapply(1:M, function(i) {
    sum(w * (x[i:(i + m - 1)] - x[(i + m):(i + 2 * m - 1)]))
  }, 0)
  72 * sum(s^2) / (M * m^4 * m^2)
}

ref_mtie <- function(x, m) {
  N <- length(x)
  max(vapply(1:(N - m), function(i) diff(range(x[i:(i + m)])), 0))
}

ref_tierms <- function(x, m) {
  N <- length(x)
  sqrt(mean((x[(1 + m):N] - x[1:(N - m)])^2))
}

# Every character string drawn by the last plot (its display list).
plot_strings <- function(expr) {
  grDevices::pdf(NULL)
  on.exit(grDevices::dev.off())
  grDevices::dev.control("enable")
  force(expr)
  p <- grDevices::recordPlot()
  unlist(lapply(p[[1]], function(e) {
    Filter(is.character, unlist(e[[2]], recursive = TRUE))
  }))
}
