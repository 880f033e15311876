# Which limits should a "measured" verdict hold the model to? On records of
# our own generator where the declared model is the truth (white N + random
# walk K, and N + flicker B + K, rad/s at 100 Hz), every reading of the
# full analysis (analyze_imu(), the loop on) is checked three ways over the
# taus it rests on: the package's verdict (the curve's limits jointly at
# 95% over the range, R/verdicts.R), and the curve's own limits point by
# point at 68% and at 95% (each +2%). A rule that calls correct readings
# bounds tells the user less than the data do; the table shows how often
# each rule rejects the final model of a true-model record, with the
# reading's median error against the truth.
#
#   Rscript bench/verdict-level.R [seeds] [n]     (defaults 20, 2e5)
source("bench/common.R")
bench_install()
ns <- asNamespace("allanvar")
options(allanvar.threads = 1L, width = 160)
args <- commandArgs(TRUE)
seeds <- if (length(args) >= 1) as.integer(args[1]) else 20L
n <- if (length(args) >= 2) as.numeric(args[2]) else 2e5
f <- 100
truth <- list(NK = c(N = 1e-3, B = 0, K = 2e-5), NBK = c(N = 1e-3, B = 1e-4, K = 2e-5))

# Flicker rate noise: white noise shaped by 1/sqrt(|k|) in the frequency
# domain (PSD ~ 1/f), scaled so that its ADEV floor is 0.664 B (IEEE 952:
# sqrt(2 ln 2 / pi) B), measured on its own curve between 1 s and a
# twentieth of the record.
flicker <- function(n, B, seed) {
  set.seed(seed)
  m <- 2 * n
  k <- c(0:(m / 2), -((m / 2 - 1):1))
  h <- ifelse(k == 0, 0, 1 / sqrt(abs(k)))
  x <- Re(stats::fft(stats::fft(stats::rnorm(m)) * h, inverse = TRUE))[1:n]
  a <- allan(x, freq = f, taus = "octave", ci = FALSE)
  floor <- stats::median(a$adev[a$tau > 1 & a$tau < n / f / 20])
  x * sqrt(2 * log(2) / pi) * B / floor
}
series <- function(p, seed) {
  set.seed(seed)
  x <- p[["N"]] * sqrt(f) * stats::rnorm(n) + cumsum(p[["K"]] / sqrt(f) * stats::rnorm(n))
  if (p[["B"]] > 0) x <- x + flicker(n, p[["B"]], seed + 1e6)
  x
}

rows <- list()
for (model in names(truth)) for (s in seq_len(seeds)) {
  p <- truth[[model]]
  X <- sapply(1:3, function(j) series(p, 1000 * s + j))
  colnames(X) <- c("gyro_x", "gyro_y", "gyro_z")
  a <- suppressWarnings(suppressMessages(
    analyze_imu(imu_record(X, freq = f, units = "rad/s"), progress = FALSE)))
  for (ch in a$channels) {
    rd <- ch$readings
    cv <- ch$curve
    model_adev <- sqrt(ns$verdict_model(cv, ns$check_coef(ch$coef)))
    z <- stats::qnorm(0.975)
    for (i in seq_len(nrow(rd))) {
      if (!(rd$term[i] %in% names(p)) || p[[rd$term[i]]] == 0) next
      w <- which(cv$tau >= rd$tau_lo[i] & cv$tau <= rd$tau_hi[i] & is.finite(cv$lower))
      m <- model_adev[w]
      out68 <- any(m > cv$upper[w] * 1.02 | m < cv$lower[w] * 0.98)
      # 95% point by point from the 68% limits' log half-widths (chi-square
      # limits are close to log-symmetric at the EDFs involved)
      up95 <- cv$adev[w] * (cv$upper[w] / cv$adev[w])^z
      lo95 <- cv$adev[w] * (cv$lower[w] / cv$adev[w])^z
      out95 <- any(m > up95 * 1.02 | m < lo95 * 0.98)
      rows[[length(rows) + 1L]] <- data.frame(
        model = model, term = rd$term[i], measured = rd$verdict[i] == "measured",
        out68 = out68, out95 = out95, err = abs(rd$value[i] / p[[rd$term[i]]] - 1))
    }
  }
}
d <- do.call(rbind, rows)
tab <- do.call(rbind, lapply(split(d, list(d$model, d$term), drop = TRUE), function(g) {
  data.frame(model = g$model[1], term = g$term[1], readings = nrow(g),
             verdict_measured = round(100 * mean(g$measured), 1),
             pointwise68_rejects = round(100 * mean(g$out68), 1),
             pointwise95_rejects = round(100 * mean(g$out95), 1),
             median_err_pct = round(100 * stats::median(g$err), 2),
             median_err_rejected68_pct = if (any(g$out68)) round(100 * stats::median(g$err[g$out68]), 2) else NA)
}))
rownames(tab) <- NULL
cat(sprintf("allanvar %s, %d seeds x 3 axes, n = %g at %g Hz, %s, load %s\n",
            utils::packageVersion("allanvar"), seeds, n, f,
            format(Sys.time(), tz = "UTC", usetz = TRUE),
            paste(strsplit(readLines("/proc/loadavg"), " ")[[1]][1:3], collapse = " ")))
print(tab)
