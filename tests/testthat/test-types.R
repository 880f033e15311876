# The further statistics of allan(): published NIST SP 1065 values for the
# NBS14 set, Stable32's runs on PHASE.DAT (the NBS14 phase), and plain R
# evaluations of each definition (helper-types-ref.R).

test_that("NBS14 1000-point set: NIST SP 1065's TDEV, MTOT, TTOT and HTOT", {
  y <- nbs14_freq()
  x <- nbs14_phase()
  for (inp in c("rate", "integrated")) {
    v <- if (inp == "rate") y else x
    td <- allan(v, 1, taus = c(1, 10, 100), type = "tdev", input = inp)
    expect_equal(signif(td$adev, 7), c(1.687202e-1, 3.563623e-1, 1.253382),
                 tolerance = 0)
    mt <- allan(v, 1, taus = c(1, 10, 100), type = "mtotdev", input = inp)
    expect_equal(mt$alpha, c(0L, 0L, 0L))  # white FM: factor 1/0.73
    expect_equal(signif(mt$adev, 7), c(2.418528e-1, 6.499161e-2, 2.287774e-2),
                 tolerance = 0)
    tt <- allan(v, 1, taus = c(1, 10, 100), type = "ttotdev", input = inp)
    expect_equal(signif(tt$adev, 7), c(1.396338e-1, 3.752293e-1, 1.320847),
                 tolerance = 0)
    ht <- allan(v, 1, taus = c(1, 10, 100), type = "htotdev", input = inp)
    # HTOTDEV(10) is 0.0961478750096 here: the published 9.614787e-2 sits a
    # hair (1e-12 relative) below the rounding tie of the 7th digit.
    expect_equal(signif(ht$adev[c(1, 3)], 7), c(2.943883e-1, 3.058103e-2),
                 tolerance = 0)
    expect_lt(abs(ht$adev[2] / 9.614787e-2 - 1), 1e-7)
  }
})

test_that("NBS14: Stable32 1.60's uncorrected MTOT, TTOT and Theo1", {
  y <- nbs14_freq()
  mt <- allan(y, 1, taus = c(1, 10, 100), type = "mtotdev", debias = FALSE)
  expect_equal(signif(mt$adev, 5), c(2.0664e-01, 5.5529e-02, 1.9547e-02),
               tolerance = 0)
  tt <- allan(y, 1, taus = c(1, 10, 100), type = "ttotdev", debias = FALSE)
  expect_equal(signif(tt$adev, 5), c(1.1930e-01, 3.2060e-01, 1.1285),
               tolerance = 0)
  # Theo1 at m = 10, 100, 1000: averaging times 0.75 m
  th <- allan(y, 1, taus = 0.75 * c(10, 100, 1000), type = "theo1",
              debias = FALSE)
  expect_equal(th$m, c(10L, 100L, 1000L))
  expect_equal(th$tau, c(7.5, 75, 750))
  expect_equal(signif(th$adev, 5), c(1.0757e-01, 3.1789e-02, 5.0524e-03),
               tolerance = 0)
  # the default multiplies by Howe and Tasset's AVAR/Theo1 ratio for the
  # noise type found at each tau: 1 for white FM
  d <- allan(y, 1, taus = 0.75 * c(10, 100, 1000), type = "theo1")
  f <- ifelse(is.na(d$alpha) | d$alpha == 0L, 1, c(2.70, 1.87)[match(d$alpha, -2:-1)] +
                c(-1.53, -1.05)[match(d$alpha, -2:-1)] /
                (0.75 * d$m)^c(0.85, 0.79)[match(d$alpha, -2:-1)])
  expect_true(all(d$alpha %in% c(-2L, -1L, 0L, NA)))
  expect_equal(d$adev, th$adev * sqrt(f), tolerance = 1e-14)
  expect_equal(d$adev[1], th$adev[1])
})

test_that("NBS14: PDEV as SigmaTheta computes it (allantools' reference)", {
  y <- nbs14_freq()
  p <- allan(y, 1, taus = 2^(0:8), type = "pdev")
  want <- c(2.9223187810675200e-01, 2.1445233564252639e-01,
            1.5618112158618463e-01, 1.1709745745448434e-01,
            6.9029585189839343e-02, 4.9749707730398392e-02,
            3.8947417330713739e-02, 3.0862392741372108e-02,
            1.2447414341332683e-02)
  expect_lt(max(abs(p$adev / want - 1)), 1e-11)
  expect_equal(p$n, c(999, 1001 - 2 * 2^(1:8)))
  expect_equal(p$adev[1], allan(y, 1, taus = I(1))$adev)
})

