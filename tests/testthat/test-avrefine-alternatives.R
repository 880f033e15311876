# Effects the raw data confirm that the final model lacks (avrefine()'s
# $refine$alternatives) and what they do to the readings' verdicts
# (mark_model_choice()).

test_that("a Gauss-Markov process the curve cannot afford is listed as an alternative", {
  skip_on_cran()
  # own generator: white noise and an AR(1) of tc 5 s at 100 Hz
  f <- 100
  n <- 2e5
  set.seed(21)
  phi <- exp(-1 / (f * 5))
  g <- as.numeric(stats::filter(rnorm(n, sd = 0.02 * sqrt(1 - phi^2)), phi,
                                method = "recursive"))
  x <- rnorm(n, sd = 0.05) + g
  # the realised tc of the AR(1) alone (its least-squares lag-1 coefficient)
  realised <- -1 / (f * log(sum(g[-1] * g[-n]) / sum(g[-n]^2)))
  fit <- avfit(allan(x, f), terms = c("N", "K"))
  # with min_gain out of reach nothing enters, and the GM the block means
  # confirm is the alternative
  r <- suppressMessages(avrefine(fit, data = x, min_gain = 1e4))
  expect_false("gm" %in% r$terms)
  al <- r$refine$alternatives
  expect_identical(al$effect, "gm")
  expect_gt(al$gain, 0)
  expect_match(al$evidence, "exponential ACF")
  co <- r$refine$alternative_coefs[[1]]
  expect_equal(unname(co["gm1.tc"]), realised, tolerance = 0.25)
  expect_output(print(r), "Not in the model, though the raw data confirm it")
  # at the default min_gain the GM enters and nothing is left out
  r10 <- suppressMessages(avrefine(fit, data = x))
  expect_true("gm" %in% r10$terms)
  expect_null(r10$refine$alternatives)
})

test_that("a reading an alternative model reads 25% lower is an upper bound, and why", {
  # the curve of N, B, K exactly, every reading measured
  tau <- 2^(0:17) / 100
  N <- 1e-3
  B <- 2e-4
  K <- 2e-5
  av <- N^2 / tau + 2 * log(2) / pi * B^2 + K^2 * tau / 3
  curve <- data.frame(tau = tau, m = 2^(0:17), avar = av, adev = sqrt(av),
                      lower = sqrt(av) * 0.9, upper = sqrt(av) * 1.1,
                      edf = rep(1e4, length(tau)))
  cf <- c(N = N, B = B, K = K)
  rd0 <- allanvar:::channel_readings(curve, cf, "gyro")
  expect_identical(rd0$verdict, rep("measured", 3))
  alt <- function(co) list(list(coef = co, effect = "gm", params = "sigma=1e-4, tc=150 s",
                                gain = 9.9, evidence = "exponential ACF (z = 14.6)",
                                min_gain = 10))
  # B 35% lower, K 10% lower with the GM: B bounded, K and N measured
  rd <- allanvar:::channel_readings(curve, cf, "gyro", alternatives = alt(
    c(N = N, B = 0.65 * B, K = 0.9 * K, gm1.sigma = 1e-4, gm1.tc = 150)))
  expect_identical(rd$verdict, c("measured", "upper_bound", "measured"))
  b <- rd$why[rd$term == "B"]
  expect_match(b, "Gauss-Markov", fixed = TRUE)
  expect_match(b, "gains only 9.9 with it, under min_gain 10", fixed = TRUE)
  expect_match(b, "B reads 0.00013 (-35%): B is at most this", fixed = TRUE)
  expect_true(rd$is_bound[rd$term == "B"])
  expect_identical(rd$value, rd0$value)
  # 30% higher: not determined
  rd2 <- allanvar:::channel_readings(curve, cf, "gyro", alternatives = alt(
    c(N = N, B = 1.3 * B, K = K, gm1.sigma = 1e-4, gm1.tc = 150)))
  expect_identical(rd2$verdict[rd2$term == "B"], "not_determined")
  expect_match(rd2$why[rd2$term == "B"], "(+30%)", fixed = TRUE)
  # 20% lower: below the mark, measured
  rd3 <- allanvar:::channel_readings(curve, cf, "gyro", alternatives = alt(
    c(N = N, B = 0.8 * B, K = K, gm1.sigma = 1e-4, gm1.tc = 150)))
  expect_identical(rd3$verdict, rep("measured", 3))
})
