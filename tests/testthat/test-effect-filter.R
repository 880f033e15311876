# The filter and resonance catalogue entries through avfit(). Curves of
# series generated here with stats::filter (not the package's simulator).

test_that("a 400 Hz curve with a 4-tap average: filter term gives N and L, N+B+K does not", {
  set.seed(51)
  freq <- 400
  tau0 <- 1 / freq
  n <- 1e6
  w <- rnorm(n + 3, sd = 0.01 / sqrt(tau0))
  x <- as.numeric(stats::filter(w, rep(0.25, 4), sides = 1))[-(1:3)] +
    cumsum(rnorm(n, sd = 1e-4 * sqrt(tau0)))
  a <- allan(x, freq)
  f <- avfit(a, terms = c("filter", "K"))
  cf <- coef(f)
  expect_equal(cf[["filter.Nf"]], 0.01, tolerance = 0.1)
  expect_equal(cf[["filter.L"]], 4, tolerance = 0.1)
  expect_equal(cf[["K"]], 1e-4, tolerance = 0.5)
  expect_lt(f$chi2, 2)
  # the datasheet model misreads such a curve (why the filter effect exists)
  f0 <- avfit(a, terms = c("N", "B", "K"))
  expect_gt(f0$chi2, 20)
})

test_that("each low-pass variant fits its own curve (parameters within 10%)", {
  set.seed(52)
  freq <- 100
  tau0 <- 1 / freq
  n <- 5e5
  w <- rnorm(n, sd = 0.01 / sqrt(tau0))
  fc <- 12
  a1 <- (2 - cos(2 * pi * fc * tau0)) - sqrt((2 - cos(2 * pi * fc * tau0))^2 - 1)
  y1 <- as.numeric(stats::filter((1 - a1) * w, a1, method = "recursive"))
  f1 <- avfit(allan(y1, freq), terms = "filter:lp1")
  cf1 <- coef(f1)
  expect_equal(unname(cf1[grepl("fc$", names(cf1))]), fc, tolerance = 0.1)
  K <- tan(pi * fc * tau0)
  den <- 1 + sqrt(2) * K + K^2
  v <- as.numeric(stats::filter(w, c(1, 2, 1) * K^2 / den, sides = 1))[-(1:2)]
  y2 <- as.numeric(stats::filter(v, c(-2 * (K^2 - 1) / den, -(1 - sqrt(2) * K + K^2) / den),
                                 method = "recursive"))
  f2 <- avfit(allan(y2, freq), terms = "filter:lp2")
  cf <- coef(f2)
  expect_equal(unname(cf[grepl("fc$", names(cf))]), fc, tolerance = 0.1)
  expect_equal(unname(cf[grepl("Nf$", names(cf))]), 0.01, tolerance = 0.1)
})

test_that("a filter run into its family's edge is not admitted; a real cutoff is", {
  set.seed(53)
  freq <- 100
  w <- rnorm(2^17, sd = 0.01 * sqrt(freq))
  # white noise: the first-order low-pass runs to its Nyquist bound (fc is
  # never above it) and is not admitted as a filter
  a <- allan(w, freq)
  f <- avfit(a, terms = "filter:lp1")
  fc <- unname(coef(f)[["filter_lp1.fc"]])
  expect_lte(fc, freq / 2)
  expect_gt(fc, 0.49 * freq)
  expect_match(inadmissible("filter:lp1", c(Nf = 0.01, fc = fc), a$tau, freq),
               "Nyquist bound")
  # a moving average of one sample is white noise
  expect_match(inadmissible("filter", c(Nf = 0.01, L = 1), a$tau, freq), "white noise")
  # a first-order low-pass at 12 Hz (our own recursion) is admitted
  a1 <- (2 - cos(2 * pi * 12 / freq)) - sqrt((2 - cos(2 * pi * 12 / freq))^2 - 1)
  y <- as.numeric(stats::filter((1 - a1) * w, a1, method = "recursive"))
  g <- avfit(allan(y, freq), terms = "filter:lp1")
  expect_null(inadmissible("filter:lp1", c(Nf = 0.01, fc = coef(g)[["filter_lp1.fc"]]),
                           a$tau, freq))
  expect_null(inadmissible("filter", c(Nf = 0.01, L = 4), a$tau, freq))
})

test_that("a resonance term fits a narrow-band process", {
  set.seed(53)
  freq <- 100
  n <- 5e5
  r <- exp(-0.01 / 0.1)
  w0 <- 2 * pi * 20 / freq
  z <- as.numeric(stats::filter(rnorm(n), c(2 * r * cos(w0), -r^2), method = "recursive"))
  x <- rnorm(n, sd = 0.5) + 0.5 * z / stats::sd(z)
  f <- avfit(allan(x, freq), terms = c("N", "resonance"),
             start = c(resonance1.fr = 19, resonance1.tc = 0.05))
  cf <- coef(f)
  expect_equal(cf[["resonance1.fr"]], 20, tolerance = 0.1)
  expect_equal(cf[["resonance1.sigma"]], 0.5, tolerance = 0.3)
  # the generator is a white-driven AR(2), whose autocovariance has a small
  # sine part the entry's cos form lacks: a slightly larger chi2
  expect_lt(f$chi2, 5)
})

test_that("short-lag autocovariance steps: a random walk cancels, the moving average's form fits them, a first-order low-pass does not", {
  # white noise through a 2-tap average (weights 1, 0.25) plus a random
  # walk: the steps c(h) - c(h + 1) are the filter's alone (lag 1 only);
  # a first-order low-pass of the same lag-1 correlation puts a fifth of
  # it at lag 2
  set.seed(52)
  freq <- 100
  n <- 4e5
  w <- rnorm(n + 1L, sd = 0.01)
  x <- (w[-1L] + 0.25 * w[-(n + 1L)]) + cumsum(rnorm(n, sd = 1e-4 / sqrt(freq)))
  raw <- acov_steps(x)
  # the filter's lag-1 autocovariance 0.25 x 0.01^2, nothing beyond
  expect_lt(max(abs(raw$d - c(0.25e-4, 0, 0)) / raw$se), 4)
  a <- allan(x, freq)
  z <- function(f) (raw$d - -diff(model_acov(f$layout, coef(f), 1:4, 1 / freq))) / raw$se
  z_ma <- z(avfit(a, terms = c("filter", "K")))
  z_lp1 <- z(avfit(a, terms = c("filter:lp1", "K")))
  expect_lt(max(abs(z_ma)), 4)
  # what acov_choice() asks: lower by more than the 0.1% point of chi-square
  expect_gt(sum(z_lp1^2) - sum(z_ma^2), stats::qchisq(0.999, 3))
})
