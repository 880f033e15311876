# detect_series_effects(): the catalogue's series entries in one pass. Series built
# here with base R (white noise, a random walk by cumsum, a Gauss-Markov by
# stats::filter) plus the deterministic effect, never with avsim().

test_that("a bias step: time within 1% of the record, size within 20%; removed on request", {
  n <- 2e5
  freq <- 100
  for (seed in 1:2) {
    x <- gen_white_walk(n, seed = 10 + seed)
    at <- 123457
    x[at:n] <- x[at:n] + 0.03
    se <- detect_series_effects(x, freq)
    st <- se$table[se$table$kind == "steps", ]
    expect_identical(se$table$kind, "steps")
    expect_lt(abs(st$time - (at - 1) / freq), 0.01 * n / freq)
    expect_equal(st$size, 0.03, tolerance = 0.2)
    # reported, not removed: x is the input
    expect_false(st$removed)
    expect_identical(se$x, x)
    expect_identical(se$removed, character())
    # the step raises the long-tau ADEV; taking it out lowers it
    big <- se$adev$tau >= 40 & se$adev$tau <= 400
    expect_true(all(se$adev$before[big] > se$adev$after[big]))
    expect_true(all(abs(se$adev$change[se$adev$tau <= 0.1]) < 1e-3))
    # removed when asked: nothing left to find
    rm <- detect_series_effects(x, freq, remove = "steps")
    expect_true(rm$table$removed)
    expect_identical(rm$removed, "steps")
    expect_equal(nrow(detect_series_effects(rm$x, freq)$table), 0L)
    expect_lt(abs(mean(rm$x[(at - 5000):(at - 1)]) - mean(rm$x[at:(at + 4999)])), 0.01)
  }
})

test_that("a sharp line does not move what the series pass finds", {
  # own generator: white noise, a random walk and a step of 8 x ADEV(10 s)
  # at 1500 s (z 6.6); then a 0.3 Hz line of twice the white sd added. The
  # line's leakage into the window means hid the step from the detector.
  set.seed(2719)
  freq <- 100
  n <- 4e5
  b <- rnorm(n, sd = 0.01) + cumsum(rnorm(n, sd = 1e-4 / sqrt(freq)))
  sz <- 8 * allan(b, freq, taus = I(10))$adev
  b <- b + sz * ((seq_len(n) - 1) / freq >= 1500)
  x <- b + 0.02 * sin(2 * pi * 0.3 * seq_len(n) / freq + 1)
  s0 <- detect_series_effects(b, freq)$table
  s1 <- detect_series_effects(x, freq)$table
  expect_identical(s0$kind, "steps")
  expect_equal(s0$time, 1500, tolerance = 1e-3)
  expect_identical(s1$kind, s0$kind)
  expect_identical(s1$index, s0$index)
  expect_equal(s1$size, s0$size, tolerance = 1e-3)
  # removed on request from the series as given (the line stays in it)
  y <- detect_series_effects(x, freq, remove = "steps")$x
  expect_equal(y - x, -s1$size * ((seq_len(n) - 1) / freq >= s1$time), tolerance = 1e-6)
})

test_that("a step's edge is no spike; a spike beside a step still is", {
  # own generator: white noise (sd 0.001) and a step of 10 sd at 100 s. Read
  # before the step was out, its first sample was an outlier of the AR
  # model: a "spike" there in 5 of 12 seeds.
  freq <- 100
  t <- seq_len(20000) / freq
  n_spikes <- vapply(1:12, function(s) {
    set.seed(s)
    x <- 0.001 * rnorm(20000) + 0.01 * (t > 100)
    tb <- detect_series_effects(x, freq)$table
    expect_identical(sum(tb$kind == "steps"), 1L)
    sum(tb$kind == "spikes")
  }, 0)
  expect_identical(sum(n_spikes), 0)
  set.seed(3)
  x <- 0.001 * rnorm(20000) + 0.01 * (t > 100)
  x[5000] <- x[5000] + 0.02
  tb <- detect_series_effects(x, freq)$table
  expect_identical(tb$kind, c("spikes", "steps"))
  expect_identical(tb$index[1], 5000L)
  expect_equal(tb$size[1], 0.02, tolerance = 0.1)
})

