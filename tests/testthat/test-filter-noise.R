# Filtered white noise. References written here, independent of the
# package: the Allan difference as a linear functional of the white input
# (its variance is sigma^2 times the sum of its squared weights), impulse
# responses from stats::filter, and series generated with stats::filter.

# Exact AV of white noise (variance s2 per sample) through impulse
# response h: the Allan difference at cluster m is sum_i c_i w_i with
# c = h convolved with the kernel (+1/m x m, -1/m x m); AV = s2 sum c^2 / 2.
av_linear <- function(h, m, s2) {
  vapply(m, function(mm) {
    k <- c(rep(1 / mm, mm), rep(-1 / mm, mm))
    c <- stats::convolve(h, rev(k), type = "open")
    s2 * sum(c^2) / 2
  }, 0)
}


tau0 <- 0.01
m <- c(1, 2, 3, 4, 5, 7, 8, 16, 33, 100)

test_that("the exact AV of every filter family matches the linear-functional reference", {
  # moving average of 4 taps
  h <- rep(1 / 4, 4)
  expect_equal(filter_av(m, filter_spec("ma", L = 4), tau0), av_linear(h, m, 1 / tau0),
               tolerance = 1e-12)
  # Bartlett: two cascaded 3-tap averages
  h2 <- stats::convolve(rep(1 / 3, 3), rev(rep(1 / 3, 3)), type = "open")
  expect_equal(filter_av(m, filter_spec("bartlett", L = 3, n = 2), tau0),
               av_linear(h2, m, 1 / tau0), tolerance = 1e-12)
  # given FIR coefficients (scaled to unit DC gain)
  hf <- c(0.5, 1, 0.3, -0.1)
  expect_equal(filter_av(m, filter_spec("fir", h = hf), tau0),
               av_linear(hf / sum(hf), m, 1 / tau0), tolerance = 1e-12)
  # first-order low-pass: y = a y[-1] + (1 - a) w, a from the -3 dB point
  fc <- 8
  w <- 2 * pi * fc * tau0
  a <- (2 - cos(w)) - sqrt((2 - cos(w))^2 - 1)
  h1 <- (1 - a) * a^(0:3999)
  expect_equal(filter_av(m, filter_spec("lp1", fc = fc, freq = 100), tau0),
               av_linear(h1, m, 1 / tau0), tolerance = 1e-10)
  # second-order Butterworth by the bilinear transform
  K <- tan(pi * fc * tau0)
  den <- 1 + sqrt(2) * K + K^2
  b <- c(1, 2, 1) * K^2 / den
  ar <- c(-2 * (K^2 - 1) / den, -(1 - sqrt(2) * K + K^2) / den)
  hb <- as.numeric(stats::filter(c(b, numeric(3997)), ar, method = "recursive"))
  expect_equal(filter_av(m, filter_spec("lp2", fc = fc, freq = 100), tau0),
               av_linear(hb, m, 1 / tau0), tolerance = 1e-10)
  # second-order all-pole section: poles of s = wn (-zeta +- i sqrt(1 -
  # zeta^2)) at z = exp(s tau0), unit DC gain; complex and real poles
  for (zeta in c(0.6, 1.7)) {
    wn <- 2 * pi * 15
    p <- exp(wn * tau0 * (-zeta + c(1, -1) * sqrt(as.complex(zeta^2 - 1))))
    a2 <- c(Re(sum(p)), -Re(prod(p)))
    h2p <- as.numeric(stats::filter(c(1 - sum(a2), numeric(3999)), a2, method = "recursive"))
    expect_equal(filter_av(m, filter_spec("ar2", fn = 15, zeta = zeta, freq = 100), tau0),
                 av_linear(h2p, m, 1 / tau0), tolerance = 1e-10)
  }
})

