# allanvar 1.1 compatibility: data(gyroz_complete) defines `gyroz`, the
# 65,536-sample series (the working directory is data/ when this runs).
gyroz <- readRDS(Find(file.exists, c(
  file.path("..", "extdata", "gyroz_long.rds"),
  file.path("..", "inst", "extdata", "gyroz_long.rds"))))
