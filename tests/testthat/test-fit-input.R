# as_av_curve(): every accepted input becomes one curve object.

test_that("allan(), avar() tables, plain tables and fits become one curve", {
  x <- avsim(2^14, 100, N = 0.01, K = 1e-3, seed = 4)
  a <- allan(x, 100, taus = "octave")
  cv <- as_av_curve(a)
  expect_s3_class(cv, "av_curve")
  expect_equal(cv$data$tau, a$tau)
  expect_equal(cv$data$edf, a$edf)
  expect_identical(c(cv$freq, cv$n, cv$L), c(100, 2^14, 2^14 + 1))
  expect_identical(cv$type, "overlapping")
  expect_identical(cv$edf_source, "input")
  # integrated input: L phase points = N
  ai <- allan(cumsum(x) / 100, 100, taus = "octave", input = "integrated")
  expect_equal(as_av_curve(ai)$L, 2^14)
  # avar(): non-overlapping, n from the error column
  av <- avar(x, 100)
  cv2 <- as_av_curve(av, freq = 100)
  expect_identical(cv2$type, "non-overlapping")
  expect_equal(cv2$n, 2^14)
  expect_identical(cv2$edf_source, "model")
  expect_true(all(is.na(cv2$data$edf)))
  # plain table; points beyond half the record are dropped without an EDF
  tab <- data.frame(tau = c(0.01, 0.1, 1, 100), avar = c(1, 0.1, 0.01, 1e-3))
  cv3 <- as_av_curve(tab, n = 1e4, freq = 100)
  expect_equal(cv3$data$tau, c(0.01, 0.1, 1))
  expect_equal(cv3$data$m, c(1, 10, 100))
  expect_output(print(cv3), "3 points")
  # a fit: its whole curve, with the EDF its model gave
  fit <- avfit(tab, "N", n = 1e4, freq = 100, tau_range = c(0, 0.5))
  cv4 <- as_av_curve(fit)
  expect_equal(nrow(cv4$data), 3)
  expect_identical(cv4$edf_source, "previous")
  expect_equal(cv4$data$edf[1:2], fit$data$edf)
  expect_identical(as_av_curve(cv4), cv4)
  expect_error(as_av_curve(fit, n = 10), "`n` cannot be given with a previous fit",
               class = "allanvar_error_argument")
})

test_that("refitting takes explicit arguments: nothing comes from the old fit", {
  x <- avsim(2^15, 100, N = 0.01, B = 0.002, seed = 5)
  a <- allan(x, 100, taus = "octave")
  f1 <- avfit(a, c("N", "B"), correlation = TRUE, bias_correct = FALSE)
  f2 <- avfit(f1, c("N", "B"))
  expect_false(f2$correlation)
  expect_true(f2$bias_correct)
  f3 <- avfit(f1, c("N", "B"), correlation = TRUE, bias_correct = FALSE)
  expect_equal(coef(f3), coef(f1))
  expect_equal(f3$objective, f1$objective)
})

test_that("as_av_curve() errors are classed and worded", {
  tab <- data.frame(tau = 1:3, avar = 1:3)
  expect_snapshot(error = TRUE, {
    as_av_curve()
    as_av_curve(1:3)
    as_av_curve(tab)
    as_av_curve(tab, n = 10, freq = 1, type = "modified")
    as_av_curve(data.frame(time = 1, av = 1, error = 0.1))
    as_av_curve(data.frame(tau = -1, avar = 1), n = 10, freq = 1)
  })
  expect_error(as_av_curve(1:3), class = "allanvar_error_curve")
  expect_error(as_av_curve(tab), class = "allanvar_error_argument")
})
