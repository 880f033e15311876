# Runs tests/testthat against the installed package and ends with the plain
# closing line "N passed, N failed, N skipped"; exits 1 on any failure.
# Tests start R processes through callr (processx) and fork workers
# (parallel). processx's SIGCHLD handler replaces parallel's unless told to
# call it: the forked workers then go unreaped, and R waited 10 s at exit
# and said "unable to terminate some child processes".
Sys.setenv(PROCESSX_NOTIFY_OLD_SIGCHLD = "true")
suppressPackageStartupMessages({
  library(testthat)
  library(allanvar)
})
options(allanvar.threads = 2L)
# Snapshot tests (the wording of errors) run here as they do on CI; only
# CRAN skips them.
Sys.setenv(NOT_CRAN = "true")
results <- testthat::test_dir(
  "tests/testthat", package = "allanvar", load_package = "installed",
  reporter = testthat::ProgressReporter$new(show_praise = FALSE),
  stop_on_failure = FALSE
)
df <- as.data.frame(results)
failed <- sum(df$failed) + sum(df$error)
skipped <- sum(df$skipped)
passed <- sum(df$nb) - sum(df$failed) - sum(df$skipped)
cat(sprintf("%d passed, %d failed, %d skipped\n", passed, failed, skipped))
quit(status = if (failed > 0) 1L else 0L, save = "no")
