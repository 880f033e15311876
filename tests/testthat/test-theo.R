# The Theo1 kernels of src/theo.cpp against the direct evaluation of
# NIST SP 1065 eq. (30) in R (ref_theo1, helper-types-ref.R). The noise is
# made here from rnorm(): white PM, white FM (its sum), random-walk FM (the
# double sum), and white FM on a large offset and quadratic drift.

theo_T_ref <- function(x, m) ref_theo1(x, m) * 0.75 * (length(x) - m) * m^2

theo_sets <- function(N, seed) {
  set.seed(seed)
  w <- rnorm(N)
  list(wpm = w, wfm = cumsum(w), rwfm = cumsum(cumsum(w)),
       drift = cumsum(w) + 1e6 + 0.01 * seq_len(N)^2)
}

test_that("fast blocked Theo1 sums agree with the direct evaluation to 1e-10", {
  for (N in c(257L, 1000L, 2001L)) {
    top <- 2 * ((N - 1) %/% 2)
    m <- unique(c(2, 4, 6, 2 * (N %/% 8), 2 * (N %/% 6), 2 * (N %/% 4),
                  2 * (N %/% 3), top - 2, top))
    for (nm in names(theo_sets(N, N))) {
      x <- theo_sets(N, N)[[nm]]
      ref <- vapply(m, function(mm) theo_T_ref(x, mm), 0)
      fast <- theo1_sums_cpp(x, FALSE, m, 1L, 2L)
      direct <- theo1_sums_cpp(x, FALSE, m, 1L, 1L)
      lab <- paste(nm, N)
      expect_lt(max(abs(fast / ref - 1)), 1e-10, label = lab)
      expect_lt(max(abs(direct / ref - 1)), 1e-10, label = lab)
    }
  }
})

test_that("fast Theo1 sums from rate input match those from its phase", {
  set.seed(5)
  y <- cumsum(rnorm(999))  # random-walk FM as frequency
  x <- c(0, cumsum(y))
  m <- c(2, 100, 332, 600, 998)
  expect_equal(theo1_sums_cpp(y, TRUE, m, 1L, 2L),
               vapply(m, function(mm) theo_T_ref(x, mm), 0), tolerance = 1e-10)
})

test_that("allan() picks the fast path at long records and stays exact", {
  N <- 20000L
  for (nm in c("wpm", "rwfm")) {
    x <- theo_sets(N, 9)[[nm]]
    a <- allan(x, 1, type = "theo1", input = "integrated", debias = FALSE)
    expect_equal(a$m, 2^(1:14))
    # the largest m take the fast path (cost model); the direct C++ stencil
    # (itself checked against ref_theo1 above) is the reference here
    m <- a$m[a$m >= 512]
    T <- theo1_sums_cpp(x, FALSE, m, 2L, 1L)
    ref <- T / (0.75 * (N - m) * m^2)
    expect_lt(max(abs(a$avar[a$m >= 512] / ref - 1)), 1e-10, label = nm)
  }
})

# TheoBR's Theo1 values come from the squared-increment recurrence
# (theo1_incr_cpp); the noise is made here: white PM, white FM, random-walk
# FM and white FM on a linear frequency drift (quadratic phase).
theobr_sets <- function(N, seed) {
  set.seed(seed)
  w <- rnorm(N)
  list(wpm = w, wfm = cumsum(w), rwfm = cumsum(cumsum(w)),
       drift = cumsum(w) + 3e4 + 0.02 * seq_len(N) + 5e-3 * seq_len(N)^2)
}

test_that("the squared-increment recurrence agrees with the definition", {
  for (N in c(401L, 1000L, 1501L)) {
    kmax <- (N - 1) %/% 2
    k <- sort(unique(c(1:4, 7, 32, 33, kmax %/% 3, kmax %/% 2, kmax - 1, kmax)))
    for (nm in names(theobr_sets(N, 1))) {
      x <- theobr_sets(N, N + 7)[[nm]]
      ref <- vapply(2 * k, function(mm) theo_T_ref(x, mm), 0)
      got <- theo1_incr_cpp(x, FALSE, k, 1L)
      expect_lt(max(abs(got / ref - 1)), 1e-10, label = paste(nm, N))
      # the order of `need` does not matter; k outside the range give NA
      expect_equal(theo1_incr_cpp(x, FALSE, c(rev(k), 0, kmax + 1), 2L),
                   c(rev(got), NA, NA))
    }
  }
})

