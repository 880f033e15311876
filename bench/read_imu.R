# Time read_imu() on Kalibr-layout CSVs made from the measured ADIS16405
# recording (../shared/data), 1e5 to 1e6 rows. Prints a table.
# Run: Rscript bench/read_imu.R  (from the package root, package installed or
# pkgload available)
if (requireNamespace("pkgload", quietly = TRUE) && file.exists("DESCRIPTION")) {
  pkgload::load_all(".", quiet = TRUE)
} else {
  library(allanvar)
}
src <- file.path("..", "shared", "data", "adis16405_unit1.rds")
if (!file.exists(src)) src <- "/work/shared/data/adis16405_unit1.rds"
m <- readRDS(src)
rows <- c(1e5, 5e5, 1e6)
out <- data.frame(rows = rows, file_MB = NA_real_, read_s = NA_real_,
                  freq_Hz = NA_real_)
for (i in seq_along(rows)) {
  n <- rows[i]
  k <- 0:(n - 1)
  stamp <- sprintf("%d%09d", 1403636579L + k %/% 100L, (k %% 100L) * 10000000L)
  si <- cbind(m[seq_len(n), 1:3] * pi / 180, m[seq_len(n), 4:6] * 9.80665)
  f <- tempfile(fileext = ".csv")
  writeLines(c("timestamp,omega_x,omega_y,omega_z,alpha_x,alpha_y,alpha_z",
               do.call(paste, c(list(stamp), lapply(1:6, function(j)
                 format(si[, j], digits = 10)), sep = ","))), f)
  t <- system.time(r <- read_imu(f))[["elapsed"]]
  out$file_MB[i] <- round(file.size(f) / 2^20, 1)
  out$read_s[i] <- round(t, 2)
  out$freq_Hz[i] <- r$freq
  unlink(f)
}
print(out, row.names = FALSE)