test_that("the all-pole section's start is read from the raw lag-1 and lag-2 autocorrelation", {
  skip_on_cran()
  set.seed(11)
  # white noise through y = w + 0.5 y[-1] - 0.15 y[-2]: poles 0.387 at
  # +-49.8 degrees, i.e. fn = 20.48 Hz and zeta = 0.737 at 100 Hz
  y <- as.numeric(stats::filter(stats::rnorm(4e5), c(0.5, -0.15), method = "recursive"))
  st <- filter_evidence(y[-(1:100)], 100)$start$ar2
  expect_equal(st$fn, 20.48, tolerance = 0.03)
  expect_equal(st$zeta, 0.737, tolerance = 0.03)
  # simulated with the package's recursion: variance g(0) per N^2
  sp <- filter_spec("ar2", fn = 20.48, zeta = 0.737, freq = 100)
  s <- sim_filtered_white(2e5, tau0, 1, sp)
  expect_equal(stats::var(s), filter_acf(sp, tau0, 0), tolerance = 0.02)
  expect_error(filter_spec("ar2", fn = 60, zeta = 0.7, freq = 100),
               class = "allanvar_error_argument")
  expect_error(filter_spec("ar2", fn = 20, zeta = 0, freq = 100),
               class = "allanvar_error_argument")
})

test_that("a fractional moving average is the MA whose autocovariance is the triangle", {
  # L = 1.25: lag-1 autocorrelation 1 - 1/L = 0.2, i.e. an MA(1) with
  # weights (1, w), w / (1 + w^2) = 0.2
  wt <- (1 - sqrt(1 - 4 * 0.2^2)) / (2 * 0.2)
  h <- c(1, wt) / (1 + wt)
  expect_equal(filter_av(m, filter_spec("ma", L = 1.25), tau0),
               av_linear(h, m, 1 / tau0), tolerance = 1e-12)
})

test_that("N keeps its meaning: the AV tends to N^2 / tau and the PSD is N^2 at DC", {
  specs <- list(filter_spec("ma", L = 1.3), filter_spec("ma", L = 6),
                filter_spec("bartlett", L = 4), filter_spec("lp1", fc = 5, freq = 100),
                filter_spec("lp2", fc = 12, freq = 100),
                filter_spec("fir", h = c(1, 2, 1)))
  for (sp in specs) {
    mm <- 1e5
    expect_equal(filter_av(mm, sp, tau0) * mm * tau0, 1, tolerance = 1e-3)
    expect_equal(filter_psd(0, sp, tau0), 1, tolerance = 1e-12)
    # below the white line at short tau: the filter removes power
    expect_lt(filter_av(1, sp, tau0), 1 / tau0)
  }
})

test_that("low-pass filters are -3 dB at their cutoff; bandwidths are reported", {
  for (fc in c(2, 10, 30)) {
    for (fam in c("lp1", "lp2")) {
      bw <- filter_bandwidth(filter_spec(fam, fc = fc, freq = 100), tau0)
      expect_equal(bw$f3db, fc, tolerance = 1e-6)
    }
  }
  # a 4-tap average: -3 dB near 0.443 fs / 4 (the boxcar's, slightly above in
  # discrete time)
  bw <- filter_bandwidth(filter_spec("ma", L = 4), tau0)
  ref <- stats::uniroot(function(f) (sin(4 * pi * f * tau0) / (4 * sin(pi * f * tau0)))^2 - 0.5,
                        c(1, 20))$root
  expect_equal(bw$f3db, ref, tolerance = 1e-6)
  # unfiltered white: noise-equivalent bandwidth is fs/2
  expect_equal(filter_bandwidth(filter_spec("fir", h = 1), tau0)$enbw, 50)
})

test_that("simulated filtered white noise has the exact AV (Monte Carlo)", {
  set.seed(11)
  n <- 2e5
  for (sp in list(filter_spec("ma", L = 1.2), filter_spec("lp2", fc = 15, freq = 100))) {
    x <- sim_filtered_white(n, tau0, 0.02, sp)
    mm <- c(1, 2, 4, 8)
    emp <- vapply(mm, function(k) {
      s <- stats::filter(x, rep(1 / k, k), sides = 1)
      s <- s[!is.na(s)]
      d <- s[-(1:k)] - s[seq_len(length(s) - k)]
      mean(d^2) / 2
    }, 0)
    expect_equal(emp, 0.02^2 * filter_av(mm, sp, tau0), tolerance = 0.03)
  }
})

