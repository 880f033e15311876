# Raw-data diagnostics and evidence (evidence.R), on series of known
# construction.

test_that("a periodogram line is found at f0 with its amplitude and significance", {
  set.seed(2)
  n <- 2e5
  t <- seq_len(n) / 100
  x <- rnorm(n, sd = 0.1) + 0.02 * sin(2 * pi * 0.5 * t + 1)
  d <- avdiagnose(x, 100)
  expect_s3_class(d, "avdiagnose")
  expect_equal(d$lines$f0[1], 0.5, tolerance = 0.01)
  expect_equal(d$lines$amp[1], 0.02, tolerance = 0.1)
  expect_lt(d$lines$p_value[1], 1e-10)
  # matched within the line's own precision (a fraction of the Welch bin
  # that shrinks as the line stands out: 5 / sqrt(its peak ratio) bins, at
  # most 1.5), not a fixed 25%
  res <- attr(d$lines, "resolution")
  prec <- res * min(1.5, 5 / sqrt(d$lines$ratio[1]))
  ev <- raw_evidence("sinusoid", list(f0 = d$lines$f0[1] + 0.9 * prec), d, x, 100)
  expect_true(ev$support)
  ev <- raw_evidence("sinusoid", list(f0 = d$lines$f0[1] + 1.1 * prec), d, x, 100)
  expect_false(ev$support)
  ev <- raw_evidence("sinusoid", list(f0 = 0.52), d, x, 100)
  expect_false(ev$support)
  ev <- raw_evidence("sinusoid", list(f0 = 2), d, x, 100)
  expect_false(ev$support)
  # White noise: no line in most seeds at the 1e-3 family-wise level.
  fa <- vapply(1:5, function(s) {
    set.seed(s)
    nrow(spectral_lines(rnorm(5e4), 100))
  }, 0)
  expect_lte(sum(fa > 0), 1)
})

test_that("welch_psd()'s C++ sums give the all-R periodogram to rounding", {
  # The reference: the form welch_psd() had in R (each pair of detrended
  # segments demeaned, windowed and transformed as one complex vector).
  ref <- function(x, freq) {
    n <- length(x)
    seg <- min(2^floor(log2(max(n / 8, 64))), 2^floor(log2(n)))
    t <- seq_len(n) - (n + 1) / 2
    x <- x - mean(x) - t * sum(t * x) / sum(t^2)
    w <- 0.5 - 0.5 * cos(2 * pi * (seq_len(seg) - 1) / seg)
    starts <- seq(1, n - seg + 1, by = seg / 2)
    half <- seg / 2 + 1
    acc <- numeric(half)
    for (s in starts) {
      xs <- x[s:(s + seg - 1)]
      acc <- acc + Mod(stats::fft((xs - mean(xs)) * w))[seq_len(half)]^2
    }
    p <- acc / length(starts) / (freq * sum(w^2))
    p[2:(half - 1)] <- 2 * p[2:(half - 1)]
    p
  }
  set.seed(17)
  # 330 samples: 9 segments of 64 (an odd one out); 5000: 18 of 512
  for (n in c(330, 5000, 2e4)) {
    x <- rnorm(n) + sin(seq_len(n)) + cumsum(rnorm(n)) * 0.01
    expect_equal(welch_psd(x, 100)$psd, ref(x, 100), tolerance = 1e-12)
  }
})

test_that("the quantization grid's C++ pass is the R expression to the bit", {
  # The reference: the all-R form quantization_grid() had before its sort,
  # gaps, medians and on-grid count moved to C++.
  ref <- function(x) {
    xs <- sort(x)
    u <- xs[c(TRUE, xs[-1L] != xs[-length(x)])]
    if (length(u) < 2L) return(list(step = NA_real_, levels = length(u), on_grid = 1))
    d <- diff(u)
    step <- stats::median(d[d > 0])
    small <- d[d < 1.5 * step]
    if (length(small)) step <- stats::median(small)
    off <- (x - u[1L]) / step
    list(step = step, levels = length(u), on_grid = mean(abs(off - round(off)) < 1e-3))
  }
  set.seed(31)
  cases <- list(rnorm(2e4), round(rnorm(2e4) / 0.05) * 0.05,
                round(rnorm(10001) / 0.05) * 0.05 + rnorm(10001, sd = 1e-6),
                rep(1, 300), c(rep(0, 100), rep(1, 200)),
                round(rnorm(5e3) * 3) * 0.1 + 0.05,
                sample(c(0, 0.3, 0.7, 1.1), 1000, TRUE),
                c(1, 2, 4, 8, 16, 32)[sample(6, 999, TRUE)],
                # signs, both zeros and the extremes (the radix sort's keys)
                c(-0, 0, -1.5, 2, -0, 1e-300, -1e-300, -.Machine$double.xmax,
                  .Machine$double.xmax, 3),
                -abs(rnorm(500)))
  for (x in cases) {
    g <- quantization_grid(x)
    expect_identical(g[c("step", "levels", "on_grid")], ref(x))
  }
})

