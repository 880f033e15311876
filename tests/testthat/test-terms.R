# General discrete formula for a stationary rate with autocovariance gamma(h)
# (Zhang 2008; vignette("noise-terms")), an independent reference for the
# closed forms.
av_from_acf <- function(m, gamma) {
  i <- seq_len(m - 1)
  (m * (gamma(0) - gamma(m)) +
     sum(i * (2 * gamma(m - i) - gamma(i) - gamma(2 * m - i)))) / m^2
}

test_that("flicker table matches direct numerical integration", {
  pl <- 2 * log(2) / pi
  for (m in c(1, 2, 3, 5, 7, 12, 40, 100, 333, 1000)) {
    f <- function(u) ifelse(u == 0, 0, sin(m * u)^4 / (m^2 * sin(u)^3))
    br <- seq(0, pi / 2, length.out = 4 * m + 2)
    I <- sum(vapply(seq_len(length(br) - 1), function(j)
      integrate(f, br[j], br[j + 1], rel.tol = 1e-12)$value, 0))
    ref <- 2 / pi * I
    expect_equal(av_model(m, c(B = 1), freq = 1), ref, tolerance = 1e-8)
  }
  # published ratios to the plateau (vignette("noise-terms"))
  r <- av_model(c(1, 2, 4, 8, 16), c(B = 1), freq = 1) / pl
  expect_equal(r, c(1.443, 1.154, 1.050, 1.015, 1.0046), tolerance = 1e-3)
  expect_equal(av_model(1, c(B = 1), freq = 1) / pl, 1 / log(2), tolerance = 1e-9)
  # large m: tends to the plateau; continuous form is the plateau
  expect_equal(av_model(1e7, c(B = 1), freq = 1), pl, tolerance = 1e-9)
  expect_equal(av_model(c(0.1, 10), c(B = 2)), rep(4 * pl, 2))
})

test_that("Gauss-Markov discrete form equals the autocovariance sum", {
  for (tc in c(0.5, 3, 40, 1e4)) {
    phi <- exp(-1 / tc)
    g <- function(h) 4 * phi^h
    for (m in c(1, 2, 5, 50, 300)) {
      expect_equal(av_model(m, c(gm1.sigma = 2, gm1.tc = tc), freq = 1),
                   av_from_acf(m, g), tolerance = 1e-7)
    }
  }
  # very long tc: stable, tends to the RRW-like limit eps (2m^2+1)/(3m)
  eps <- 1e-9
  m <- c(1, 10, 100)
  expect_equal(av_model(m, c(gm1.sigma = 1, gm1.tc = 1 / eps), freq = 1),
               eps * (2 * m^2 + 1) / (3 * m), tolerance = 1e-4)
  v <- av_model(m, c(gm1.sigma = 1, gm1.tc = 1e6), freq = 1)
  expect_equal(v, vapply(m, function(mm) av_from_acf(mm, function(h) exp(-h / 1e6)), 0),
               tolerance = 1e-3)
})

test_that("Gauss-Markov continuous form: peak at 1.893 tc, 0.6174 sigma", {
  tc <- 7
  f <- function(tau) sqrt(av_model(tau, c(gm1.sigma = 1, gm1.tc = tc)))
  o <- optimize(f, c(0.1, 100), maximum = TRUE, tol = 1e-10)
  expect_equal(o$maximum / tc, 1.893, tolerance = 1e-3)
  expect_equal(o$objective, 0.6174, tolerance = 1e-3)
  # direct closed form away from the series branch, and the series branch
  tau <- c(0.01, 0.3, 1, 5, 100)
  x <- tau / tc
  direct <- (tc / tau)^2 * (2 * x - 3 + 4 * exp(-x) - exp(-2 * x))
  expect_equal(av_model(tau[-1], c(gm1.sigma = 1, gm1.tc = tc)), direct[-1],
               tolerance = 1e-9)
  expect_equal(av_model(tau[1], c(gm1.sigma = 1, gm1.tc = tc)), 2 / 3 * x[1],
               tolerance = 1e-3)
})

