# Residual signatures (signatures.R); see also test-trace.R.

tau <- 10^seq(-2, 3.5, by = 0.1)
base <- list(N = 0.01, B = 0.002, K = 2e-4)
model <- do.call(av_ref, c(list(tau = tau), base))

test_that("pure noise residuals rarely show structure", {
  hits <- vapply(1:20, function(s) {
    set.seed(s)
    nrow(residual_signatures(tau, rnorm(length(tau)))) > 0
  }, logical(1))
  expect_lte(sum(hits), 2)
  expect_equal(nrow(residual_signatures(1:2, c(5, 5))), 0)
})
