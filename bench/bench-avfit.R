# Timings of the noise-model fit, the closed loop and the white-noise
# covariance kernel. Measures the installed package (compiled -O2;
# pkgload::load_all() builds with -O0, which is several times slower for
# Eigen code):
#   R CMD INSTALL . && Rscript bench/bench-avfit.R
# ALLANVAR_LIB=<library> measures the allanvar installed there instead (to
# compare two versions in one session of the machine).
# Prints one row per case: what was timed, the size, the median elapsed
# seconds over `reps` runs (2 threads at most) and the ratio to R's sum(x)
# on a vector of 1e6 doubles timed in the same run.
lib <- Sys.getenv("ALLANVAR_LIB")
if (nzchar(lib)) library(allanvar, lib.loc = lib) else library(allanvar)
cat("allanvar", format(utils::packageVersion("allanvar")), "from",
    dirname(system.file(package = "allanvar")), "\n")
avar_white_cov <- allanvar:::avar_white_cov
options(allanvar.threads = 2L)
reps <- 3L
time_it <- function(expr) {
  e <- substitute(expr)
  env <- parent.frame()
  median(vapply(seq_len(reps), function(i) system.time(eval(e, env))[["elapsed"]], 0))
}
rows <- list()
add <- function(case, size, sec) {
  rows[[length(rows) + 1L]] <<- data.frame(case = case, size = size,
                                           seconds = signif(sec, 3))
}
y <- rnorm(1e6)
yard <- median(vapply(1:50, function(i) system.time(for (k in 1:20) sum(y))[["elapsed"]] / 20, 0))
add("sum(x) (yardstick)", "n=1e6", yard)
f <- 100
for (n in c(1e5, 1e6)) {
  m_oct <- 2^(0:floor(log2(n / 3)))
  m_dense <- unique(round(10^seq(0, log10(n / 3), by = 0.05)))
  for (ov in c(TRUE, FALSE)) {
    add(sprintf("white covariance, %s, octave", if (ov) "overlapping" else "non-overlapping"),
        sprintf("n=%g, %d taus", n, length(m_oct)),
        time_it(avar_white_cov(m_oct, n, ov, 2L)))
    add(sprintf("white covariance, %s, 20/decade", if (ov) "overlapping" else "non-overlapping"),
        sprintf("n=%g, %d taus", n, length(m_dense)),
        time_it(avar_white_cov(m_dense, n, ov, 2L)))
  }
}
n <- 2^18
x <- avsim(n, f, N = 0.01, B = 0.002, K = 1e-4,
           gm = data.frame(sigma = c(0.01, 0.004), tc = c(0.5, 40)),
           sinusoid = list(amp = 0.01, f0 = 1.3), seed = 1)
a <- allan(x, f)
for (tm in list(c("N", "B", "K"), c("N", "B", "K", "gm"), c("N", "gm", "gm"),
                c("N", "B", "sinusoid"), c("N", "B", "K", "gm", "gm", "sinusoid"))) {
  add(paste("avfit", paste(tm, collapse = "+")), sprintf("%d taus", nrow(a)),
      time_it(avfit(a, tm)))
  add(paste("avfit", paste(tm, collapse = "+"), "correlation = TRUE"),
      sprintf("%d taus", nrow(a)), time_it(avfit(a, tm, correlation = TRUE)))
}
# A 9,999-tau table (allan_variance_ros's grid): the points are weighed as
# independent (the whitening kept as its diagonal), so no 10k x 10k matrix
# is formed; issue 9 asks <= 1 s. The curve: N + B + K + a GM (sigma 0.004,
# Tc 5 s; continuous-time AV formula) with chi-square(50) scatter.
tau_ros <- 10^seq(-2, 3, length.out = 9999)
set.seed(2)
av_ros <- (0.01^2 / tau_ros + 2 * log(2) / pi * 0.002^2 + 1e-4^2 * tau_ros / 3 +
             0.004^2 * 10 / tau_ros * (1 - 2.5 / tau_ros * (3 - 4 * exp(-tau_ros / 5) + exp(-2 * tau_ros / 5)))) *
  stats::rchisq(length(tau_ros), 50) / 50
tab_ros <- data.frame(tau = tau_ros, avar = av_ros)
for (tm in list(c("N", "B", "K"), c("N", "B", "K", "gm"))) {
  add(paste("avfit", paste(tm, collapse = "+"), "(table)"), "9999 taus",
      time_it(avfit(tab_ros, tm, n = 1e8, freq = 100)))
}
fit <- avfit(a, c("N", "B", "K"))
add("avrefine (curve only), from N+B+K", sprintf("%d taus", nrow(a)),
    time_it(avrefine(fit)))
add("avrefine with the raw series, from N+B+K", sprintf("%d taus, n=%d", nrow(a), n),
    time_it(avrefine(fit, data = x)))
out <- do.call(rbind, rows)
out$x_sum <- signif(out$seconds / yard, 3)
print(out, row.names = FALSE)