test_that("start values read from the raw ACF recover each family within 10%", {
  set.seed(3)
  n <- 2e5
  w <- rnorm(n + 10)
  # MA of 4 taps, with a random walk beside it
  x <- as.numeric(stats::filter(w, rep(0.25, 4), sides = 1))[-(1:3)] +
    cumsum(rnorm(n + 7, sd = 2e-3))
  ev <- filter_evidence(x, 100)
  expect_true(ev$filtered)
  expect_equal(ev$length, 3L)
  expect_equal(ev$start$ma$L, 4, tolerance = 0.1)
  # first-order low-pass at 10 Hz
  fc <- 10
  a <- (2 - cos(2 * pi * fc / 100)) - sqrt((2 - cos(2 * pi * fc / 100))^2 - 1)
  y <- as.numeric(stats::filter((1 - a) * w, a, method = "recursive"))[-(1:10)]
  ev <- filter_evidence(y, 100)
  expect_equal(ev$start$lp1$fc, fc, tolerance = 0.1)
  # fractional average of L = 1.2 samples (an MA(1) with weights 1, w)
  wt <- (1 - sqrt(1 - 4 * (1 / 6)^2)) / (2 / 6)
  z <- as.numeric(stats::filter(w, c(1, wt), sides = 1))[-1]
  ev <- filter_evidence(z, 100)
  expect_equal(ev$start$ma$L, 1.2, tolerance = 0.1)
  expect_equal(ev$length, 1L)
  # Bartlett: two cascaded 5-tap averages (triangular taps over 9 samples)
  tri <- c(1:5, 4:1) / 25
  b <- as.numeric(stats::filter(w, tri, sides = 1))[-(1:8)]
  expect_equal(filter_evidence(b, 100)$start$bartlett$L, 5)
  # second-order Butterworth at 15 Hz (bilinear, written out here)
  K <- tan(pi * 15 / 100)
  den <- 1 + sqrt(2) * K + K^2
  v <- as.numeric(stats::filter(w, c(1, 2, 1) * K^2 / den, sides = 1))[-(1:2)]
  y2 <- as.numeric(stats::filter(v, c(-2 * (K^2 - 1) / den, -(1 - sqrt(2) * K + K^2) / den),
                                 method = "recursive"))[-(1:50)]
  expect_equal(filter_evidence(y2, 100)$start$lp2$fc, 15, tolerance = 0.1)
})

test_that("slow processes raise the ACF but are not read as a filter", {
  hits <- 0L
  for (seed in 1:10) {
    set.seed(seed)
    n <- 1e5
    # white + random walk + Gauss-Markov (Tc = 2 s) strong at the sample level
    phi <- exp(-0.01 / 2)
    gm <- as.numeric(stats::filter(rnorm(n, sd = 0.3 * sqrt(1 - phi^2)), phi,
                                   method = "recursive"))
    x <- rnorm(n) + cumsum(rnorm(n, sd = 5e-3)) + gm
    ev <- filter_evidence(x, 100)
    # the raw lag-1 ACF is clearly positive ...
    expect_gt(ev$acf$r[1], 0.05)
    hits <- hits + ev$filtered
  }
  # ... but the filter's part is not
  expect_lte(hits, 1L)
})

test_that("bad filter specifications are refused with classed errors", {
  expect_error(filter_spec("boxcar", L = 2), class = "allanvar_error_argument")
  expect_error(filter_spec("ma", L = 0.5), class = "allanvar_error_argument")
  expect_error(filter_spec("lp2", fc = 60, freq = 100), class = "allanvar_error_argument")
  expect_error(filter_spec("lp1", fc = 0, freq = 100), class = "allanvar_error_argument")
  expect_error(filter_spec("fir", h = c(1, -1)), class = "allanvar_error_argument")
  expect_snapshot(filter_spec("lp2", fc = 60, freq = 100), error = TRUE)
})

