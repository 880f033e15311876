# Monte Carlo EDF of the Hadamard total variance (HTOT, NIST SP 1065 sec.
# 5.2.14) under white and flicker PM, where Howe et al. (2000) publish
# none, and the fit of the approximation extra_edf_known() uses for them
# (R/allan-types.R). As Howe et al. derived their Table 1 for the FM noises:
# the EDF of each (N, m) is 2 E[v]^2 / Var[v] of the uncorrected HTOT
# variance v over `reps` independent series (HTOT has no bias correction
# under PM). Own generators, not the package's simulator avsim() (the same
# as tools/mc-coverage.R's): white PM = diff(rnorm(N + 1)); flicker PM =
# diff of flicker phase by Kasdin & Walter's fractional integration
# (h_k = h_{k-1} (k - 1.5)/(k - 1), applied by FFT). N is the number of
# frequency values, m = 2, 4, ..., N/4.
#
#   Rscript tools/htot-pm-edf.R [reps] [sizes] [seed] [fit|check|tail|tailcheck]
#   fit   (default 4000 512,2048,4096,8192 1065): the Monte Carlo EDFs and
#         the least-squares fit (in log EDF) of the forms below;
#   check (e.g. 4000 256,1024 7 check): the Monte Carlo EDFs against the
#         installed package's extra_edf("htotdev", ..., alpha = 2, 1);
#   tail  (2000 512,2048 1066 tail): the same at the last taus (m from N/4
#         to (N - 1)/3) and the fit of the factor there (see below);
#   tailcheck (2000 256,1024 12 tailcheck): those taus against the package.
# Run with the package installed (library(allanvar)); one thread. The
# coefficients, their fit errors and the checks' ratios are quoted where
# they are used, in extra_edf_known(). A few minutes for `fit` at 4000
# replicates.

htot_pm_generators <- function(N) {
  n <- N + 1
  h <- numeric(n)
  h[1] <- 1
  for (k in 2:n) h[k] <- h[k - 1] * (k - 1.5) / (k - 1)
  fh <- stats::fft(c(h, rep(0, n)))
  flicker <- function() {
    Re(stats::fft(fh * stats::fft(c(stats::rnorm(n), rep(0, n))),
                  inverse = TRUE))[1:n] / (2 * n)
  }
  list(wpm = function() diff(stats::rnorm(n)),
       fpm = function() diff(flicker()))
}

# Monte Carlo EDF of the uncorrected HTOT variance by noise, N and m, at
# the m that grid(N) gives.
htot_pm_run <- function(reps, sizes, grid) {
  out <- list()
  for (N in sizes) {
    gens <- htot_pm_generators(N)
    m <- grid(N)
    for (noise in names(gens)) {
      v <- vapply(seq_len(reps), function(i) {
        allanvar::allan(gens[[noise]](), 1, taus = I(m), type = "htotdev",
                        debias = FALSE)$avar
      }, numeric(length(m)))
      edf <- 2 * rowMeans(v)^2 / apply(v, 1, stats::var)
      out[[length(out) + 1L]] <- data.frame(noise = noise, N = N, m = m,
                                            N_over_m = N / m, edf = edf)
    }
  }
  do.call(rbind, out)
}

# octave m up to N/4
htot_pm_mc <- function(reps, sizes) {
  htot_pm_run(reps, sizes, function(N) 2^(1:floor(log2(N / 4))))
}

# The forms, in N (frequency values) and m; both fall as (1 + b m/N) at
# long tau, as Howe et al.'s FM rows do:
#  * white PM: nearly proportional to N (a phase point enters few terms
#    whatever m): N / (b0 + b1/m + b2 m/N);
#  * flicker PM: (N/m) (b0 + b1 ln m)^2 / (1 + b2 m/N) (flicker phase
#    spreads the estimator's power evenly over the ln m octaves between 1/m
#    and the Nyquist frequency: (sum of power)^2 / (sum of squared power)
#    ~ (ln m)^2 / m per sample).
htot_pm_forms <- list(
  wpm = list(f = log(edf) ~ log(N / (b0 + b1 / m + b2 * m / N)),
             start = list(b0 = 1.3, b1 = 0.6, b2 = 1)),
  fpm = list(f = log(edf) ~ log(N / m * (b0 + b1 * log(m))^2 / (1 + b2 * m / N)),
             start = list(b0 = 0.7, b1 = 0.55, b2 = 1)))

# Least squares in log EDF (relative error) of each form.
htot_pm_fit <- function(d) {
  lapply(names(htot_pm_forms), function(noise) {
    x <- d[d$noise == noise, ]
    fit <- stats::nls(htot_pm_forms[[noise]]$f, x,
                      start = htot_pm_forms[[noise]]$start)
    r <- stats::residuals(fit)
    list(noise = noise, coef = stats::coef(fit), rms = sqrt(mean(r^2)),
         max = max(abs(r)), resid = cbind(x[, c("N", "m")], log_ratio = r))
  })
}

