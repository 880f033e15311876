# The closed loop's results on the measured ADIS16405 units, saved and
# compared: a refactor of the loop must leave them unchanged.
#
#   R_LIBS=/tmp/lib-a Rscript tools/compare-loop.R run  a.rds [data dir]
#   R_LIBS=/tmp/lib-b Rscript tools/compare-loop.R run  b.rds [data dir]
#   Rscript tools/compare-loop.R compare a.rds b.rds
#
# `run` calls analyze_imu() on each unit (all six axes, the loop with the
# raw series) with one thread and no future plan, and saves per axis the
# steps, coefficients, readings, rejections, failures, unexplained
# structure and the automatic tau range. `compare` reports, per axis and
# field, whether the two runs are identical(), else the largest relative
# difference; it exits 1 when any field differs beyond 1e-8.
# The recordings stay in the shared data directory (never shipped).

args <- commandArgs(trailingOnly = TRUE)
if (length(args) < 2L || !args[1L] %in% c("run", "compare")) {
  stop("usage: compare-loop.R run OUT.rds [DATA_DIR] | compare A.rds B.rds")
}

run_units <- function(out, dir) {
  suppressPackageStartupMessages(library(allanvar))
  options(allanvar.threads = 1L)
  res <- list()
  for (u in 1:3) {
    f <- file.path(dir, sprintf("adis16405_unit%d.rds", u))
    if (!file.exists(f)) stop("missing ", f)
    m <- readRDS(f)
    rec <- imu_record(m, freq = attr(m, "freq"), name = sprintf("unit%d", u),
                      units = c(gyro = "deg/s", accel = "g"))
    t0 <- proc.time()[["elapsed"]]
    a <- suppressWarnings(suppressMessages(analyze_imu(rec, progress = FALSE)))
    cat(sprintf("unit %d: %.1f s\n", u, proc.time()[["elapsed"]] - t0))
    for (ch in names(a$channels)) {
      fit <- a$channels[[ch]]$fit
      r <- fit$refine
      res[[sprintf("unit%d/%s", u, ch)]] <- list(
        terms = fit$terms, coefficients = stats::coef(fit), chi2 = fit$chi2,
        steps = fit$steps, readings = a$channels[[ch]]$readings,
        rejected = r$rejected,
        failures = if (!is.null(r$failures)) r$failures[, c("step", "effect", "stage", "message")],
        unexplained = fit$unexplained, tau_range = r$tau_range,
        unconfirmed = r$unconfirmed)
    }
  }
  saveRDS(res, out)
  cat("saved", length(res), "axes to", out, "\n")
}

# Largest relative difference between two objects of the same shape (NA
# when their structure differs).
max_rel <- function(a, b) {
  if (is.data.frame(a) && is.data.frame(b)) {
    if (!identical(dim(a), dim(b)) || !identical(names(a), names(b))) return(NA_real_)
    return(max(c(0, vapply(names(a), function(n) max_rel(a[[n]], b[[n]]), 0))))
  }
  if (is.list(a) && is.list(b)) {
    if (length(a) != length(b)) return(NA_real_)
    return(max(c(0, vapply(seq_along(a), function(i) max_rel(a[[i]], b[[i]]), 0))))
  }
  if (is.numeric(a) && is.numeric(b) && length(a) == length(b)) {
    d <- abs(a - b) / pmax(abs(a), abs(b), 1e-300)
    d[a == b] <- 0
    if (anyNA(d)) return(if (identical(is.na(a), is.na(b))) max(c(0, d), na.rm = TRUE) else NA_real_)
    return(max(c(0, d)))
  }
  if (identical(a, b)) 0 else NA_real_
}

compare_runs <- function(fa, fb) {
  a <- readRDS(fa)
  b <- readRDS(fb)
  axes <- union(names(a), names(b))
  bad <- 0L
  for (ax in axes) {
    if (is.null(a[[ax]]) || is.null(b[[ax]])) {
      cat(sprintf("%-16s missing in one run\n", ax))
      bad <- bad + 1L
      next
    }
    for (fld in union(names(a[[ax]]), names(b[[ax]]))) {
      x <- a[[ax]][[fld]]
      y <- b[[ax]][[fld]]
      if (identical(x, y)) next
      r <- max_rel(x, y)
      ok <- is.finite(r) && r <= 1e-8
      cat(sprintf("%-16s %-12s %s\n", ax, fld,
                  if (is.na(r)) "DIFFERS (structure or text)"
                  else sprintf("max relative difference %.3g%s", r, if (ok) "" else "  DIFFERS")))
      if (!ok) bad <- bad + 1L
    }
  }
  cat(sprintf("%d axes compared; %s\n", length(axes),
              if (bad) paste(bad, "field(s) differ") else
                "every field identical() or within 1e-8 relative"))
  invisible(bad)
}

if (args[1L] == "run") {
  run_units(args[2L], if (length(args) >= 3L) args[3L] else {
    d <- "../shared/data"
    if (dir.exists(d)) d else "/work/shared/data"
  })
} else {
  if (length(args) < 3L) stop("compare needs two files")
  quit(status = if (compare_runs(args[2L], args[3L]) > 0L) 1L else 0L)
}
