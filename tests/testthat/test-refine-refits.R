# The loop's refits: without the covariance's sandwich, made once per call.
# Own generator (white noise plus a Gauss-Markov process by its recursion).

refit_series <- function(n, seed) {
  set.seed(seed)
  phi <- exp(-1 / (100 * 2))
  w <- rnorm(n, sd = 0.02 * sqrt(1 - phi^2))
  gm <- as.numeric(stats::filter(w, phi, method = "recursive"))
  rnorm(n, sd = 0.01) + gm
}

test_that("a refit without the sandwich gets avfit()'s covariance back", {
  x <- refit_series(2^16, 31)
  fit <- avfit(allan(x, 100), c("N", "K"))
  args <- refit_args(fit, c("N", "K", "gm"), refit_settings(fit, list()))
  full <- do.call(avfit, args)
  part <- refit_curve(args)
  expect_true(isTRUE(part$partial_vcov))
  # the same fit; only the covariance differs before it is completed
  expect_identical(coef(part), coef(full))
  expect_identical(part$chi2, full$chi2)
  expect_false(isTRUE(all.equal(part$vcov, full$vcov)))
  done <- complete_covariance(part)
  expect_null(done$partial_vcov)
  expect_identical(done$vcov, full$vcov)
  expect_identical(done$se, full$se)
  # a fit with its covariance is left as it is
  expect_identical(complete_covariance(full), full)
})

test_that("within a call a refit is made once and its conditions replayed", {
  x <- refit_series(2^15, 32)
  fit <- avfit(allan(x, 100), c("N", "K"))
  args <- refit_args(fit, c("N", "K", "gm"), refit_settings(fit, list()))
  cnt <- new.env()
  cnt$n <- 0L
  suppressMessages(trace("fit_curve", bquote(assign("n", get("n", envir = .(cnt)) + 1L,
                                                     envir = .(cnt))),
                         print = FALSE, where = asNamespace("allanvar")))
  on.exit(suppressMessages(untrace("fit_curve", where = asNamespace("allanvar"))),
          add = TRUE)
  call_store_open(refit_memo)
  a <- try_refit(args, "first")
  b <- try_refit(args, "second")
  args2 <- args
  args2$start <- c(gm1.tc = 3)
  d <- try_refit(args2, "third")
  expect_identical(cnt$n, 2L)
  expect_identical(b$fit, a$fit)
  # the conditions a refit raised come again under the stage that asks
  args3 <- args
  args3$start <- c(gm1.tc = 7)
  refit_memo_put(args3, a$fit, list(list(condition = simpleWarning("w"), stage = "first")))
  r <- try_refit(args3, "again")
  expect_identical(cnt$n, 2L)
  expect_identical(r$conditions[[1L]]$stage, "again")
  expect_identical(conditionMessage(r$conditions[[1L]]$condition), "w")
  call_store_close(refit_memo, "entries")
  # outside a call nothing is kept
  expect_identical(length(refit_memo$entries), 0L)
  e <- try_refit(args, "outside")
  expect_identical(cnt$n, 3L)
  expect_identical(e$fit, a$fit)
})
