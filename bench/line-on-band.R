# A sharp line in a resonance's reach (on its flank or in its
# background), own generator: white noise (sd 0.01), an AR(2) resonance
# (sd 0.01 x `res_sd`) at fr with damping time tc, and a line of amplitude
# `amp` at f0; 3e5 samples at 100 Hz. Each case runs the loop as
# analyze_imu() does per axis (avfit N, B, K; avrefine with the raw
# series), with and without the line, and prints: the line named (a
# sinusoid within 1% of f0), the resonance's centre and tc, and N against
# the run without the line.
#   R_LIBS=/tmp/lib Rscript bench/line-on-band.R
suppressPackageStartupMessages(library(allanvar))
options(allanvar.threads = 1L)
freq <- 100
n <- 3e5
ar2 <- function(fr, tc) {
  r <- exp(-1 / (freq * tc))
  z <- as.numeric(stats::filter(rnorm(n + 2000), c(2 * r * cos(2 * pi * fr / freq), -r^2),
                                method = "recursive"))[-(1:2000)]
  z / sd(z)
}
loop <- function(x) {
  f <- avfit(allan(x, freq), terms = c("N", "B", "K"))
  suppressWarnings(suppressMessages(avrefine(f, data = x)))
}
cases <- expand.grid(seed = 1:3, f0_rel = c(0.88, 0.94, 1.07, 1.15), amp = c(0.004, 0.007),
                     KEEP.OUT.ATTRS = FALSE)
rows <- list()
for (i in seq_len(nrow(cases))) {
  cs <- cases[i, ]
  set.seed(100 * cs$seed + i)
  fr <- round(stats::runif(1, 6, 20), 2)
  tc <- round(exp(stats::runif(1, log(0.25), log(0.8))), 2)
  f0 <- round(fr * cs$f0_rel, 2)
  b <- rnorm(n, sd = 0.01) + 0.01 * ar2(fr, tc)
  x <- b + cs$amp * sin(2 * pi * f0 * seq_len(n) / freq + stats::runif(1, 0, 2 * pi))
  rb <- loop(b)
  t0 <- proc.time()[["elapsed"]]
  rx <- loop(x)
  sec <- proc.time()[["elapsed"]] - t0
  cf <- coef(rx)
  fs <- cf[grepl("^sinusoid[0-9]+\\.f0$", names(cf))]
  rc <- cf[grepl("^resonance[0-9]+\\.fr$", names(cf))]
  j <- if (length(rc)) which.min(abs(rc - fr)) else NA
  nx <- unname(cf["N"])
  nb <- unname(coef(rb)["N"])
  rows[[i]] <- data.frame(
    fr = fr, tc = tc, f0 = f0, amp = cs$amp,
    named = any(abs(fs / f0 - 1) < 0.01),
    fr_fit = if (is.na(j)) NA else signif(rc[j], 4),
    tc_fit = if (is.na(j)) NA else signif(cf[sub("fr$", "tc", names(rc)[j])], 3),
    N_change = if (is.na(nx) || is.na(nb)) NA else round(100 * (nx / nb - 1), 1),
    terms = paste(rx$terms, collapse = " "),
    base = paste(rb$terms, collapse = " "),
    sec = round(sec, 1))
  print(rows[[i]], row.names = FALSE)
}
out <- do.call(rbind, rows)
cat("\nline named:", sum(out$named), "/", nrow(out),
    "| resonance centre within 1%:", sum(abs(out$fr_fit / out$fr - 1) <= 0.01, na.rm = TRUE),
    "| tc within 15%:", sum(abs(out$tc_fit / out$tc - 1) <= 0.15, na.rm = TRUE),
    "| N within 1% of the run without the line:", sum(abs(out$N_change) <= 1, na.rm = TRUE),
    "| median seconds", stats::median(out$sec), "\n")