test_that("an exponential warm-up: time constant within 30%", {
  n <- 2e5
  freq <- 100
  t <- (seq_len(n) - 1) / freq
  covered <- logical()
  for (seed in 1:2) {
    for (tc in c(30, 120)) {
      x <- gen_white_walk(n, rw = 2e-5, seed = seed) + 0.1 * exp(-t / tc)
      se <- detect_series_effects(x, freq, remove = "warmup")
      w <- se$table[se$table$kind == "warmup", ]
      expect_equal(nrow(w), 1L)
      expect_equal(w$tc, tc, tolerance = 0.3)
      expect_equal(w$size, 0.1, tolerance = 0.3)
      expect_identical(se$table$kind, "warmup")
      # its 95% interval (profile likelihood) holds the estimate and is
      # reported in the evidence
      ci <- asNamespace("allanvar")$detect_warmup(x, freq)$all
      expect_true(ci$tc_lower < w$tc && w$tc < ci$tc_upper)
      expect_lt(ci$tc_upper / ci$tc_lower, 2)
      expect_match(w$evidence, sprintf("tc 95%% interval %s-%s s",
                                       format_num(ci$tc_lower, 2), format_num(ci$tc_upper, 2)),
                   fixed = TRUE)
      covered <- c(covered, ci$tc_lower <= tc && tc <= ci$tc_upper)
      # the corrected start is level with the rest
      expect_lt(abs(mean(se$x[1:500]) - mean(se$x[(5 * tc * freq):(6 * tc * freq)])), 0.02)
    }
  }
  # the generator's tc in 3 of the 4 intervals (seed 1 at 120 s reads
  # 137 s, 120.6-155.9; bench/warmup-interval.R measures the coverage)
  expect_gte(sum(covered), 3L)
})

test_that("a warm-up and a step at its start: each read with the other out", {
  # own generator: white noise, a random walk, a warm-up of 40 x ADEV(10 s)
  # decaying over 100 s and a step of 15 x ADEV(10 s) at 40 s (a measured
  # accelerometer has one there). The warm-up's slope cancels the step's
  # edge in the Allan differences, and the step bends the exponential:
  # read once in catalogue order, no seed had both, the time constant
  # came out at 156 and 182 s where a warm-up was named at all.
  freq <- 100
  n <- 4e5
  t <- (seq_len(n) - 1) / freq
  both <- vapply(501:506, function(seed) {
    set.seed(seed)
    b <- rnorm(n, sd = 0.01) + cumsum(rnorm(n, sd = 1e-4 / sqrt(freq)))
    a10 <- allan(b, freq, taus = I(10))$adev
    x <- b + 40 * a10 * exp(-t / 100) + 15 * a10 * (t >= 40)
    tb <- detect_series_effects(x, freq)$table
    w <- tb[tb$kind == "warmup", ]
    st <- tb[tb$kind == "steps", ]
    # what is named is right
    expect_true(all(abs(w$tc / 100 - 1) <= 0.25))
    expect_true(all(abs(st$time - 40) <= 1))
    expect_true(all(abs(st$size / (15 * a10) - 1) <= 0.25))
    nrow(w) == 1L && nrow(st) == 1L && nrow(tb) == 2L
  }, TRUE)
  # both, and nothing else, in 4 of 6 (in the other two the step and the
  # warm-up's slope cancel at every window, and no detector reads the two
  # jointly: they come out as one transient)
  expect_gte(sum(both), 4L)
})

test_that("a sharp step inside a slow warm-up stands beside it", {
  # own generator: white noise, a random walk, a warm-up of 50 x ADEV(tc)
  # with tc 780 s and a step of 11 x ADEV(10 s) at 530 s. The step is
  # judged beside the warm-up by the warm-up's likelihood, which must not
  # take a genuine step for the exponential's misfit
  freq <- 100
  n <- 1e6
  t <- (seq_len(n) - 1) / freq
  for (seed in 611:612) {
    set.seed(seed)
    b <- rnorm(n, sd = 0.01) + cumsum(rnorm(n, sd = 1e-4 / sqrt(freq)))
    a10 <- allan(b, freq, taus = I(10))$adev
    size <- -11 * a10
    x <- b + 50 * allan(b, freq, taus = I(780))$adev * exp(-t / 780) + size * (t >= 530)
    tb <- detect_series_effects(x, freq)$table
    st <- tb[tb$kind == "steps", ]
    w <- tb[tb$kind == "warmup", ]
    expect_equal(nrow(st), 1L)
    expect_lt(abs(st$time - 530), 2)
    expect_lt(abs(st$size / size - 1), 0.25)
    expect_match(st$evidence, "beside the warm-up, likelihood ratio z = ")
    expect_equal(nrow(w), 1L)
  }
})

