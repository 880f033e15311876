# `[` of allan(), three_cornered_hat() and the curve readers' results
# (R/subset.R): attributes kept while every column is.

test_that("a row subset of allan() keeps its class and attributes; a column subset is a plain data frame", {
  set.seed(1)
  a <- allan(rnorm(4000), 100)
  r <- a[a$tau > 0.05, ]
  expect_s3_class(r, "allan")
  expect_identical(attributes(r)[c("freq", "type", "input", "N", "conf")],
                   attributes(a)[c("freq", "type", "input", "N", "conf")])
  expect_identical(as.data.frame(r), as.data.frame(a)[a$tau > 0.05, ])
  expect_identical(r$adev, a$adev[a$tau > 0.05])
  # columns reordered: still every column
  expect_s3_class(a[rev(names(a))], "allan")
  # print and plot read the attributes: they failed on a column subset
  # ("argument is of length zero") when it kept the class without them
  cols <- a[, c("tau", "adev")]
  expect_identical(class(cols), "data.frame")
  expect_identical(attr(cols, "type"), NULL)
  expect_identical(cols, as.data.frame(a)[, c("tau", "adev")])
  expect_output(print(cols), "adev")
  expect_identical(a[2, "adev"], a$adev[2])
  expect_identical(class(subset(a, tau > 0.05, select = c(tau, adev))),
                   "data.frame")
  expect_snapshot(print(utils::head(a, 2)))
})

test_that("a channel picked out of a multi-channel curve prints as one", {
  set.seed(2)
  a <- allan(cbind(x = rnorm(2000), y = rnorm(2000)), 10, taus = "decade")
  y <- a[a$channel == "y", ]
  expect_s3_class(y, "allan")
  expect_identical(2L * nrow(y), nrow(a))
  expect_match(capture.output(print(a))[1], "2 channels")
  expect_no_match(capture.output(print(y))[1], "channels")
  # without `channel` the rows of two channels would be mixed up
  expect_identical(class(a[, names(a) != "channel"]), "data.frame")
})

test_that("three_cornered_hat() and a read curve keep their attributes under a row subset", {
  set.seed(3)
  n <- 4000
  u <- rnorm(n); v <- rnorm(n, sd = 2); w <- rnorm(n, sd = 3)
  h <- three_cornered_hat(cbind("A-B" = u - v, "B-C" = v - w, "C-A" = w - u), 1)
  hb <- h[h$source == "B", ]
  expect_s3_class(hb, "allan_sources")
  expect_identical(attr(hb, "comparisons"), attr(h, "comparisons"))
  expect_output(print(hb), "allan_sources")
  expect_identical(class(h[, c("tau", "adev")]), "data.frame")

  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  tau <- c(0.1, 1, 10)
  utils::write.table(cbind(tau, matrix(0.01 / sqrt(tau), 3, 6)), f,
                     row.names = FALSE, col.names = FALSE)
  cv <- read_allan_variance_ros_curve(f)
  g <- cv[cv$channel == "gyro_x", ]
  expect_s3_class(g, "tool_curve")
  expect_identical(attr(g, "conventions"), attr(cv, "conventions"))
  expect_output(print(g), "tool_curve")
  expect_identical(class(cv[c("tau", "adev")]), "data.frame")
})
