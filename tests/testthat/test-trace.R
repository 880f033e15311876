# Tracing residual signatures to effects with start values (trace.R).
# References: the continuous IEEE 952 AV forms written out independently in
# helper-avref.R (av_ref), and residuals of a model that lacks one effect.

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