test_that("rate input gives the Theo1 sums of its phase", {
  set.seed(3)
  y <- cumsum(rnorm(1200))  # random-walk FM as frequency
  x <- c(0, cumsum(y))
  k <- c(1, 40, 300, 600)
  expect_equal(theo1_incr_cpp(y, TRUE, k, 1L),
               vapply(2 * k, function(mm) theo_T_ref(x, mm), 0),
               tolerance = 1e-10)
})

test_that("TheoBR's factor agrees with its direct evaluation", {
  for (N in c(301L, 513L, 800L)) {  # the helper keeps every i (N %% 6 != 0)
    for (nm in names(theobr_sets(N, 1))) {
      x <- theobr_sets(N, 2 * N)[[nm]]
      kf <- theobr_factor(x, 1, FALSE, N, 2L)
      expect_lt(abs(kf / ref_theobr_factor(x) - 1), 1e-10,
                label = paste(nm, N))
    }
  }
})

test_that("the recurrence keeps its digits on long random-walk FM records", {
  # against the double-double recurrence (theo1_all_cpp, itself checked
  # against the definition in test-types.R) over the whole k range
  N <- 12001L
  set.seed(11)
  x <- cumsum(cumsum(rnorm(N)))
  k <- c(32, 100, 1000, 3000, 5999, 6000)
  ref <- theo1_all_cpp(x, FALSE, max(k), k)[k]
  expect_lt(max(abs(theo1_incr_cpp(x, FALSE, k, 2L) / ref - 1)), 1e-10)
})

test_that("Theo1 sums are the same bit for bit between calls and threads", {
  # the edge sums of the recurrence were gathered per worker, in an order
  # set by the threads' timing: two calls on 2 threads differed in the
  # last bits (one run in five at N = 4000)
  x <- theobr_sets(6001L, 29)$rwfm
  k <- seq(32, 2000, by = 3)
  a <- theo1_incr_cpp(x, FALSE, k, 2L)
  for (i in 1:4) expect_identical(theo1_incr_cpp(x, FALSE, k, 2L), a)
  expect_identical(theo1_incr_cpp(x, FALSE, k, 1L), a)
  m <- c(2, 64, 1000, 4096)
  s <- theo1_sums_cpp(x, FALSE, m, 2L)
  expect_identical(theo1_sums_cpp(x, FALSE, m, 2L), s)
  expect_identical(theo1_sums_cpp(x, FALSE, m, 1L), s)
  on_threads <- function(nt, type) {
    op <- options(allanvar.threads = nt)
    on.exit(options(op))
    allan(x, 1, type = type, input = "integrated")
  }
  for (type in c("theo1", "theobr", "theoh")) {
    b <- on_threads(2L, type)
    for (i in 1:2) expect_identical(on_threads(2L, type), b, label = type)
    expect_identical(on_threads(1L, type), b, label = type)
  }
})

test_that("the ladder N/30 is floor(0.1 N / 3 - 3) rungs", {
  for (N in c(301L, 800L)) {
    x <- theobr_sets(N, N)$rwfm
    kf <- theobr_factor(x, 1, FALSE, N, 2L, ladder = "N/30")
    expect_lt(abs(kf / ref_theobr_factor(x, floor(0.1 * N / 3 - 3)) - 1),
              1e-10, label = N)
  }
})

