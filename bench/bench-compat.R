# Speed of avar(), avari() and exact avarn() against CRAN allanvar 1.1, in one
# run on the same data. The original runs in its own R process (it has this
# package's name) from ALLANVAR_ORIGINAL_LIB; this package must be installed.
#   ALLANVAR_ORIGINAL_LIB=/tmp/origlib Rscript bench/bench-compat.R
orig_lib <- Sys.getenv("ALLANVAR_ORIGINAL_LIB", "/tmp/origlib")
stopifnot(file.exists(file.path(orig_lib, "allanvar", "DESCRIPTION")))

median_time <- function(expr, reps) {
  expr <- substitute(expr)
  env <- parent.frame()
  times <- vapply(seq_len(reps), function(i) {
    gc(FALSE)
    t0 <- proc.time()[["elapsed"]]
    eval(expr, env)
    proc.time()[["elapsed"]] - t0
  }, numeric(1))
  stats::median(times)
}

set.seed(42)
cases <- list(
  list(fun = "avar", n = 1e6, reps_orig = 3, reps_new = 21),
  list(fun = "avari", n = 1e6, reps_orig = 3, reps_new = 21),
  list(fun = "avarn", n = 2e4, reps_orig = 3, reps_new = 11)
)
data <- lapply(cases, function(case) {
  x <- cumsum(rnorm(case$n, sd = 1e-3)) * 1e-2 + rnorm(case$n, sd = 1e-2)
  if (case$fun == "avari") cumsum(x) / 100 else x
})

original <- callr::r(function(cases, data, orig_lib, median_time) {
  library(allanvar, lib.loc = orig_lib)
  Map(function(case, x) {
    f <- match.fun(case$fun)
    res <- NULL
    t <- median_time(utils::capture.output(res <- f(x, 100)), case$reps_orig)
    list(time = t, result = res)
  }, cases, data)
}, list(cases = cases, data = data, orig_lib = orig_lib,
        median_time = median_time))

library(allanvar)
rows <- Map(function(case, x, orig) {
  f <- match.fun(case$fun)
  t <- median_time(f(x, 100), case$reps_new)
  sum_t <- median_time(sum(x), 21)
  data.frame(
    function_ = case$fun, N = format(case$n, scientific = TRUE),
    original_s = signif(orig$time, 3), allanvar_s = signif(t, 3),
    speedup = round(orig$time / t), sum_x_s = signif(sum_t, 3),
    vs_sum = round(t / sum_t, 1), identical = identical(f(x, 100), orig$result)
  )
}, cases, data, original)
table <- do.call(rbind, rows)
names(table)[1] <- "function"
cat(sprintf("allanvar %s vs allanvar 1.1, %d threads for avarn, %s\n",
            utils::packageVersion("allanvar"),
            getOption("allanvar.threads", 2L), R.version.string))
print(table, row.names = FALSE)
