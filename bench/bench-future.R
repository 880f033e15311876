# When does a parallel `future` plan pay for analyze_imu()? Per-axis cost
# against worker start-up, measured: the same 6-axis record (two files of
# 3 axes) analysed sequentially and with 2 multisession / multicore
# workers, without and with the refinement loop, plus the start-up of a
# multisession plan alone. Prints one table with medians.
#
# Run from the repository root (the package installed):
#   Rscript bench/bench-future.R [n] [reps]
# n samples per axis (default 2e5 at 100 Hz), reps repetitions (default 3).
library(allanvar)
args <- commandArgs(TRUE)
n <- if (length(args) >= 1L) as.numeric(args[1L]) else 2e5
reps <- if (length(args) >= 2L) as.integer(args[2L]) else 3L
freq <- 100
options(allanvar.threads = 1L)

# Two static 3-axis records: white noise + random walk + a Gauss-Markov
# term, generated here with base R.
gen <- function(seed) {
  set.seed(seed)
  phi <- exp(-1 / (freq * 20))
  m <- vapply(1:3, function(k) {
    gm <- as.numeric(stats::filter(rnorm(n, sd = 2e-4 * sqrt(1 - phi^2)), phi,
                                   method = "recursive"))
    rnorm(n, sd = 0.005) + cumsum(rnorm(n, sd = 2e-6)) + gm
  }, numeric(n))
  colnames(m) <- c("gyro_x", "gyro_y", "gyro_z")
  imu_record(m, freq = freq, units = c(gyro = "rad/s"), name = paste0("record", seed))
}
recs <- list(a = gen(1), b = gen(2))

time_med <- function(f) {
  stats::median(vapply(seq_len(reps), function(i) {
    gc(FALSE)
    system.time(f())[["elapsed"]]
  }, 0))
}
run <- function(refine) {
  function() suppressWarnings(analyze_imu(recs, refine = refine, progress = FALSE))
}
rows <- list()
add <- function(task, plan, s) {
  rows[[length(rows) + 1L]] <<- data.frame(task = task, plan = plan, median_s = s)
  message(sprintf("%-40s %-22s %8.3f s", task, plan, s))
}
x <- rnorm(6 * n)
add("sum(x) on the same amount of data", "", time_med(function() sum(x)))
plans <- list(
  "sequential" = function() future::plan(future::sequential),
  "multisession, 2 workers" = function() future::plan(future::multisession, workers = 2L),
  "multicore, 2 workers" = function() future::plan(future::multicore, workers = 2L))
# Start-up of the workers alone: plan() and one trivial future.
add("start 2 multisession workers + 1 future", "", time_med(function() {
  future::plan(future::multisession, workers = 2L)
  future::value(future::future(1))
  future::plan(future::sequential)
}))
for (refine in c(FALSE, TRUE)) {
  task <- sprintf("analyze_imu(), 6 axes, refine = %s", refine)
  for (p in names(plans)) {
    plans[[p]]()
    invisible(run(refine)())  # warm: workers started, package loaded
    add(task, p, time_med(run(refine)))
  }
  future::plan(future::sequential)
}
tab <- do.call(rbind, rows)
seq_t <- ifelse(grepl("^analyze", tab$task),
                tab$median_s[match(paste(tab$task, "sequential"),
                                   paste(tab$task, tab$plan))], NA)
tab$speedup <- round(seq_t / tab$median_s, 2)
tab$median_s <- signif(tab$median_s, 3)
cat(sprintf("\nn = %g samples per axis, 6 axes in 2 records, %d reps\n", n, reps))
cat(sprintf("Machine: %s, %d cores, load average at the end: %s\n", R.version$platform,
            parallel::detectCores(), readLines("/proc/loadavg", warn = FALSE)))
print(tab, row.names = FALSE, right = FALSE)
