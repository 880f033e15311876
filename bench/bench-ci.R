# What the confidence limits cost: allan() with limits (the default: noise
# identification at every tau, EDF, chi-square interval) and without
# (`ci = FALSE`), against R's sum(x) and Python allantools (which computes
# no limits) on the same white-FM data at octave taus, in one run.
#
# Run from the repository root:  Rscript bench/bench-ci.R
#   BENCH_CI_N           samples (default 1e7)
#   BENCH_CI_TYPES       comma-separated allan() types (default the six
#                        Allan-family types)
#   ALLANTOOLS_PATH      directory holding the allantools package source
#                        (default /tmp/allantools); skipped when absent or
#                        when no python3 with numpy is found
#   BENCH_PY_TIMEOUT     seconds per allantools call (default 120)
# Prints median elapsed times (allan: 5 runs, sum: 21; allantools: median
# of 3 calls in one Python process) and the ratios.

source(file.path("bench", "common.R"))
lib <- bench_install()
options(allanvar.threads = 2)

N <- as.numeric(Sys.getenv("BENCH_CI_N", "1e7"))
types <- strsplit(Sys.getenv("BENCH_CI_TYPES",
                             "standard,overlapping,modified,hadamard,ohadamard,total"),
                  ",")[[1]]
py_path <- Sys.getenv("ALLANTOOLS_PATH", "/tmp/allantools")
py_timeout <- Sys.getenv("BENCH_PY_TIMEOUT", "120")
python <- NA_character_
for (p in unique(c(Sys.getenv("BENCH_PYTHON"), "/usr/bin/python3",
                   unname(Sys.which("python3"))))) {
  if (!nzchar(p) || !file.exists(p)) next
  ok <- suppressWarnings(system2(p, c("-c", shQuote("import numpy")),
                                 stdout = FALSE, stderr = FALSE))
  if (ok == 0) {
    python <- p
    break
  }
}
have_py <- !is.na(python) && nzchar(Sys.which("timeout")) &&
  dir.exists(file.path(py_path, "allantools"))
py_name <- c(standard = "adev", overlapping = "oadev", modified = "mdev",
             hadamard = "hdev", ohadamard = "ohdev", total = "totdev")
py_time <- function(fun, file) {
  code <- sprintf(paste0(
    "import sys, time, numpy as np; sys.path.insert(0, '%s'); ",
    "import allantools as at; y = np.fromfile('%s'); r = []\n",
    "for i in range(3):\n",
    "    t = time.time(); at.%s(y, rate=1.0, data_type='freq', taus='octave'); ",
    "r.append(time.time() - t)\n",
    "print(sorted(r)[1])"), py_path, file, fun)
  out <- suppressWarnings(system2("timeout", c(py_timeout, python, "-c",
                                               shQuote(code)),
                                  stdout = TRUE, stderr = FALSE))
  st <- attr(out, "status")
  if (!is.null(st) && st == 124) return(Inf)
  v <- suppressWarnings(as.numeric(utils::tail(out, 1)))
  if (length(v) != 1L || is.na(v)) NA_real_ else v
}

set.seed(1)
x <- rnorm(N)
f <- tempfile(fileext = ".bin")
writeBin(x, f)
s <- timed(sum(x), 21)
rows <- list()
for (ty in types) {
  with_ci <- timed(allan(x, 1, type = ty))
  no_ci <- timed(allan(x, 1, type = ty, ci = FALSE))
  py <- if (have_py && ty %in% names(py_name)) py_time(py_name[[ty]], f) else NA
  rows[[ty]] <- data.frame(
    type = ty, N = format(N, scientific = TRUE),
    no_ci_s = signif(no_ci, 3), no_ci_x_sum = round(no_ci / s, 2),
    ci_s = signif(with_ci, 3), ci_x_sum = round(with_ci / s, 2),
    allantools_s = signif(py, 3),
    allantools_over_no_ci = round(py / no_ci, 1),
    allantools_over_ci = round(py / with_ci, 1))
  message(ty, " done")
}
unlink(f)
cat(sprintf("bench-ci: %s UTC, %d cores, load %s; sum(x) %.4g s; allantools %s\n",
            format(Sys.time(), tz = "UTC"), parallel::detectCores(),
            tryCatch(readLines("/proc/loadavg"), error = function(e) "?"), s,
            if (have_py) py_path else "not run"))
print(do.call(rbind, rows), row.names = FALSE)
