# What one tau of the Total family and of Theo1 costs at 1e6 samples, next
# to R's sum(x) on the same data: the steady-state kernel time of each
# octave m on one thread (a call holding m twice less a call holding it
# once, so the call's set-up and fresh memory are left out), and the whole
# octave call on one and two threads. It shows where the time of
# allan(type = "mtotdev") and allan(type = "theo1") goes, tau by tau.
#
# Run from the repository root:  Rscript bench/bench-per-tau.R [N]
source(file.path("bench", "common.R"))
lib <- bench_install()
ns <- asNamespace("allanvar")

args <- commandArgs(TRUE)
N <- if (length(args) >= 1) as.numeric(args[1]) else 1e6
set.seed(1)
x <- rnorm(N)
s <- timed(sum(x), reps = 51)

# median over `reps` of (one call with m twice) - (one call with m once)
steady <- function(f, m, reps = 5) {
  one <- timed(f(m), reps = reps)
  two <- timed(f(c(m, m)), reps = reps)
  max(two - one, 0)
}
mtot <- function(m, threads = 1L) ns$total_sums_cpp(x, TRUE, m, FALSE, threads)
theo <- function(m, threads = 1L) ns$theo1_sums_cpp(x, TRUE, m, threads)

mt <- 2^(0:floor(log2(N / 3)))
th <- 2^(1:floor(log2(N - 1)))
rows <- rbind(
  data.frame(statistic = "MTOT", m = mt,
             seconds = vapply(mt, function(m) steady(mtot, m), 0),
             windows = N + 1 - 3 * mt + 1),
  data.frame(statistic = "Theo1", m = th,
             seconds = vapply(th, function(m) steady(theo, m), 0),
             windows = N + 1 - th))
rows$ns_per_window <- signif(1e9 * rows$seconds / rows$windows, 3)
rows$x_sum <- round(rows$seconds / s, 1)
rows$seconds <- signif(rows$seconds, 3)
whole <- data.frame(
  statistic = rep(c("MTOT", "Theo1"), each = 2), threads = rep(1:2, 2),
  seconds = c(timed(mtot(mt, 1L), reps = 3), timed(mtot(mt, 2L), reps = 3),
              timed(theo(th, 1L), reps = 3), timed(theo(th, 2L), reps = 3)))
whole$x_sum <- round(whole$seconds / s, 1)
whole$seconds <- signif(whole$seconds, 3)

cat(sprintf("bench-per-tau: %s, N = %g, sum(x) %.3g ms, load %s\n",
            format(Sys.time(), "%Y-%m-%d %H:%M %Z"), N, 1e3 * s,
            if (file.exists("/proc/loadavg")) {
              paste(utils::head(strsplit(readLines("/proc/loadavg"), " ")[[1]], 3),
                    collapse = " ")
            } else "?"))
cat("Each octave m alone, one thread, steady state (set-up excluded):\n")
print(rows, row.names = FALSE)
cat("sum over the octave m: MTOT", signif(sum(rows$seconds[rows$statistic == "MTOT"]), 3),
    "s, Theo1", signif(sum(rows$seconds[rows$statistic == "Theo1"]), 3), "s\n")
cat("The whole octave call (set-up and fresh memory included):\n")
print(whole, row.names = FALSE)
