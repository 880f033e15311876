# The fuzz battery of tools/fuzz.R, quick subset: bad and extreme
# input to every exported function, S3 method and the CLI must give a result
# or a classed error naming the argument; never R's own wording, NaN/Inf/
# negative variances, or a dead R. The full battery: Rscript tools/fuzz.R.

fuzz_script <- function() {
  dir <- normalizePath(testthat::test_path(), mustWork = FALSE)
  for (i in 1:3) {
    f <- file.path(dir, "tools", "fuzz.R")
    if (file.exists(f)) return(f)
    dir <- dirname(dir)
  }
  NULL
}

test_that("the quick fuzz battery finds no unclear error, garbage or crash", {
  skip_on_cran()
  skip_if_not_installed("callr")
  script <- fuzz_script()
  if (is.null(script)) skip("tools/fuzz.R is not in this tree (built package)")
  env <- new.env()
  sys.source(script, envir = env)
  ns <- asNamespace("allanvar")
  # the working tree when the tests run under load_all(), else the installed package
  dev <- !installed_allanvar()
  pkg <- if (dev) getNamespaceInfo(ns, "path") else ""
  df <- env$fuzz_run(env$fuzz_cases(quick = TRUE), pkg_path = pkg, timeout = 60)
  bad <- env$fuzz_findings(df)
  expect(nrow(bad) == 0L, paste0(
    nrow(bad), " finding(s):\n",
    paste0(bad$class, " ", bad$fun, "(", bad$label, "): ",
           substr(bad$detail, 1, 160), collapse = "\n")))
  # it does exercise the error paths and the valid ones
  expect_gt(sum(df$class == "CLEAN"), 150)
  expect_gt(sum(df$class == "OK"), 40)
  # every exported function and every registered S3 method is called
  exports <- Filter(function(f) is.function(get(f, ns)), getNamespaceExports(ns))
  s3 <- getNamespaceInfo(ns, "S3methods")
  methods <- unique(paste(s3[, 1], s3[, 2], sep = "."))
  missing <- setdiff(c(exports, methods), df$fun)
  expect(length(missing) == 0L,
         paste("not covered by the battery:", paste(missing, collapse = ", ")))
})
