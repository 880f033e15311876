test_that("avarn() is identical to allanvar 1.1 on the golden battery", {
  for (fixture in original_fixtures()) {
    if (is.null(fixture$expected$avarn)) next
    expect_identical(avarn(fixture$values, fixture$freq),
                     fixture$expected$avarn)
  }
})

test_that("avarn() is identical to allanvar 1.1 on fresh random inputs", {
  skip_if(is.null(original_lib()), "ALLANVAR_ORIGINAL_LIB is not set")
  skip_if_not_installed("callr")
  set.seed(as.integer(Sys.time()) %% 100000L + 1L)
  for (i in 1:3) {
    n <- sample(2:3000, 1)
    x <- round(rnorm(n, mean = runif(1, -1e3, 1e3)) / 0.01) * 0.01
    expect_identical(avarn(x, 100), run_original("avarn", x, 100))
  }
})

test_that("avarn() gives the same bits with one thread and with two", {
  x <- rnorm(3001, mean = 1e5)
  one <- withr_options(list(allanvar.threads = 1L), avarn(x, 10))
  two <- withr_options(list(allanvar.threads = 2L), avarn(x, 10))
  expect_identical(one, two)
})

test_that("avarn() agrees with avar() at the octave cluster sizes", {
  x <- rnorm(4097)
  all <- avarn(x, 4)
  oct <- avar(x, 4)
  expect_identical(all$av[2^(seq_len(nrow(oct)) - 1)], oct$av)
  expect_equal(nrow(all), ceiling((4097 - 1) / 2))
})

test_that("avarn() of white noise is sigma^2 / c at every cluster size", {
  set.seed(3)
  n <- 20000
  av <- avarn(rnorm(n, sd = 2), 1)
  c <- 1:50
  M <- floor(n / c)
  z <- (av$av[c] / white_noise_av(2, c) - 1) / sqrt(2 / (M - 1))
  expect_lt(max(abs(z)), 5)
})

test_that("avarn() checks its arguments", {
  expect_error(avarn(NULL, 1), "`values` must be a numeric vector, not NULL",
    class = "allanvar_error_argument")
  expect_error(avarn(1, 1), "`values` must have at least 2 samples",
    class = "allanvar_error_argument")
  expect_error(avarn(c(1, NA), 1), "`values` must contain only finite numbers",
    class = "allanvar_error_argument")
  expect_error(avarn(1:10, -2), "`freq` must be a single positive number.*not -2",
    class = "allanvar_error_argument")
  expect_error(avarn(1:10, 1, exact = NA), "`exact` must be TRUE or FALSE",
    class = "allanvar_error")
  expect_error(avarn(1:10, 1, exact = "yes"), "`exact` must be TRUE or FALSE",
    class = "allanvar_error")
})
