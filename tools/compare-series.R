# The series pass (detect_series_effects()) on the measured ADIS16405
# units, saved and compared: a speed-up of the pass must leave it unchanged.
#
#   R_LIBS=/tmp/lib-a Rscript tools/compare-series.R run a.rds [units] [data dir]
#   R_LIBS=/tmp/lib-b Rscript tools/compare-series.R run b.rds [units] [data dir]
#   Rscript tools/compare-series.R compare a.rds b.rds
#
# `run` calls detect_series_effects(x, freq) on every axis of the units
# (default 1:3, e.g. "2" or "1,3") with one thread, after one warm-up call
# (the catalogue and lazy loads), and saves per axis the result and its
# CPU time (user + sys). Run the two builds alternately, unit by unit, for
# a fair timing. `compare` reports per axis whether the results are
# identical(), else the largest relative difference of the numbers and
# whether every decision (kinds, indices, counts, removed flags) agrees;
# it exits 1 when a decision differs or a number beyond 1e-10.

args <- commandArgs(trailingOnly = TRUE)
if (length(args) < 2L || !args[1L] %in% c("run", "compare")) {
  stop("usage: compare-series.R run OUT.rds [UNITS] [DATA_DIR] | compare A.rds B.rds")
}

run_units <- function(out, units, dir) {
  suppressPackageStartupMessages(library(allanvar))
  options(allanvar.threads = 1L)
  invisible(detect_series_effects(rnorm(5000), 100))
  res <- list()
  for (u in units) {
    f <- file.path(dir, sprintf("adis16405_unit%d.rds", u))
    if (!file.exists(f)) stop("missing ", f)
    m <- readRDS(f)
    for (j in seq_len(ncol(m))) {
      x <- m[, j]
      t0 <- proc.time()
      r <- detect_series_effects(x, attr(m, "freq"))
      t1 <- proc.time() - t0
      key <- sprintf("unit%d/%s", u, colnames(m)[j])
      res[[key]] <- list(result = r, cpu = t1[["user.self"]] + t1[["sys.self"]])
      cat(sprintf("%-16s %.3f s\n", key, res[[key]]$cpu))
    }
  }
  saveRDS(res, out)
}

# largest relative difference of the numbers of two like objects
rel_diff <- function(a, b) {
  if (is.list(a)) {
    if (!is.list(b) || length(a) != length(b)) return(Inf)
    return(max(0, vapply(seq_along(a), function(i) rel_diff(a[[i]], b[[i]]), 0)))
  }
  if (is.numeric(a) && is.numeric(b) && length(a) == length(b)) {
    if (!identical(is.na(a), is.na(b))) return(Inf)
    ok <- !is.na(a)
    d <- abs(a[ok] - b[ok]) / pmax(abs(a[ok]), abs(b[ok]), .Machine$double.xmin)
    return(max(0, d[a[ok] != b[ok]]))
  }
  if (identical(a, b)) 0 else Inf
}

compare_runs <- function(fa, fb) {
  a <- readRDS(fa)
  b <- readRDS(fb)
  bad <- FALSE
  cat(sprintf("%-16s %-10s %-9s %8s %8s\n", "axis", "identical", "decisions", "cpu a", "cpu b"))
  for (k in union(names(a), names(b))) {
    ra <- a[[k]]$result
    rb <- b[[k]]$result
    if (is.null(ra) || is.null(rb)) {
      cat(sprintf("%-16s missing in one run\n", k))
      bad <- TRUE
      next
    }
    same <- identical(ra, rb)
    dec <- function(r) list(r$table[c("kind", "index", "removed")], r$removed, r$kinds,
                            nrow(r$adev), nrow(r$adev_kinds), r$reading_bias$kind)
    dsame <- identical(dec(ra), dec(rb))
    d <- if (same) 0 else rel_diff(unclass(ra), unclass(rb))
    if (!dsame || d > 1e-10) bad <- TRUE
    cat(sprintf("%-16s %-10s %-9s %8.3f %8.3f%s\n", k, same, dsame, a[[k]]$cpu, b[[k]]$cpu,
                if (same) "" else sprintf("  max rel diff %.2g", d)))
  }
  ta <- sum(vapply(a, `[[`, 0, "cpu"))
  tb <- sum(vapply(b, `[[`, 0, "cpu"))
  cat(sprintf("%-16s %-10s %-9s %8.3f %8.3f  (b / a = %.2f)\n", "total", "", "", ta, tb, tb / ta))
  if (bad) quit(status = 1L)
}

if (args[1L] == "run") {
  units <- if (length(args) >= 3L) as.integer(strsplit(args[3L], ",")[[1L]]) else 1:3
  run_units(args[2L], units, if (length(args) >= 4L) args[4L] else "/work/shared/data")
} else {
  compare_runs(args[2L], args[3L])
}
