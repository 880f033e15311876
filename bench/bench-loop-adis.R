# Speed of the closed loop on the measured ADIS16405 units (issue 27's
# speed point), one or more builds in the same run:
#   Rscript bench/bench-loop-adis.R LIB_A[=label] [LIB_B[=label] ...] [--data DIR]
# Each build runs in its own child process (R_LIBS = its library):
# - per axis (18 = 3 units x 6), one thread: the series pass, the curve and
#   the first fit as analyze_imu() makes them, then the loop timed alone:
#   avrefine(fit, data = x, series = <the series pass>) (CPU and elapsed);
# - per unit: analyze_imu() of the 6-axis record with its defaults (elapsed
#   and CPU, the forked workers' included once they are reaped), again
#   with workers = 1 (elapsed), the reading (readRDS + imu_record()) timed
#   apart.
# Builds alternate unit by unit so that the machine's load moves them
# alike. Prints a per-axis table and the summary; CPU is the figure to
# compare (elapsed follows the shared machine's load); the machine's own
# speed (a fixed sort and sum() at the start and the end) is printed last.
# The recordings stay in the shared data directory (never shipped).

args <- commandArgs(TRUE)
if (length(args) >= 2L && args[1L] == "--worker") {
  # child: one unit with the library first in R_LIBS; writes an RDS
  unit <- as.integer(args[2L])
  dir <- args[3L]
  out <- args[4L]
  suppressPackageStartupMessages(library(allanvar))
  # CPU of this process and of the children it waited for (forked workers)
  cpu <- function(t) sum(t[c(1L, 2L, 4L, 5L)], na.rm = TRUE)
  t0 <- proc.time()
  m <- readRDS(file.path(dir, sprintf("adis16405_unit%d.rds", unit)))
  rec <- imu_record(m, freq = attr(m, "freq"), name = sprintf("unit%d", unit),
                    units = c(gyro = "deg/s", accel = "g"))
  t_read <- proc.time() - t0
  # analyze_imu() as a user runs it (default threads, no future plan: the
  # axes in allanvar.threads forked workers where the build has `workers`),
  # then with the axes one after another (workers = 1)
  t0 <- proc.time()
  a <- suppressWarnings(suppressMessages(analyze_imu(rec, progress = FALSE)))
  t_an <- proc.time() - t0
  # the workers' CPU counts once they are reaped, shortly after the call
  # returns (a fork cluster's workers exit after stopCluster()): CPU is
  # read after a pause, elapsed at once
  Sys.sleep(1)
  cpu_an <- cpu(proc.time() - t0)
  t_seq <- if ("workers" %in% names(formals(analyze_imu))) {
    t0 <- proc.time()
    a1 <- suppressWarnings(suppressMessages(analyze_imu(rec, progress = FALSE, workers = 1)))
    proc.time() - t0
  } else t_an
  # the loop alone per axis, one thread, prepared as analyze_channel() does
  options(allanvar.threads = 1L)
  rows <- list()
  for (ch in colnames(rec$data)) {
    x <- rec$data[, ch]
    series <- detect_series_effects(x, rec$freq)
    x <- series$x
    fit <- avfit(allan(x, rec$freq))
    t0 <- proc.time()
    r <- suppressWarnings(suppressMessages(avrefine(fit, data = x, series = series)))
    t1 <- proc.time() - t0
    rows[[ch]] <- data.frame(unit = unit, axis = ch, loop_cpu = cpu(t1),
                             loop_elapsed = t1[["elapsed"]], steps = nrow(r$steps))
  }
  saveRDS(list(axes = do.call(rbind, rows),
               unit = data.frame(unit = unit, read_elapsed = t_read[["elapsed"]],
                                 analyze_elapsed = t_an[["elapsed"]],
                                 analyze_cpu = cpu_an,
                                 sequential_elapsed = t_seq[["elapsed"]])), out)
  quit(save = "no")
}