test_that("spikes: all found, none invented; removal restores the short-tau ADEV", {
  n <- 1e5
  freq <- 100
  for (seed in 1:3) {
    clean <- gen_white_walk(n, seed = 30 + seed)
    set.seed(300 + seed)
    at <- sort(sample(10:(n - 10), 12))
    size <- sample(c(-1, 1), 12, replace = TRUE) * runif(12, 1, 3)  # 10-30 sd
    x <- clean
    x[at] <- x[at] + size
    se <- detect_series_effects(x, freq, remove = "spikes")
    sp <- se$table[se$table$kind == "spikes", ]
    expect_identical(sp$index, as.integer(at))
    expect_equal(sp$size, size, tolerance = 0.1)
    expect_identical(unique(se$table$kind), "spikes")
    # without the spikes the ADEV at tau0 is the clean series' within 1%
    a0 <- allan(clean, freq, taus = I(1 / freq))$adev
    expect_equal(allan(se$x, freq, taus = I(1 / freq))$adev, a0, tolerance = 0.01)
    expect_gt(se$adev$before[1], 1.01 * a0)
  }
})

test_that("controls: red noise, a slow Gauss-Markov and a sinusoid add nothing (<= 1 in 10 seeds)", {
  n <- 1e5
  freq <- 100
  t <- seq_len(n) / freq
  phi <- exp(-1 / (freq * 30))
  added <- 0L
  for (seed in 1:10) {
    set.seed(500 + seed)
    gm <- as.numeric(stats::filter(rnorm(n, sd = 0.05 * sqrt(1 - phi^2)), phi,
                                   method = "recursive"))
    x <- rnorm(n, sd = 0.1) + cumsum(rnorm(n, sd = 5e-4)) + gm +
      0.05 * sin(2 * pi * 0.01 * t + seed)
    added <- added + nrow(detect_series_effects(x, freq)$table)
  }
  expect_lte(added, 1L)
})

test_that("the effects together: each kind found once, `all` removes every one", {
  n <- 2e5
  freq <- 100
  t <- (seq_len(n) - 1) / freq
  x <- gen_white_walk(n, rw = 2e-5, seed = 61) + 0.1 * exp(-t / 50)
  x[150001:n] <- x[150001:n] - 0.04
  x[c(20000, 90000)] <- x[c(20000, 90000)] + c(2, -2.5)
  se <- detect_series_effects(x, freq, remove = "all")
  expect_setequal(se$table$kind, c("spikes", "warmup", "steps"))
  expect_equal(sum(se$table$kind == "spikes"), 2L)
  expect_equal(se$table$time[se$table$kind == "steps"], 1500, tolerance = 0.01 * n / freq / 1500)
  expect_true(all(se$table$removed))
  expect_identical(se$removed, c("spikes", "warmup", "steps"))
  expect_setequal(se$adev_kinds$kind, c("spikes", "warmup", "steps"))
  # looking only for spikes leaves the rest alone
  only <- detect_series_effects(x, freq, kinds = "spikes")
  expect_identical(unique(only$table$kind), "spikes")
  expect_identical(only$kinds, "spikes")
})

test_that("a ts comes back as a ts; freq is taken from it", {
  x <- stats::ts(gen_white_walk(5000, seed = 71), start = 3, frequency = 50)
  x[1000] <- x[1000] + 2
  se <- detect_series_effects(x, remove = "spikes")
  expect_true(stats::is.ts(se$x))
  expect_equal(stats::tsp(se$x), stats::tsp(x))
  expect_equal(se$freq, 50)
  expect_equal(se$table$index, 1000L)
})

test_that("detect_series_effects() prints what it found and what it removed", {
  x <- gen_white_walk(2e4, seed = 81)
  x[5000] <- x[5000] + 2
  x[12001:2e4] <- x[12001:2e4] + 0.08
  expect_snapshot({
    print(detect_series_effects(x, 100, remove = "spikes"))
    print(detect_series_effects(gen_white_walk(2e4, seed = 82), 100))
  })
})

