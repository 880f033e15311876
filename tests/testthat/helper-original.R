# Golden results of CRAN allanvar 1.1 (fixtures/make-fixtures.R makes them).
original_fixtures <- function() {
  fixtures <- readRDS(test_path("fixtures", "allanvar-1.1.rds"))
  for (name in names(fixtures)) {
    values <- fixtures[[name]]$values
    if (is.character(values)) {
      dataset <- sub("^data\\((.*)\\)$", "\\1", values)
      env <- new.env()
      utils::data(list = dataset, package = "allanvar", envir = env)
      fixtures[[name]]$values <- env[[dataset]]
    }
  }
  fixtures
}

# A library holding CRAN allanvar 1.1, for live comparisons on fresh inputs.
original_lib <- function() {
  lib <- Sys.getenv("ALLANVAR_ORIGINAL_LIB")
  if (nzchar(lib) && file.exists(file.path(lib, "allanvar", "DESCRIPTION"))) lib
}

run_original <- function(fun, values, freq) {
  callr::r(function(fun, values, freq, lib) {
    library(allanvar, lib.loc = lib)
    utils::capture.output(value <- suppressWarnings(
      match.fun(fun)(values, freq)))
    value
  }, list(fun = fun, values = values, freq = freq, lib = original_lib()))
}

# Non-overlapping AV of white noise, straight from the definition, for the
# tests that do not lean on the original.
white_noise_av <- function(sigma, c) sigma^2 / c

# Evaluate `code` with options set, restoring them afterwards.
withr_options <- function(new, code) {
  old <- options(new)
  on.exit(options(old))
  code
}
