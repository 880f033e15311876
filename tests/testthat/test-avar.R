test_that("avar() is identical to allanvar 1.1 on the golden battery", {
  for (fixture in original_fixtures()) {
    expect_identical(avar(fixture$values, fixture$freq), fixture$expected$avar)
  }
})

test_that("avar() is identical to allanvar 1.1 on fresh random inputs", {
  skip_if(is.null(original_lib()), "ALLANVAR_ORIGINAL_LIB is not set")
  skip_if_not_installed("callr")
  set.seed(as.integer(Sys.time()) %% 100000L)
  for (i in 1:5) {
    n <- sample(2:20000, 1)
    x <- rnorm(n, mean = runif(1, -1e6, 1e6), sd = 10^runif(1, -6, 3))
    freq <- runif(1, 0.1, 1000)
    expect_identical(avar(x, freq), run_original("avar", x, freq))
  }
})

test_that("avar() returns the documented structure", {
  x <- rnorm(1000)
  av <- avar(x, 50)
  expect_s3_class(av, "data.frame")
  expect_named(av, c("time", "av", "error"))
  expect_identical(attr(av, "row.names"), seq_len(nrow(av)))
  # p = floor(log2(ceiling(999 / 2))) = 8, so cluster sizes 1..256.
  expect_equal(av$time, 2^(0:8) / 50)
  expect_equal(av$error, 1 / sqrt(2 * (1000 / 2^(0:8) - 1)))
})

test_that("avar() follows the definition on a hand-computed example", {
  x <- c(1, 3, 2, 6, 4, 4, 0, 8)
  av <- avar(x, 2)
  # c = 1: diffs 2, -1, 4, -2, 0, -4, 8 -> sum sq 105 over 2 * 7.
  # c = 2: means 2, 4, 4, 4 -> diffs 2, 0, 0 -> 4 / (2 * 3).
  # c = 4: means 3, 4 -> 1 / (2 * 1).
  expect_equal(av$av, c(105 / 14, 4 / 6, 1 / 2))
  expect_equal(av$time, c(0.5, 1, 2))
})

test_that("avar() of white noise is sigma^2 / c (no reference to the original)", {
  set.seed(1)
  sigma <- 0.3
  av <- avar(rnorm(2^18, sd = sigma), 100)
  keep <- av$time * 100 <= 64
  c <- av$time[keep] * 100
  # The relative standard error of the estimate is about sqrt(2 / (3 M) * 2).
  M <- 2^18 / c
  expect_true(all(abs(av$av[keep] / white_noise_av(sigma, c) - 1) <
                    4 * sqrt(2 / M)))
})

test_that("avar() shows the +1/2 ADEV slope of a random walk", {
  set.seed(2)
  av <- avar(cumsum(rnorm(2^18)), 1)
  mid <- av$time >= 16 & av$time <= 2048
  slope <- unname(coef(lm(log(sqrt(av$av[mid])) ~ log(av$time[mid])))[2])
  expect_equal(slope, 0.5, tolerance = 0.1)
})

test_that("avar() accepts integers, ts and one-column matrices as their values", {
  x <- sample(-100:100, 300, replace = TRUE)
  expect_identical(avar(x, 10), avar(as.double(x), 10))
  expect_identical(avar(ts(x, frequency = 10), 10), avar(as.double(x), 10))
  expect_identical(avar(matrix(x), 10), avar(as.double(x), 10))
  expect_identical(avar(data.frame(x = x), 10), avar(as.double(x), 10))
})

test_that("avar() sums large integer counts without overflow", {
  x <- rep(c(.Machine$integer.max, .Machine$integer.max - 1L), 64)
  av <- avar(x, 1)
  expect_false(anyNA(av$av))
  expect_equal(av$av, avar(as.double(x), 1)$av)
  expect_equal(av$av[1], 1 / 2 * 127 / 127)
})

