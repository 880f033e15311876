plot_to_file <- function(code) {
  path <- tempfile(fileext = ".png")
  grDevices::png(path)
  on.exit({
    grDevices::dev.off()
    unlink(path)
  })
  code
}

settable_par <- function() {
  p <- graphics::par(no.readonly = TRUE)
  # Plot state that any plot sets, as the original's did.
  p[setdiff(names(p), c("usr", "xlog", "ylog", "xaxp", "yaxp", "plt", "fig", "mfg"))]
}

test_that("plotav() draws all three compatibility results and returns them invisibly", {
  x <- rnorm(2000)
  plot_to_file({
    for (av in list(avar(x, 10), avarn(x[1:300], 10), avari(cumsum(x) / 10, 10))) {
      before <- settable_par()
      expect_invisible(out <- expect_no_warning(plotav(av)))
      expect_identical(out, av)
      expect_identical(settable_par(), before)
      # The plot is in log coordinates, as the demo's abline() expects.
      expect_true(graphics::par("xlog") && graphics::par("ylog"))
    }
  })
})

test_that("plotav() rejects what it cannot plot, naming `avdf`", {
  expect_error(plotav(), "`avdf` is missing",
    class = "allanvar_error_missing_argument")
  expect_error(plotav(1:3), "`avdf` must be the data frame returned by avar",
    class = "allanvar_error_argument")
  expect_error(plotav(data.frame(time = 1, av = 1)), "lacks `error`",
    class = "allanvar_error_argument")
  expect_error(plotav(data.frame(time = 1, av = "a", error = 1)),
               "`avdf\\$av` must be numeric", class = "allanvar_error_argument")
  expect_error(plotav(data.frame(time = 1, av = 0, error = 1)),
               "no row with positive, finite",
               class = "allanvar_error_argument")
})

test_that("plotav() draws allan() results and bars that reach below zero", {
  set.seed(3)
  # random-walk rate: few degrees of freedom at the longest tau (white rate
  # noise is now typed white there, from its own points, and its last bar
  # no longer reaches below zero). Typed random walk there, as the
  # "coverage" rules do: Stable32's B1 rule (the default) types it white FM
  # at m = 128, with 3.9 degrees of freedom instead of 2.2.
  x <- cumsum(rnorm(500))
  old <- options(allanvar.noise_id = "coverage")
  a <- allan(x, 10)
  options(old)
  # the symmetric half width of the last points exceeds the deviation:
  # adev - (upper - adev) < 0 cannot be drawn on a log axis
  expect_true(any(2 * a$adev - a$upper <= 0, na.rm = TRUE))
  plot_to_file({
    expect_invisible(out <- expect_no_warning(plotav(a)))
    expect_identical(out, a)
    expect_true(graphics::par("ylog"))
    # the y range holds the chi-square limits, not a clipped symmetric bar
    usr <- 10^graphics::par("usr")[3:4]
    expect_lte(usr[1], min(a$lower, na.rm = TRUE))
    expect_gte(usr[2], max(a$upper, na.rm = TRUE))
    big <- data.frame(time = c(1, 2, 4), av = c(1, 0.5, 0.25),
                      error = c(0.1, 0.5, 1.5))
    expect_no_warning(plotav(big))
    # the third bar is cut at the lowest positive end of the others
    expect_equal(10^graphics::par("usr")[3],
                 min(sqrt(big$av[1:2]) * (1 - big$error[1:2])), tolerance = 0.1)
  })
})

test_that("plotav() errors are classed", {
  expect_error(plotav(1:3), class = "allanvar_error_argument")
  expect_error(plotav(data.frame(time = 1, av = 1)), class = "allanvar_error_argument")
  expect_error(plotav(data.frame(time = 1, av = 0, error = 1)),
               class = "allanvar_error_argument")
})

test_that("plotav() draws rows without an interval without warnings", {
  plot_to_file({
    expect_no_warning(plotav(data.frame(time = 1:3, av = c(1, 0.5, 0.3),
                                        error = c(0.1, NA, 0))))
  })
})
