# Speed of every allan() type at octave taus against R's sum(x) on the same
# data, in one run, with Python allantools timed on the same data when it
# is available.
#
# Run from the repository root:  Rscript bench/bench-types.R
# It installs the package into a temporary library first (pkgload would
# compile without optimisation). Environment:
#   BENCH_TYPES_N        sizes to try (default "1e4,1e5,1e6");
#   BENCH_TYPES_CAP      seconds: a type is not run at the next size once one
#                        run took longer than this (default 30);
#   ALLANTOOLS_PATH      a directory holding the allantools package source
#                        (e.g. `git archive` of github.com/aewallin/allantools
#                        unpacked in /tmp/allantools); timed with python3 and
#                        numpy, each call under `timeout` (BENCH_PY_TIMEOUT,
#                        default 120 s).
# Prints one table: median elapsed seconds (3 or 9 runs after a first for
# calls under 5 s, else one run), ratio to sum(x), allantools' time.

source(file.path("bench", "common.R"))
lib <- bench_install()

env_num <- function(name, default) {
  v <- Sys.getenv(name)
  if (nzchar(v)) as.numeric(strsplit(v, ",")[[1]]) else default
}
sizes <- env_num("BENCH_TYPES_N", c(1e4, 1e5, 1e6))
cap <- env_num("BENCH_TYPES_CAP", 30)
py_timeout <- env_num("BENCH_PY_TIMEOUT", 120)

timed_adaptive <- function(expr) {
  f <- substitute(expr)
  e <- parent.frame()
  t1 <- system.time(eval(f, e))[["elapsed"]]
  if (t1 > 5) return(c(t1, 1))
  reps <- if (t1 < 0.05) 9 else 3
  c(stats::median(vapply(seq_len(reps), function(i)
    system.time(eval(f, e))[["elapsed"]], 0)), reps)
}

# allantools: one call per (type, N), timed inside Python
py_path <- Sys.getenv("ALLANTOOLS_PATH", "/tmp/allantools")
# a python3 that has numpy (BENCH_PYTHON, Debian's, or the first on PATH)
pythons <- unique(c(Sys.getenv("BENCH_PYTHON"), "/usr/bin/python3",
                    unname(Sys.which("python3"))))
pythons <- pythons[nzchar(pythons) & file.exists(pythons)]
python <- NA_character_
for (p in pythons) {
  ok <- suppressWarnings(system2(p, c("-c", shQuote("import numpy")),
                                 stdout = FALSE, stderr = FALSE))
  if (ok == 0) {
    python <- p
    break
  }
}
have_py <- !is.na(python) && nzchar(Sys.which("timeout")) &&
  dir.exists(file.path(py_path, "allantools"))
py_time <- function(fun, file) {
  code <- sprintf(paste0(
    "import sys, time, numpy as np; sys.path.insert(0, '%s'); ",
    "import allantools as at; y = np.fromfile('%s'); t = time.time(); ",
    "at.%s(y, rate=1.0, data_type='freq', taus='octave'); ",
    "print(time.time() - t)"), py_path, file, fun)
  out <- suppressWarnings(system2("timeout", c(py_timeout, python, "-c",
                                               shQuote(code)),
                                  stdout = TRUE, stderr = FALSE))
  st <- attr(out, "status")
  if (!is.null(st) && st == 124) return(Inf)  # timed out
  v <- suppressWarnings(as.numeric(utils::tail(out, 1)))
  if (length(v) != 1L || is.na(v)) NA_real_ else v
}
py_name <- c(standard = "adev", overlapping = "oadev", modified = "mdev",
             hadamard = "hdev", ohadamard = "ohdev", total = "totdev", tdev = "tdev",
             mtotdev = "mtotdev", ttotdev = "ttotdev", htotdev = "htotdev",
             theo1 = "theo1", mtie = "mtie", tierms = "tierms", pdev = "pdev")

types <- c("standard", "overlapping", "modified", "hadamard", "ohadamard",
           "total", "tdev", "tierms", "mtie", "pdev",
           "mtotdev", "ttotdev", "htotdev", "theo1", "theobr", "theoh")
options(allanvar.threads = 2)
set.seed(1)
big <- rnorm(max(sizes))
rows <- list()
stopped <- character(0)
py_stopped <- character(0)
for (N in sizes) {
  y <- big[seq_len(N)]
  # the yardstick at sub-millisecond resolution (bench::mark when installed;
  # system.time() ticks in milliseconds, about half of sum() at 1e6)
  s <- timed(sum(y), reps = 51)
  if (s == 0) s <- system.time(for (i in 1:100) sum(y))[["elapsed"]] / 100
  f <- tempfile(fileext = ".bin")
  writeBin(y, f)
  for (ty in types) {
    if (ty %in% stopped) {
      rows[[length(rows) + 1L]] <- data.frame(type = ty, N = N, seconds = NA,
                                              runs = 0, ratio = NA,
                                              allantools = NA)
      next
    }
    t <- timed_adaptive(allan(y, 1, type = ty))
    py <- if (have_py && ty %in% names(py_name) && !ty %in% py_stopped) {
      py_time(py_name[[ty]], f)
    } else {
      NA
    }
    if (!is.na(py) && py > py_timeout / 4) py_stopped <- c(py_stopped, ty)
    rows[[length(rows) + 1L]] <- data.frame(type = ty, N = N,
                                            seconds = signif(t[1], 3),
                                            runs = t[2],
                                            ratio = round(t[1] / s, 1),
                                            allantools = signif(py, 3))
    message(sprintf("%-12s %8.0e %10.4g s  %8.1f x sum  allantools %s", ty, N,
                    t[1], t[1] / s, format(signif(py, 3))))
    # not run at the next size when it would take over 10 caps (TheoBR's
    # factor, so TheoBR and TheoH, is O(N^2); the others about O(N log N))
    p <- if (ty %in% c("theobr", "theoh")) 2 else 1.1
    if (t[1] > cap || t[1] * 10^p > 10 * cap) stopped <- c(stopped, ty)
  }
  rows[[length(rows) + 1L]] <- data.frame(type = "sum(x)", N = N,
                                          seconds = signif(s, 3), runs = 51,
                                          ratio = 1, allantools = NA)
  unlink(f)
}
tab <- do.call(rbind, rows)
tab$N <- format(tab$N, scientific = TRUE)
tab$allantools <- ifelse(is.infinite(tab$allantools),
                         paste0(">", py_timeout), format(tab$allantools))
cat(sprintf("bench-types: %s, %d cores, load %s; allantools %s\n",
            format(Sys.time(), "%Y-%m-%d %H:%M %Z"), parallel::detectCores(),
            if (file.exists("/proc/loadavg")) {
              paste(utils::head(strsplit(readLines("/proc/loadavg"), " ")[[1]], 3),
                    collapse = " ")
            } else "?",
            if (have_py) py_path else "not available"))
cat("NA seconds: not run (the type took more than", cap,
    "s at the previous size, or would take more than", 10 * cap, "s here); allantools NA: not timed (no such function or",
    "a smaller size already timed out), >", py_timeout, ": timed out\n")
print(tab, row.names = FALSE)