test_that("the fast path's expectations hold against dense covariances", {
  # white FM: Theo1 is unbiased for AVAR, the ladder's ratio is 1 exactly
  expect_equal(theo_ladder_ratio(function(s) abs(s), 40), 1, tolerance = 1e-13)
  # AVAR of the phase averaged by r, from the box-filtered generalized
  # covariance, against the quadratic form on the covariance matrix of the
  # discrete noise: white PM, Kasdin's flicker PM, white FM (cumsum)
  r <- 3L
  nb <- 14L
  n <- nb * r
  # flicker PM: Kasdin's filter started P = 2e6 samples before the record
  # (its increments become stationary as P grows; the rest is ~1e-6)
  P <- 2e6
  h <- cumprod(c(1, (seq_len(P + n) - 0.5) / seq_len(P + n)))
  fl <- matrix(0, n, n)
  for (d in 0:(n - 1)) {
    cs <- cumsum(h[1:(P + n - d)] * h[(1 + d):(P + n)])
    for (i in 1:(n - d)) fl[i, i + d] <- fl[i + d, i] <- cs[P + i]
  }
  covs <- list("2" = diag(n), "1" = fl,
               "0" = outer(seq_len(n), seq_len(n), pmin))
  B <- kronecker(diag(nb), matrix(1 / r, 1, r))  # the block means
  for (a in names(covs)) {
    K <- theo_gcov(as.integer(a))
    u <- seq(-(r - 1), r - 1)
    w <- (r - abs(u)) / r^2
    Kr <- function(t) vapply(t, function(tt) sum(w * K(tt + u)), 0)
    Dr <- function(s) 2 * (Kr(0) - Kr(r * s))
    for (M in c(1L, 3L, 6L)) {
      st <- numeric(nb)
      st[c(1, 1 + M, 1 + 2 * M)] <- c(1, -2, 1)
      dense <- drop(t(st) %*% B %*% covs[[a]] %*% t(B) %*% st)
      expect_equal(4 * Dr(M) - Dr(2 * M), dense, tolerance = 1e-5,
                   label = paste(a, M))
    }
  }
})

test_that("the fast factor is within 1% of the exact one for each noise type", {
  skip_on_cran()
  N <- 20000L
  set.seed(29)
  flick <- function(N) {
    h <- cumprod(c(1, (seq_len(N - 1) - 0.5) / seq_len(N - 1)))
    Re(stats::fft(stats::fft(c(h, numeric(N))) *
                    stats::fft(c(rnorm(N), numeric(N))), inverse = TRUE))[
      seq_len(N)] / (2 * N)
  }
  sets <- list("2" = rnorm(N), "1" = flick(N), "0" = cumsum(rnorm(N)),
               "-1" = cumsum(flick(N)), "-2" = cumsum(cumsum(rnorm(N))))
  for (a in names(sets)) {
    x <- sets[[a]]
    ex <- theobr_factor(x, 1, FALSE, N, 2L)
    fast <- theobr_factor_fast(x, FALSE, N, 4L, as.integer(a), 2L)
    expect_lt(abs(sqrt(fast / ex) - 1), 0.01, label = a)
    if (a == "2") {
      # without the correction, averaging white PM lowers it by 10%
      raw <- theobr_factor_fast(x, FALSE, N, 4L, NA, 2L)
      expect_gt(abs(sqrt(raw / ex) - 1), 0.05)
    }
  }
  # allan() takes it when asked, the Theo1 values unchanged
  a <- allan(sets[["0"]], 1, type = "theobr", input = "integrated",
             taus = "decade")
  b <- allan(sets[["0"]], 1, type = "theobr", input = "integrated",
             taus = "decade", theo = list(method = "fast", fast_points = 5000))
  k <- b$avar / a$avar
  expect_equal(k, rep(k[1], length(k)), tolerance = 1e-12)
  expect_lt(abs(sqrt(k[1]) - 1), 0.01)
})

test_that("above 1e5 phase points the fast factor is chosen, with a message", {
  skip_on_cran()
  set.seed(5)
  y <- rnorm(1e5 + 10)
  expect_snapshot(a <- allan(y, 1, type = "theoh", taus = "decade"))
  expect_message(allan(y, 1, type = "theobr", taus = "decade"),
                 class = "allanvar_message_theo_fast")
  expect_no_message(allan(y[1:5000], 1, type = "theobr", taus = "decade"))
})

test_that("bad `theo` gives classed errors", {
  y <- rnorm(200)
  expect_error(allan(y, 1, type = "theobr", theo = list(ladder = "N/7")),
               class = "allanvar_error_argument")
  expect_error(allan(y, 1, type = "theobr", theo = list(method = "quick")),
               class = "allanvar_error_argument")
  expect_error(allan(y, 1, type = "theobr", theo = list(fast_points = 10)),
               class = "allanvar_error_argument")
  expect_error(allan(y, 1, type = "theobr", theo = list(speed = 1)),
               class = "allanvar_error_argument")
  expect_error(allan(y, 1, type = "theobr", theo = "fast"),
               class = "allanvar_error_argument")
  expect_error(allan(y, 1, type = "theo1", theo = list(method = "fast")),
               class = "allanvar_error_argument")
})

