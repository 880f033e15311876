# av_information(): the exact Fisher information of a rate record against
# the dense Gaussian information 0.5 tr(S^-1 S_i S^-1 S_j) of the first
# differences, built here from the model's exact covariance (white noise N,
# rate random walk K, Gauss-Markov sigma/tc as an AR(1) from its stationary
# law), and against a Monte Carlo of the score.

# Covariance of the n - 1 differences of the rate and its derivatives in
# the log parameters, written from the noise definitions only.
dense_info <- function(p, n, freq) {
  tau0 <- 1 / freq
  D <- diff(diag(n))
  d <- list()
  S <- matrix(0, n - 1, n - 1)
  if ("N" %in% names(p)) {
    W <- p[["N"]]^2 / tau0 * tcrossprod(D)
    S <- S + W
    d$N <- 2 * W
  }
  if ("K" %in% names(p)) {
    W <- diag(p[["K"]]^2 * tau0, n - 1)
    S <- S + W
    d$K <- 2 * W
  }
  lag <- abs(outer(seq_len(n), seq_len(n), "-"))
  for (g in grep("^gm[0-9]+[.]sigma$", names(p), value = TRUE)) {
    lab <- sub("[.]sigma$", "", g)
    sig <- p[[g]]; tc <- p[[paste0(lab, ".tc")]]
    phi <- exp(-tau0 / tc)
    C <- sig^2 * phi^lag
    W <- D %*% C %*% t(D)
    S <- S + W
    d[[g]] <- 2 * W
    # d phi^h / d log tc = h phi^h tau0 / tc
    d[[paste0(lab, ".tc")]] <- D %*% (C * lag * tau0 / tc) %*% t(D)
  }
  d <- d[names(p)]
  Si <- solve(S)
  A <- lapply(d, function(x) Si %*% x)
  I <- outer(seq_along(p), seq_along(p),
             Vectorize(function(i, j) 0.5 * sum(A[[i]] * t(A[[j]]))))
  dimnames(I) <- list(names(p), names(p))
  I
}

test_that("the information equals the dense Gaussian information", {
  cases <- list(
    list(p = c(N = 0.01, K = 2e-3, gm1.sigma = 0.02, gm1.tc = 0.2), n = 120, f = 100),
    list(p = c(N = 0.05, K = 0.01), n = 60, f = 10),
    list(p = c(N = 0.01, gm1.sigma = 0.03, gm1.tc = 0.05), n = 150, f = 100),
    list(p = c(N = 0.01, K = 5e-3, gm1.sigma = 0.02, gm1.tc = 0.1,
               gm2.sigma = 0.01, gm2.tc = 1), n = 200, f = 50))
  for (cs in cases) {
    got <- av_information(cs$p, n = cs$n, freq = cs$f)
    ref <- dense_info(cs$p, cs$n, cs$f)
    expect_equal(got$information, ref, tolerance = 1e-6)
    expect_equal(got$bound$rel_se, sqrt(diag(solve(ref))), tolerance = 1e-6,
                 ignore_attr = TRUE)
    expect_equal(got$bound$se, cs$p * sqrt(diag(solve(ref))), tolerance = 1e-6,
                 ignore_attr = TRUE)
  }
})

test_that("a long record extends the settled filter exactly", {
  # past the filter's settling the information grows by the same increment
  # per sample: the 1e5-sample information is the 2e4 one plus 8e4 increments
  p <- c(N = 0.01, K = 1e-3, gm1.sigma = 0.02, gm1.tc = 0.5)
  i1 <- av_information(p, n = 2e4, freq = 100)$information
  i2 <- av_information(p, n = 3e4, freq = 100)$information
  i5 <- av_information(p, n = 1e5, freq = 100)$information
  expect_equal(i5, i1 + 8 * (i2 - i1), tolerance = 1e-9)
})