test_that("sinusoid: first peak 0.7246 A at 0.371/f0, nulls at k/f0", {
  f0 <- 0.2
  f <- function(tau) sqrt(av_model(tau, c(sinusoid1.amp = 1, sinusoid1.f0 = f0)))
  o <- optimize(f, c(0.1, 4), maximum = TRUE, tol = 1e-10)
  expect_equal(o$maximum * f0, 0.3710, tolerance = 1e-3)
  expect_equal(o$objective, 0.7246, tolerance = 1e-3)
  expect_lt(f(1 / f0), 1e-7)
  # discrete Dirichlet form: average over phase of the exact sampled AV
  freq <- 10; m <- 3; A <- 1.5
  ph <- seq(0, 2 * pi, length.out = 401)[-401]
  av_ph <- vapply(ph, function(p) {
    y <- A * sin(2 * pi * f0 * (1:(2 * m)) / freq + p)
    (mean(y[(m + 1):(2 * m)]) - mean(y[1:m]))^2 / 2
  }, 0)
  expect_equal(av_model(m / freq, c(sinusoid1.amp = A, sinusoid1.f0 = f0), freq),
               mean(av_ph), tolerance = 1e-10)
})

test_that("Q, N, K, R closed forms", {
  tau <- c(0.01, 0.02, 0.5, 10)
  expect_equal(av_model(tau, c(Q = 2), 100), 12 / tau^2)
  expect_equal(av_model(tau, c(N = 2), 100), 4 / tau)
  expect_equal(av_model(tau, c(K = 2), 100), 4 * tau / 3 + 4 * 1e-4 / (6 * tau))
  expect_equal(av_model(tau, c(K = 2)), 4 * tau / 3)
  expect_equal(av_model(tau, c(R = 2), 100), 2 * tau^2)
  # random walk: exact integer-m value from the phase covariance
  # b_k = sum of k steps of variance K^2 tau0 -> E[D^2]/(2 tau^2)
  m <- 3; s2 <- 1
  w <- c(rep(1, m), rep(-1, m)) / m          # cluster-mean difference weights
  C <- outer(1:(2 * m), 1:(2 * m), pmin) * s2
  expect_equal(av_model(m, c(K = 1), freq = 1), drop(t(w) %*% C %*% w) / 2)
})

test_that("terms add in variance; by_term gives the parts", {
  cf <- c(N = 0.1, B = 0.02, gm1.sigma = 0.05, gm1.tc = 3, gm2.sigma = 0.01,
          gm2.tc = 100, sinusoid1.amp = 0.2, sinusoid1.f0 = 1.3)
  tau <- 10^seq(-2, 3, by = 0.25)
  parts <- av_model(tau, cf, 100, by_term = TRUE)
  expect_equal(colnames(parts), c("N", "B", "gm1", "gm2", "sinusoid1"))
  expect_equal(rowSums(parts), av_model(tau, cf, 100))
  expect_equal(parts[, "gm2"], av_model(tau, c(gm1.sigma = 0.01, gm1.tc = 100), 100))
})

test_that("catalogue listing and argument checks", {
  tt <- av_terms()
  expect_setequal(unique(tt$term[tt$component == "av"]),
                  c("Q", "N", "B", "K", "R", "gm", "sinusoid", "filter", "resonance", "band"))
  expect_setequal(unique(tt$term[tt$component == "series"]),
                  c("spikes", "warmup", "steps", "transients"))
  expect_setequal(unique(tt$component), c("av", "series"))
  expect_equal(tt$unit[tt$parameter == "N"], "u*sqrt(s)")
  expect_equal(tt$slope[tt$term == "K"], 0.5)
  expect_error(av_model(-1, c(N = 1)), "`tau`",
    class = "allanvar_error_argument")
  expect_error(av_model(1, c(N = 1), freq = -1), "`freq`",
    class = "allanvar_error_argument")
  expect_error(av_model(1, c(X = 1)), "unknown term",
    class = "allanvar_error_argument")
  expect_error(av_model(1, c(gm1.sigma = 1)), "gm1.tc",
    class = "allanvar_error_argument")
  expect_error(av_model(1, c(N = -1)), "non-negative",
    class = "allanvar_error_argument")
  expect_error(av_model(1, 1), "`coef`", class = "allanvar_error_argument")
  expect_equal(coef_layout(c("gm", "N", "sinusoid", "gm"))$name,
               c("N", "gm1.sigma", "gm1.tc", "gm2.sigma", "gm2.tc",
                 "sinusoid1.amp", "sinusoid1.f0"))
  expect_error(check_terms(c("N", "N")), "only gm, sinusoid, resonance and band",
    class = "allanvar_error_argument")
  expect_error(check_terms("Z"), "unknown term",
    class = "allanvar_error_argument")
})