test_that("PHASE.DAT: Stable32's MTIE, TIE rms and Theo1 digits and counts", {
  x <- nbs14_phase()
  mt <- allan(x, 1, taus = 2^(1:9) - 1, type = "mtie", input = "integrated")
  expect_equal(signif(mt$adev, 5),
               c(5.0597e-01, 1.2984e+00, 2.2922e+00, 2.9949e+00, 4.4550e+00,
                 6.5989e+00, 6.8061e+00, 7.8205e+00, 7.8205e+00), tolerance = 0)
  expect_equal(mt$n, c(1000, 998, 994, 986, 970, 938, 874, 746, 490))
  expect_true(all(is.na(mt$lower) & is.na(mt$edf) & is.na(mt$alpha)))
  ti <- allan(x, 1, taus = 1:10, type = "tierms", input = "integrated")
  expect_equal(signif(ti$adev, 5),
               c(2.8832e-01, 4.0240e-01, 4.9390e-01, 5.7044e-01, 6.4195e-01,
                 7.0066e-01, 7.5338e-01, 7.9644e-01, 8.3728e-01, 8.7588e-01),
               tolerance = 0)
  th <- allan(x, 1, taus = 0.75 * c(10, 20, 40, 100, 202, 400, 998),
              type = "theo1", input = "integrated", debias = FALSE)
  expect_equal(signif(th$adev, 5),
               c(1.0757e-01, 7.2762e-02, 4.8652e-02, 3.1789e-02, 2.4120e-02,
                 1.4321e-02, 5.0234e-03), tolerance = 0)
  expect_equal(signif(th$n, 5),
               c(4955, 9810, 19220, 45050, 80699, 120200, 1497))
})

test_that("PHASE.DAT: Stable32's Total family values and limits (25% of half-width)", {
  x <- nbs14_phase()
  within <- function(a, lo, hi, dev) {
    expect_lt(max(abs(a$lower - lo) / (dev - lo)), 0.25)
    expect_lt(max(abs(a$upper - hi) / (hi - dev)), 0.25)
  }
  m <- 2^(0:5)
  mt <- allan(x, 1, taus = m, type = "mtotdev", input = "integrated",
              debias = FALSE)
  dev <- c(2.0664e-01, 1.4337e-01, 9.4613e-02, 6.5721e-02, 3.7135e-02,
           2.9114e-02)
  expect_equal(signif(mt$adev, 5), dev, tolerance = 0)
  expect_equal(mt$n, c(999, 996, 990, 978, 954, 906))
  within(mt, c(2.0163e-01, 1.3898e-01, 9.0598e-02, 6.1866e-02, 3.4536e-02,
               2.6331e-02),
         c(2.1204e-01, 1.4821e-01, 9.9218e-02, 7.0406e-02, 4.0425e-02,
           3.3017e-02), dev)
  tt <- allan(x, 1, taus = m[1:5], type = "ttotdev", input = "integrated",
              debias = FALSE)
  expect_equal(signif(tt$adev, 5),
               c(1.1930e-01, 1.6555e-01, 2.1850e-01, 3.0355e-01, 3.4304e-01),
               tolerance = 0)
  ht <- allan(x, 1, taus = m[1:5], type = "htotdev", input = "integrated")
  dev <- c(2.9439e-01, 2.0297e-01, 1.4252e-01, 1.0822e-01, 6.5265e-02)
  expect_equal(signif(ht$adev, 5), dev, tolerance = 0)
  expect_equal(ht$n, c(998, 995, 989, 977, 953))
  within(ht, c(2.8670e-01, 1.9726e-01, 1.3744e-01, 1.0303e-01, 6.1280e-02),
         c(3.0274e-01, 2.0922e-01, 1.4821e-01, 1.1430e-01, 7.0151e-02), dev)
})