test_that("the quantization grid and the -1/2 lag-1 ACF are recognised", {
  set.seed(3)
  xq <- round(rnorm(1e5) / 0.05) * 0.05
  g <- quantization_grid(xq)
  expect_true(g$quantized)
  expect_equal(g$step, 0.05, tolerance = 1e-9)
  expect_equal(g$on_grid, 1)
  expect_false(quantization_grid(rnorm(1e5))$quantized)
  # Differenced uniform noise (quantization Q) has lag-1 ACF -1/2 exactly.
  y <- diff(runif(1e5 + 1)) * 100
  d <- avdiagnose(y, 100)
  expect_equal(d$acf1, -0.5, tolerance = 0.03)
  expect_equal(round(d$noise_id$alpha[1]), 2)
  expect_true(raw_evidence("Q", list(Q = 1), d, y, 100)$support)
})

test_that("exponential ACF gives Tc; trend and lag-1 noise id are right", {
  set.seed(4)
  n <- 1e6
  phi <- exp(-1 / (100 * 10))
  g <- as.numeric(stats::filter(rnorm(n, sd = 0.05 * sqrt(1 - phi^2)), phi, "recursive"))
  y <- rnorm(n, sd = 0.1) + g
  a <- acf_exponential(y, 100, 7)
  expect_equal(a$tc, 10, tolerance = 0.2)
  w <- rnorm(n, sd = 0.1)
  expect_false(isTRUE(raw_evidence("gm", list(tc = 7), avdiagnose(w, 100), w, 100)$support))
  # Ramp of 1e-5 u/s over 10000 s in white noise.
  t <- seq_len(n) / 100
  tr <- linear_trend(w + 1e-5 * t, 100)
  expect_true(tr$significant)
  expect_equal(tr$slope, 1e-5, tolerance = 0.05)
  expect_false(linear_trend(w, 100)$significant)
  expect_equal(lag1_noise_id(w, 10), 0, tolerance = 0.1)
  expect_equal(round(lag1_noise_id(cumsum(rnorm(n)), 10)), -2)
})

test_that("a random walk's own drift is no ramp: the trend's likelihood beside the noise", {
  # own generators: a random walk (with white noise) drifts over a record,
  # and the t of a line through 100 block means reads that drift as
  # significant; the likelihood ratio with each model fitting its own noise
  # (white, random walk, AR(1)s) does not. A ramp on white noise passes both.
  freq <- 100
  n <- 5e5
  t <- seq_len(n) / freq
  zs <- ts <- numeric(0)
  for (seed in 1:4) {
    set.seed(seed)
    x <- rnorm(n, sd = 0.01) + cumsum(rnorm(n, sd = 1e-4 / sqrt(freq)))
    tr <- linear_trend(x, freq)
    ts <- c(ts, abs(tr$t))
    zs <- c(zs, tr$z)
  }
  expect_gt(max(ts), 5)
  expect_length(zs, 4L)
  expect_true(all(zs < 5))
  set.seed(5)
  y <- rnorm(n, sd = 0.01) + 2e-6 * t
  ty <- linear_trend(y, freq)
  expect_gt(ty$z, 5)
  expect_true(ty$significant)
  ev <- allanvar:::evidence_trend(list(R = 2e-6), structure(list(trend = ty), class = "avdiagnose"), y, freq)
  expect_true(ev$support)
  expect_match(ev$text, "likelihood z")
})

test_that("a GM of a few samples must keep its correlation at lag 2, as a filter does not", {
  # own generators: white noise through a two-tap average (0.6, 0.4): lag-1
  # ACF 0.46, none at lag 2; and white noise beside a GM of Tc 3 samples
  set.seed(2718)
  n <- 4e5
  freq <- 100
  e <- rnorm(n)
  ma <- 0.6 * e + 0.4 * c(0, e[-n])
  phi <- exp(-1 / 3)
  gm <- as.numeric(stats::filter(rnorm(n, sd = sqrt(1 - phi^2)), phi, method = "recursive"))
  ar <- rnorm(n) + gm
  ev <- function(x, tc) {
    raw <- allanvar:::refine_diagnostics(x, freq)
    # the GM sized for the raw lag-1 ACF: sigma^2 phi / var = r1
    ph <- exp(-1 / (tc * freq))
    sigma <- sqrt(allanvar:::diag_value(raw, "acf1") * stats::var(x) / ph)
    raw_evidence("gm", list(sigma = sigma, tc = tc), raw, x, freq)
  }
  two <- ev(ma, 2.05 / freq)
  expect_false(two$support)
  expect_match(two$text, "at lag 2 -?0[.]0[0-9]* against its 0[.]2[0-9]*: a filter's short correlation")
  expect_true(ev(ar, 3 / freq)$support)
  # without the filter's diagnostics (a bare avdiagnose()) the lag-1 check alone
  expect_true(raw_evidence("gm", list(sigma = 0.8, tc = 2.05 / freq), avdiagnose(ma, freq), ma, freq)$support)
})