dir <- "../shared/data"
if (!dir.exists(dir)) dir <- "/work/shared/data"
k <- match("--data", args)
if (!is.na(k)) {
  dir <- args[k + 1L]
  args <- args[-c(k, k + 1L)]
}
if (!length(args)) stop("usage: bench-loop-adis.R LIB_A[=label] [LIB_B[=label] ...] [--data DIR]")
libs <- sub("=.*$", "", args)
labels <- ifelse(grepl("=", args), sub("^[^=]*=", "", args), basename(libs))
me <- sub("^--file=", "", grep("^--file=", commandArgs(FALSE), value = TRUE)[1L])
res <- list()
# The machine's own speed, the same fixed work at the start and the end:
# this machine kind's speed has moved by up to 1.9 x between runs an hour
# apart (the same build read 0.93 s and 1.74 s per axis), so runs are
# compared through it, builds only within one run.
yardstick <- function() {
  set.seed(1)
  x <- stats::runif(2e6)
  c(sort = stats::median(replicate(5, system.time(sort(x))[["elapsed"]])),
    sum = stats::median(replicate(5, system.time(for (i in 1:50) sum(x))[["elapsed"]])) / 50)
}
ys0 <- yardstick()
cat(sprintf("load average at start: %s\n", paste(readLines("/proc/loadavg", warn = FALSE), collapse = " ")))
for (u in 1:3) {
  for (b in seq_along(libs)) {
    out <- tempfile(fileext = ".rds")
    st <- system2(file.path(R.home("bin"), "Rscript"),
                  c(me, "--worker", u, dir, out),
                  env = paste0("R_LIBS=", libs[b]))
    if (st != 0) stop("worker failed: ", labels[b], " unit ", u)
    r <- readRDS(out)
    r$axes$build <- labels[b]
    r$unit$build <- labels[b]
    res[[length(res) + 1L]] <- r
  }
}
axes <- do.call(rbind, lapply(res, `[[`, "axes"))
units <- do.call(rbind, lapply(res, `[[`, "unit"))
cat("\nThe loop per axis (avrefine() with the raw series, one thread), seconds:\n")
wide <- reshape(axes[, c("build", "unit", "axis", "loop_cpu")], idvar = c("unit", "axis"),
                timevar = "build", direction = "wide")
names(wide) <- sub("^loop_cpu\\.", "cpu ", names(wide))
print(wide, row.names = FALSE, digits = 3)
cat("\nanalyze_imu() per 6-axis unit (default threads), seconds:\n")
print(units[, c("build", "unit", "read_elapsed", "analyze_elapsed", "analyze_cpu",
               "sequential_elapsed")], row.names = FALSE, digits = 3)
cat("\n| build | loop CPU per axis, median (s) | max (s) | loop elapsed median (s) | analyze_imu() elapsed per unit, median (s) | its CPU median (s) | with workers = 1, elapsed median (s) | reading median (s) |\n|---|---|---|---|---|---|---|---|\n")
for (lb in labels) {
  a <- axes[axes$build == lb, ]
  v <- units[units$build == lb, ]
  cat(sprintf("| %s | %.2f | %.2f | %.2f | %.1f | %.1f | %.1f | %.2f |\n", lb,
              stats::median(a$loop_cpu), max(a$loop_cpu), stats::median(a$loop_elapsed),
              stats::median(v$analyze_elapsed), stats::median(v$analyze_cpu),
              stats::median(v$sequential_elapsed), stats::median(v$read_elapsed)))
}
cat(sprintf("load average at end: %s\n", paste(readLines("/proc/loadavg", warn = FALSE), collapse = " ")))
ys1 <- yardstick()
cat(sprintf(paste("machine yardstick (start, end): sort(runif(2e6)) %.3f, %.3f s;",
                  "sum() of 2e6 doubles %.2f, %.2f ms\n"),
            ys0[["sort"]], ys1[["sort"]], 1e3 * ys0[["sum"]], 1e3 * ys1[["sum"]]))
