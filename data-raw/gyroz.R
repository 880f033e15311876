# Builds the package's copies of allanvar 1.1's example series from
# ../shared/data (the original's data/gyroz.rda and data/gyroz_complete.rda).
# Run from the package root: Rscript data-raw/gyroz.R
shared <- file.path("..", "shared", "data")
gyroz <- readRDS(file.path(shared, "gyroz.rds"))
stopifnot(inherits(gyroz, "ts"), length(gyroz) == 10000L,
          abs(frequency(gyroz) - 97.65625) < 1e-9)
save(gyroz, file = file.path("data", "gyroz.rda"), compress = "xz")

# The 65,536-sample series, stored once: data(gyroz_long) gives it under its
# own name and, for code written for allanvar 1.1, data(gyroz_complete)
# (data/gyroz_complete.R) defines an object `gyroz` holding it, as the
# original's gyroz_complete.rda did.
gyroz_long <- readRDS(file.path(shared, "gyroz_long.rds"))
stopifnot(length(gyroz_long) == 65536L,
          abs(frequency(gyroz_long) - 97.65625) < 1e-9)
save(gyroz_long, file = file.path("data", "gyroz_long.rda"), compress = "xz")
