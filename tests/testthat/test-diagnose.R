# Diagnostics for the closed loop. References: the continuous IEEE 952 AV
# forms (noise-models.md section 1), written out here independently of the
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

tau <- 10^seq(-2, 3.5, by = 0.1)
base <- list(N = 0.01, B = 0.002, K = 2e-4)
model <- do.call(av_ref, c(list(tau = tau), base))

test_that("a missing Gauss-Markov term shows as a bump traced to Tc = tau_peak / 1.893", {
  gm <- list(sigma = 0.004, tc = 20)
  full <- do.call(av_ref, c(list(tau = tau, gm = gm), base))
  sig <- residual_signatures(tau, z_missing(tau, full, model))
  expect_true("bump" %in% sig$kind)
  b <- sig[sig$kind == "bump", ][1, ]
  expect_true(b$tau_from < 1.893 * 20 && b$tau_to > 1.893 * 20)
  tr <- trace_candidates(tau, full, model, sig, present = c("N", "B", "K"))
  g <- tr$init[tr$effect == "gm"][[1]]
  # The excess AV peaks a little after the ADEV peak of the term alone.
  expect_equal(g$tc, 20, tolerance = 0.3)
  expect_equal(g$sigma, 0.004, tolerance = 0.3)
  expect_false(any(tr$effect %in% c("N", "B", "K")))
})

test_that("a missing sinusoid shows as an oscillation; first peak gives f0 = 0.371 / tau", {
  tau2 <- 10^seq(-2, 3, by = 0.05)
  model2 <- do.call(av_ref, c(list(tau = tau2), base))
  sn <- list(amp = 0.02, f0 = 0.1)
  full <- do.call(av_ref, c(list(tau = tau2, sn = sn), base))
  sig <- residual_signatures(tau2, z_missing(tau2, full, model2))
  expect_true("oscillation" %in% sig$kind)
  # The strongest positive run holds the first peak at 0.371 / f0 = 3.71 s.
  pos <- sig[sig$sign > 0 & sig$kind == "bump", ]
  expect_true(any(pos$tau_from <= 3.71 & pos$tau_to >= 3.71))
  tr <- trace_candidates(tau2, full, model2, sig, present = names(base))
  s <- tr[tr$effect == "sinusoid", ][1, ]
  expect_equal(s$init[[1]]$f0, 0.1, tolerance = 0.1)
  expect_equal(s$init[[1]]$amp, 0.02, tolerance = 0.15)
  # Nulls of the sinusoid at k / f0 fall in negative stretches or near-zero z.
  expect_true(length(attr(sig, "nulls")) >= 1)
})

test_that("quantization is a short-tau run with excess slope -1; Q recovered", {
  full <- do.call(av_ref, c(list(tau = tau, Q = 0.002), base))
  sig <- residual_signatures(tau, z_missing(tau, full, model))
  expect_equal(sig$kind[1], "short_end")
  expect_equal(sig$sign[1], 1L)
  tr <- trace_candidates(tau, full, model, sig, present = names(base))
  q <- tr[tr$effect == "Q", ]
  expect_equal(q$init[[1]]$Q, 0.002, tolerance = 0.05)
  expect_match(q$signature, "slope -1.0", fixed = TRUE)
  # The slope score ranks Q above white noise for this run.
  expect_gt(q$score, 1.5)
})

test_that("a ramp is a long-tau run with excess slope +1, RRW with +1/2", {
  base2 <- list(N = 0.01, B = 0.002)
  model2 <- do.call(av_ref, c(list(tau = tau), base2))
  full <- do.call(av_ref, c(list(tau = tau, R = 1e-5), base2))
  sig <- residual_signatures(tau, z_missing(tau, full, model2))
  expect_true("long_end" %in% sig$kind)
  tr <- trace_candidates(tau, full, model2, sig, present = names(base2))
  expect_equal(tr$init[tr$effect == "R"][[1]]$R, 1e-5, tolerance = 0.05)
  expect_gt(tr$score[tr$effect == "R"], tr$score[tr$effect == "K"])
  full <- do.call(av_ref, c(list(tau = tau, K = 3e-4), base2))
  sig <- residual_signatures(tau, z_missing(tau, full, model2))
  tr <- trace_candidates(tau, full, model2, sig, present = names(base2))
  expect_equal(tr$init[tr$effect == "K"][[1]]$K, 3e-4, tolerance = 0.05)
  expect_gt(tr$score[tr$effect == "K"], tr$score[tr$effect == "R"])
})