test_that("avar() rejects bad values with a message naming `values`", {
  expect_error(avar(NULL, 1), "`values` must be a numeric vector, not NULL",
    class = "allanvar_error_argument")
  expect_error(avar(numeric(), 1), "`values` must have at least 2 samples, not 0",
    class = "allanvar_error_argument")
  expect_error(avar(1, 1), "`values` must have at least 2 samples, not 1",
    class = "allanvar_error_argument")
  expect_error(avar(c("a", "b"), 1), "`values` must be a numeric vector, not a character vector",
    class = "allanvar_error_argument")
  expect_error(avar(factor(1:3), 1), "`values` must be a numeric vector, not a factor",
    class = "allanvar_error_argument")
  expect_error(avar(list(1, 2, 3), 1), "`values` must be a numeric vector, not a list",
    class = "allanvar_error_argument")
  expect_error(avar(c(TRUE, FALSE, TRUE), 1), "`values` must be a numeric vector, not a logical vector",
    class = "allanvar_error_argument")
  expect_error(avar(c(1i, 2i, 3i), 1), "`values` must be a numeric vector, not a complex vector",
    class = "allanvar_error_argument")
  expect_error(avar(c(1, NA, 3), 1), "`values` must contain only finite numbers; found NA at position 2",
    class = "allanvar_error_argument")
  expect_error(avar(c(1, NaN, 3), 1), "`values` .*found NaN at position 2",
    class = "allanvar_error_argument")
  expect_error(avar(c(1, 2, Inf), 1), "`values` .*found Inf at position 3",
    class = "allanvar_error_argument")
  expect_error(avar(c(-Inf, 2, 3), 1), "`values` .*found -Inf at position 1",
    class = "allanvar_error_argument")
  expect_error(avar(matrix(1:10, 5), 1), "`values` must be a single series",
    class = "allanvar_error_argument")
  expect_error(avar(data.frame(a = 1:5, b = 1:5), 1), "`values` must be a single series",
    class = "allanvar_error_argument")
  expect_error(avar(freq = 1), "`values` is missing",
    class = "allanvar_error_missing_argument")
})

test_that("avar() rejects bad freq with a message naming `freq`", {
  x <- rnorm(10)
  expect_error(avar(x), "`freq` is missing",
    class = "allanvar_error_missing_argument")
  expect_error(avar(x, NULL), "`freq` must be a single positive number.*not NULL",
    class = "allanvar_error_argument")
  expect_error(avar(x, "10"), "`freq` must be a single positive number.*not a character vector",
    class = "allanvar_error_argument")
  expect_error(avar(x, NA), "`freq` must be a single positive number.*not a logical vector",
    class = "allanvar_error_argument")
  expect_error(avar(x, NA_real_), "`freq` must be a single positive number.*not NA",
    class = "allanvar_error_argument")
  expect_error(avar(x, 0), "`freq` must be a single positive number.*not 0",
    class = "allanvar_error_argument")
  expect_error(avar(x, -1), "`freq` must be a single positive number.*not -1",
    class = "allanvar_error_argument")
  expect_error(avar(x, Inf), "`freq` must be a single positive number.*not Inf",
    class = "allanvar_error_argument")
  expect_error(avar(x, c(1, 2)), "`freq` must be a single positive number.*not of length 2",
    class = "allanvar_error_argument")
  expect_error(avar(x, factor(10)), "`freq` must be a single positive number.*not a factor",
    class = "allanvar_error_argument")
  expect_error(avar(x, 1i), "`freq` must be a single positive number.*not a complex vector",
    class = "allanvar_error_argument")
})

test_that("avar() does not print", {
  expect_silent(avar(rnorm(100), 1))
})

test_that("avar/avari/avarn: values near 1e300 scale exactly, 1.1's bits otherwise", {
  set.seed(15)
  z <- rnorm(4096)
  a <- avar(z * 2^510, 1)
  expect_true(all(is.finite(a$av)))
  expect_equal(a$av, avar(z, 1)$av * 2^1020, tolerance = 1e-14)
  expect_equal(a$time, avar(z, 1)$time)
  a <- avari(cumsum(z) * 2^-500, 2^500)
  expect_equal(a$av, avari(cumsum(z), 1)$av, tolerance = 1e-14)
  a <- avarn(z[1:300] * 2^510, 1)
  expect_equal(a$av, avarn(z[1:300], 1)$av * 2^1020, tolerance = 1e-14)
  expect_error(avar(z * 1e300, 1), class = "allanvar_error_overflow")
  expect_error(avari(cumsum(z), 1e300), class = "allanvar_error_overflow")
})
