# three_cornered_hat() and groslambert(): SigmaTheta's GCoDev reference run,
# exact identities on hand-made input, recovery of known individual Allan
# variances of simulated clocks (our own generators), interval coverage,
# and the argument checks.

# --- numpy's legacy generator, to rebuild the data of SigmaTheta's run -------
# numpy.random.seed(s) is MT19937's init_genrand(s); randn() is the polar
# method on 53-bit doubles made of two 32-bit words, returning f * x2 first,
# then the cached f * x1. R's Mersenne-Twister, given the same state, yields
# the same words (runif() * 2^32).
np_words <- function(seed, n) {
  u32_mul <- function(a, x) {
    ah <- a %/% 65536
    al <- a %% 65536
    xh <- x %/% 65536
    xl <- x %% 65536
    (al * xl + 65536 * ((ah * xl + al * xh) %% 65536)) %% 4294967296
  }
  u32_xor <- function(a, b) {
    bitwXor(a %/% 65536, b %/% 65536) * 65536 + bitwXor(a %% 65536, b %% 65536)
  }
  mt <- numeric(624)
  mt[1] <- seed
  for (i in 2:624) {
    p <- mt[i - 1]
    mt[i] <- (u32_mul(1812433253, u32_xor(p, p %/% 2^30)) + (i - 1)) %%
      4294967296
  }
  as_int <- function(v) as.integer(ifelse(v >= 2^31, v - 2^32, v))
  had <- exists(".Random.seed", envir = globalenv())
  if (had) saved <- get(".Random.seed", envir = globalenv())
  kind <- RNGkind()
  on.exit({
    do.call(RNGkind, as.list(kind))
    if (had) assign(".Random.seed", saved, envir = globalenv())
  })
  RNGkind("Mersenne-Twister", "Inversion", "Rejection")
  assign(".Random.seed", c(10403L, 624L, as_int(mt)), envir = globalenv())
  floor(stats::runif(n) * 2^32)
}

np_randn <- function(seed, n) {
  w <- np_words(seed, ceiling(n / 2 / 0.78) * 4 + 4000)
  d <- (floor(w[c(TRUE, FALSE)] / 32) * 67108864 +
          floor(w[c(FALSE, TRUE)] / 64)) / 9007199254740992
  x1 <- 2 * d[c(TRUE, FALSE)] - 1
  x2 <- 2 * d[c(FALSE, TRUE)] - 1
  r2 <- x1 * x1 + x2 * x2
  ok <- r2 < 1 & r2 != 0
  f <- sqrt(-2 * log(r2[ok]) / r2[ok])
  out <- as.vector(rbind(f * x2[ok], f * x1[ok]))
  out[seq_len(n)]
}

test_that("groslambert() reproduces SigmaTheta's GCoDev run", {
  # allantools tests/test_gcodev.py: three white-PM clocks (numpy seed 42,
  # N = 1e5, amplitudes 1, 5, 10), phase comparisons AB, BC, CA, written as
  # frequency with "%.12f" and run through SigmaTheta v3.0 GCoDev, which
  # prints sign(c) sqrt(|c|) of the raw (unoriented) covariance.
  N <- 1e5
  z <- np_randn(42, 3 * N)
  A <- z[1:N]
  B <- 5 * z[N + 1:N]
  C <- 10 * z[2 * N + 1:N]
  # the generator check printed in allantools' test
  expect_equal(c(A[N], B[N], C[N]),
               c(0.12006294082414522, -5.324739839420351, -3.578461741191343),
               tolerance = 1e-15)
  freq12 <- function(p) as.numeric(sprintf("%.12f", diff(p)))
  y <- cbind("A-B" = freq12(A - B), "B-C" = freq12(B - C),
             "C-A" = freq12(C - A))
  g <- groslambert(y, freq = 1)
  st <- list(
    A = c(-1.5822698768801253e+00, -7.1516620564809252e-01,
          -3.6211155665136197e-01, -1.7060913297684019e-01,
          -1.0714277882857023e-01, -5.0828253381873023e-02,
          -2.3379022940577421e-02, -1.3214052398385969e-02,
          -5.9325361833646468e-03, -3.1859793758841873e-03,
          -1.1872594305012082e-03, -7.9181618114116986e-04,
          -3.1864022889666255e-04, -1.8946156459394094e-04,
          -9.2401802887092055e-05, -4.7453355340743471e-05),
    B = c(-8.6572265057967588e+00, -4.3432005973471712e+00,
          -2.1721589652062332e+00, -1.0880738273515811e+00,
          -5.4146914222235154e-01, -2.7216329996649430e-01,
          -1.3536179632154205e-01, -6.7521150727460719e-02,
          -3.3923783921641061e-02, -1.6903085282002191e-02,
          -8.5454849855555823e-03, -4.2376272243631599e-03,
          -2.1168485094171896e-03, -1.0600373993369303e-03,
          -5.2776620159470755e-04, -2.6352955508714208e-04),
    C = c(-1.7326873626967341e+01, -8.6728637511045310e+00,
          -4.3259160453426837e+00, -2.1672253715364658e+00,
          -1.0832324591986147e+00, -5.4196999788713551e-01,
          -2.7112486792251950e-01, -1.3560263809161266e-01,
          -6.7501039944739105e-02, -3.3778774118065999e-02,
          -1.6967984008809077e-02, -8.4465947630849424e-03,
          -4.2428213734232445e-03, -2.1174831713595926e-03,
          -1.0558534636972263e-03, -5.2745664531139290e-04))
  for (src in names(st)) {
    s <- g[g$source == src, ]
    expect_equal(s$m, 2^(0:15))
    # each source sits first in one comparison and second in the other, so
    # the raw covariance is minus our oriented one
    expect_true(all(s$status == "ok"))
    expect_equal(-s$adev, st[[src]], tolerance = 1e-10)
  }
  # the loop closes (to the 12 printed decimals): the hat agrees
  h <- three_cornered_hat(y, freq = 1)
  expect_equal(h$avar, g$gcov, tolerance = 1e-6)
})