# The last taus, m up to (N - 1)/3: as the number of terms n = N + 1 - 3m
# falls to a few, nearly the same data enter every window and the EDF drops
# below the forms (at n = 2, N = 1024: 53 for white PM where they give 595,
# 16 for flicker PM for 34). The ratio of the Monte Carlo EDF to the form is
# close to a function of x = n/N alone (N = 256 and 1024 agree): white PM
# 1 - exp(-x/x0), flicker PM min(1, (x/x1)^p). `tail` mode fits x0, x1, p
# at n = 2, 4, 8, ... up to N/4, against the forms with the coefficients of
# `fit` mode (htot_pm_main).
htot_pm_main <- function(noise, N, m) {
  if (noise == "wpm") {
    N / (1.337 + 0.621 / m + 1.152 * m / N)
  } else {
    N / m * (0.713 + 0.5725 * log(m))^2 / (1 + 1.344 * m / N)
  }
}

# m from N/4 up, where n = N + 1 - 3m is 2, 4, 8, ...
htot_pm_tail_mc <- function(reps, sizes) {
  htot_pm_run(reps, sizes, function(N) {
    n <- 2^(1:floor(log2(N / 4)))
    m <- sort(unique(floor((N + 1 - n) / 3)))
    m[m >= N / 4]
  })
}

htot_pm_tail_fit <- function(d) {
  d$x <- (d$N + 1 - 3 * d$m) / d$N
  d$r <- log(d$edf / vapply(seq_len(nrow(d)), function(i) {
    htot_pm_main(d$noise[i], d$N[i], d$m[i])
  }, 0))
  w <- d[d$noise == "wpm", ]
  f <- d[d$noise == "fpm", ]
  fw <- stats::nls(r ~ log(1 - exp(-x / x0)), w, start = list(x0 = 0.02))
  # flicker PM: a line in log x below x = 0.1 (where the ratio is below 1)
  ff <- stats::lm(r ~ log(x), f[f$x < 0.1, ])
  p <- unname(stats::coef(ff)[2])
  x1 <- exp(-unname(stats::coef(ff)[1]) / p)
  rf <- f$r - log(pmin(1, (f$x / x1)^p))
  rw <- stats::residuals(fw)
  list(wpm = list(coef = stats::coef(fw), rms = sqrt(mean(rw^2)),
                  max = max(abs(rw))),
       fpm = list(coef = c(x1 = x1, p = p), rms = sqrt(mean(rf^2)),
                  max = max(abs(rf))))
}

if (sys.nframe() == 0L) {
  args <- commandArgs(TRUE)
  reps <- if (length(args) >= 1) as.integer(args[1]) else 4000L
  sizes <- if (length(args) >= 2) as.integer(strsplit(args[2], ",")[[1]]) else
    c(512L, 2048L, 4096L, 8192L)
  seed <- if (length(args) >= 3) as.integer(args[3]) else 1065L
  mode <- if (length(args) >= 4) args[4] else "fit"
  suppressMessages(library(allanvar))
  options(allanvar.threads = 1)
  set.seed(seed)
  # HTOT_PM_DATA: a table saved by an earlier run (HTOT_PM_SAVE), to refit
  # without simulating again
  d <- if (nzchar(Sys.getenv("HTOT_PM_DATA"))) {
    readRDS(Sys.getenv("HTOT_PM_DATA"))
  } else if (mode %in% c("tail", "tailcheck")) {
    htot_pm_tail_mc(reps, sizes)
  } else {
    htot_pm_mc(reps, sizes)
  }
  if (nzchar(Sys.getenv("HTOT_PM_SAVE"))) saveRDS(d, Sys.getenv("HTOT_PM_SAVE"))
  ns <- asNamespace("allanvar")
  d$edf_pkg <- vapply(seq_len(nrow(d)), function(i) {
    ns$extra_edf("htotdev", d$m[i], d$N[i] + 1,
                 c(wpm = 2L, fpm = 1L)[[d$noise[i]]], d$N[i] + 1 - 3 * d$m[i])
  }, 0)
  d$ratio <- d$edf_pkg / d$edf
  print(d, digits = 4, row.names = FALSE)
  for (noise in unique(d$noise)) {
    r <- log(d$ratio[d$noise == noise])
    cat(sprintf("%s: package EDF / Monte Carlo EDF %.3f-%.3f, rms log ratio %.3f\n",
                noise, exp(min(r)), exp(max(r)), sqrt(mean(r^2))))
  }
  if (mode == "tail") {
    for (nm in c("wpm", "fpm")) {
      f <- htot_pm_tail_fit(d)[[nm]]
      cat(sprintf("%s tail fit: %s; rms log error %.3f, max %.3f\n", nm,
                  paste(names(f$coef), signif(f$coef, 3), sep = " = ",
                        collapse = ", "), f$rms, f$max))
    }
  }
  if (mode == "fit") {
    for (f in htot_pm_fit(d)) {
      cat(sprintf("%s fit: %s; rms log error %.3f, max %.3f\n", f$noise,
                  paste(names(f$coef), signif(f$coef, 4), sep = " = ",
                        collapse = ", "), f$rms, f$max))
    }
  }
}
