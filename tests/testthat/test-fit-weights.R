# The weights of a curve's points: one EDF engine for allan() and avfit().

test_that("allan() and avfit() give the same EDF for white noise (one engine)", {
  x <- avsim(2^14, 100, N = 0.01, seed = 3)
  for (type in c("overlapping", "standard")) {
    a <- allan(x, 100, taus = "octave", type = type)
    fit <- avfit(data.frame(tau = a$tau, avar = a$avar), "N", n = 2^14,
                 freq = 100, type = type)
    expect_equal(fit$edf_source, "model")
    # rows where allan() identified white noise and the EDF is above the
    # fit's floor of 1
    ok <- a$alpha == 0 & a$edf > 1
    expect_gt(sum(ok), 8)
    expect_equal(fit$data$edf[ok], a$edf[ok], tolerance = 1e-12)
  }
})

test_that("the mixture EDF combines the terms' EDFs by their AV shares", {
  m <- c(1, 4, 16, 64, 256)
  n <- 1e4
  w <- edf_power_law(m, n, "overlapping", 0)
  k <- edf_power_law(m, n, "overlapping", -2)
  comp <- cbind(N = 1 / m, K = m / 50)
  expect_equal(edf_model(m, n, "overlapping", comp, cbind(0 * m, 0 * m - 2)),
               rowSums(comp)^2 / (comp[, 1]^2 / w + comp[, 2]^2 / k))
  # a deterministic term adds no variance: the EDF rises by its share
  comp2 <- cbind(N = 1 / m, R = 1 / m)
  expect_equal(edf_model(m, n, "overlapping", comp2, cbind(0 * m, NA)), pmin(4 * w, n))
  # only deterministic terms: white-noise EDF
  expect_equal(edf_model(m, n, "overlapping", cbind(1 / m), NA), w)
})

test_that("independent points keep W as its diagonal, and the fit is the same", {
  W <- whitening(c(0.5, 0.25, 0.1), NULL)
  expect_equal(dim(W), c(3L, 1L))
  v <- c(1, 2, 3)
  expect_equal(as.numeric(wmul(W, v)), as.numeric(diag(1 / c(0.5, 0.25, 0.1)) %*% v))
  A <- matrix(1:6, 3)
  expect_equal(wmul(W, A), diag(1 / c(0.5, 0.25, 0.1)) %*% A)
  expect_equal(w_logdet(W), -2 * sum(log(1 / c(0.5, 0.25, 0.1))))
  # the C++ solve with the diagonal as a column equals the dense one
  set.seed(3)
  B <- cbind(1 / (1:40), (1:40) / 3)
  y <- log(B %*% c(2, 0.5)) + rnorm(40, sd = 0.05)
  s <- runif(40, 0.05, 0.2)
  a <- avfit_log_nnls(B, numeric(40), as.numeric(y), matrix(1 / s, ncol = 1), numeric(2), 100L, 1e-12)
  b <- avfit_log_nnls(B, numeric(40), as.numeric(y), diag(1 / s), numeric(2), 100L, 1e-12)
  expect_equal(a$c, b$c, tolerance = 1e-10)
  expect_equal(a$objective, b$objective, tolerance = 1e-10)
})

test_that("the model's correlation of AV estimates: white noise exact, a random walk by Monte Carlo", {
  n <- 4096
  m <- c(1, 2, 4, 8, 16, 32, 64, 128)
  M <- allan_nterms("overlapping", m, n + 1)
  # white rate noise: the closed form of avar_white_cov()
  expect_equal(avfit_model_corr(m, M, 0L, 1, 0), white_corr(m, n, "overlapping"),
               tolerance = 1e-3)
  # rate random walk (own generator, direct second differences of the phase)
  skip_on_cran()
  oav <- function(y, k) {
    x <- c(0, cumsum(y))
    L <- length(x)
    d <- x[(2 * k + 1):L] - 2 * x[(k + 1):(L - k)] + x[1:(L - 2 * k)]
    mean(d^2) / (2 * k^2)
  }
  set.seed(11)
  sims <- replicate(1500, {
    y <- cumsum(rnorm(n))
    vapply(m, function(k) oav(y, k), 0)
  })
  R <- avfit_model_corr(m, M, 1L, 1, 0)
  # the white-noise correlation is far off here (0.07 for m = 1 and 8)
  expect_equal(cor(t(sims))[4, ], R[4, ], tolerance = 0.06)
  expect_gt(R[1, 4], 0.25)
  # a Gauss-Markov term beside white noise
  phi <- exp(-1 / 20)
  sims <- replicate(1500, {
    w <- rnorm(n) * sqrt(1 - phi^2)
    y <- as.numeric(stats::filter(w, phi, method = "recursive")) + 0.3 * rnorm(n)
    vapply(m, function(k) oav(y, k), 0)
  })
  R <- avfit_model_corr(m, M, c(3L, 0L), c(1, 0.09), c(phi, 0))
  expect_equal(cor(t(sims))[5, ], R[5, ], tolerance = 0.06)
})
