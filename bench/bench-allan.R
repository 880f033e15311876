# Speed of allan() against R's own sum(x) on the same data, in one run.
#
# Run from the repository root:  Rscript bench/bench-allan.R
# It installs the package into a temporary library first (pkgload would
# compile without optimisation). Optional comparisons, skipped when absent:
#   the CRAN original allanvar 1.1 in /tmp/origlib (run in a separate process),
#   the CRAN package avar in /tmp/avarlib.
# Prints a table of median elapsed times and ratios; takes a few minutes.

source(file.path("bench", "common.R"))
lib <- bench_install()

rows <- list()
add <- function(task, N, seconds, base = NA_real_, target = NA_character_, reps = 5) {
  rows[[length(rows) + 1L]] <<- data.frame(
    task = task, N = format(N, scientific = TRUE), median_s = signif(seconds, 3),
    ratio_to_sum = if (is.na(base)) NA_real_ else round(seconds / base, 1),
    target = target, reps = reps)
}

options(allanvar.threads = 2)
set.seed(1)
x7 <- rnorm(1e7)
x6 <- x7[1:1e6]

first <- system.time(allan(x7, 1))[["elapsed"]]  # first call in this process
sum7 <- timed(sum(x7), 21)
sum6 <- timed(sum(x6), 51)
add("sum(x)", 1e7, sum7, sum7, reps = 21)
add("sum(x)", 1e6, sum6, sum6, reps = 51)
add("allan standard, octave", 1e7, timed(allan(x7, 1, type = "standard")), sum7, "<= 3")
add("allan overlapping, octave", 1e7, timed(allan(x7, 1)), sum7, "<= 10")
add("allan overlapping, octave (first call)", 1e7, first, sum7, reps = 1)
options(allanvar.threads = 1)
add("allan overlapping, octave, 1 thread", 1e7, timed(allan(x7, 1)), sum7)
options(allanvar.threads = 2)
add("allan standard, all m", 1e6, timed(allan(x6, 1, type = "standard", taus = "all"), 3),
    sum6, "<= 100", reps = 3)
add("allan modified, octave", 1e6, timed(allan(x6, 1, type = "modified"), 3), sum6, reps = 3)
add("allan hadamard, octave", 1e6, timed(allan(x6, 1, type = "hadamard"), 3), sum6, reps = 3)
add("allan ohadamard, octave", 1e6, timed(allan(x6, 1, type = "ohadamard"), 3), sum6, reps = 3)
add("allan total, octave", 1e6, timed(allan(x6, 1, type = "total"), 3), sum6, reps = 3)
add("avar() (exact 1.1 results)", 1e7, timed(avar(x7, 1), 3), sum7, reps = 3)
add("avarn(exact = FALSE)", 1e6, timed(avarn(x6, 1, exact = FALSE), 3), sum6, reps = 3)

# six channels of 1e6 samples: one thread against two
x66 <- matrix(rnorm(6e6), ncol = 6)
sum66 <- timed(sum(x66), 21)
options(allanvar.threads = 1)
t1 <- timed(allan(x66, 100), 3)
options(allanvar.threads = 2)
t2 <- timed(allan(x66, 100), 3)
cpu <- system.time(allan(x66, 100))
add("sum(x), 6 x 1e6 matrix", 6e6, sum66, sum66, reps = 21)
add("allan overlapping, 6 channels, 1 thread", 6e6, t1, sum66, reps = 3)
add("allan overlapping, 6 channels, 2 threads", 6e6, t2, sum66, reps = 3)

# the CRAN original, in its own process (it prints "Calculating...")
if (dir.exists("/tmp/origlib/allanvar") && requireNamespace("callr", quietly = TRUE)) {
  orig <- callr::r(function(n) {
    library(allanvar, lib.loc = "/tmp/origlib")
    set.seed(1)
    x <- rnorm(n)
    th <- cumsum(x) / 100
    c(avar = system.time(utils::capture.output(avar(x, 100)))[["elapsed"]],
      avari = system.time(utils::capture.output(avari(th, 100)))[["elapsed"]])
  }, args = list(n = 1e6))
  add("original allanvar 1.1 avar()", 1e6, orig[["avar"]], sum6, reps = 1)
  add("original allanvar 1.1 avari()", 1e6, orig[["avari"]], sum6, reps = 1)
  add("allan standard, octave (vs original avar)", 1e6,
      timed(allan(x6, 100, type = "standard")), sum6)
  th6 <- cumsum(x6) / 100
  add("allan overlapping integrated (vs original avari)", 1e6,
      timed(allan(th6, 100, input = "integrated")), sum6)
}

# CRAN avar (SMAC-Group): maximal-overlap AV, O(N^2)
if (requireNamespace("avar", lib.loc = "/tmp/avarlib", quietly = TRUE) ||
    dir.exists("/tmp/avarlib/avar")) {
  res <- callr::r(function(ns) {
    library(avar, lib.loc = "/tmp/avarlib")
    set.seed(1)
    vapply(ns, function(n) {
      x <- rnorm(n)
      system.time(avar::avar(x, type = "mo"))[["elapsed"]]
    }, 0)
  }, args = list(ns = c(1e4, 1e5)))
  for (i in 1:2) {
    n <- c(1e4, 1e5)[i]
    xs <- x7[seq_len(n)]
    add("CRAN avar, maximal overlap", n, res[i], timed(sum(xs), 51), reps = 1)
    add("allan overlapping, octave (same N)", n, timed(allan(xs, 1), 11),
        timed(sum(xs), 51), reps = 11)
  }
}

tab <- do.call(rbind, rows)
print(tab, row.names = FALSE)
cat(sprintf("\nsix channels: 2 threads %.2fx faster than 1; CPU/elapsed with 2 threads = %.2f\n",
            t1 / t2, (cpu[["user.self"]] + cpu[["sys.self"]]) / cpu[["elapsed"]]))
cat("machine:", utils::sessionInfo()$running, "|", parallel::detectCores(), "cores | load",
    tryCatch(readLines("/proc/loadavg"), error = function(e) "?"), "\n")