test_that("av_model() errors are classed and worded", {
  expect_snapshot(error = TRUE, {
    av_model(c(N = 1))
    av_model(-1, c(N = 1))
    av_model(1, c(X = 1))
    av_model(1, c(gm1.sigma = 1))
    av_model(1, c(N = -1))
    av_model(1, c(gm1.sigma = 1, gm1.tc = 0))
    av_model(1, 1)
  })
})

test_that("the catalogue's autocovariances and PSDs give its AV forms", {
  # autocovariance route (discrete forms) for every entry that defines one
  pars <- list(Q = NULL, N = NULL, gm = c(tc = 0.4), sinusoid = c(f0 = 3.3))
  for (k in names(pars)) {
    e <- allanvar:::effect_entry(k)
    expect_false(is.null(e$acf))
    for (m in c(1, 2, 7, 40)) {
      expect_equal(e$basis(m / 100, 0.01, pars[[k]]),
                   av_from_acf(m, function(h) e$acf(h, 0.01, pars[[k]])),
                   tolerance = 1e-9, label = paste(k, m))
    }
  }
  # PSD route (continuous forms): AV = 4 int S(f) sin^4(pi f tau)/(pi f tau)^2 df,
  # in x = pi f tau, period by period, plus the tail (mean of sin^4 is 3/8)
  av_psd <- function(tau, S) {
    g <- function(x) S(x / (pi * tau)) * sin(x)^4 / x^2
    body <- sum(vapply(0:299, function(k)
      integrate(g, k * pi, (k + 1) * pi, rel.tol = 1e-10)$value, 0))
    4 / (pi * tau) * (body + S(300 / tau) * 3 / 8 / (300 * pi))
  }
  pars <- list(N = NULL, B = NULL, K = NULL, gm = c(tc = 0.4))
  for (k in names(pars)) {
    e <- allanvar:::effect_entry(k)
    for (tau in c(0.05, 1, 20)) {
      expect_equal(av_psd(tau, function(f) e$psd(f, pars[[k]])),
                   e$basis(tau, NULL, pars[[k]]), tolerance = 2e-3,
                   label = paste(k, tau))
    }
  }
})

test_that("the Gauss-Markov basis in C++ is the R forms to the bit", {
  e <- effect_entry("gm")
  r_form <- function(tau, tau0, tc) {
    out <- gm_basis_continuous(tau, tc)
    d <- discrete_tau(tau, tau0)
    if (any(d)) out[d] <- gm_basis_discrete(tau[d] / tau0, tau0 / tc)
    out
  }
  set.seed(34)
  for (i in 1:300) {
    tau0 <- 10^runif(1, -4, 1)
    # octave grids, whole cluster sizes, taus below a sample (the series
    # of the continuous form) and at m eps < 1e-5 (the first-order form)
    tau <- switch(i %% 3 + 1, tau0 * 2^(0:20), tau0 * unique(round(10^runif(40, 0, 6))),
                  10^runif(30, -6, 4) * tau0)
    tc <- 10^runif(1, -5, 6)
    expect_identical(e$basis(tau, tau0, c(tc = tc)), r_form(tau, tau0, tc))
  }
  # without a sample period: the continuous form
  expect_identical(e$basis(c(0.1, 1, 10), NULL, c(tc = 3)), gm_basis_continuous(c(0.1, 1, 10), 3))
})
