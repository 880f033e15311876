# The series pass on effects added to noise it was not tuned to (issue 27,
# items 3 and 7): warm-ups of time constant 1% to 30% of the record and
# spike-count stability, on simulated noise (own generators, fixed seeds)
# and on the measured ADIS16405 records (../shared/data) with the effect
# added. Prints tables; not run by the tests.
#   Rscript bench/battery-series.R [quick]
suppressMessages(library(allanvar))
quick <- identical(commandArgs(TRUE)[1], "quick")
freq <- 100
data_dir <- Sys.getenv("ALLANVAR_SHARED_DATA", "../shared/data")

# own generators (never avsim())
gen <- list(
  white_rw = function(n, seed) { set.seed(seed); rnorm(n, sd = 0.1) + cumsum(rnorm(n, sd = 2e-5)) },
  iir_rw = function(n, seed) {
    set.seed(seed)
    as.numeric(stats::filter(rnorm(n, sd = 0.1), 0.8, method = "recursive")) +
      cumsum(rnorm(n, sd = 2e-5))
  },
  quantized = function(n, seed) {
    set.seed(seed)
    round((rnorm(n, sd = 0.1) + cumsum(rnorm(n, sd = 2e-5))) / 0.1) * 0.1
  })

warmup_case <- function(x, frac, seed, k_amp = 50) {
  n <- length(x)
  t <- (seq_len(n) - 1) / freq
  tc <- frac * n / freq
  amp <- k_amp * allan(x, freq, taus = I(min(tc, n / freq / 4)))$adev *
    sample(c(-1, 1), 1)
  y <- x + amp * exp(-t / tc)
  t0 <- proc.time()[[3]]
  se <- detect_series_effects(y, freq, kinds = c("spikes", "warmup"))
  el <- proc.time()[[3]] - t0
  w <- se$table[se$table$kind == "warmup", ]
  # the found exponential nearest the added one (an axis may have its own)
  j <- if (nrow(w)) which.min(abs(log(w$tc / tc))) else integer()
  data.frame(tc = tc, amp = signif(amp, 3), found = nrow(w),
             tc_hat = if (length(j)) signif(w$tc[j], 4) else NA,
             err = if (length(j)) round(w$tc[j] / tc - 1, 3) else NA,
             z = if (length(j)) round(w$z[j], 1) else NA, sec = round(el, 2))
}

fracs <- c(0.01, 0.03, 0.1, 0.3)
seeds <- if (quick) 1:2 else 1:4
cat("== warm-up, simulated (5000 s at 100 Hz; amplitude 50 x ADEV(tc), random sign; the GLS under the true noise model (oracle) reaches the same errors, so the error is the statistical limit at that amplitude)\n")
rows <- list()
for (g in names(gen)) for (s in seeds) {
  x <- gen[[g]](5e5, 100 + s)
  ctl <- detect_series_effects(x, freq, kinds = c("spikes", "warmup"))$table
  for (f in fracs) {
    set.seed(s)
    rows[[length(rows) + 1L]] <- cbind(noise = g, seed = s, frac = f,
                                       control_found = sum(ctl$kind == "warmup"),
                                       warmup_case(x, f, s))
  }
}
sim <- do.call(rbind, rows)
print(sim, row.names = FALSE)
cat(sprintf("simulated: named %d/%d, |tc error| <= 25%% in %d/%d, median |err| %.3f, max %.3f\n",
            sum(sim$found > 0), nrow(sim), sum(abs(sim$err) <= 0.25, na.rm = TRUE), nrow(sim),
            stats::median(abs(sim$err), na.rm = TRUE), max(abs(sim$err), na.rm = TRUE)))

