# Stored once in extdata; the working directory is data/ when this runs.
gyroz_long <- readRDS(Find(file.exists, c(
  file.path("..", "extdata", "gyroz_long.rds"),
  file.path("..", "inst", "extdata", "gyroz_long.rds"))))
