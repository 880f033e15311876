# dynamic_allan(): every window against allan() on that window alone (an
# independent evaluation), a direct R loop, a non-stationary series with a
# known change, Greenhall EDFs against allantools, and the argument checks.

types <- c("overlapping", "standard", "modified", "hadamard", "ohadamard")

test_that("every window equals allan() on that window, for every type and input", {
  skip_on_cran()
  set.seed(11)
  y <- rnorm(900)
  # a large bias and a drift: the sums must keep their digits
  series <- list(rate = 1e4 + 1e-3 * seq_along(y) + y,
                 integrated = 1e6 + cumsum(y))
  for (input in names(series)) {
    z <- series[[input]]
    for (type in types) {
      for (st in c(7, 60)) {
        d <- dynamic_allan(z, freq = 2, window = 26.5, step = st / 2,
                           type = type, input = input)
        expect_equal(d$window, 53)
        expect_equal(d$step, st)
        expect_equal(length(d$time), floor((900 - 53) / st) + 1)
        for (w in seq_along(d$time)) {
          s <- d$start[w]
          a <- allan(z[s:(s + 52)], freq = 2, taus = I(d$tau), type = type,
                     input = input)
          expect_equal(a$n, d$n)
          expect_equal(d$avar[w, ], a$avar, tolerance = 1e-12)
        }
      }
    }
  }
})

test_that("a direct R loop gives the same overlapping and standard sums", {
  skip_on_cran()
  set.seed(12)
  y <- rnorm(300, mean = 50)
  W <- 40; S <- 9; f <- 1
  d <- dynamic_allan(y, freq = f, window = W, step = S, taus = "all")
  ds <- dynamic_allan(y, freq = f, window = W, step = S, taus = "all",
                      type = "standard")
  for (w in seq_along(d$time)) {
    # minus 50, exact here (Sterbenz), so that R's plain cumsum keeps the
    # digits the reference needs; a constant rate changes no difference
    v <- y[d$start[w]:(d$start[w] + W - 1)] - 50
    x <- c(0, cumsum(v))
    for (k in seq_along(d$m)) {
      m <- d$m[k]
      i <- seq_len(length(x) - 2 * m)
      dd <- x[i + 2 * m] - 2 * x[i + m] + x[i]
      expect_equal(d$avar[w, k], sum(dd^2) / (2 * m^2 * length(i)),
                   tolerance = 1e-12)
      j <- seq(1, by = m, length.out = ds$n[k])
      expect_equal(ds$avar[w, k], sum(dd[j]^2) / (2 * m^2 * length(j)),
                   tolerance = 1e-12)
    }
  }
})

test_that("one window over the whole record is allan() of the record", {
  set.seed(13)
  y <- cumsum(rnorm(5000)) * 1e-3 + rnorm(5000)
  for (type in types) {
    d <- dynamic_allan(y, freq = 50, window = 100, step = 1, type = type)
    a <- allan(y, freq = 50, type = type)
    expect_equal(nrow(d$avar), 1L)
    expect_equal(d$tau, a$tau)
    expect_equal(as.vector(d$avar), a$avar, tolerance = 1e-12)
  }
})

test_that("the surface follows white noise whose level doubles halfway", {
  set.seed(14)
  N <- 40000
  sd <- rep(c(1, 2), each = N / 2)
  y <- rnorm(N) * sd  # our own generator: white rate noise, sigma 1 then 2
  d <- dynamic_allan(y, freq = 1, window = 4000, step = 400, alpha = 0)
  # white rate noise: AV(m) = sigma^2 / m exactly
  truth_first <- 1 / d$m
  before <- d$start + 3999 <= N / 2
  after <- d$start > N / 2
  expect_true(sum(before) >= 8 && sum(after) >= 8)
  r1 <- sweep(d$avar[before, ], 2L, truth_first, "/")
  r2 <- sweep(d$avar[after, ], 2L, 4 * truth_first, "/")
  # within 4 standard errors of the chi-square law with the reported EDF
  se <- sqrt(2 / d$edf)
  expect_true(all(abs(sweep(r1 - 1, 2L, se, "/")) < 4))
  expect_true(all(abs(sweep(r2 - 1, 2L, se, "/")) < 4))
  # level ratio at tau = 1 s: 2 in deviation
  k <- 1L
  expect_equal(median(d$adev[after, k]) / median(d$adev[before, k]), 2,
               tolerance = 0.03)
  # windows across the change follow the share of loud samples in them
  f_loud <- pmin(pmax((d$start + 3999 - N / 2) / 4000, 0), 1)
  expect_gt(cor(d$avar[, k], 1 + 3 * f_loud), 0.995)
  expect_equal(d$time, (d$start - 1) + 1999.5)
})

test_that("Greenhall EDFs agree with allantools' implementation", {
  ref <- utils::read.table(test_path("fixtures", "greenhall-allantools.txt"),
                           header = TRUE, stringsAsFactors = FALSE)
  ref <- ref[is.finite(ref$edf), ]
  expect_gt(nrow(ref), 140)
  # the package's one engine, Greenhall's path (src/edf.cpp)
  mine <- mapply(function(t, a, m) {
    allan_edf_cpp(allan_type_code(t), m, allan_nterms(t, m, 1001), 1001,
                  as.integer(a), FALSE)
  }, ref$type, ref$alpha, ref$m)
  expect_equal(unname(mine), ref$edf, tolerance = 1e-8)
})

