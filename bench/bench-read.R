# Reading speed: read_imu() on a 1e6 x 7 Kalibr CSV against data.table::fread
# and base read.csv, read_imu() on 1e6 sensor_msgs/Imu messages in each bag
# format and compression, and the command line end to end on a 1e6 x 6 CSV
# (--no-refine). Prints one table with medians and R's sum(x) as yardstick.
#
# Run from the repository root: Rscript bench/bench-read.R
# It installs the package into a temporary library (byte-compiled, as users
# have it), writes its files into tempdir(), and needs the lz4 and zstd
# command-line tools for the compressed bags. About 5 minutes.
source(file.path("bench", "common.R"))
lib <- bench_install()
.libPaths(c(lib, .libPaths()))
# No warm-up run: each file was just written, so it is in the page cache.
formals(timed)$warm <- FALSE
source(file.path("tools", "make-bag-fixtures.R"))
options(allanvar.threads = 2L)

n <- 1e6
src <- Sys.getenv("ALLANVAR_SHARED_DATA", file.path("..", "shared", "data"))
f_adis <- file.path(src, "adis16405_unit1.rds")
if (!file.exists(f_adis)) f_adis <- "/work/shared/data/adis16405_unit1.rds"
if (file.exists(f_adis)) {
  m <- readRDS(f_adis)[seq_len(n), ]
  gyro <- m[, 1:3] * pi / 180
  accel <- m[, 4:6] * 9.80665
  what <- "ADIS16405 unit 1 (measured), 100 Hz"
} else {
  set.seed(1)
  gyro <- matrix(rnorm(3 * n, sd = 0.005), n)
  accel <- cbind(matrix(rnorm(2 * n, sd = 0.02), n), 9.81 + rnorm(n, sd = 0.02))
  what <- "simulated white noise, 100 Hz"
}
rec <- list(sec = 1403636579 + (0:(n - 1)) %/% 100, nsec = ((0:(n - 1)) %% 100) * 1e7,
            gyro = gyro, accel = accel)
dir <- tempfile("benchread")
dir.create(dir)

rows <- list()
add <- function(task, size, s, note = "") {
  rows[[length(rows) + 1L]] <<- data.frame(task = task, size = size, median_s = s,
                                           note = note, stringsAsFactors = FALSE)
  message(sprintf("%-45s %8.3f s", task, s))
}

# Yardstick.
x <- as.vector(gyro)
add("sum(x), 6e6 doubles", "6e6", timed(sum(x), 20L))

# CSV, 1e6 x 7 (Kalibr layout, ns stamps).
csv <- file.path(dir, "imu.csv")
write_imu_csv(rec, csv)
csv_mb <- sprintf("%.0f MB", file.size(csv) / 2^20)
invisible(read_imu(csv))
add("read_imu(), Kalibr CSV 1e6 x 7", csv_mb, timed(read_imu(csv), 3L))
add("data.table::fread(), same file", csv_mb,
    timed(data.table::fread(csv, nThread = 2L, showProgress = FALSE), 3L))
add("utils::read.csv(), same file", csv_mb, timed(utils::read.csv(csv), 1L), "one run")

# Bags, 1e6 messages of /imu0 (and a few of two other topics).
t1 <- fixture_topics(rec, "ros1")
t2 <- fixture_topics(rec, "cdr")
# MCAP uncompressed first: the other formats' ratio column is against it.
bag_files <- list(
  "MCAP, uncompressed (CDR)" = function(f) write_mcap(f, t2, ""),
  "ROS1 bag, uncompressed" = function(f) write_ros1_bag(f, t1, "none"),
  "ROS1 bag, lz4 chunks" = function(f) write_ros1_bag(f, t1, "lz4"),
  "ROS1 bag, bz2 chunks" = function(f) write_ros1_bag(f, t1, "bz2"),
  "MCAP, lz4 chunks (CDR)" = function(f) write_mcap(f, t2, "lz4"),
  "MCAP, zstd chunks (CDR)" = function(f) write_mcap(f, t2, "zstd"),
  "ROS2 db3 (SQLite, CDR)" = function(f) write_db3(f, t2))
ref <- read_imu(csv)
for (k in seq_along(bag_files)) {
  nm <- names(bag_files)[k]
  f <- file.path(dir, sprintf("imu%d.%s", k, if (grepl("ROS1", nm)) "bag" else
    if (grepl("MCAP", nm)) "mcap" else "db3"))
  message("writing ", nm, " ...")
  bag_files[[k]](f)
  r <- read_imu(f, topic = "/imu0")
  same <- identical(unname(r$data), unname(ref$data)) && identical(r$time, ref$time)
  add(paste0("read_imu(), ", nm), sprintf("1e6 msgs, %.0f MB", file.size(f) / 2^20),
      timed(read_imu(f, topic = "/imu0"), 3L),
      if (same) "record identical to the CSV's" else "RECORD DIFFERS FROM THE CSV")
  if (grepl("bz2", nm)) {
    # The yardstick for bz2: base R's memDecompress() on the same chunks
    # (read_imu() decodes each with it, one chunk in memory at a time).
    s <- allanvar:::bag_scan(f)
    raws <- lapply(s$chunks$pos, function(p) allanvar:::rosbag_chunk_cpp(f, p)$data)
    add("  memDecompress() of its bz2 chunks alone", "", timed(for (r in raws)
      memDecompress(r, type = "bzip2"), 1L), "one run")
  }
  unlink(f)
}

# The command line, end to end, on a 1e6 x 6 CSV; the analysis alone beside it.
out <- file.path(dir, "out")
rscript <- file.path(R.home("bin"), "Rscript")
cli_t <- timed(system2(rscript, c("-e", shQuote(sprintf(
  ".libPaths(c('%s', .libPaths())); allanvar::allanvar_cli()", lib)), "--args",
  csv, "--out", out, "--no-refine", "--quiet"), stdout = FALSE, stderr = FALSE), 1L)
add("CLI end to end (Rscript, --no-refine)", csv_mb, cli_t, "one run, R start-up included")
r <- read_imu(csv)
add("  of which analyze_imu(refine = FALSE)", "6 axes",
    timed(suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE)), 1L),
    "in-process, one run")
add("Rscript -e 'library(allanvar)' (start-up)", "",
    timed(system2(rscript, c("-e", shQuote(sprintf(
      ".libPaths(c('%s', .libPaths())); library(allanvar)", lib))),
      stdout = FALSE, stderr = FALSE), 1L), "one run")

tab <- do.call(rbind, rows)
tab$x_sum <- round(tab$median_s / tab$median_s[1L], 0)
# Ratios in this run: the CSV readers against fread, the bag readers
# against the uncompressed MCAP reader.
ref_of <- function(task) {
  if (grepl("CSV|same file", task)) "data.table::fread(), same file"
  else if (grepl("^read_imu\\(\\), (ROS|MCAP)", task)) "read_imu(), MCAP, uncompressed (CDR)"
  else NA_character_
}
refs <- vapply(tab$task, ref_of, "")
tab$ratio <- ifelse(is.na(refs), NA, round(tab$median_s / tab$median_s[match(refs, tab$task)], 2))
tab$ratio_to <- ifelse(is.na(refs), "", ifelse(grepl("fread", refs), "fread", "MCAP"))
tab$median_s <- signif(tab$median_s, 3)
cat("\nData:", what, "\n")
cat(sprintf("Machine: %s, load average at the end: %s\n", R.version$platform,
            paste(readLines("/proc/loadavg", warn = FALSE), collapse = " ")))
print(tab, row.names = FALSE, right = FALSE)
unlink(c(dir, lib), recursive = TRUE)