test_that("Theo1, ThéoBR: fast kernels against the direct O(N^2) evaluation", {
  set.seed(11)
  N <- 400
  w <- rnorm(N)
  sets <- list(wpm = w, wfm = cumsum(w), rwfm = cumsum(cumsum(w)),
               drift = cumsum(w) + 1e3 + 0.05 * (1:N)^2)
  for (nm in names(sets)) {
    x <- sets[[nm]]
    a <- allan(x, 1, taus = "all", type = "theo1", input = "integrated",
               debias = FALSE)
    expect_equal(a$m, seq(2, N - 2, by = 2))
    pick <- c(1, 2, 3, 5, 25, 50, 100, 150, 199)
    ref <- vapply(a$m[pick], function(m) ref_theo1(x, m), 0)
    expect_lt(max(abs(a$avar[pick] / ref - 1)), 1e-10, label = nm)
    # the all-k recurrence (double-double) against the same reference
    T <- theo1_all_cpp(x, FALSE, (N - 1) %/% 2, numeric(0))
    mm <- a$m[pick]
    fast <- T[mm / 2] / (0.75 * (N - mm) * mm^2)
    expect_lt(max(abs(fast / ref - 1)), 1e-10, label = nm)
    # ThéoBR's factor
    br <- allan(x, 1, taus = I(0.75 * c(10, 100)), type = "theobr",
                input = "integrated")
    kf <- br$avar / a$avar[a$m %in% c(10, 100)]
    expect_lt(max(abs(kf / ref_theobr_factor(x) - 1)), 1e-10, label = nm)
  }
})

test_that("Total family, PDEV, MTIE, TIE rms against their definitions", {
  set.seed(12)
  N <- 300
  line <- 1e9 + 3e4 * (1:N)
  sets <- list(wfm = cumsum(rnorm(N)), rwfm = cumsum(cumsum(rnorm(N))),
               offset = line + rnorm(N))
  for (nm in names(sets)) {
    x <- sets[[nm]]
    # the statistics that ignore a linear phase term: the reference works
    # on the stored values minus the line, exactly (a plain R evaluation on
    # values near 1e9 would itself lose seven digits)
    z <- if (nm == "offset") x - line else x
    m <- c(1, 2, 3, 5, 8, 17, 40, 99)
    mt <- allan(x, 1, taus = m, type = "mtotdev", input = "integrated",
                debias = FALSE)
    expect_lt(max(abs(mt$avar / vapply(m, function(k) ref_mtotvar(z, k), 0) - 1)),
              1e-10, label = nm)
    ht <- allan(x, 1, taus = m, type = "htotdev", input = "integrated",
                debias = FALSE)
    expect_lt(max(abs(ht$avar / vapply(m, function(k) ref_htotvar(z, k), 0) - 1)),
              1e-10, label = nm)
    pm <- c(1, 2, 3, 7, 20, 64, 149)
    pv <- allan(x, 1, taus = pm, type = "pdev", input = "integrated")
    expect_lt(max(abs(pv$avar / vapply(pm, function(k) ref_pvar(z, k), 0) - 1)),
              1e-10, label = nm)
    em <- c(1, 2, 5, 31, 100, 299)
    ti <- allan(x, 1, taus = em, type = "tierms", input = "integrated")
    expect_lt(max(abs(ti$adev / vapply(em, function(k) ref_tierms(x, k), 0) - 1)),
              1e-12, label = nm)
    mi <- allan(x, 1, taus = em, type = "mtie", input = "integrated")
    expect_lt(max(abs(mi$adev / vapply(em, function(k) ref_mtie(x, k), 0) - 1)),
              1e-12, label = nm)
  }
})

test_that("MTIE at octave taus is the definition's", {
  set.seed(17)
  for (L in c(3, 4, 5, 17, 33, 9000)) {
    x <- cumsum(rnorm(L)) + 50 * (seq_len(L) %% 997 == 0)  # a walk with spikes
    m <- 2^(0:20)
    m <- m[m <= L - 1]
    mi <- allan(x, 1, taus = I(m), type = "mtie", input = "integrated")
    ref <- vapply(m, function(k) ref_mtie(x, k), 0)
    expect_equal(mi$adev, ref, tolerance = 1e-13, label = paste("L =", L))
    # a subset of the octaves (the levels between are built all the same)
    if (length(m) > 3) {
      sub <- m[c(2, length(m))]
      ms <- allan(x, 1, taus = I(sub), type = "mtie", input = "integrated")
      expect_equal(ms$adev, ref[c(2, length(m))], tolerance = 1e-13)
    }
  }
})