test_that("a curve alone gives the filter's start value from its first point", {
  tau0 <- 0.01
  for (sp in list(filter_spec("ma", L = 1.2), filter_spec("ma", L = 4),
                  filter_spec("lp1", fc = 12, freq = 100),
                  filter_spec("lp2", fc = 20, freq = 100))) {
    q <- filter_av(1, sp, tau0) * tau0
    st <- filter_start_from_curve(q, sp$family, 100)
    par <- if (sp$family == "ma") "L" else "fc"
    expect_equal(st[[par]], sp[[par]], tolerance = 1e-6)
  }
  expect_equal(filter_start_from_curve(q = 1 / (3 * 1.2 - 2), "ma", 100)$L, 1.2)
  expect_null(filter_start_from_curve(1.1, "ma", 100))
})

test_that("the raw data support a fitted filter, and contradict one on white noise", {
  set.seed(8)
  n <- 1e5
  w <- rnorm(n + 3, sd = 0.1)
  x <- as.numeric(stats::filter(w, rep(0.25, 4), sides = 1))[-(1:3)]
  fe <- filter_evidence(x, 100)
  N <- 0.1 * sqrt(0.01)                 # white level of the input
  ok <- filter_raw_support(filter_spec("ma", L = 4), N, fe, var(x), 100)
  expect_true(ok$support)
  wrong <- filter_raw_support(filter_spec("ma", L = 4), N,
                              filter_evidence(rnorm(n, sd = 0.05), 100), 0.05^2, 100)
  expect_false(wrong$support)
  # a filter sized for more than the raw data hold: 2.5 x the raw lag-1
  # excess is contradicted, 1.8 x undecided, 1.3 x supported
  for (k in c(2.5, 1.8, 1.3)) {
    s <- filter_raw_support(filter_spec("ma", L = 4), N * sqrt(k), fe, var(x), 100)$support
    if (k > 2) expect_false(s) else if (k > 1.5) expect_true(is.na(s)) else expect_true(s)
  }
})

test_that("the C++ Welch periodogram is R's matrix expression to rounding", {
  # The reference: the all-R form welch_psd_lin() had before its segments
  # and sums moved to C++ (one real segment per transform).
  ref <- function(x, freq, seg) {
    n <- length(x)
    seg <- as.integer(min(seg, 2^floor(log2(n))))
    starts <- seq.int(1L, n - seg + 1L, by = seg %/% 2L)
    win <- 0.5 - 0.5 * cos(2 * pi * (seq_len(seg) - 1) / seg)
    half <- seg %/% 2L + 1L
    acc <- numeric(half)
    chunk <- max(1L, (2^22) %/% seg)
    for (c0 in seq.int(1L, length(starts), by = chunk)) {
      st <- starts[c0:min(length(starts), c0 + chunk - 1L)]
      X <- matrix(x[outer(seq_len(seg) - 1L, st, `+`)], nrow = seg)
      X <- (X - rep(colMeans(X), each = seg)) * win
      acc <- acc + rowSums(Mod(stats::mvfft(X)[seq_len(half), , drop = FALSE])^2)
    }
    p <- acc / length(starts) / (freq * sum(win^2))
    p[2:(half - 1L)] <- 2 * p[2:(half - 1L)]
    p
  }
  set.seed(7)
  # 300 samples in 64-sample segments: 8 segments; 330: 9 (an odd one out)
  for (n in c(300, 330, 20011)) {
    x <- 3 + cumsum(rnorm(n)) * 1e-2 + rnorm(n)
    for (seg in c(64L, 512L)) {
      expect_equal(welch_psd(x, 50, seg, detrend = FALSE)$psd, ref(x, 50, seg), tolerance = 1e-12)
    }
  }
  # more than one chunk of columns (2^22 / seg columns, 2^21 samples each)
  x <- rnorm(2.2e6)
  expect_equal(welch_psd(x, 10, 4096L, detrend = FALSE)$psd, ref(x, 10, 4096L), tolerance = 1e-12)
})

