# Tau grids and the largest cluster size of each estimator.

test_that("octave, decade and all grids", {
  y <- rnorm(100)
  expect_equal(allan(y, 1)$m, 2^(0:5))
  expect_equal(allan(y, 1, taus = "decade")$m, c(1, 2, 4, 10, 20, 40))
  expect_equal(allan(y, 1, taus = "all")$m, 1:50)
  expect_equal(allan(y, 1, type = "total")$m, 2^(0:6))
  expect_equal(allan(y, 1, taus = "decade", type = "total")$m,
               c(1, 2, 4, 10, 20, 40, 100))
})

test_that("the largest cluster size of each type has one term, the next none", {
  for (input in c("rate", "integrated")) {
    y <- rnorm(101)
    L <- if (input == "rate") 102 else 101
    for (type in allan_types) {
      a <- allan(y, 1, taus = "all", type = type, input = input)
      mx <- max(a$m)
      expect_equal(mx, allan_max_m(type, L), info = type)
      expect_gte(min(a$n), 1)
      if (type != "total") expect_lt(allan_nterms(type, mx + 1, L), 1)
      expect_equal(a$m, seq_len(mx))
    }
  }
  expect_equal(allan_max_m("overlapping", 101), 50)
  expect_equal(allan_max_m("modified", 101), 33)
  expect_equal(allan_max_m("hadamard", 101), 33)
  expect_equal(allan_max_m("total", 101), 100)
})

test_that("points per decade and taus in seconds", {
  y <- rnorm(2000)
  a <- allan(y, 10, taus = 10)
  expect_equal(a$m, unique(round(10^seq(0, 3, by = 0.1))))
  a <- allan(y, 10, taus = c(0.14, 0.26, 1, 1))
  expect_equal(a$m, c(1L, 3L, 10L))
  expect_equal(a$tau, c(0.1, 0.3, 1))
  expect_equal(allan(y, 10, taus = I(2.5))$m, 25L)
  expect_error(allan(y, 10, taus = 2.5), "points per decade",
    class = "allanvar_error")
  expect_warning(allan(y, 10, taus = c(0.01, 1)), "were dropped")
  expect_error(suppressWarnings(allan(rnorm(4), 1, taus = I(10), type = "hadamard")),
               "No averaging time", class = "allanvar_error")
})

test_that("the estimator table is defined once (src/types.h) and mirrored in R", {
  tab <- allan_type_table()
  expect_setequal(tab$name, allan_types)
  expect_equal(tab$code, seq_along(tab$name) - 1L)
  # what Greenhall's EDF needs, per type
  expect_equal(tab$d[match(c("standard", "hadamard", "ohadamard"), tab$name)],
               c(2L, 3L, 3L))
  expect_equal(tab$overlapping[match(c("standard", "overlapping", "modified"),
                                     tab$name)], c(FALSE, TRUE, TRUE))
  expect_equal(tab$modified, tab$name == "modified")
})

test_that("the sums kernel validates its options struct once", {
  ok <- allan_opts("overlapping", rate = TRUE)
  expect_type(allan_sums_cpp(rnorm(10), 10, 1, 9, 1, ok), "list")
  bad <- ok
  bad$type <- 99L
  expect_error(allan_sums_cpp(rnorm(10), 10, 1, 9, 1, bad), "unknown estimator",
    class = "Rcpp::exception")
  bad <- ok
  bad$rate <- NA
  expect_error(allan_sums_cpp(rnorm(10), 10, 1, 9, 1, bad), "TRUE or FALSE",
    class = "Rcpp::exception")
  bad <- allan_opts("overlapping", rate = TRUE, octave = TRUE)
  expect_error(allan_sums_cpp(rnorm(10), 10, 1, 9, 1, bad), "octave",
    class = "Rcpp::exception")
})
