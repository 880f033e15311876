test_that("data(gyroz) is allanvar 1.1's series", {
  env <- new.env()
  utils::data("gyroz", package = "allanvar", envir = env)
  g <- env$gyroz
  expect_s3_class(g, "ts")
  expect_length(g, 10000)
  expect_equal(frequency(g), 97.65625)
  expect_equal(tsp(g)[1], 1)
  skip_if_no_shared()
  expect_identical(g, readRDS(shared_file("gyroz.rds")))
})

test_that("data(gyroz_long) and data(gyroz_complete) give the long series", {
  env <- new.env()
  utils::data("gyroz_long", package = "allanvar", envir = env)
  utils::data("gyroz_complete", package = "allanvar", envir = env)
  expect_length(env$gyroz_long, 65536)
  # As in the original, gyroz_complete defines an object named gyroz.
  expect_identical(env$gyroz, env$gyroz_long)
  utils::data("gyroz", package = "allanvar", envir = env)
  expect_identical(as.numeric(env$gyroz_long[1:10000]), as.numeric(env$gyroz))
  skip_if_no_shared()
  expect_identical(env$gyroz_long, readRDS(shared_file("gyroz_long.rds")))
})

test_that("demo(allanvar) runs without error", {
  path <- tempfile(fileext = ".pdf")
  grDevices::pdf(path)
  on.exit({
    grDevices::dev.off()
    unlink(path)
  })
  expect_no_error(utils::capture.output(
    demo("allanvar", package = "allanvar", ask = FALSE, echo = FALSE)))
})
