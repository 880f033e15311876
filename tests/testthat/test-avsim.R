# Monte Carlo: the mean overlapping AV of independent simulations matches the
# catalogue's exact expectation within sampling error (4 standard errors of
# the replicate mean), term by term.
mc_check <- function(args, ms = c(1, 2, 4, 16, 64, 256), reps = 6,
                     n = 1e5, freq = 100) {
  set.seed(42)
  r <- replicate(reps, {
    x <- do.call(avsim, c(list(n = n, freq = freq), args))
    vapply(ms, function(m) oav_ref(x, m, 1 / freq), 0)
  })
  x <- do.call(avsim, c(list(n = 2, freq = freq), args))
  th <- av_model(ms / freq, attr(x, "coef"), freq)
  se <- apply(r, 1, sd) / sqrt(reps)
  list(ratio = rowMeans(r) / th, z = (rowMeans(r) - th) / se)
}

test_that("simulated AV matches the catalogue, term by term", {
  cases <- list(Q = list(Q = 0.01), N = list(N = 0.02), B = list(B = 0.003),
                K = list(K = 1e-3),
                gm = list(gm = list(sigma = 0.01, tc = 0.5)),
                sin = list(sinusoid = list(amp = 0.02, f0 = 0.7)))
  for (nm in names(cases)) {
    res <- mc_check(cases[[nm]])
    expect_true(all(abs(res$z) < 4), label = paste(nm, "within 4 SE"))
    expect_true(all(abs(res$ratio - 1) < 0.05), label = paste(nm, "within 5%"))
  }
  # the ramp is deterministic: exact for every realisation
  x <- avsim(1e4, 100, R = 0.01)
  expect_equal(vapply(c(1, 7, 100), function(m) oav_ref(x, m, 0.01), 0),
               av_model(c(1, 7, 100) / 100, c(R = 0.01), 100), tolerance = 1e-8)
})

test_that("flicker shows the exact discrete excess at m = 1", {
  set.seed(3)
  v <- replicate(6, oav_ref(avsim(1e5, 1, B = 1), 1, 1))
  # 1.443 times the IEEE plateau, far from the flat approximation
  expect_equal(mean(v) / (2 * log(2) / pi), 1 / log(2), tolerance = 0.02)
})

test_that("a composite model adds in variance", {
  args <- list(N = 0.01, B = 0.002, K = 2e-4,
               gm = data.frame(sigma = c(0.01, 0.004), tc = c(0.2, 5)),
               sinusoid = list(amp = 0.01, f0 = 3))
  res <- mc_check(args, reps = 4)
  expect_true(all(abs(res$z) < 4))
})

test_that("seed gives reproducible output and leaves the RNG state alone", {
  set.seed(10)
  before <- .Random.seed
  a <- avsim(100, 10, N = 1, B = 1, seed = 5)
  expect_identical(.Random.seed, before)
  b <- avsim(100, 10, N = 1, B = 1, seed = 5)
  expect_identical(a, b)
  expect_false(identical(a, avsim(100, 10, N = 1, B = 1, seed = 6)))
  expect_s3_class(a, "ts")
  expect_equal(frequency(a), 10)
  expect_equal(attr(a, "coef"), c(N = 1, B = 1))
  # no seed existed before: none afterwards
  if (exists(".Random.seed", globalenv())) rm(".Random.seed", envir = globalenv())
  avsim(10, 1, N = 1, seed = 1)
  expect_false(exists(".Random.seed", globalenv()))
  set.seed(10)
})

test_that("avsim checks its arguments", {
  expect_error(avsim(1, 10, N = 1), "`n`", class = "allanvar_error_argument")
  expect_error(avsim(100, 0, N = 1), "`freq`",
    class = "allanvar_error_argument")
  expect_error(avsim(100, 10, N = -1), "`N`", class = "allanvar_error_argument")
  expect_error(avsim(100, 10, gm = list(sigma = 1)), "`gm`",
    class = "allanvar_error_argument")
  expect_error(avsim(100, 10, gm = list(sigma = 1, tc = -1)), "gm\\$tc",
    class = "allanvar_error_argument")
  expect_error(avsim(100, 10, sinusoid = list(amp = 1, f0 = 6)), "Nyquist",
    class = "allanvar_error_argument")
  expect_error(avsim(100, 10, seed = "a"), "`seed`",
    class = "allanvar_error_argument")
  expect_equal(length(avsim(100, 10)), 100)
})

test_that("avsim() errors are classed and worded", {
  expect_snapshot(error = TRUE, {
    avsim()
    avsim(1, 10, N = 1)
    avsim(100, 10, N = -1)
    avsim(100, 10, gm = list(sigma = 1))
    avsim(100, 10, gm = list(sigma = 1, tc = -1))
    avsim(100, 10, sinusoid = list(amp = 1, f0 = 6))
    avsim(100, 10, X = 1)
    avsim(100, 10, 0.1)
  })
  expect_error(avsim(100, 10, X = 1), class = "allanvar_error_argument")
})