test_that("pure noise residuals rarely show structure", {
  hits <- vapply(1:20, function(s) {
    set.seed(s)
    nrow(residual_signatures(tau, rnorm(length(tau)))) > 0
  }, logical(1))
  expect_lte(sum(hits), 2)
  expect_equal(nrow(residual_signatures(1:2, c(5, 5))), 0)
})

test_that("a periodogram line is found at f0 with its amplitude and significance", {
  set.seed(2)
  n <- 2e5
  t <- seq_len(n) / 100
  x <- rnorm(n, sd = 0.1) + 0.02 * sin(2 * pi * 0.5 * t + 1)
  d <- avdiagnose(x, 100)
  expect_s3_class(d, "avdiagnose")
  expect_equal(d$lines$f0[1], 0.5, tolerance = 0.01)
  expect_equal(d$lines$amp[1], 0.02, tolerance = 0.1)
  expect_lt(d$lines$p_value[1], 1e-10)
  ev <- raw_evidence("sinusoid", list(f0 = 0.52), d, x, 100)
  expect_true(ev$support)
  ev <- raw_evidence("sinusoid", list(f0 = 2), d, x, 100)
  expect_false(ev$support)
  # White noise: no line in most seeds at the 1e-3 family-wise level.
  fa <- vapply(1:5, function(s) {
    set.seed(s)
    nrow(spectral_lines(rnorm(5e4), 100))
  }, 0)
  expect_lte(sum(fa > 0), 1)
})

test_that("the quantization grid and the -1/2 lag-1 ACF are recognised", {
  set.seed(3)
  xq <- round(rnorm(1e5) / 0.05) * 0.05
  g <- quantization_grid(xq)
  expect_true(g$quantized)
  expect_equal(g$step, 0.05, tolerance = 1e-9)
  expect_equal(g$on_grid, 1)
  expect_false(quantization_grid(rnorm(1e5))$quantized)
  # Differenced uniform noise (quantization Q) has lag-1 ACF -1/2 exactly.
  y <- diff(runif(1e5 + 1)) * 100
  d <- avdiagnose(y, 100)
  expect_equal(d$acf1, -0.5, tolerance = 0.03)
  expect_equal(round(d$noise_id$alpha[1]), 2)
  expect_true(raw_evidence("Q", list(Q = 1), d, y, 100)$support)
})

test_that("exponential ACF gives Tc; trend and lag-1 noise id are right", {
  set.seed(4)
  n <- 1e6
  phi <- exp(-1 / (100 * 10))
  g <- as.numeric(stats::filter(rnorm(n, sd = 0.05 * sqrt(1 - phi^2)), phi, "recursive"))
  y <- rnorm(n, sd = 0.1) + g
  a <- acf_exponential(y, 100, 7)
  expect_equal(a$tc, 10, tolerance = 0.2)
  w <- rnorm(n, sd = 0.1)
  expect_false(isTRUE(raw_evidence("gm", list(tc = 7), avdiagnose(w, 100), w, 100)$support))
  # Ramp of 1e-5 u/s over 10000 s in white noise.
  t <- seq_len(n) / 100
  tr <- linear_trend(w + 1e-5 * t, 100)
  expect_true(tr$significant)
  expect_equal(tr$slope, 1e-5, tolerance = 0.05)
  expect_false(linear_trend(w, 100)$significant)
  expect_equal(lag1_noise_id(w, 10), 0, tolerance = 0.1)
  expect_equal(round(lag1_noise_id(cumsum(rnorm(n)), 10)), -2)
})

test_that("avdiagnose validates its arguments and prints", {
  expect_error(avdiagnose(), "`x` is missing")
  expect_error(avdiagnose(rnorm(1000), -1), "`freq` must be a single positive")
  expect_error(avdiagnose(letters, 1), "`x` must be a numeric vector")
  expect_error(avdiagnose(rnorm(10), 1), "at least 256")
  x <- stats::ts(round(rnorm(5000) / 0.1) * 0.1, frequency = 50)
  d <- avdiagnose(x)
  expect_equal(d$freq, 50)
  expect_output(print(d), "Quantized: step 0.1")
})