test_that("a moving average far longer than the curve's clusters needs only the lags it reads", {
  # the search may try L far beyond the record: only lags < 2m are read
  h <- rep(1 / 5000, 5000)
  expect_equal(filter_av(m, filter_spec("ma", L = 5000), tau0), av_linear(h, m, 1 / tau0),
               tolerance = 1e-10)
  frac <- c(2.5, 7.25, 50.5)
  lo <- floor(frac)
  w <- frac - lo
  expect_equal(filter_av(frac, filter_spec("ma", L = 5000), tau0),
               (1 - w) * av_linear(h, lo, 1 / tau0) + w * av_linear(h, lo + 1, 1 / tau0),
               tolerance = 1e-10)
  # L = 1e9 (as a search may propose; filter_spec() itself refuses it)
  # would need 8 GB of lags; the answer is finite and positive
  v <- filter_av(c(1, 10, 1000), filter_spec_of("ma", list(L = 1e9), tau0), tau0)
  expect_true(all(is.finite(v) & v > 0))
})

test_that("a moving average's AV at whole m in C++ is the R form to the bit", {
  r_form <- function(m, L, tau0) {
    sp <- list(family = "ma", L = L)
    K <- filter_support(sp)
    need <- min(K, 2 * ceiling(max(m)) + 2)
    g <- filter_acf(sp, tau0, 0:(need - 1L))
    acov_av(round(m), g, if (need < K) ma_sums(L, tau0))
  }
  set.seed(34)
  for (i in 1:300) {
    tau0 <- 10^runif(1, -3, 0)
    L <- switch(i %% 4 + 1, 1 + 10^runif(1, -4, 0.5), 10^runif(1, 0, 3),
                round(10^runif(1, 0, 2)), 10^runif(1, 3, 9))
    m <- if (i %% 2) 2^(0:sample(3:18, 1)) else sort(unique(round(10^runif(25, 0, 5))))
    # (cluster sizes as tau / tau0 give them: whole within 1e-9)
    if (i %% 5 == 0) m <- (m * tau0) / tau0
    expect_identical(filter_av(m, filter_spec_of("ma", list(L = L), tau0), tau0),
                     r_form(m, L, tau0))
  }
  # fractional m stay with the R interpolation
  expect_null(filter_ma_av_cpp(c(1, 2.5), 3, 0.01))
})

test_that("the low-passes' AV in C++ is the R expression to the bit", {
  r_form <- function(m, spec, tau0) {
    ra <- rational_acov(filter_rational(spec))
    out <- ra$d0 / m
    for (j in seq_along(ra$p)) out <- out + geometric_av(m, ra$A[j], ra$p[j])
    Re(out) / tau0
  }
  set.seed(34)
  for (i in 1:300) {
    freq <- sample(c(100, 200, 819.2, 1000), 1)
    tau0 <- 1 / freq
    v <- if (i %% 2) "lp1" else "lp2"
    fc <- exp(runif(1, log(freq / 1e5), log(if (v == "lp2") 0.499 * freq else 0.5 * freq)))
    sp <- filter_spec_of(v, c(fc = fc), tau0)
    # whole m below and above 65536 (R's repeated products and cpow),
    # fractional m
    m <- switch(i %% 3 + 1, 2^(0:20), unique(round(exp(runif(30, 0, log(3e5))))),
                runif(25, 1, 1e6))
    expect_identical(filter_av(m, sp, tau0), r_form(m, sp, tau0))
  }
  # a named m takes the R expression (its names kept)
  m <- c(a = 1, b = 4)
  sp <- filter_spec_of("lp2", c(fc = 10), 0.01)
  expect_identical(filter_av(m, sp, 0.01), r_form(m, sp, 0.01))
})