test_that("TheoBR's intervals carry its bias factor's uncertainty", {
  # TheoBR = kappa * Theo1, kappa estimated from the same record: one random
  # factor on every row (its EDF ~20-30 under FM noise, N/6 ladder), where
  # Theo1's EDF alone claims hundreds at small m (68% coverage 0.1-0.35).
  # Own generators (white FM: rnorm; random-walk FM: cumsum), the truth the
  # ensemble mean; both ladders.
  skip_on_cran()
  N <- 256L
  reps <- 200L
  gens <- list(wfm = function() rnorm(N), rwfm = function() cumsum(rnorm(N)))
  set.seed(2929)
  for (g in names(gens)) {
    runs <- lapply(seq_len(reps), function(i) {
      y <- gens[[g]]()
      list(allan(y, 1, type = "theobr", taus = I(c(3, 6, 12))),
           allan(y, 1, type = "theobr", taus = I(c(3, 6, 12)),
                 theo = list(ladder = "N/30")))
    })
    for (j in 1:2) {
      get <- function(col) sapply(runs, function(r) r[[j]][[col]])
      truth <- sqrt(rowMeans(get("avar")))
      cover <- rowMeans(get("lower") <= truth & truth <= get("upper"))
      lab <- paste(g, c("N/6", "N/30")[j])
      expect_true(all(cover > 0.57 & cover < 0.79),
                  label = paste(lab, paste(cover, collapse = " ")))
      # the EDF against the Monte Carlo one of log TheoBR
      edf_mc <- 2 / apply(log(get("avar")), 1, stats::var)
      ratio <- apply(get("edf"), 1, stats::median) / edf_mc
      expect_true(all(ratio > 0.7 & ratio < 1.45),
                  label = paste(lab, paste(signif(ratio, 3), collapse = " ")))
    }
  }
})

test_that("TheoBR's law at few averages matches a simulation of its parts", {
  # Theo1's exact weights, the factor's EDF and correlation as the package
  # takes them; the law of kappa * Theo1 over its mean by simulation
  # (rchisq, rnorm), against the grid-and-quadrature of theobr_exact_factors()
  skip_on_cran()
  set.seed(77)
  for (a in c(0L, -2L)) {
    m <- 128
    L <- 257
    lam <- exact_dense_weights("exact_form_theo1", m, L, a)
    sk <- sqrt(2 / theobr_nu_kappa(a, L, "N/6"))
    rho <- theobr_rho(a, m, L, "N/6")
    n <- 2e5
    t <- colSums(lam * matrix(stats::rchisq(length(lam) * n, 1), length(lam)))
    x <- log(t)
    z <- (x - mean(x)) / stats::sd(x)
    b <- t * exp(sk * (rho * z + sqrt(1 - rho^2) * stats::rnorm(n)))
    b <- b / mean(b)
    for (conf in c(0.683, 0.95)) {
      p <- (1 - conf) / 2
      sim <- sqrt(1 / stats::quantile(b, c(1 - p, p), names = FALSE))
      f <- theobr_exact_factors(m, L, a, a, "N/6", L, conf)
      expect_equal(f, sim, tolerance = 0.02,
                   label = paste("alpha", a, "conf", conf))
    }
  }
})

test_that("TheoBR's intervals cover at two and four averages", {
  # own generators, the truth the ensemble mean; the chi-square with the
  # two-moment EDF it replaced covered 0.79-0.93 (68%) at N/m <= 4
  skip_on_cran()
  N <- 256L
  reps <- 300L
  gens <- list(wfm = function() rnorm(N), rwfm = function() cumsum(rnorm(N)))
  set.seed(4141)
  for (g in names(gens)) {
    runs <- lapply(seq_len(reps), function(i) {
      y <- gens[[g]]()
      # the default grid: a row at few averages leans on the type read at
      # shorter taus (exact_sets())
      list(allan(y, 1, type = "theobr"),
           allan(y, 1, type = "theobr", conf = 0.95))
    })
    for (j in 1:2) {
      get <- function(col) {
        sapply(runs, function(r) r[[j]][[col]][r[[j]]$m %in% c(64, 128)])
      }
      truth <- sqrt(rowMeans(get("avar")))
      cover <- rowMeans(get("lower") <= truth & truth <= get("upper"))
      band <- if (j == 1L) c(0.6, 0.77) else c(0.915, 0.985)
      expect_true(all(cover > band[1L] & cover < band[2L]),
                  label = paste(g, c("68%", "95%")[j],
                                paste(cover, collapse = " ")))
    }
  }
})
