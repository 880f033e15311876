test_that("Greenhall's EDF agrees with allantools' edf_greenhall on a grid", {
  # tools/make-greenhall-fixture.py: allantools 599dc9e, five types, alpha
  # 2..-4, m 1..1000, N 10..1e5 (every case of the algorithm)
  ref <- utils::read.csv(test_path("fixtures", "edf-greenhall.csv"),
                         stringsAsFactors = FALSE)
  expect_gt(nrow(ref), 1400)
  mine <- mapply(function(t, a, m, N) {
    allan_edf_cpp(allan_type_code(t), m, 1, N, as.integer(a), FALSE)
  }, ref$type, ref$alpha, ref$m, ref$N)
  expect_equal(unname(mine), ref$edf, tolerance = 1e-8)
})

test_that("the terms' eigenvalues give the exact discrete EDF", {
  # 1 / sum(lambda^2) is the EDF 2 E^2 / Var; the engine's Isserlis sums
  # (src/edf.cpp) are an independent computation for white and random-walk
  # FM; non-overlapping white FM has 2 n^2 / (3 n - 1) in closed form
  for (n in c(2, 5, 15)) {
    l <- gchisq_weights_cpp(0L, 4, n, 0L)
    expect_equal(sum(l), 1)
    expect_equal(1 / sum(l^2), 2 * n^2 / (3 * n - 1), tolerance = 1e-10)
  }
  for (type in c("standard", "overlapping", "modified", "hadamard",
                 "ohadamard")) {
    for (a in c(0L, -2L)) for (m in c(1, 3, 8)) {
      L <- 12 * m + 1
      n <- allan_nterms(type, m, L)
      l <- gchisq_weights_cpp(allan_type_code(type), m, n, a)
      expect_equal(1 / sum(l^2),
                   allan_edf_cpp(allan_type_code(type), m, n, L, a, TRUE),
                   tolerance = 1e-9)
    }
  }
})

test_that("the term covariance matches a dense covariance under flicker noise", {
  # phase x = (1 - B)^(-delta) e from time 0 over a long burn-in: its dense
  # covariance (the MA weights' cross products), the standard AV's terms
  # at stride m, their correlation against the kernel's eigenvalues
  set.seed(1)
  for (alpha in c(1L, -1L)) {
    delta <- (2 - alpha) / 2
    burn <- 6000
    len <- burn + 40
    psi <- cumprod(c(1, (seq_len(len - 1) - 1 + delta) / seq_len(len - 1)))
    m <- 4; n <- 6
    idx <- burn + seq(0, (n + 1) * m, by = 1)
    # x_t = sum_{j <= t} psi_j e_{t-j}
    X <- outer(idx, seq_len(len), function(t, s) {
      ifelse(s <= t, psi[pmax(1, t - s + 1)], 0)
    })
    W <- matrix(0, n, length(idx))
    for (k in seq_len(n)) {
      W[k, (k - 1) * m + c(1, m + 1, 2 * m + 1)] <- c(1, -2, 1)
    }
    C <- W %*% X %*% t(X) %*% t(W)
    ev <- sort(eigen(C, symmetric = TRUE, only.values = TRUE)$values,
               decreasing = TRUE)
    expect_equal(gchisq_weights_cpp(0L, m, n, alpha), ev / sum(ev),
                 tolerance = 2e-3)
  }
})

test_that("Imhof quantiles agree with CompQuadForm and the chi-square", {
  p <- c(0.025, 0.16, 0.84, 0.975)
  expect_equal(gchisq_quantile_cpp(rep(0.1, 10), p), qchisq(p, 10) / 10,
               tolerance = 1e-5)
  # two weights: Imhof's integrand decays as u^-2 only (dqagi's error
  # about 1e-4 in the 97.5% quantile)
  expect_equal(gchisq_quantile_cpp(c(0.5, 0.5), p), qchisq(p, 2) / 2,
               tolerance = 1e-3)
  skip_if_not_installed("CompQuadForm")
  lam <- c(0.6, 0.25, 0.1, 0.05)
  q <- c(0.05, 0.3, 1, 2.5)
  ref <- vapply(q, function(x) {
    1 - CompQuadForm::imhof(x, lam, epsabs = 1e-10, epsrel = 1e-10,
                            limit = 10000)$Qq
  }, 0)
  expect_equal(gchisq_cdf_cpp(lam, q), ref, tolerance = 1e-6)
  # 300 weights, compressed beyond the 40 largest
  l <- gchisq_weights_cpp(1L, 25, 300, -1L)
  qq <- gchisq_quantile_cpp(l, p)
  back <- vapply(qq, function(x) {
    1 - CompQuadForm::imhof(x, l, epsabs = 1e-10, epsrel = 1e-10,
                            limit = 10000)$Qq
  }, 0)
  expect_equal(back, p, tolerance = 1e-4)
})

