# The closed loop on the measured ADIS16405 units: avrefine(fit, data = x)
# from N, B, K on three axes of each unit (gyro_x, gyro_z, accel_z), one
# thread, elapsed and CPU seconds per axis and in all (a third argument
# "all": every axis; the median CPU per axis is the figure of issue 27's
# speed point, the load moving elapsed more than CPU). Compare two builds by
# running it with each library first in R_LIBS, alternately (the machine's
# load moves the figures; take the medians of a few alternations):
#   R_LIBS=/tmp/lib-a Rscript bench/bench-refine-adis.R a [data dir]
# The recordings stay in the shared data directory (never shipped).
suppressPackageStartupMessages(library(allanvar))
options(allanvar.threads = 1L)
args <- commandArgs(TRUE)
label <- if (length(args) >= 1L) args[1L] else "this build"
dir <- if (length(args) >= 2L) args[2L] else {
  if (dir.exists("../shared/data")) "../shared/data" else "/work/shared/data"
}
rows <- list()
axes <- if (length(args) >= 3L && args[3L] == "all") 1:6 else c(1L, 3L, 6L)
for (u in 1:3) {
  m <- readRDS(file.path(dir, sprintf("adis16405_unit%d.rds", u)))
  for (j in axes) {
    z <- m[, j]
    f <- avfit(allan(z, 100), terms = c("N", "B", "K"))
    t0 <- proc.time()
    r <- suppressMessages(avrefine(f, data = z))
    t1 <- proc.time() - t0
    rows[[length(rows) + 1L]] <- data.frame(
      build = label, unit = u, axis = colnames(m)[j],
      seconds = round(t1[["elapsed"]], 2), cpu = round(t1[[1L]] + t1[[2L]], 2),
      steps = nrow(r$steps),
      duplicates = NROW(r$refine$series_duplicates))
  }
}
tab <- do.call(rbind, rows)
print(tab, row.names = FALSE)
cat(sprintf("%s: %.1f s in all over %d axes; CPU per axis: median %.2f s, max %.2f s\n",
            label, sum(tab$seconds), nrow(tab), stats::median(tab$cpu), max(tab$cpu)))