test_that("avdiagnose validates its arguments and prints", {
  expect_error(avdiagnose(), "`x` is missing",
    class = "allanvar_error_missing_argument")
  expect_error(avdiagnose(rnorm(1000), -1), "`freq` must be a single positive",
    class = "allanvar_error_argument")
  expect_error(avdiagnose(letters, 1), "`x` must be a numeric vector",
    class = "allanvar_error_argument")
  expect_error(avdiagnose(rnorm(10), 1), "at least 256",
    class = "allanvar_error_argument")
  x <- stats::ts(round(rnorm(5000) / 0.1) * 0.1, frequency = 50)
  d <- avdiagnose(x)
  expect_equal(d$freq, 50)
  expect_output(print(d), "Quantized: step 0.1")
})

test_that("avdiagnose() errors are classed and worded", {
  expect_snapshot(error = TRUE, {
    avdiagnose()
    avdiagnose(rnorm(1000), -1)
    avdiagnose(letters, 1)
    avdiagnose(rep(1, 10), 1)
    avdiagnose(rnorm(1000), 1, alpha = 2)
  })
})

# The linear-time kernels against their definitions (base R on the same
# data): the running-median end rule against stats::smoothEnds(), the lag
# sums against shifted products, the detrend against lm.fit() residuals,
# the paired-segment Welch PSD against one FFT per segment.
test_that("smooth_ends() is stats::smoothEnds(), ties and -Inf included", {
  set.seed(11)
  for (i in 1:60) {
    n <- sample(c(5:30, 200), 1)
    k <- 2L * sample(seq_len((n - 1) %/% 2), 1) + 1L
    y <- switch(i %% 3 + 1, rnorm(n), round(rnorm(n) * 2), c(-Inf, rnorm(n - 1)))
    expect_identical(smooth_ends(y, k), stats::smoothEnds(y, k))
  }
  # one end only: the other is left as it was
  y <- rnorm(50)
  s <- smooth_ends(y, 9, left = FALSE)
  expect_identical(s[1:5], y[1:5])
  expect_identical(s[46:50], stats::smoothEnds(y, 9)[46:50])
})

test_that("spectral_lines' background equals runmed() of the whole periodogram per band", {
  set.seed(12)
  x <- rnorm(2e5) + 0.3 * sin(2 * pi * 1.3 * seq_len(2e5) / 100) +
    cumsum(rnorm(2e5, sd = 0.01))
  w <- welch_psd(x, 100)
  lp <- log(w$psd)
  nb <- length(lp)
  ref <- rep(NA_real_, nb)
  bands <- unique(c(2^(0:floor(log2(nb))), nb + 1))
  for (b in seq_len(length(bands) - 1L)) {
    lo <- bands[b]
    hi <- bands[b + 1L] - 1L
    k <- min(max(11L, 2L * floor(0.1 * lo) + 1L), 2L * floor((nb - 1L) / 2L) - 1L)
    ref[lo:hi] <- stats::runmed(lp, k, endrule = "median")[lo:hi]
  }
  nu <- w$nu
  ratio <- w$psd / exp(ref - log(stats::qchisq(0.5, nu) / nu))
  l <- spectral_lines(x, 100)
  expect_equal(l$ratio[1], max(ratio[5:(nb - 2)]), tolerance = 1e-12)
  expect_equal(l$f0[1], 1.3, tolerance = 1e-3)
})

test_that("acf_sums, detrend_line and the paired Welch PSD match their definitions", {
  set.seed(13)
  x <- as.numeric(stats::filter(rnorm(5003), 0.7, method = "recursive"))
  xc <- x - mean(x)
  direct <- vapply(0:40, function(k) sum(xc[seq_len(5003 - k)] * xc[(k + 1):5003]), 0)
  expect_equal(acf_sums(xc, 40L), direct, tolerance = 1e-13)
  expect_equal(acf_sums(xc[1:3], 5L), c(sum(xc[1:3]^2), sum(xc[1:2] * xc[2:3]),
                                          xc[1] * xc[3], 0, 0, 0))
  t <- seq_along(x)
  expect_equal(detrend_linear(x + 0.01 * t),
               unname(stats::residuals(stats::lm.fit(cbind(1, t), x + 0.01 * t))),
               tolerance = 1e-12)
  # Welch: one FFT per segment, odd and even segment counts
  for (n in c(4096, 4096 + 1024)) {
    y <- x[seq_len(n)]
    w <- welch_psd(y, 10, seg = 1024)
    yd <- detrend_linear(y)
    win <- 0.5 - 0.5 * cos(2 * pi * (0:1023) / 1024)
    starts <- seq(1, n - 1024 + 1, by = 512)
    acc <- Reduce(`+`, lapply(starts, function(s) {
      ys <- yd[s:(s + 1023)]
      Mod(stats::fft((ys - mean(ys)) * win)[1:513])^2
    }))
    p <- acc / length(starts) / (10 * sum(win^2))
    p[2:512] <- 2 * p[2:512]
    expect_equal(w$psd, p, tolerance = 1e-12)
  }
})
