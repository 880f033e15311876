# Do the files a user takes away agree on every verdict? For analyses of the
# measured ADIS16405 units (../shared/data; or saved analyses given as
# arguments), writes datasheet.csv, imu.yaml and the OpenVINS, imu_utils,
# VINS and MATLAB files, reads each file's verdict of every written value
# back, and compares them with the readings. Also counts "measured"
# readings whose model leaves the curve's own (68%) limits over the range
# (informative: the verdicts use joint 95% limits).
#   Rscript tools/check-verdicts.R [analysis.rds ...]
suppressPackageStartupMessages(library(allanvar))
ns <- asNamespace("allanvar")
args <- commandArgs(trailingOnly = TRUE)
analyses <- if (length(args)) lapply(args, readRDS) else {
  lapply(1:3, function(u) {
    m <- readRDS(sprintf("../shared/data/adis16405_unit%d.rds", u))
    r <- imu_record(m, freq = 100, units = c(rep("deg/s", 3), rep("g", 3)),
                    name = sprintf("adis16405_unit%d", u))
    suppressWarnings(analyze_imu(r, progress = FALSE))
  })
}
word <- function(v) toupper(gsub("_", " ", v))
bad <- 0L
checked <- 0L
for (a in analyses) {
  d <- tempfile("verdicts")
  dir.create(d)
  write_datasheet(a, file.path(d, "datasheet.csv"))
  ds <- utils::read.csv(file.path(d, "datasheet.csv"))
  write_kalibr_yaml(a, file.path(d, "imu.yaml"))
  y <- readLines(file.path(d, "imu.yaml"))
  tools <- c("openvins", "imu_utils", "vins", "matlab")
  for (t in tools) write_tool_params(a, t, file.path(d, paste0(t, ".txt")))
  for (s in c("gyro", "accel")) {
    long <- if (s == "gyro") "gyroscope" else "accelerometer"
    for (k in c("N", "K")) {
      key <- paste0(long, if (k == "N") "_noise_density" else "_random_walk")
      rows <- ds[ds$sensor == s & ds$term == k & !duplicated(paste(ds$axis, ds$term)), ]
      worst <- rows[which.max(rows$value), ]
      line <- y[startsWith(y, paste0(key, ":"))]
      ok <- grepl(word(worst$verdict), line, fixed = TRUE)
      checked <- checked + 1L
      if (!ok) {
        bad <- bad + 1L
        cat("imu.yaml disagrees:", a$name, key, worst$verdict, "\n")
      }
    }
  }
  for (t in tools) {
    txt <- readLines(file.path(d, paste0(t, ".txt")))
    tp <- tool_params(a, t)
    for (i in seq_len(nrow(tp))) {
      # the file's verdict list holds "axis key: NOTE"
      hit <- grep(sprintf("  %s %s: ", tp$axis[i], tp$key[i]), txt, fixed = TRUE, value = TRUE)
      # the value's own verdict, from the readings of its axis (or the max)
      sym <- sub("^.*(N|B|K)$", "\\1", sub(" .*", "", tp$formula[i]))
      rows <- ds[ds$sensor == tp$sensor[i] & ds$term == sym & !duplicated(paste(ds$axis, ds$term)), ]
      v <- if (tp$axis[i] %in% rows$axis) rows$verdict[rows$axis == tp$axis[i]]
           else if (tp$axis[i] == "max") rows$verdict[which.max(rows$value)] else tp$verdict[i]
      checked <- checked + 1L
      if (!length(hit) || !grepl(word(v), hit[1L], fixed = TRUE) || tp$verdict[i] != v) {
        bad <- bad + 1L
        cat(t, "disagrees:", a$name, tp$axis[i], tp$key[i], v, "|", hit[1L], "\n")
      }
    }
  }
}
cat(sprintf("verdicts compared: %d, disagreements: %d\n", checked, bad))
# measured readings against the curve's own 68% limits (+2%)
outside <- 0L
measured <- 0L
for (a in analyses) for (ch in a$channels) {
  rd <- ch$readings
  if (is.null(ch$fit)) next
  model <- sqrt(ns$verdict_model(ch$curve, ns$check_coef(ch$coef)))
  cv <- ch$curve
  for (i in which(rd$verdict == "measured")) {
    w <- cv$tau >= rd$tau_lo[i] & cv$tau <= rd$tau_hi[i] & is.finite(cv$lower)
    measured <- measured + 1L
    if (any(model[w] > cv$upper[w] * 1.02 | model[w] < cv$lower[w] * 0.98)) outside <- outside + 1L
  }
}
cat(sprintf("measured readings: %d; of them outside the curve's 68%% limits (+2%%) somewhere in their range: %d\n",
            measured, outside))
