# The records the previous (whole-file) bag/MCAP/db3 readers gave on the
# committed fixtures, for test-read-foreign.R's check that the streaming
# readers give the same. Run once with a library holding allanvar as of
# 2b1db2b (before the streaming readers were merged in e1240d0):
#   R_LIBS=<old lib> Rscript tools/make-previous-reader-ref.R
suppressMessages(library(allanvar))
dir <- file.path("tests", "testthat", "fixtures", "ros")
files <- c(list.files(dir, pattern = "^imu.*[.](bag|mcap|db3)$"),
           list.files(dir, pattern = "^(rosbag_(none|lz4)[.]bag|mcap_official.*[.]mcap)$"))
ref <- list()
for (f in files) {
  r <- tryCatch(read_imu(file.path(dir, f), topic = "/imu0"), error = function(e) NULL)
  if (is.null(r)) {
    message(f, ": not read by this version")
    next
  }
  ref[[f]] <- list(data = unname(r$data), time = r$time, freq = r$freq, segments = r$segments)
}
ref$.version <- as.character(packageVersion("allanvar"))
saveRDS(ref, file.path(dir, "previous-reader.rds"), version = 2)
cat(names(ref), "\n")
