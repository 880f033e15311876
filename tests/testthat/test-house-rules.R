# Rules of the house that the code itself can check.

test_that("every expect_error() in the suite checks the condition's class", {
  files <- list.files(test_path(), pattern = "^test-.*\\.R$", full.names = TRUE)
  unclassed <- character()
  for (f in files) {
    pd <- utils::getParseData(parse(f, keep.source = TRUE))
    sym <- pd[pd$token == "SYMBOL_FUNCTION_CALL" & pd$text == "expect_error", ]
    for (i in seq_len(nrow(sym))) {
      call_id <- pd$parent[pd$id == sym$parent[i]]
      call <- str2lang(utils::getParseText(pd, call_id))
      if (!"class" %in% names(call)) {
        unclassed <- c(unclassed, paste0(basename(f), ":", pd$line1[pd$id == call_id]))
      }
    }
  }
  expect_identical(unclassed, character())
})

test_that("comments say why, not which tracker issue asked for the code", {
  dir <- test_path("..", "..", "R")
  skip_if_not(dir.exists(dir), "the R sources are not at hand")
  files <- c(list.files(dir, "[.]R$", full.names = TRUE),
             list.files(test_path(), "^(test|helper)-.*[.]R$", full.names = TRUE))
  pat <- "#.*(\\b[Ii]ssues? #?[0-9]+|\\bissue's\\b|\\(#[0-9]+\\))"
  hits <- character()
  for (f in files) {
    code <- readLines(f, warn = FALSE)
    i <- grep(pat, code)
    if (length(i)) hits <- c(hits, paste0(basename(f), ":", i))
  }
  expect_identical(hits, character())
  # the pattern finds what it is meant to find
  iss <- "issue"  # spelled apart, so that this file passes its own test
  expect_true(all(grepl(pat, c(sprintf("# rules (%s 9, item 3)", iss),
                               sprintf("# see (%s%d)", "#", 14L),
                               sprintf("  # within the %s's band", iss)))))
})
