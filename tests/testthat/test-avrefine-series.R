# The loop beside the series pass: a term is not accepted for what the
# series pass found and left in the data. Own generators (white + random
# walk + an exponential warm-up, a first-order Gauss-Markov by recursion).

series_case <- function(seed, n = 5e5, freq = 100, gm_tc = NA, wu_tc = 60, wu = 0.1) {
  set.seed(seed)
  t <- (seq_len(n) - 1) / freq
  x <- rnorm(n, sd = 0.01 * sqrt(freq)) + cumsum(rnorm(n, sd = 1e-4 / sqrt(freq))) +
    wu * exp(-t / wu_tc)
  if (is.finite(gm_tc)) {
    a <- exp(-1 / (freq * gm_tc))
    x <- x + as.numeric(stats::filter(rnorm(n, sd = 0.01 * sqrt(1 - a^2)), a,
                                      method = "recursive"))
  }
  x
}

test_that("a warm-up left in the data is not described again by a GM term", {
  skip_on_cran()
  for (s in 1:2) {
    x <- series_case(s)
    fit <- avfit(allan(x, 100), terms = c("N", "B", "K"))
    ref <- suppressMessages(avrefine(fit, data = x))
    wu <- ref$series$table[ref$series$table$kind == "warmup", , drop = FALSE]
    expect_equal(nrow(wu), 1L)
    expect_lt(abs(wu$tc / 60 - 1), 0.25)
    # without the rule a GM of tc 33-48 s took the warm-up's place
    expect_false("gm" %in% ref$steps$effect)
    d <- ref$refine$series_duplicates
    expect_true(all(d$series_kind == "warmup"))
    expect_true("gm" %in% d$effect)
    expect_gte(min(d$ratio), 1)
    expect_output(print(ref), "would describe the warmup left in the series")
    # removed in the series, there is nothing left to describe again
    rem <- suppressMessages(avrefine(fit, data = x, remove = "warmup"))
    expect_equal(NROW(rem$refine$series_duplicates), 0L)
    expect_lt(abs(stats::coef(rem)[["N"]] / 0.01 - 1), 0.05)
  }
})

test_that("a genuine GM beside a slow warm-up stays (tc within 25%)", {
  skip_on_cran()
  x <- series_case(1, gm_tc = 2, wu_tc = 300, wu = 0.2)
  fit <- avfit(allan(x, 100), terms = c("N", "B", "K"))
  ref <- suppressMessages(avrefine(fit, data = x))
  expect_true("gm" %in% ref$steps$effect)
  expect_lt(abs(stats::coef(ref)[["gm1.tc"]] / 2 - 1), 0.25)
  expect_equal(NROW(ref$refine$series_duplicates), 0L)
})

test_that("series_duplicate() reads the series effect's AV against the term's", {
  # a term whose AV the series effect's excess matches is a duplicate; a
  # removed series effect, or none, never is
  tau <- 2^(0:6)
  fit <- list(data = list(tau = tau),
              components = cbind(N = 1 / tau, gm1 = c(0, 0.1, 1, 2, 1, 0.5, 0.2)))
  pass <- list(table = data.frame(kind = "warmup", removed = FALSE),
               adev_kinds = data.frame(kind = "warmup", tau = tau,
                                       before = sqrt(1 / tau + c(0, 0, 0.5, 1.5, 1, 0.4, 0.1)),
                                       after = sqrt(1 / tau)))
  d <- series_duplicate(pass, fit, "gm1", share = 0.7)
  expect_equal(d$series_kind, "warmup")
  expect_equal(d$tau, 8)
  expect_equal(d$ratio, 0.75)
  expect_null(series_duplicate(pass, fit, "gm1"))
  expect_equal(series_duplicate(pass, fit, "gm1", share = 0.5)$ratio, 0.75)
  pass$table$removed <- TRUE
  expect_null(series_duplicate(pass, fit, "gm1"))
  expect_null(series_duplicate(NULL, fit, "gm1"))
})