test_that("rate input with a large bias loses nothing", {
  set.seed(13)
  y <- 1e7 + rnorm(5000)  # a bias of 1e7 noise sigmas
  x <- c(0, cumsum(y - 1e7))  # y - 1e7 is exact
  for (ty in c("tdev", "mtotdev", "htotdev", "theo1", "pdev")) {
    a <- allan(y, 1, type = ty, debias = FALSE)
    b <- allan(x, 1, type = ty, input = "integrated", debias = FALSE)
    expect_lt(max(abs(a$avar / b$avar - 1)), 1e-11, label = ty)
  }
  # the time errors keep the offset: window sums of y
  m <- c(1, 16, 1000)
  ti <- allan(y, 1, taus = m, type = "tierms")
  ref <- vapply(m, function(k) {
    s <- x[(1 + k):length(x)] - x[1:(length(x) - k)]
    sqrt(mean((s + 1e7 * k)^2))
  }, 0)
  expect_lt(max(abs(ti$adev / ref - 1)), 1e-12)
  mi <- allan(y, 1, taus = m, type = "mtie")
  ref <- vapply(m, function(k) ref_mtie(x + 1e7 * (seq_along(x) - 1), k), 0)
  expect_lt(max(abs(mi$adev / ref - 1)), 1e-9)
})

test_that("ThéoH: Allan deviation to 20% of the record, then ThéoBR", {
  x <- nbs14_phase()
  h <- allan(x, 1, type = "theoh", input = "integrated")
  avar_rows <- h$tau == h$m
  expect_equal(h$m[avar_rows], 2^(0:7))   # m <= 0.2 * 1000
  expect_equal(h$m[!avar_rows], c(256, 512))
  expect_equal(h$tau[!avar_rows], 0.75 * c(256, 512))
  oa <- allan(x, 1, taus = I(2^(0:7)), type = "overlapping", input = "integrated")
  expect_equal(h$adev[avar_rows], oa$adev)
  # the Allan rows' limits are the overlapping type's (exact at few
  # averages), not a chi-square with the EDF of the type read
  expect_identical(h$lower[avar_rows], oa$lower)
  expect_identical(h$upper[avar_rows], oa$upper)
  br <- allan(x, 1, taus = I(0.75 * c(256, 512)), type = "theobr",
              input = "integrated")
  expect_equal(h$adev[!avar_rows], br$adev)
})

test_that("allantools' names are aliases of the six types", {
  y <- nbs14_freq()
  for (al in names(allan_type_aliases)) {
    expect_identical(allan(y, 1, type = al),
                     allan(y, 1, type = allan_type_aliases[[al]]), label = al)
  }
})

test_that("several channels and threads", {
  set.seed(14)
  y <- matrix(rnorm(3000), ncol = 2, dimnames = list(NULL, c("a", "b")))
  y[, 2] <- 2 * y[, 1]
  for (ty in c("mtotdev", "theo1", "mtie", "pdev", "tdev")) {
    a <- allan(y, 10, type = ty)
    expect_equal(unique(a$channel), c("a", "b"))
    expect_equal(a$adev[a$channel == "b"], 2 * a$adev[a$channel == "a"],
                 tolerance = 1e-12)
    one <- with_threads(1L, allan(y, 10, type = ty))
    expect_identical(one, a)
  }
})

test_that("taus of the Theo1 types map to even m at 0.75 m tau0", {
  y <- nbs14_freq()
  expect_equal(allan(y, 1, type = "theo1")$m, 2^(1:9))
  expect_equal(allan(y, 1, type = "theo1", taus = "decade")$m,
               c(2, 4, 10, 20, 40, 100, 200, 400, 1000))
  expect_snapshot(a <- allan(y, 1, type = "theo1", taus = c(0.5, 3, 2000)))
  expect_equal(a$m, 4L)
})

test_that("errors and warnings are classed and name the argument", {
  y <- nbs14_freq()
  expect_error(allan(y, 1, type = "theo1", debias = NA),
               class = "allanvar_error_argument")
  expect_snapshot(error = TRUE, allan(y, 1, type = "mtotdev", debias = "yes"))
  expect_snapshot(error = TRUE, allan(y, 1, type = "avar"))
  expect_error(allan(y[1:10], 1, type = "theobr"),
               class = "allanvar_error_argument")
  y[5] <- NaN
  expect_snapshot(error = TRUE, allan(y, 1, type = "mtie"))
})

