test_that("avari() is identical to allanvar 1.1 on the golden battery", {
  for (fixture in original_fixtures()) {
    if (is.null(fixture$expected$avari)) next
    expect_identical(avari(fixture$values, fixture$freq),
                     fixture$expected$avari)
  }
})

test_that("avari() is identical to allanvar 1.1 on fresh random inputs", {
  skip_if(is.null(original_lib()), "ALLANVAR_ORIGINAL_LIB is not set")
  skip_if_not_installed("callr")
  set.seed(as.integer(Sys.time()) %% 100000L + 2L)
  for (i in 1:5) {
    n <- sample(4:20000, 1)
    x <- cumsum(rnorm(n)) / 100 + runif(1, -1e4, 1e4)
    expect_identical(avari(x, 100), run_original("avari", x, 100))
  }
})

test_that("avari() follows the definition on a hand-computed example", {
  theta <- c(0, 1, 4, 2, 8, 3)
  av <- avari(theta, 1)
  # N = 6 gives p = 1, so only c = 1: second differences 2, -5, 8, -11
  # -> 214 / (2 * 1^2 * 4).
  expect_equal(av$av, 214 / 8)
  expect_equal(av$time, 1)
})

test_that("avari() of integrated white noise is sigma^2 / c", {
  set.seed(4)
  n <- 2^17
  sigma <- 0.5
  freq <- 50
  angle <- cumsum(rnorm(n, sd = sigma)) / freq
  av <- avari(angle, freq)
  c <- av$time * freq
  keep <- c <= 64
  expect_true(all(abs(av$av[keep] / white_noise_av(sigma, c[keep]) - 1) <
                    5 * sqrt(1 / (n / c[keep]))))
})

test_that("avari() needs at least 4 samples and checks its arguments", {
  expect_error(avari(1:3, 1), "`values` must have at least 4 samples, not 3",
    class = "allanvar_error_argument")
  expect_error(avari("a", 1), "`values` must be a numeric vector",
    class = "allanvar_error_argument")
  expect_error(avari(c(1, 2, NaN, 4), 1), "`values` .*found NaN at position 3",
    class = "allanvar_error_argument")
  expect_error(avari(1:10, 0), "`freq` must be a single positive number.*not 0",
    class = "allanvar_error_argument")
  expect_error(avari(1:10), "`freq` is missing",
    class = "allanvar_error_missing_argument")
})