files <- file.path(data_dir, sprintf("adis16405_unit%d.rds", 1:3))
if (all(file.exists(files))) {
  cat("\n== warm-up added to the measured ADIS16405 axes (1e6 samples, 10000 s)\n")
  rows <- list()
  units <- if (quick) 1L else 1:3
  for (u in units) {
    m <- readRDS(files[u])
    for (ax in colnames(m)) {
      x <- m[, ax]
      ctl <- detect_series_effects(x, freq, kinds = c("spikes", "warmup"))$table
      own <- ctl[ctl$kind == "warmup", ]
      for (f in fracs) {
        set.seed(u * 10 + match(ax, colnames(m)))
        rows[[length(rows) + 1L]] <- cbind(unit = u, axis = ax, frac = f,
                                           own_tc = if (nrow(own)) paste(signif(own$tc, 3), collapse = ",") else "-",
                                           warmup_case(x, f, u))
      }
    }
  }
  real <- do.call(rbind, rows)
  print(real, row.names = FALSE)
  cat(sprintf("measured: named %d/%d, |tc error| <= 25%% in %d/%d, median |err| %.3f\n",
              sum(real$found > 0), nrow(real), sum(abs(real$err) <= 0.25, na.rm = TRUE),
              nrow(real), stats::median(abs(real$err), na.rm = TRUE)))

  cat("\n== spike counts: as recorded, + a Gauss-Markov of tc 20 s (ADEV(20 s) about +45%), + a 1.7 Hz line, + white raising the robust scale 2%\n")
  ns <- asNamespace("allanvar")
  rows <- list()
  for (u in units) {
    m <- readRDS(files[u])
    for (ax in colnames(m)) {
      x <- m[, ax]
      n <- length(x)
      t <- (seq_len(n) - 1) / freq
      set.seed(u)
      phi <- exp(-1 / (freq * 20))
      gm <- as.numeric(stats::filter(rnorm(n, sd = sqrt(1 - phi^2)), phi, method = "recursive")) *
        1.1 * allan(x, freq, taus = I(20))$adev
      r <- x - stats::runmed(x, 7)
      s0 <- ns$robust_scale(r)
      cnt <- vapply(list(x, x + gm, x + 0.5 * s0 * sin(2 * pi * 1.7 * t),
                         x + rnorm(n, sd = 0.2 * s0)),
                    function(y) nrow(ns$detect_spikes(y, freq)), 0L)
      se <- detect_series_effects(x, freq, kinds = "spikes")
      nb <- se$reading_bias
      rows[[length(rows) + 1L]] <- data.frame(unit = u, axis = ax, as_is = cnt[1],
        plus_gm = cnt[2], plus_line = cnt[3], plus_2pc = cnt[4],
        N_change_if_left = if (nrow(nb)) round(nb$bias_change[nb$term == "N"][1], 4) else 0)
    }
  }
  print(do.call(rbind, rows), row.names = FALSE)
}

cat("\n== spikes in Gaussian noise of several colours (1e6 samples, no spike added)\n")
flicker <- function(n) {
  f <- c(0, 1 / sqrt(seq_len(n / 2)))
  sp <- f * exp(2i * pi * runif(n / 2 + 1))
  y <- Re(stats::fft(c(sp, Conj(rev(sp[2:(n / 2)]))), inverse = TRUE))
  y / sd(y)
}
rows <- list()
for (s in if (quick) 1:2 else 1:5) {
  set.seed(900 + s)
  w <- rnorm(1e6)
  cs <- list(white = w, iir_0.9 = as.numeric(stats::filter(w, 0.9, method = "recursive")),
             iir2 = as.numeric(stats::filter(w, c(1.6, -0.7), method = "recursive")),
             fir4 = as.numeric(stats::filter(w, rep(0.25, 4), sides = 1))[-(1:3)],
             rw = 0.1 * w + cumsum(rnorm(1e6, sd = 1e-3)), flicker = w + 3 * flicker(1e6),
             quantized = round(w / 0.8) * 0.8)
  rows[[s]] <- as.data.frame(c(seed = s, lapply(cs, function(x)
    nrow(asNamespace("allanvar")$detect_spikes(x, freq)))))
}
print(do.call(rbind, rows), row.names = FALSE)