# Direct sums over hand-made data, for each type and input.
direct_cross <- function(p, q, m, type, rate, freq) {
  ph <- function(v) if (rate) c(0, cumsum(v)) else v
  x1 <- ph(p)
  x2 <- ph(q)
  L <- length(x1)
  d2 <- function(x, k, m) x[k + 2 * m] - 2 * x[k + m] + x[k]
  d3 <- function(x, k, m) x[k + 3 * m] - 3 * x[k + 2 * m] + 3 * x[k + m] - x[k]
  sm <- function(x, k, m) sum(vapply(0:(m - 1), function(j) d2(x, k + j, m), 1))
  k <- switch(type,
    overlapping = seq_len(L - 2 * m),
    standard = seq(1, by = m, length.out = floor((L - 1) / m) - 1),
    modified = seq_len(L - 3 * m + 1),
    hadamard = seq(1, by = m, length.out = floor((L - 1) / m) - 2),
    ohadamard = seq_len(L - 3 * m))
  terms <- vapply(k, function(i) switch(type,
    overlapping = , standard = d2(x1, i, m) * d2(x2, i, m),
    modified = sm(x1, i, m) * sm(x2, i, m),
    d3(x1, i, m) * d3(x2, i, m)), 1)
  norm <- switch(type, modified = 2 * m^4, hadamard = , ohadamard = 6 * m^2,
                 2 * m^2)
  sum(terms) / (norm * length(k)) * (if (rate) 1 else freq^2)
}

test_that("groslambert() is the mean product of the differences, every type", {
  p <- c(3, -1, 4, 1, -5, 9, 2, -6, 5, 3, -5, 8, 9, -7, 9, 3, 2, -3, 8, 4)
  q <- c(2, 7, -1, 8, 2, -8, 1, 8, 2, -8, 4, 5, -9, 0, 4, 5, 2, -3, 5, 3)
  for (type in c("overlapping", "standard", "modified", "hadamard",
                 "ohadamard")) {
    for (input in c("rate", "integrated")) {
      g <- groslambert(cbind("A-B" = p, "A-C" = q), freq = 4, type = type,
                       input = input, taus = "all")
      ref <- vapply(g$m, direct_cross, 1, p = p, q = q, type = type,
                    rate = input == "rate", freq = 4)
      expect_equal(g$gcov, ref, tolerance = 1e-13)
      expect_equal(g$avar, ifelse(ref > 0, ref, NA_real_))
      expect_equal(g$status, ifelse(ref > 0, "ok", "negative"))
      # orientation: B-A with A-C estimates minus the same product
      g2 <- groslambert(cbind("B-A" = -p, "A-C" = q), freq = 4, type = type,
                        input = input, taus = "all")
      expect_equal(g2$gcov, ref, tolerance = 1e-13)
      g3 <- groslambert(cbind(p, q), freq = 4, pairs = c("A-B", "C-A"),
                        type = type, input = input, taus = "all")
      expect_equal(g3$gcov, -ref, tolerance = 1e-13)
    }
  }
})

