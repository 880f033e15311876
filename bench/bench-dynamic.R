# Speed of dynamic_allan() (and groslambert()) against R's own sum(x) on the
# same data, in one run, and against the obvious alternative: allan() called
# on every window.
#
# Run from the repository root:  Rscript bench/bench-dynamic.R
# It installs the package into a temporary library first (pkgload would
# compile without optimisation). Prints a table of median elapsed times and
# ratios; takes about a minute.

source(file.path("bench", "common.R"))
lib <- bench_install()

rows <- list()
add <- function(task, N, seconds, base, reps) {
  rows[[length(rows) + 1L]] <<- data.frame(
    task = task, N = format(N, scientific = TRUE),
    median_s = signif(seconds, 3), ratio_to_sum = round(seconds / base, 1),
    reps = reps)
}

# allan() on every window of the same surface (the alternative)
per_window <- function(x, W, S, type = "overlapping") {
  starts <- seq(1, length(x) - W + 1, by = S)
  lapply(starts, function(s) allan(x[s:(s + W - 1)], freq = 1, type = type))
}

options(allanvar.threads = 2)
set.seed(1)
x <- rnorm(1e6)
s6 <- timed(sum(x), 51)
add("sum(x)", 1e6, s6, s6, 51)

d <- dynamic_allan(x, freq = 1, window = 1e5, step = 1e4)
stopifnot(length(d$time) == 91L, length(d$tau) == 16L)
add("dynamic_allan, window 1e5, step 1e4 (91 x 16)", 1e6,
    timed(dynamic_allan(x, freq = 1, window = 1e5, step = 1e4)), s6, 5)
options(allanvar.threads = 1)
add("  same, 1 thread", 1e6,
    timed(dynamic_allan(x, freq = 1, window = 1e5, step = 1e4)), s6, 5)
options(allanvar.threads = 2)
add("  same, alpha fixed (no slope noise id)", 1e6,
    timed(dynamic_allan(x, freq = 1, window = 1e5, step = 1e4, alpha = 0)),
    s6, 5)
add("allan() on each of the 91 windows", 1e6,
    timed(per_window(x, 1e5, 1e4), 3), s6, 3)
add("dynamic_allan, window 1e5, step 1e3 (901 x 16)", 1e6,
    timed(dynamic_allan(x, freq = 1, window = 1e5, step = 1e3)), s6, 5)
add("allan() on each of the 901 windows", 1e6,
    timed(per_window(x, 1e5, 1e3), 1), s6, 1)
add("dynamic_allan, window 1e4, step 100 (9901 x 13)", 1e6,
    timed(dynamic_allan(x, freq = 1, window = 1e4, step = 100), 3), s6, 3)
for (type in c("standard", "modified", "hadamard", "ohadamard")) {
  add(paste0("dynamic_allan ", type, ", window 1e5, step 1e4"), 1e6,
      timed(dynamic_allan(x, freq = 1, window = 1e5, step = 1e4,
                          type = type), 3), s6, 3)
}

x7 <- rnorm(1e7)
s7 <- timed(sum(x7), 21)
add("sum(x)", 1e7, s7, s7, 21)
add("dynamic_allan, window 1e6, step 1e5 (91 x 19)", 1e7,
    timed(dynamic_allan(x7, freq = 1, window = 1e6, step = 1e5), 3), s7, 3)

# three comparisons of 1e6 samples
y <- cbind("A-B" = x, "B-C" = x7[1:1e6], "C-A" = x7[1e6 + 1:1e6])
s3 <- timed(sum(y), 21)
add("sum(x), 1e6 x 3 comparisons", 3e6, s3, s3, 21)
add("three_cornered_hat, octave", 3e6,
    timed(three_cornered_hat(y, freq = 1), 3), s3, 3)
add("groslambert, octave", 3e6, timed(groslambert(y, freq = 1), 3), s3, 3)

out <- do.call(rbind, rows)
cat(sprintf("dynamic_allan() benchmark, %s, R %s, %s\n",
            format(Sys.time(), "%Y-%m-%d %H:%M %Z"), getRversion(),
            Sys.info()[["machine"]]))
cat(sprintf("load average at the end: %s\n",
            tryCatch(paste(scan("/proc/loadavg", what = "", n = 3,
                                quiet = TRUE), collapse = " "),
                     error = function(e) "n/a")))
options(width = 150)
print(out, row.names = FALSE)
