# What every bench script shares: the package installed into a temporary
# library (optimised and byte-compiled, as users have it; pkgload would
# compile without optimisation), a median timer and timings in fresh
# processes. Sourced from the
# repository root: source("bench/common.R").
stopifnot(file.exists("DESCRIPTION"))

# Installs the working tree into a temporary library and attaches it;
# returns the library path (for child processes).
bench_install <- function() {
  # BENCH_LIB: a library where this tree is already installed (a rebuild
  # takes minutes on a loaded machine).
  pre <- Sys.getenv("BENCH_LIB")
  if (nzchar(pre)) {
    library(allanvar, lib.loc = pre)
    return(pre)
  }
  lib <- tempfile("allanlib")
  dir.create(lib)
  status <- system2(file.path(R.home("bin"), "R"),
                    c("CMD", "INSTALL", "--preclean", "--no-test-load",
                      paste0("--library=", lib), "."),
                    stdout = FALSE, stderr = FALSE)
  if (status != 0) stop("R CMD INSTALL failed")
  library(allanvar, lib.loc = lib)
  lib
}

# Median elapsed seconds over `reps` runs (after one warm-up run unless
# `warm = FALSE`); bench::mark when available (sub-millisecond resolution),
# else system.time().
timed <- function(expr, reps = 5, warm = TRUE) {
  f <- substitute(expr)
  e <- parent.frame()
  if (warm) eval(f, e)
  if (reps > 1 && requireNamespace("bench", quietly = TRUE)) {
    b <- bench::mark(eval(f, e), iterations = reps, check = FALSE,
                     memory = FALSE, filter_gc = FALSE)
    return(as.numeric(b$median))
  }
  stats::median(vapply(seq_len(reps), function(i) {
    gc(FALSE)
    system.time(eval(f, e))[["elapsed"]]
  }, 0))
}

# The composite series of the GMWM comparison (bench-gmwm.R and its
# record gmwm-k-variants.R), our own generator rather than avsim(): white
# rate noise (sd N / sqrt(tau0)), a rate random walk (increments
# K sqrt(tau0)) and an AR(1) Gauss-Markov process started from its
# stationary law; `truth` holds N, K, sigma and tc.
composite_series <- function(n, seed, truth, tau0) {
  set.seed(seed)
  phi <- exp(-tau0 / truth[["tc"]])
  w <- rnorm(n, sd = truth[["sigma"]] * sqrt(1 - phi^2))
  w[1] <- rnorm(1, sd = truth[["sigma"]])
  rnorm(n, sd = truth[["N"]] / sqrt(tau0)) +
    cumsum(rnorm(n, sd = truth[["K"]] * sqrt(tau0))) +
    as.numeric(stats::filter(w, phi, method = "recursive"))
}

# allan() on a fixed series of N samples (a random walk plus white noise),
# timed in a fresh callr process with the library `lib`: the first call
# (nothing cached) and a second one in the same process.
# options(allanvar.ci_exact = exact); returns c(first, again) in seconds.
allan_fresh_times <- function(N, type, taus, exact, lib, ci = TRUE) {
  callr::r(function(N, type, taus, exact, lib, ci) {
    library(allanvar, lib.loc = lib)
    options(allanvar.threads = 1, allanvar.ci_exact = exact)
    set.seed(1)
    y <- cumsum(rnorm(N)) * 1e-3 + rnorm(N)
    t1 <- system.time(allan(y, 1, type = type, taus = taus, ci = ci))[["elapsed"]]
    t2 <- system.time(allan(y, 1, type = type, taus = taus, ci = ci))[["elapsed"]]
    c(first = t1, again = t2)
  }, list(N, type, taus, exact, lib, ci))
}
