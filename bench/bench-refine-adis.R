# The closed loop on the measured ADIS16405 units: avrefine(fit, data = x)
# from N, B, K on three axes of each unit (gyro_x, gyro_z, accel_z), one
# thread, elapsed seconds per axis and in all. Compare two builds by
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
for (u in 1:3) {
  m <- readRDS(file.path(dir, sprintf("adis16405_unit%d.rds", u)))
  for (j in c(1L, 3L, 6L)) {
    z <- m[, j]
    f <- avfit(allan(z, 100), terms = c("N", "B", "K"))
    t0 <- proc.time()[["elapsed"]]
    r <- suppressMessages(avrefine(f, data = z))
    rows[[length(rows) + 1L]] <- data.frame(
      build = label, unit = u, axis = colnames(m)[j],
      seconds = round(proc.time()[["elapsed"]] - t0, 2), steps = nrow(r$steps))
  }
}
tab <- do.call(rbind, rows)
print(tab, row.names = FALSE)
cat(sprintf("%s: %.1f s in all over %d axes\n", label, sum(tab$seconds), nrow(tab)))