test_that("a closed loop makes the hat and Groslambert covariance equal", {
  # x_AB + x_BC + x_CA = 0 exactly (small integers): sigma^2_BC expands to
  # sigma^2_AB + sigma^2_CA + 2 cov(AB, CA), so the two estimators coincide
  p <- c(3, -1, 4, 1, -5, 9, 2, -6, 5, 3, -5, 8, 9, -7, 9, 3, 2, -3, 8, 4)
  q <- c(2, 7, -1, 8, 2, -8, 1, 8, 2, -8, 4, 5, -9, 0, 4, 5, 2, -3, 5, 3)
  y <- cbind("A-B" = p, "B-C" = q, "C-A" = -(p + q))
  for (type in c("overlapping", "standard", "modified", "hadamard",
                 "ohadamard")) {
    for (input in c("rate", "integrated")) {
      h <- three_cornered_hat(y, freq = 1, type = type, input = input,
                              taus = "all")
      g <- groslambert(y, freq = 1, type = type, input = input, taus = "all")
      expect_equal(h$avar, g$avar, tolerance = 1e-12)
      expect_equal(h$status, g$status)
    }
  }
})

test_that("the hat is the combination of the pairwise variances, any order", {
  set.seed(21)
  ab <- rnorm(64)
  bc <- rnorm(64)
  ca <- rnorm(64)
  for (type in c("overlapping", "standard", "modified", "hadamard",
                 "total")) {
    h <- three_cornered_hat(cbind(ab, bc, ca), freq = 1, type = type)
    S <- sapply(list(ab, bc, ca), function(v) allan(v, 1, type = type)$avar)
    est <- list(A = (S[, 1] + S[, 3] - S[, 2]) / 2,
                B = (S[, 1] + S[, 2] - S[, 3]) / 2,
                C = (S[, 2] + S[, 3] - S[, 1]) / 2)
    for (src in c("A", "B", "C")) {
      s <- h[h$source == src, ]
      e <- est[[src]]
      expect_equal(s$avar, ifelse(e > 0, e, NA))
      expect_true(all(is.na(s$adev[e <= 0]) & is.na(s$lower[e <= 0])))
      expect_true(all(s$status[e <= 0] == "negative"))
      expect_true(all(grepl("exceeds", s$reason[e <= 0])))
      expect_true(all(is.na(s$reason[e > 0])))
    }
    # the same comparisons listed as A-B, A-C, B-C (signs flipped)
    h2 <- three_cornered_hat(cbind("A-B" = ab, "A-C" = -ca, "B-C" = bc),
                             freq = 1, type = type)
    h2 <- h2[order(h2$source, h2$tau), ]
    expect_equal(h2$avar, h[order(h$source, h$tau), ]$avar)
  }
})

# Exact Allan variance (overlapping = standard in expectation) of white
# rate noise of sd s and of a random walk of the rate with steps of sd s:
# half the variance of a difference of cluster means, from its weights on
# the innovations.
av_exact <- function(m, kind, s) {
  if (kind == "white") return(s^2 / m)
  j <- seq_len(2 * m - 1)
  w <- ifelse(j < m, j, 2 * m - j) / m
  s^2 * sum(w^2) / 2
}

test_that("individual variances of three simulated clocks are recovered", {
  # A: white FM, B: white FM four times weaker in variance, C: random-walk
  # FM; long record, estimates within 4 sigma of the exact values (sigma
  # from the reported EDF, which is what the intervals use)
  set.seed(22)
  n <- 2e5
  a <- rnorm(n, sd = 1)
  b <- rnorm(n, sd = 0.5)
  c <- cumsum(rnorm(n, sd = 0.003))
  y <- cbind("A-B" = a - b, "B-C" = b - c, "C-A" = c - a)
  truth <- function(src, m) {
    switch(src, A = av_exact(m, "white", 1), B = av_exact(m, "white", 0.5),
           C = av_exact(m, "rw", 0.003))
  }
  for (fun in c("three_cornered_hat", "groslambert")) {
    r <- do.call(fun, list(y, freq = 1, taus = I(c(1, 4, 16, 64, 256, 1024))))
    for (src in c("A", "B", "C")) {
      s <- r[r$source == src, ]
      tv <- vapply(s$m, function(m) truth(src, m), 1)
      big <- tv > 0.05 * vapply(s$m, function(m) {
        truth("A", m) + truth("B", m) + truth("C", m)
      }, 1)
      ok <- s$status == "ok"
      expect_true(all(ok[big]))
      z <- (s$avar - tv) / (tv * sqrt(2 / s$edf))
      expect_true(all(abs(z[big & ok]) < 4), label = paste(fun, src))
    }
  }
})