test_that("the intervals cover the true deviation about 68% of the time", {
  # independent white-rate records, one window each; noise type identified
  # from the slope
  set.seed(15)
  reps <- 300
  hit <- matrix(NA, reps, 3)
  for (i in seq_len(reps)) {
    y <- rnorm(2000)
    d <- dynamic_allan(y, freq = 1, window = 2000, step = 1,
                       taus = I(c(1, 16, 128)))
    truth <- sqrt(1 / d$m)
    hit[i, ] <- d$lower[1, ] <= truth & truth <= d$upper[1, ]
  }
  cover <- colMeans(hit)
  expect_true(all(cover > 0.6 & cover < 0.78), label = paste(cover))
})

test_that("the noise type is read from the slope, or fixed by alpha", {
  set.seed(16)
  y <- cumsum(rnorm(20000))  # random-walk rate: slope +1, alpha -2
  d <- dynamic_allan(y, freq = 1, window = 5000, step = 1000)
  expect_true(all(d$alpha[d$m <= 256] == -2L))
  wpm <- diff(rnorm(20001))  # white phase noise: alpha 2 or 1 (same slope)
  d2 <- dynamic_allan(wpm, freq = 1, window = 5000, step = 1000)
  expect_true(all(d2$alpha[d2$m <= 256] %in% c(1L, 2L)))
  d3 <- dynamic_allan(wpm, freq = 1, window = 5000, step = 1000, alpha = 0)
  expect_true(all(d3$alpha == 0L))
  expect_identical(d3$alpha_rule, "fixed")
  ref <- allan_edf_direct("overlapping", d3$m,
                          allan_nterms("overlapping", d3$m, 5001), 5001,
                          rep(0L, length(d3$m)))
  expect_equal(d3$edf, ref)
})

test_that("threads do not change the result; ts input sets the time origin", {
  set.seed(17)
  y <- ts(rnorm(3000), start = 100, frequency = 10)
  old <- options(allanvar.threads = 1L)
  d1 <- dynamic_allan(y, window = 30, step = 5)
  options(allanvar.threads = 2L)
  d2 <- dynamic_allan(y, window = 30, step = 5)
  options(old)
  expect_identical(d1, d2)
  expect_equal(d1$freq, 10)
  expect_equal(d1$time[1], 100 + 299 / 2 / 10)
})

test_that("defaults: a tenth of the record, a tenth of the window", {
  set.seed(18)
  d <- dynamic_allan(rnorm(10000), freq = 100)
  expect_equal(d$window, 1000)
  expect_equal(d$step, 100)
  expect_equal(length(d$time), 91)
  expect_equal(max(d$m), 256)  # octave grid up to floor((1001 - 1) / 2)
  small <- dynamic_allan(rnorm(50), freq = 1)
  expect_equal(small$window, 50)
  expect_equal(length(small$time), 1)
})

test_that("print, summary and as.data.frame", {
  set.seed(19)
  d <- dynamic_allan(rnorm(4000), freq = 10, window = 50, step = 25)
  expect_snapshot(print(d))
  expect_snapshot(print(summary(d)))
  df <- as.data.frame(d)
  expect_equal(nrow(df), length(d$time) * length(d$tau))
  expect_equal(names(df), c("time", "start", "tau", "m", "n", "avar", "adev",
                            "lower", "upper", "edf", "alpha"))
  expect_equal(df$adev[df$time == d$time[3]], d$adev[3, ])
  expect_true(all(df$lower <= df$adev & df$adev <= df$upper))
  s <- summary(d)
  expect_equal(s$adev_max, apply(d$adev, 2, max))
})

test_that("plots draw", {
  set.seed(20)
  y <- c(rnorm(3000), rnorm(3000, sd = 3))
  d <- dynamic_allan(y, freq = 10, window = 100, step = 20)
  skip_if_not_installed("vdiffr")
  vdiffr::expect_doppelganger("dynamic surface", function() plot(d))
  vdiffr::expect_doppelganger("dynamic windows",
                              function() plot(d, what = "windows"))
  vdiffr::expect_doppelganger("dynamic taus",
                              function() plot(d, what = "taus", at = c(0.1, 3)))
})

test_that("bad input is refused with classed errors", {
  y <- rnorm(100)
  expect_snapshot(error = TRUE, {
    dynamic_allan()
    dynamic_allan(y)
    dynamic_allan(y, freq = -1)
    dynamic_allan(cbind(y, y), freq = 1)
    dynamic_allan(c(y, NA), freq = 1)
    dynamic_allan(y, freq = 1, window = 1)
    dynamic_allan(y, freq = 1, window = 200)
    dynamic_allan(y, freq = 1, step = 0)
    dynamic_allan(y, freq = 1, type = "total")
    dynamic_allan(y, freq = 1, alpha = 3)
    dynamic_allan(y, freq = 1, alpha = -3)
    dynamic_allan(y, freq = 1, taus = "weekly")
    dynamic_allan(y, freq = 1, window = 20, taus = c(100, 200))
    plot(dynamic_allan(y, freq = 1), what = "contour")
  })
  expect_error(dynamic_allan(y, freq = 1, window = 1),
               class = "allanvar_error_argument")
  expect_error(dynamic_allan(y), class = "allanvar_error_missing_argument")
  expect_warning(dynamic_allan(y, freq = 1, window = 20, taus = c(1, 200)),
                 class = "allanvar_warning_taus_dropped")
})
