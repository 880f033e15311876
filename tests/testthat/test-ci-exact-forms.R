# The exact law of the total family and Theo1 at few averages
# (R/ci-exact-forms.R): their quadratic forms, the law against a Monte
# Carlo of own generators, and the coverage of allan()'s intervals.

test_that("the dense forms reproduce the total family and Theo1", {
  # V = x' A x (or |W x|^2) up to the estimator's constant: the ratio to
  # allan()'s value is the same for every record
  qf <- function(A, x) {
    if (isTRUE(attr(A, "terms"))) sum((A %*% x)^2) else drop(x %*% A %*% x)
  }
  set.seed(11)
  L <- 49
  for (m in c(2, 4, 10, 16)) {
    r <- vapply(1:3, function(i) {
      x <- cumsum(stats::rnorm(L))
      y <- diff(x)
      val <- function(type, tau) {
        allan(y, 1, taus = I(tau), type = type, ci = FALSE, debias = FALSE)$avar
      }
      c(val("total", m) / qf(exact_form_total(m, L), x),
        val("mtotdev", m) / qf(exact_form_mtot(m, L), x),
        val("htotdev", m) / qf(exact_form_htot(m, L), x),
        val("theo1", 0.75 * m) / qf(exact_form_theo1(m, L), x))
    }, numeric(4))
    expect_equal(r[, 2:3], r[, c(1, 1)], tolerance = 1e-10)
  }
})

test_that("the dense law's EDF matches a Monte Carlo of own generators", {
  skip_on_cran()
  # 2 E^2 / Var of the estimate, 3000 records of 129 phase points; the
  # law's 1 / sum(lambda^2) (its weights sum to 1); the chi-square EDF of
  # the formulas (Table 5's white PM, Table 11's random walk) is 2-10 times
  # off at these N/m
  set.seed(12)
  N <- 128
  gens <- list(wpm = function() diff(stats::rnorm(N + 1)),
               rwfm = function() cumsum(stats::rnorm(N)))
  cases <- list(list("total", "exact_form_total", 16, "wpm", 2L),
                list("mtotdev", "exact_form_mtot", 32, "rwfm", -2L),
                list("theo1", "exact_form_theo1", 32, "wpm", 2L))
  for (cs in cases) {
    tau <- if (cs[[1]] == "theo1") 0.75 * cs[[3]] else cs[[3]]
    v <- replicate(3000, allan(gens[[cs[[4]]]](), 1, taus = I(tau),
                               type = cs[[1]], ci = FALSE,
                               debias = FALSE)$avar)
    w <- exact_dense_weights(cs[[2]], cs[[3]], N + 1, cs[[5]])
    expect_equal(sum(w), 1)
    expect_equal(1 / sum(w^2), 2 * mean(v)^2 / stats::var(v),
                 tolerance = 0.1)
  }
})

test_that("the total type's limits cover under white PM at few averages", {
  skip_on_cran()
  # white PM, N = 256, N/m = 8: the law at the true type covers; so does
  # the chi-square interval with the exact two-moment EDF (src/edf.cpp;
  # Table 5's simple formula gave 111 against the law's 59 and covered
  # 0.55); allan() joins the types its reading leaves plausible, so it may
  # over-cover a little
  set.seed(13)
  N <- 256
  recs <- replicate(600, diff(stats::rnorm(N + 1)), simplify = FALSE)
  res <- lapply(recs, function(y) {
    a <- allan(y, 1, taus = I(c(1, 2, 4, 8, 16, 32)), type = "total")
    a[a$m == 32, ]
  })
  dev <- vapply(res, `[[`, 0, "adev")
  truth <- sqrt(mean(dev^2))
  f <- exact_dense_factors("exact_form_total", 32, N + 1, 2L, 0.683)
  expect_equal(mean(dev * f[1] <= truth & truth <= dev * f[2]), 0.683,
               tolerance = 0.06)
  e5 <- allan_edf_direct("total", 32, N - 1, N + 1, 2L)
  expect_lt(e5, 80)
  ci <- allan_ci(dev^2, rep(e5, length(dev)), 0.683)
  expect_equal(mean(ci$lower <= truth & truth <= ci$upper), 0.683, tolerance = 0.06)
  cover <- mean(vapply(res, function(r) r$lower <= truth && truth <= r$upper,
                       TRUE))
  expect_gt(cover, 0.6)
  expect_lt(cover, 0.85)
})

test_that("the scaled problem keeps the window inside its record (m = N/3)", {
  # rounding the scaled m up gave a 3m window longer than the record
  pr <- exact_dense_problem(500, 1501, 0L)
  expect_gte(pr[2] - 1, 3 * pr[1])
  set.seed(11)
  a <- allan(rnorm(1500), 1, type = "mtotdev", taus = c(499, 500))
  expect_true(all(is.finite(c(a$lower, a$upper))))
})