test_that("print says the statistic and the unit; plot labels the axis", {
  x <- nbs14_phase()
  a <- allan(x, 1, type = "mtie", input = "integrated", taus = "decade")
  expect_snapshot(print(a))
  b <- allan(x, 1, type = "mtotdev", input = "integrated", taus = "decade")
  expect_snapshot(print(b))
  labels <- c(tdev = "time deviation TDEV (s)",
              mtie = "maximum time interval error MTIE (s)",
              tierms = "rms time interval error TIE rms (s)",
              ttotdev = "time total deviation TTOT (s)",
              theo1 = "Theo1 deviation",
              mtotdev = "modified total deviation",
              htotdev = "Hadamard total deviation",
              pdev = "parabolic deviation")
  for (ty in names(labels)) {
    s <- plot_strings(plot(allan(x, 1, type = ty, input = "integrated")))
    expect_true(labels[[ty]] %in% s, label = ty)
  }
})

# White PM, white FM, random-walk FM and a large offset with drift (the
# cancellation cases of the closed-form kernels), N points each.
four_noises <- function(N) {
  list(wpm = rnorm(N), wfm = cumsum(rnorm(N)),
       rwfm = cumsum(cumsum(rnorm(N))),
       drift = 1e6 + 1e3 * (1:N) + 0.01 * (1:N)^2 + cumsum(rnorm(N)))
}

test_that("the Total family's closed form equals its direct evaluation", {
  set.seed(15)
  N <- 4000
  sets <- four_noises(N)
  m <- c(8, 9, 16, 31, 100, 257, 1000, 1333)
  for (nm in names(sets)) {
    x <- sets[[nm]]
    for (h in c(FALSE, TRUE)) {
      mm <- if (h) m[m <= (N - 1) / 3] else m
      direct <- total_sums_cpp(x, FALSE, mm, h, 2L, 1L)
      fast <- total_sums_cpp(x, FALSE, mm, h, 2L, 2L)
      expect_lt(max(abs(fast / direct - 1)), 1e-10, label = paste(nm, h))
    }
  }
})

test_that("PDEV's doubling recursion (octave m) equals the other kernels", {
  set.seed(18)
  N <- 20000  # long enough for every grouping of levels (src/pdev.cpp)
  sets <- four_noises(N)
  sets$offset <- cumsum(rnorm(N, 1e6))
  m <- 2^(0:13)
  for (nm in names(sets)) {
    x <- sets[[nm]]
    blocked <- pdev_sums_cpp(x, FALSE, m, 2L, 1L)
    octave <- pdev_sums_cpp(x, FALSE, m, 2L, 3L)
    expect_lt(max(abs(octave / blocked - 1)), 1e-10, label = nm)
    # the same sums whatever the number of threads, and chosen by default
    expect_identical(pdev_sums_cpp(x, FALSE, m, 1L, 3L), octave, label = nm)
    expect_identical(pdev_sums_cpp(x, FALSE, m, 2L, 0L), octave, label = nm)
    # tiles of 64 values (many residue blocks, short records): the same
    # values, the squares summed in another order
    expect_lt(max(abs(pdev_sums_cpp(x, FALSE, m, 1L, 4L) / octave - 1)),
              1e-13, label = nm)
    y <- diff(x)
    expect_lt(max(abs(pdev_sums_cpp(y, TRUE, m, 2L, 3L) / blocked - 1)),
              1e-10, label = nm)
  }
  # against the definition, where a plain sum has nothing to cancel
  x <- sets$wpm
  mm <- c(2, 64, 4096, 8192)
  ref <- vapply(mm, function(k) ref_pvar(x, k) * (N - 2 * k) * k^6 / 18, 0)
  expect_lt(max(abs(pdev_sums_cpp(x, FALSE, mm, 2L, 3L) / ref - 1)), 1e-12)
})