test_that("hat and Groslambert intervals cover about 68% of the time", {
  skip_on_cran()
  # white-FM clocks of levels 1, 3 and 0.1: the quiet one's estimate is a
  # small difference of large ones (EDF about 2), where a chi-square
  # interval would never cover it; the comparisons for groslambert() carry
  # their own counter noise
  set.seed(23)
  reps <- 250
  n <- 3000
  lv <- c(A = 1, B = 3, C = 0.1)
  taus <- I(c(1, 4, 16))
  hits <- list(hat = NULL, gcov = NULL)
  for (i in seq_len(reps)) {
    a <- rnorm(n, sd = lv[["A"]])
    b <- rnorm(n, sd = lv[["B"]])
    c <- rnorm(n, sd = lv[["C"]])
    y <- cbind("A-B" = a - b, "B-C" = b - c, "C-A" = c - a)
    for (k in c("hat", "gcov")) {
      r <- if (k == "hat") three_cornered_hat(y, 1, taus = taus) else
        groslambert(y + matrix(rnorm(3 * n, sd = 0.5), n), 1, taus = taus)
      t <- lv[r$source] / sqrt(r$m)
      hits[[k]] <- rbind(hits[[k]], r$lower <= t & t <= r$upper)
    }
  }
  for (k in names(hits)) {
    cover <- colMeans(hits[[k]], na.rm = TRUE)
    expect_true(all(cover > 0.6 & cover < 0.8),
                label = paste(k, paste(round(cover, 3), collapse = " ")))
    # the quiet clock is often negative (no interval), the others never
    expect_true(all(colSums(!is.na(hits[[k]])) > 0.4 * reps))
  }
})

test_that("Groslambert removes uncorrelated measurement noise; the hat does not", {
  set.seed(24)
  n <- 1e5
  a <- rnorm(n, sd = 1)
  b <- rnorm(n, sd = 1)
  c <- rnorm(n, sd = 1)
  # each comparison has its own counter, adding white noise of sd 2
  e <- matrix(rnorm(3 * n, sd = 2), n)
  y <- cbind("A-B" = a - b, "B-C" = b - c, "C-A" = c - a) + e
  g <- groslambert(y, freq = 1, taus = I(c(1, 4, 16)))
  h <- three_cornered_hat(y, freq = 1, taus = I(c(1, 4, 16)))
  for (src in c("A", "B", "C")) {
    gs <- g[g$source == src, ]
    hs <- h[h$source == src, ]
    # truth 1/m; the hat adds (4 + 4 - 4) / 2 / m of counter noise. Within
    # 4 sigma of the reported EDF, and the hat's bias is 10 of them.
    zg <- (gs$avar * gs$m - 1) / sqrt(2 / gs$edf)
    zh <- (hs$avar * hs$m - 3) / (3 * sqrt(2 / hs$edf))
    expect_true(all(abs(zg) < 4), label = paste(src, zg))
    expect_true(all(abs(zh) < 4), label = paste(src, zh))
    expect_true(all(abs(hs$avar * hs$m - 1) / sqrt(2 / gs$edf) > 10))
  }
})

test_that("print, summary and plot", {
  set.seed(25)
  n <- 3000
  a <- rnorm(n, sd = 1)
  b <- rnorm(n, sd = 3)
  c <- rnorm(n, sd = 0.1)
  y <- cbind("A-B" = a - b, "B-C" = b - c, "C-A" = c - a)
  h <- three_cornered_hat(y, freq = 10)
  g <- groslambert(y, freq = 10, taus = "decade")
  expect_snapshot(print(h))
  expect_snapshot(print(summary(g)))
  expect_s3_class(as.data.frame(h), "data.frame")
  expect_null(attr(as.data.frame(h), "comparisons"))
  expect_true(any(h$status == "negative"))
  skip_if_not_installed("vdiffr")
  vdiffr::expect_doppelganger("three-cornered hat", function() plot(h))
  vdiffr::expect_doppelganger("groslambert", function() plot(g))
})

test_that("bad input is refused with classed errors", {
  y <- matrix(rnorm(300), 100)
  expect_snapshot(error = TRUE, {
    three_cornered_hat()
    three_cornered_hat(y)
    three_cornered_hat(y[, 1:2], freq = 1)
    three_cornered_hat(y, freq = 1, pairs = c("A-B", "B-C"))
    three_cornered_hat(y, freq = 1, pairs = c("A-B", "B-C", "CA"))
    three_cornered_hat(y, freq = 1, pairs = c("A-B", "B-C", "A-A"))
    three_cornered_hat(y, freq = 1, pairs = c("A-B", "B-C", "B-A"))
    three_cornered_hat(y, freq = 1, pairs = c("A-B", "B-C", "C-D"))
    three_cornered_hat(list(1:10, 1:10, 1:9), freq = 1)
    three_cornered_hat(y, freq = 1, type = "mtie")
    three_cornered_hat(replace(y, 5, NaN), freq = 1)
    groslambert(y[, 1:2], freq = 1, pairs = c("A-B", "C-D"))
    groslambert(y, freq = 1, type = "total")
    groslambert(y[, 1], freq = 1)
  })
  expect_error(three_cornered_hat(y[, 1:2], freq = 1),
               class = "allanvar_error_argument")
  expect_error(groslambert(y), class = "allanvar_error_missing_argument")
})
