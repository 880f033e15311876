# The further types against every Stable32 run of allantools' and
# allantoolkit's test suites (tools/check-stable32-types.R). The reference
# files are not shipped: set ALLANVAR_PEER_DATA to checkouts of those
# repositories (":"-separated) to run this test from the source tree.

test_that("Stable32's values, counts and limits (with its noise types)", {
  roots <- strsplit(Sys.getenv("ALLANVAR_PEER_DATA"), ":", fixed = TRUE)[[1]]
  skip_if(!length(roots) || !any(dir.exists(roots)),
          "ALLANVAR_PEER_DATA does not point at allantools/allantoolkit")
  script <- file.path("..", "..", "tools", "check-stable32-types.R")
  skip_if_not(file.exists(script), "tools/ is not beside the tests")
  env <- new.env(parent = asNamespace("allanvar"))
  sys.source(script, envir = env)
  d <- env$check_stable32_types(roots, verbose = FALSE)
  skip_if(is.null(d), "no reference run found")
  d <- d[!d$loose & is.finite(d$s32) & d$s32 > 0, ]
  expect_gt(nrow(d), 100)
  # every value to Stable32's printed digits (a last-digit tie at most:
  # ours within 0.51 of a unit, a value on a rounding boundary that Stable32
  # rounded the other way). Ties stay rare: 6 of 2,068 values with
  # allantools' runs alone, 6 of 4,806 with allantoolkit's as well.
  expect_equal(sum(!(d$value_ok | d$value_tie)), 0)
  expect_lte(sum(d$value_tie), nrow(d) / 300)
  expect_true(all(d$n_ok))
  # the EDF formulas: every limit within 25% of Stable32's half-width when
  # Stable32's noise type is used
  expect_true(all(d$lim_a_ok, na.rm = TRUE))
})
