# The measured recordings live in ../shared/data beside the repository; they
# are never shipped. Tests that need them skip when they are absent.
shared_data_dir <- function() {
  env <- Sys.getenv("ALLANVAR_SHARED_DATA")
  if (nzchar(env) && dir.exists(env)) return(normalizePath(env))
  dir <- normalizePath(getwd(), mustWork = FALSE)
  repeat {
    candidate <- file.path(dir, "shared", "data")
    if (file.exists(file.path(candidate, "gyroz.rds"))) return(candidate)
    parent <- dirname(dir)
    if (identical(parent, dir)) return(NULL)
    dir <- parent
  }
}

skip_if_no_shared <- function() {
  if (is.null(shared_data_dir())) skip("../shared/data is not available")
}

shared_file <- function(name) file.path(shared_data_dir(), name)

# a measured ADIS16405 axis: the series, its rate and its white sd a sample
measured_axis <- function(unit, axis) {
  m <- readRDS(shared_file(sprintf("adis16405_unit%d.rds", unit)))
  b <- as.numeric(m[, axis])
  list(b = b, freq = attr(m, "freq"), s = stats::sd(diff(b)) / sqrt(2))
}
