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
  expect_error(plotav(), "`avdf` is missing")
  expect_error(plotav(1:3), "`avdf` must be the data frame returned by avar")
  expect_error(plotav(data.frame(time = 1, av = 1)), "lacks `error`")
  expect_error(plotav(data.frame(time = 1, av = "a", error = 1)),
               "`avdf\\$av` must be numeric")
  expect_error(plotav(data.frame(time = 1, av = 0, error = 1)),
               "no row with positive, finite")
})
