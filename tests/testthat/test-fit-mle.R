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

test_that("the fixed-gain tail of the filter keeps the likelihood exact", {
  # short filter memory (strong walk, fast Gauss-Markov): the Riccati
  # recursion settles within a few hundred steps and the kernel runs the
  # rest with a fixed gain; the dense likelihood does not know about that
  tau0 <- 0.1
  y <- gen_series(1200, tau0, 0.01, 0.02, 0.03, 0.3, seed = 5)
  lay <- allanvar:::coef_layout(c("N", "K", "gm"))
  entries <- lapply(c("N", "K", "gm"), allanvar:::effect_entry)
  m <- allanvar:::mle_model(c(N = 0.012, K = 0.025, gm1.sigma = 0.025, gm1.tc = 0.4),
                            lay, entries, tau0)
  expect_equal(allanvar:::mle_loglik(y, m),
               dense_loglik(y, tau0, 0.012, 0.025, 0.025, 0.4), tolerance = 1e-12)
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
  # the reported SEs are the expected information's at the estimate: near
  # the bound
  expect_true(all(fit$se / truth > crb / 2 & fit$se / truth < crb * 2))
})

test_that("a stop short of the maximum is finished by Fisher scoring, and only then converged", {
  y <- gen_series(2e4, 0.01, 0.01, 1e-3, 0.02, 1, seed = 8)
  fit <- avmle(y, 100)
  expect_true(fit$convergence$converged)
  lay <- allanvar:::coef_layout(c("N", "K", "gm"))
  entries <- lapply(c("N", "K", "gm"), allanvar:::effect_entry)
  model <- function(p) allanvar:::mle_model(p, lay, entries, 0.01)
  # a line search that stopped half an SE away from the maximum
  p1 <- coef(fit) * exp(0.5 * fit$se / coef(fit) * c(1, -1, 1, -1))
  est <- list(par = p1, loglik = allanvar:::mle_loglik(y, model(p1)),
              convergence = list(converged = FALSE, message = "ABNORMAL_TERMINATION_IN_LNSRCH"))
  out <- allanvar:::mle_scoring_check(y, est, lay, model, 100)
  expect_gt(out$loglik, est$loglik)
  expect_lt(fit$loglik - out$loglik, 1e-3)
  expect_true(out$convergence$converged)
  expect_match(out$convergence$message, "Fisher scoring")
  # far from the maximum one step is not enough: not converged
  p2 <- coef(fit) * exp(8 * fit$se / coef(fit) * c(1, -1, 1, -1))
  est2 <- list(par = p2, loglik = allanvar:::mle_loglik(y, model(p2)),
               convergence = list(converged = FALSE, message = "ABNORMAL_TERMINATION_IN_LNSRCH"))
  expect_false(allanvar:::mle_scoring_check(y, est2, lay, model, 100)$convergence$converged)
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
  f <- avmle(y, 1e300, c("N", "K"))
  expect_true(all(coef(f) >= 0 & is.finite(coef(f))))
  expect_error(avmle(y, -1), class = "allanvar_error")
  expect_error(avmle(c(y, NA), 100), class = "allanvar_error")
})

test_that("a collapsed amplitude is 0 with a profile-likelihood upper bound", {
  # no rate random walk in the series: K's likelihood is highest at 0
  y <- gen_series(5000, 0.01, 0.01, 0, 0.02, 0.5, seed = 2)
  fit <- avmle(y, 100)
  expect_identical(coef(fit)[["K"]], 0)
  expect_true(is.na(fit$se[["K"]]))
  up <- fit$bound_upper[["K"]]
  expect_true(is.finite(up) && up > 0)
  expect_equal(unname(confint(fit)["K", ]), c(0, up))
  expect_match(fit$interval[["K"]], "profile")
  # the other parameters: Wald on the log scale
  ci <- confint(fit)[c("N", "gm1.sigma", "gm1.tc"), ]
  cf <- coef(fit)[c("N", "gm1.sigma", "gm1.tc")]
  expect_equal(ci[, 2] / cf, cf / ci[, 1], tolerance = 1e-12)
  expect_true(all(is.finite(fit$se[c("N", "gm1.sigma", "gm1.tc")])))
  # the bound is where the profile log-likelihood (the others re-fitted
  # here by optim() on the Kalman likelihood) has dropped by
  # qchisq(0.90, 1) / 2
  lay <- allanvar:::coef_layout(c("N", "K", "gm"))
  entries <- lapply(c("N", "K", "gm"), allanvar:::effect_entry)
  ll <- function(p) allanvar:::mle_loglik(y, allanvar:::mle_model(p, lay, entries, 0.01))
  prof <- function(k) {
    o <- optim(log(cf), function(lp) -ll(c(N = exp(lp[[1]]), K = k, gm1.sigma = exp(lp[[2]]),
                                             gm1.tc = exp(lp[[3]]))),
               control = list(reltol = 1e-12, maxit = 2000))
    -o$value
  }
  llmax <- ll(coef(fit))
  expect_equal(fit$loglik, llmax, tolerance = 1e-8)
  expect_equal(2 * (llmax - prof(up)), qchisq(0.90, 1), tolerance = 0.03)
  expect_lt(2 * (llmax - prof(up / 3)), qchisq(0.90, 1))
})

test_that("95% intervals of avmle() cover the truth (small Monte Carlo)", {
  skip_on_cran()
  # N + K at 10 Hz, 2000 samples, 100 series from the generator above; the
  # full check (>= 400 seeds per cell) is bench/mle-coverage.R
  truth <- c(N = 0.05, K = 0.02)
  hit <- matrix(NA, 100, 2, dimnames = list(NULL, names(truth)))
  for (s in 1:100) {
    y <- gen_series(2000, 0.1, truth[["N"]], truth[["K"]], 0, 1, seed = 1000 + s)
    fit <- avmle(y, 10, c("N", "K"))
    ci <- confint(fit)
    # an interval for every parameter of every converged fit
    expect_true(!fit$convergence$converged || all(is.finite(ci[, 1]) & !is.na(ci[, 2])))
    hit[s, ] <- ci[, 1] <= truth & truth <= ci[, 2]
  }
  # 95% coverage: P(<= 88 of 100) = 0.6%
  expect_true(all(colSums(hit) >= 89), label = paste(colSums(hit), collapse = " "))
})