test_that("allan() uses the exact limits at N/m <= 16 only", {
  set.seed(3)
  y <- rnorm(1024)
  old <- options(allanvar.ci_exact = 0)
  on.exit(options(old))
  a0 <- allan(y, 1, type = "overlapping")
  options(allanvar.ci_exact = 16)
  a1 <- allan(y, 1, type = "overlapping")
  few <- 1024 / a0$m <= 16
  expect_identical(a1$adev, a0$adev)
  expect_identical(a1$lower[!few], a0$lower[!few])
  many <- few & a1$n > 1
  expect_true(all(a1$upper[many] != a0$upper[many]))
  # a row's factors: the union over the types exact_sets() keeps (the
  # reading at N/m >= 64 where it is FM, else the own reading and its
  # redder neighbour)
  i <- which(many)[1]
  set <- exact_sets(a1$m, 1025, a1$alpha, -2L)[[i]]
  f <- sapply(set, function(a) {
    exact_factors_one(allan_type_code("overlapping"), a1$m[i], a1$n[i], a,
                      0.683)
  })
  expect_equal(a1$upper[i] / a1$adev[i], max(f[2, ]))
  expect_equal(a1$lower[i] / a1$adev[i], min(f[1, ]))
  # one term: chi-square(1) whatever the type
  one <- which(a1$n == 1)
  expect_equal(a1$upper[one],
               a1$adev[one] / sqrt(qchisq((1 - 0.683) / 2, 1)))
  # the default threshold is N/m <= 32
  options(allanvar.ci_exact = NULL)
  a2 <- allan(y, 1, type = "overlapping")
  few32 <- 1024 / a0$m <= 32 & a0$n > 1
  expect_true(any(few32 & !few))
  expect_true(all(a2$upper[few32] != a0$upper[few32]))
  expect_identical(a2$lower[!few32], a0$lower[!few32])
  options(allanvar.ci_exact = "a")
  expect_error(allan(y, 1), class = "allanvar_error_argument")
})

test_that("exact_sets() rests few-average rows on the reading at many averages", {
  L <- 1025
  m <- c(1, 16, 64, 128, 256)  # N/m 1024, 64, 16, 8, 4
  # an FM reading at N/m >= 64 alone where the own reading is not redder
  expect_identical(exact_sets(m, L, c(0L, 0L, 0L, 0L, NA), -2L)[3:5],
                   list(0L, 0L, 0L))
  expect_identical(exact_sets(m, L, c(-1L, -1L, 0L, 1L, NA), -2L)[3:5],
                   list(-1L, -1L, -1L))
  # ... but for a value bias-corrected by the type read, a whiter own
  # reading joins it (its correction moves the value)
  expect_identical(exact_sets(m, L, c(-1L, -1L, 0L, 1L, NA), -2L,
                              join_own = TRUE)[3:5],
                   list(-1:0, -1:1, -1:1))
  expect_identical(exact_sets(m, L, c(0L, 0L, 0L, 0L, NA), -2L,
                              join_own = TRUE)[3:5], list(0L, 0L, 0L))
  # an own reading redder than it: both, with the own one's neighbour
  expect_identical(exact_sets(m, L, c(0L, 0L, -1L, -1L, NA), -2L)[3:5],
                   list(-2:0, -2:0, -2:0))
  # a PM reading at many averages: the own reading's set where they agree,
  # else both and the types between (flicker PM read as white FM at a few
  # averages)
  expect_identical(exact_sets(m, L, c(2L, 2L, 2L, 0L, NA), -2L)[3:5],
                   list(2L, -1:2, -1:2))
  expect_identical(exact_sets(m, L, c(1L, 1L, 1L, 0L, NA), -2L)[3:5],
                   list(1L, -1:1, -1:1))
  expect_identical(exact_sets(m, L, c(1L, 1L, 2L, 2L, NA), -2L)[3:5],
                   list(1:2, 1:2, 1:2))
  # no reading at many averages: the own reading's set
  expect_identical(exact_sets(m[3:5], L, c(0L, -1L, NA), -2L),
                   list(-1:0, -2:-1, -2:-1))
  expect_identical(exact_sets(m[3:5], L, c(NA, NA, NA), -2L)[[1]], -2:2)
})

