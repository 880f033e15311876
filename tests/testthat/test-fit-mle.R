# avmle(): the exact Gaussian likelihood of the rate series. Series from a
# generator written here (not avsim()): white rate noise, a rate random
# walk and an AR(1) Gauss-Markov process.
gen_series <- function(n, tau0, N, K, sigma, tc, seed) {
  set.seed(seed)
  phi <- exp(-tau0 / tc)
  g <- numeric(n)
  g[1] <- rnorm(1, sd = sigma)
  e <- rnorm(n, sd = sigma * sqrt(1 - phi^2))
  for (i in 2:n) g[i] <- phi * g[i - 1] + e[i]
  rnorm(n, sd = N / sqrt(tau0)) + cumsum(rnorm(n, sd = K * sqrt(tau0))) + g
}

# log-likelihood written out densely: y[-1] | y[1] with the walk's level
# unknown is the Gaussian likelihood of diff(y)
dense_loglik <- function(y, tau0, N, K, sigma, tc) {
  n <- length(y)
  phi <- exp(-tau0 / tc)
  h <- abs(outer(seq_len(n), seq_len(n), "-"))
  S <- diag(N^2 / tau0, n) + sigma^2 * phi^h
  D <- diff(diag(n))
  Sd <- D %*% S %*% t(D) + diag(K^2 * tau0, n - 1)
  d <- diff(y)
  ch <- chol(Sd)
  z <- backsolve(ch, d, transpose = TRUE)
  -0.5 * ((n - 1) * log(2 * pi) + 2 * sum(log(diag(ch))) + sum(z^2))
}

test_that("the Kalman likelihood equals the dense Gaussian likelihood of the differences", {
  tau0 <- 0.01
  y <- gen_series(300, tau0, 0.01, 1e-3, 0.02, 0.05, seed = 11)
  p <- c(N = 0.012, K = 2e-3, gm1.sigma = 0.015, gm1.tc = 0.08)
  lay <- allanvar:::coef_layout(c("N", "K", "gm"))
  entries <- lapply(c("N", "K", "gm"), allanvar:::effect_entry)
  m <- allanvar:::mle_model(p, lay, entries, tau0)
  expect_equal(allanvar:::mle_loglik(y, m),
               dense_loglik(y, tau0, 0.012, 2e-3, 0.015, 0.08), tolerance = 1e-10)
  # without a walk the sensor's constant bias is still unknown: a diffuse
  # level, so again the likelihood of the differences
  lay2 <- allanvar:::coef_layout(c("N", "gm"))
  m2 <- allanvar:::mle_model(p[c("N", "gm1.sigma", "gm1.tc")], lay2, entries[c(1, 3)], tau0)
  expect_equal(allanvar:::mle_loglik(y, m2),
               dense_loglik(y, tau0, 0.012, 0, 0.015, 0.08), tolerance = 1e-10)
  expect_equal(allanvar:::mle_loglik(y + 3, m2), allanvar:::mle_loglik(y, m2),
               tolerance = 1e-10)
})

test_that("a constant bias does not move the fit", {
  # without the level a bias of 25 sigma was read as a Gauss-Markov term
  # (sigma 0.50, tc 379 s instead of 0.045, 2.5 s)
  y <- gen_series(2e4, 0.01, 0.01, 0, 0.02, 0.5, seed = 7)
  a <- avmle(y, 100, c("N", "gm"))
  b <- avmle(y + 0.5, 100, c("N", "gm"))
  expect_equal(coef(b), coef(a), tolerance = 1e-4)
  expect_lt(abs(coef(a)[["gm1.tc"]] / 0.5 - 1), 0.5)
})

test_that("avmle() recovers N, K, sigma and tc within 3 Cramer-Rao SDs", {
  # relative Cramer-Rao SDs at 1e5 samples, 100 Hz, N 0.01, K 1e-3,
  # sigma 0.02, tc 2 s (bench/gmwm-mle.R, exact): N 0.227%, K 30.9%,
  # sigma 3.98%, tc 11.5%
  y <- gen_series(1e5, 0.01, 0.01, 1e-3, 0.02, 2, seed = 5)
  fit <- avmle(y, 100)
  truth <- c(N = 0.01, K = 1e-3, gm1.sigma = 0.02, gm1.tc = 2)
  crb <- c(0.00227, 0.309, 0.0398, 0.115)
  expect_true(all(abs(coef(fit) / truth - 1) < 3 * crb))
  # the reported SEs are the observed information's: near the bound
  expect_true(all(fit$se / truth > crb / 2 & fit$se / truth < crb * 2))
})

test_that("avmle() returns an avfit object the methods accept", {
  y <- gen_series(2e4, 0.01, 0.01, 1e-3, 0, 1, seed = 3)
  fit <- avmle(y, 100, c("N", "K"))
  expect_s3_class(fit, "avfit")
  expect_identical(fit$method, "mle")
  expect_named(coef(fit), c("N", "K"))
  expect_identical(dim(vcov(fit)), c(2L, 2L))
  expect_true(fit$convergence$converged)
  expect_true(is.finite(fit$loglik))
  expect_s3_class(fit$avfit, "avfit")
  expect_length(predict(fit, c(1, 10)), 2L)
  expect_output(print(fit), "N")
  # the MLE maximises the likelihood: the curve fit's values do not beat it
  lay <- allanvar:::coef_layout(c("N", "K"))
  entries <- lapply(c("N", "K"), allanvar:::effect_entry)
  ll_av <- allanvar:::mle_loglik(y, allanvar:::mle_model(coef(fit$avfit), lay, entries, 0.01))
  expect_gte(fit$loglik, ll_av - 1e-6)
})

test_that("avmle() rejects terms without a state-space form and bad input", {
  y <- gen_series(1000, 0.01, 0.01, 1e-3, 0, 1, seed = 1)
  expect_snapshot(error = TRUE, avmle(y, 100, c("N", "B")))
  expect_error(avmle(y, 100, c("N", "B")), class = "allanvar_error_argument")
  # variances per sample beyond double precision: a clear error, and at the
  # other extreme no error from the covariance (found by tools/fuzz.R)
  expect_snapshot(error = TRUE, avmle(y, 1e-300, c("N", "K")))
  # (there the SEs are not finite, and a classed warning says so)
  f <- expect_warning(avmle(y, 1e300, c("N", "K")), class = "allanvar_warning_fit_not_finite")
  expect_true(all(coef(f) >= 0 & is.finite(coef(f))))
  expect_error(avmle(y, -1), class = "allanvar_error")
  expect_error(avmle(c(y, NA), 100), class = "allanvar_error")
})