test_that("detect_series_effects() errors are classed and worded", {
  x <- gen_white_walk(1000, seed = 91)
  expect_snapshot(error = TRUE, {
    detect_series_effects()
    detect_series_effects(x)
    detect_series_effects(x, 100, remove = "bumps")
    detect_series_effects(x, 100, remove = TRUE)
    detect_series_effects(x, 100, kinds = 1)
    detect_series_effects(x, 100, 1)
    detect_series_effects(stats::ts(x, frequency = 10), 100)
    detect_series_effects(x[1:100], 100)
  })
  expect_error(detect_series_effects(x, 100, remove = "x"),
               class = "allanvar_error_argument")
})

test_that("avrefine() reports the series effects and removes those asked for", {
  skip_if_not("remove" %in% names(formals(avrefine)))
  n <- 1e5
  freq <- 100
  x <- gen_white_walk(n, rw = 1e-5, seed = 101)
  x[60001:n] <- x[60001:n] + 0.03
  x[c(7000, 33000)] <- x[c(7000, 33000)] + 2
  fit <- avfit(allan(x, freq), terms = c("N", "K"))
  ref <- avrefine(fit, data = x, remove = c("spikes", "steps"), max_steps = 1)
  tb <- ref$series$table
  expect_identical(sort(unique(tb$kind)), c("spikes", "steps"))
  expect_equal(tb$time[tb$kind == "steps"], 600, tolerance = 0.01 * n / freq / 600)
  expect_identical(ref$series$removed, c("spikes", "steps"))
})

test_that("avrefine(series =) takes an earlier pass instead of running it again", {
  n <- 5e4
  freq <- 100
  x <- gen_white_walk(n, rw = 1e-5, seed = 102)
  x[c(7000, 33000)] <- x[c(7000, 33000)] + 2
  se <- detect_series_effects(x, freq, remove = "spikes")
  fit <- avfit(allan(se$x, freq), terms = c("N", "K"))
  again <- avrefine(fit, data = se$x, max_steps = 1)
  given <- avrefine(fit, data = se$x, series = se, max_steps = 1)
  # the loop itself is the same; the series pass kept is the caller's
  expect_identical(coef(given), coef(again))
  expect_identical(given$steps, again$steps)
  kept <- se
  kept$x <- NULL
  expect_identical(given$series, kept)
  # the fit does not carry a copy of the data
  expect_null(again$series$x)
  expect_identical(given$refine$removed, "spikes")
  expect_identical(again$refine$removed, character())
  expect_error(avrefine(fit, data = se$x, series = list()),
               class = "allanvar_error_argument")
  expect_error(avrefine(fit, series = se), class = "allanvar_error_argument")
  expect_error(avrefine(fit, data = se$x, series = se, remove = "spikes"),
               class = "allanvar_error_argument")
  # data that is not the pass's series
  expect_error(avrefine(fit, data = x, series = se), class = "allanvar_error_argument")
})

test_that("analyze_imu(remove =) and the CLI's --remove take the effects out before the curve", {
  set.seed(111)
  n <- 6000
  d <- data.frame(time = (0:(n - 1)) / 50, gx = rnorm(n, sd = 0.05),
                  ax = rnorm(n, sd = 2))
  spikes <- c(700, 2500, 4100)
  d$gx[spikes] <- d$gx[spikes] + 1.5
  f <- tempfile(fileext = ".csv")
  out <- tempfile("cli")
  on.exit(unlink(c(f, out), recursive = TRUE))
  utils::write.csv(d, f, row.names = FALSE)
  r <- read_imu(f, time_unit = "s", columns = c("gx", "ax"),
                sensors = c("gyro", "accel"))
  a <- suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE,
                                    remove = "spikes"))
  s <- a$channels$gyro_x$series
  expect_identical(s$table$index, as.integer(spikes))
  expect_identical(s$removed, "spikes")
  # with the loop, the pass is handed to avrefine(), not run again on its output
  ar <- suppressWarnings(analyze_imu(r, refine = TRUE, progress = FALSE,
                                     remove = "spikes"))
  expect_identical(ar$channels$gyro_x$fit$series, ar$channels$gyro_x$series)
  expect_identical(ar$channels$gyro_x$fit$refine$removed, "spikes")
  # without `remove` the pass still runs (its effects mark the readings),
  # and nothing is taken out
  keep <- suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE))
  expect_identical(keep$channels$gyro_x$series$removed, character())
  expect_identical(keep$channels$gyro_x$series$table$index, as.integer(spikes))
  expect_lt(a$channels$gyro_x$curve$adev[1], 0.97 * keep$channels$gyro_x$curve$adev[1])
  capture.output(res <- suppressMessages(suppressWarnings(allanvar_cli(c(
    f, "--out", out, "--gyro-cols", "gx", "--accel-cols", "ax", "--time-unit", "s",
    "--no-refine", "--quiet", "--remove", "spikes,steps")))))
  expect_equal(res$analyses[[1]]$channels$gyro_x$curve$adev,
               a$channels$gyro_x$curve$adev)
  expect_error(analyze_imu(r, refine = FALSE, progress = FALSE, remove = "bumps"),
               class = "allanvar_error_argument")
})

