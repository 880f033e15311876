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