test_that("the score's covariance is the information (Monte Carlo)", {
  skip_on_cran()
  # rate = white + random walk + AR(1), simulated here; the score by
  # central differences of the exact log-likelihood (the Kalman kernel of
  # avmle()) in the log parameters, at the truth
  p <- c(N = 0.02, K = 0.01, gm1.sigma = 0.05, gm1.tc = 0.3)
  freq <- 20; tau0 <- 1 / freq; n <- 400; reps <- 600
  im <- allanvar:::info_model(p, freq)
  ll <- function(y, q) allanvar:::mle_loglik(y, allanvar:::mle_model(q, im$lay, im$entries, tau0))
  set.seed(20261128)
  phi <- exp(-tau0 / p[["gm1.tc"]])
  h <- 1e-4
  sc <- t(vapply(seq_len(reps), function(r) {
    g <- stats::filter(rnorm(n, sd = p[["gm1.sigma"]] * sqrt(1 - phi^2)), phi,
                       method = "recursive", init = rnorm(1, sd = p[["gm1.sigma"]]))
    y <- 3 + rnorm(n, sd = p[["N"]] / sqrt(tau0)) +
      cumsum(rnorm(n, sd = p[["K"]] * sqrt(tau0))) + as.numeric(g)
    vapply(seq_along(p), function(j) {
      (ll(y, replace(p, j, p[[j]] * exp(h))) - ll(y, replace(p, j, p[[j]] * exp(-h)))) / (2 * h)
    }, 0)
  }, numeric(length(p))))
  info <- av_information(p, n = n, freq = freq)$information
  # mean score 0 and E[score^2] = I, each within 4 Monte Carlo SEs
  expect_true(all(abs(colMeans(sc)) < 4 * sqrt(diag(info) / reps)))
  s2 <- sc^2
  expect_true(all(abs(colMeans(s2) - diag(info)) < 4 * apply(s2, 2, sd) / sqrt(reps)))
  # and the off-diagonal entries
  for (i in 1:3) for (j in (i + 1):4) {
    pr <- sc[, i] * sc[, j]
    expect_lt(abs(mean(pr) - info[i, j]), 4 * sd(pr) / sqrt(reps))
  }
})

test_that("av_plan() inverts the bound and reports the bound at n", {
  p <- c(N = 0.01, K = 1e-3, gm1.sigma = 0.02, gm1.tc = 2)
  pl <- av_plan(p, freq = 100, target = c(K = 0.2, gm1.tc = 0.1), n = 1e5)
  expect_equal(pl$parameter, c("K", "gm1.tc"))
  for (i in seq_len(nrow(pl))) {
    m <- pl$n_needed[i]
    b <- function(n) av_information(p, n = n, freq = 100)$bound
    # the length found meets the target; 0.2% fewer samples do not
    expect_lte(b(m)$rel_se[b(m)$parameter == pl$parameter[i]], pl$target[i] * (1 + 1e-6))
    expect_gt(b(floor(m / 1.002))$rel_se[b(m)$parameter == pl$parameter[i]], pl$target[i])
  }
  expect_equal(pl$duration, pl$n_needed / 100)
  ref <- av_information(p, n = 1e5, freq = 100)$bound
  expect_equal(pl$rel_se, ref$rel_se[match(pl$parameter, ref$parameter)], tolerance = 1e-9)
})

test_that("bad models and arguments are refused with classed errors", {
  expect_error(av_information(c(N = 0.01, K = 0), n = 100, freq = 1),
               class = "allanvar_error_argument")
  expect_error(av_information(c(N = 0.01, B = 1e-3), n = 100, freq = 1),
               class = "allanvar_error_argument")
  expect_error(av_information(c(N = 0.01), n = 2, freq = 1),
               class = "allanvar_error")
  expect_error(av_information(c(N = 0.01), n = 100),
               class = "allanvar_error_missing_argument")
  expect_error(av_plan(c(N = 0.01, K = 1e-3), freq = 1, target = c(Q = 0.1)),
               class = "allanvar_error_argument")
  expect_error(av_plan(c(N = 0.01, K = 1e-3), freq = 1, target = -1),
               class = "allanvar_error_argument")
})

test_that("information that spans many orders is inverted; information beyond double precision is refused", {
  # 1000 samples at 1 MHz: K's information is 1e-21 of N's, and solve()
  # called the matrix singular, every bound Inf (on main 5294e57). The
  # bounds are the 2 x 2 inverse's, written out (information of the log
  # parameters): N's about 2%, K's finite but enormous
  p <- c(N = 0.01, K = 1e-3)
  b <- av_information(p, n = 1000, freq = 1e6)
  I <- b$information
  det <- I[1, 1] * I[2, 2] - I[1, 2]^2
  expect_equal(b$bound$rel_se, sqrt(c(I[2, 2], I[1, 1]) / det), tolerance = 1e-9)
  expect_lt(b$bound$rel_se[1], 0.03)
  expect_gt(b$bound$rel_se[2], 1e6)
  expect_true(all(is.finite(av_plan(p, freq = 1e6, target = 0.1, n = 1000)$rel_se)))
  # at 100 Hz the bounds are those of the plain inverse
  b100 <- av_information(p, n = 1000, freq = 100)
  expect_equal(b100$bound$rel_se, sqrt(diag(solve(b100$information))), tolerance = 1e-9,
               ignore_attr = TRUE)
  expect_error(av_information(p, n = 1000, freq = 1e300), "`freq`",
               class = "allanvar_error_argument")
  expect_error(av_plan(p, freq = 1e-300, target = 0.1, n = 1000), "`freq`",
               class = "allanvar_error_argument")
})