test_that("PDEV's octave kernel in two parts (long records) equals the others", {
  # from 2^16 points the first levels run in two parts, each with the
  # margin past its end that its upper levels read (src/pdev.cpp)
  set.seed(19)
  N <- 70001
  m <- 2^(0:14)
  for (x in list(cumsum(rnorm(N)), rnorm(N) + 1e-4 * (1:N))) {
    blocked <- pdev_sums_cpp(x, FALSE, m, 2L, 1L)
    octave <- pdev_sums_cpp(x, FALSE, m, 2L, 3L)
    expect_lt(max(abs(octave / blocked - 1)), 1e-10)
    expect_identical(pdev_sums_cpp(x, FALSE, m, 1L, 3L), octave)
    expect_lt(max(abs(pdev_sums_cpp(x, FALSE, m, 1L, 4L) / octave - 1)),
              1e-13)
  }
})

test_that("PDEV keeps its digits on long random-walk records", {
  set.seed(16)
  N <- 4000
  for (x in list(cumsum(cumsum(rnorm(N))), cumsum(rnorm(N)) + 1e-3 * (1:N)^2)) {
    m <- c(2, 3, 8, 64, 500, 1999)
    p <- allan(x, 1, taus = m, type = "pdev", input = "integrated")
    ref <- vapply(m, function(k) ref_pvar(x, k), 0)
    expect_lt(max(abs(p$avar / ref - 1)), 1e-10)
  }
})

test_that("tdev with gaps keeps the modified terms without a gap (by hand)", {
  set.seed(3)
  x <- cumsum(rnorm(200))
  x[c(17, 90, 91)] <- NA
  a <- allan(x, 2, taus = c(0.5, 1, 2.5, 5), type = "tdev",
             input = "integrated")
  # TVAR = mean over complete terms of (second difference of m-point
  # phase means)^2 / 6; a term uses x[k .. k + 3m - 1]
  hand <- vapply(a$m, function(m) {
    t <- vapply(seq_len(200 - 3 * m + 1), function(k) {
      j <- k:(k + m - 1)
      sum(x[j + 2 * m] - 2 * x[j + m] + x[j]) / m
    }, 0)
    t <- t[!is.na(t)]
    c(length(t), mean(t^2) / 6)
  }, c(0, 0))
  expect_equal(a$n, as.integer(hand[1, ]), ignore_attr = TRUE)
  expect_equal(a$avar, hand[2, ], tolerance = 1e-12)
  expect_equal(attr(a, "type"), "tdev")
  expect_equal(unname(attr(a, "missing")), 3L)
  # one gap-free stretch: the same as without gaps
  b <- allan(x[18:89], 2, taus = c(0.5, 1), type = "tdev",
             input = "integrated")
  y <- c(x[18:89], NA)
  expect_equal(allan(y, 2, taus = c(0.5, 1), type = "tdev",
                     input = "integrated")$avar, b$avar, tolerance = 1e-12)
})

test_that("types without a gap rule refuse NA with a classed error", {
  x <- c(cumsum(rnorm(300)), NA, cumsum(rnorm(99)))
  for (type in c("mtotdev", "ttotdev", "htotdev", "theo1", "theobr",
                 "theoh", "mtie", "tierms", "pdev", "total")) {
    expect_error(allan(x, 1, type = type, input = "integrated"),
                 class = "allanvar_error_gaps")
  }
})

test_that("PDEV's global kernel equals its blocked kernel and a plain sum", {
  set.seed(17)
  N <- 4000
  sets <- four_noises(N)
  m <- c(2, 3, 8, 31, 100, 257, 1000, 1999)
  for (nm in names(sets)) {
    x <- sets[[nm]]
    blocked <- pdev_sums_cpp(x, FALSE, m, 2L, 1L)
    global <- pdev_sums_cpp(x, FALSE, m, 2L, 2L)
    chosen <- pdev_sums_cpp(x, FALSE, m, 1L, 0L)
    expect_lt(max(abs(global / blocked - 1)), 1e-11, label = nm)
    expect_lt(max(abs(chosen / blocked - 1)), 1e-11, label = nm)
  }
  # white PM: the plain sum of the definition has no cancellation to fear
  x <- sets$wpm
  mm <- c(2, 7, 500, 1999)
  ref <- vapply(mm, function(k) ref_pvar(x, k) * (N - 2 * k) * k^6 / 18, 0)
  expect_lt(max(abs(pdev_sums_cpp(x, FALSE, mm, 2L, 2L) / ref - 1)), 1e-13)
})