test_that("degenerate series: a constant has nothing, a noiseless step is one step", {
  s <- detect_series_effects(rep(1, 5000), 100)
  expect_equal(nrow(s$table), 0L)
  expect_true(all(s$adev$change == 0))
  x <- c(rep(0, 3000), rep(1, 3000))
  s <- detect_series_effects(x, 100, remove = "all")
  expect_identical(s$table$kind, "steps")
  expect_identical(s$table$index, 3001L)
  expect_equal(s$table$size, 1)
  expect_equal(s$x, rep(0, 6000))
  expect_output(print(s), "bias step of 1 at 30 s \\[removed\\]")
})

test_that("a transient whose return is weak is paired, and a bias step stays a step", {
  found <- 0L
  for (seed in 1:6) {
    set.seed(seed)
    x <- rnorm(2e4, sd = 0.1)
    x[5001:7000] <- x[5001:7000] + 0.05        # 20 s at 50 s
    tb <- detect_series_effects(x, 100, kinds = c("steps", "transients"))$table
    expect_false("steps" %in% tb$kind)
    if (identical(tb$kind, "transients")) {
      found <- found + 1L
      expect_lt(abs(tb$time - 50), 1)
      expect_equal(tb$duration, 20, tolerance = 0.1)
    }
    set.seed(seed + 100)
    y <- rnorm(2e4, sd = 0.1)
    y[12001:2e4] <- y[12001:2e4] + 0.08
    expect_identical(detect_series_effects(y, 100, kinds = c("steps", "transients"))$table$kind,
                     "steps")
  }
  expect_gte(found, 5L)
})

test_that("series_reading_bias(): what outliers left in do to N, against the clean series' Allan deviation", {
  n <- 1e5
  freq <- 100
  clean <- gen_white_walk(n, rw = 1e-5, seed = 121)
  set.seed(121)
  at <- sample.int(n, 200)
  x <- clean
  x[at] <- x[at] + sample(c(-1, 1), 200, TRUE) * 1.5
  se <- detect_series_effects(x, freq, kinds = "spikes")
  b <- series_reading_bias(se)
  expect_identical(b, se$reading_bias)
  expect_setequal(b$term, c("N", "B", "K"))
  expect_identical(unique(b$kind), "spikes")
  # independent reference: ADEV at 1 s with the outliers over the clean series'
  ref <- allan(x, freq, taus = I(1))$adev / allan(clean, freq, taus = I(1))$adev - 1
  expect_gt(ref, 0.02)
  expect_equal(b$bias_change[b$term == "N"], ref, tolerance = 0.05)
  # readings' own taus are used
  rb <- series_reading_bias(se, data.frame(term = c("N", "K"), tau = c(0.1, 100)))
  expect_equal(rb$tau[rb$term == "N"], 0.1)
  # removed kinds bias nothing
  expect_equal(nrow(series_reading_bias(detect_series_effects(x, freq, kinds = "spikes",
                                                       remove = "spikes"))), 0L)
  expect_error(series_reading_bias(list()), class = "allanvar_error_argument")
  expect_error(series_reading_bias(se, readings = 1), class = "allanvar_error_argument")
})