test_that("exact 95% intervals cover under random-walk FM (quick Monte Carlo)", {
  skip_on_cran()
  # own generator; truth (2 m^2 + 1) / (6 m) for unit innovations
  set.seed(29)
  m <- c(64, 128, 256)
  # on the rows alone (their own readings) and on the octave curve (the
  # reading at N/m >= 64 behind them)
  hits <- replicate(200, {
    y <- cumsum(rnorm(1024))
    a <- allan(y, 1, taus = I(m), type = "overlapping", conf = 0.95)
    b <- allan(y, 1, type = "overlapping", conf = 0.95)
    b <- b[match(m, b$m), ]
    truth <- sqrt((2 * m^2 + 1) / (6 * m))
    c(a$lower <= truth & truth <= a$upper,
      b$lower <= truth & truth <= b$upper)
  })
  cover <- rowMeans(hits)
  # 200 draws: binomial sd 0.015 at 0.95
  expect_true(all(cover >= 0.90 & cover <= 0.995))
})

test_that("a dense grid's exact factors come from knots, interpolated", {
  # taus = "all": each row its own problem; computed at knots spaced by
  # 5% in m and in the number of terms, interpolated in log m between
  L <- 301
  m <- 10:148
  n <- L - 2 * m
  code <- allan_type_code("overlapping")
  one <- function(i, a) exact_factors_one(code, m[i], n[i], a, 0.683)
  rows <- seq_along(m)
  sets <- rep(list(c(0L, 2L)), length(m))
  a <- exact_factor_table(rows, sets, m, n, one, smooth = TRUE)
  b <- exact_factor_table(rows, sets, m, n, one, smooth = FALSE)
  k <- exact_knots(m, n)
  expect_lt(length(k), 0.8 * length(m))
  expect_true(all(c(1L, length(m)) %in% k))
  for (al in c("0", "2")) {
    expect_identical(a[[al]][, k], b[[al]][, k])
    expect_lt(max(abs(a[[al]] / b[[al]] - 1)), 1e-2)
  }
  # with few terms every row is a knot (the law moves with each one)
  expect_true(all(which(n <= 20) %in% k))
})

test_that("the total type reads the overlapping variance only where exact_sets() looks", {
  set.seed(31)
  recs <- list(rnorm(4000), cumsum(rnorm(4000)), diff(rnorm(4001)),
               rnorm(20000))
  for (x in recs) {
    L <- length(x) + 1
    m <- allan(x, 1, type = "total", ci = FALSE)$m
    full <- extra_alpha(x, 1, m, "overlapping", "rate", L)
    part <- exact_id_alpha(x, 1, m, "overlapping", "rate", L)
    rows <- exact_rows(m, L)
    expect_identical(exact_sets(m, L, part, -2L)[rows],
                     exact_sets(m, L, full, -2L)[rows])
    expect_lt(sum(!is.na(part)), length(m))
  }
})

test_that("exact_minimax() is the shortest interval holding every law", {
  minimax <- allanvar:::exact_minimax
  # two chi-square laws of the variance ratio, the second shifted by its
  # correction s (sigma_hat^2 s / sigma^2 ~ chi2_nu / nu)
  nu <- c(12, 15)
  s <- c(1, 1.35)
  conf <- 0.68
  cdfs <- lapply(nu, function(v) function(q) stats::pchisq(q * v, v))
  eq <- vapply(1:2, function(k) {
    q <- stats::qchisq(c(1 + conf, 1 - conf) / 2, nu[k]) / nu[k]
    sqrt(s[k] / q)
  }, numeric(2))
  f <- minimax(cdfs, s, eq, conf)
  # coverage of [sigma_hat f1, sigma_hat f2] under law k
  cover <- function(f, k) {
    stats::pchisq(s[k] / f[1]^2 * nu[k], nu[k]) -
      stats::pchisq(s[k] / f[2]^2 * nu[k], nu[k])
  }
  cov <- c(cover(f, 1), cover(f, 2))
  expect_true(all(cov > conf - 1e-3))
  expect_lt(min(cov), conf + 1e-3)  # tight under one law at least
  union <- c(min(eq[1, ]), max(eq[2, ]))
  expect_gt(min(cover(union, 1), cover(union, 2)), conf + 0.03)
  expect_lt(f[2] / f[1], 0.97 * union[2] / union[1])
  # the brute-force optimum over lower ends on a fine grid
  t <- exp(seq(log(1 / union[2]^2), log(1 / union[1]^2), length.out = 4000))
  upper_end <- function(k) {
    p <- stats::pchisq(t * s[k] * nu[k], nu[k]) + conf
    ifelse(p < 1, stats::qchisq(pmin(p, 1 - 1e-12), nu[k]) / nu[k] / s[k],
           NA)
  }
  w <- pmax(upper_end(1), upper_end(2))
  best <- min(log(w / t), na.rm = TRUE)
  expect_equal(2 * log(f[2] / f[1]), best, tolerance = 2e-3)
  # one law, or laws that coincide: no wider than its equal-tailed interval
  g <- minimax(cdfs[c(1, 1)], c(1, 1), eq[, c(1, 1)], conf)
  expect_lte(g[2] / g[1], eq[2, 1] / eq[1, 1] + 1e-9)
})
