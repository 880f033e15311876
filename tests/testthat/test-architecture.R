# The package's layout rules, read from its R sources (skipped where the
# sources are not at hand, as in an installed package's tests).

r_dir <- function() {
  for (d in c(test_path("..", "..", "R"), file.path("..", "..", "R"))) {
    if (dir.exists(d) && file.exists(file.path(d, "catalogue.R"))) return(d)
  }
  NULL
}

# String literals of an R file that name an effect kind (or a family's
# "kind:variant" or variant), as data frame file, line, literal.
kind_literals <- function(file, names) {
  pd <- utils::getParseData(parse(file, keep.source = TRUE))
  s <- pd[pd$token == "STR_CONST", , drop = FALSE]
  if (!nrow(s)) return(data.frame(file = character(), line = integer(), literal = character()))
  v <- vapply(s$text, function(t) eval(parse(text = t)), "", USE.NAMES = FALSE)
  hit <- v %in% names
  data.frame(file = rep(basename(file), sum(hit)), line = s$line1[hit],
             literal = v[hit], stringsAsFactors = FALSE)
}

effect_names <- function() {
  fam <- unlist(lapply(entries_with("family"), function(e) {
    c(e$family$variants, paste0(e$name, ":", e$family$variants))
  }))
  unique(c(effect_kinds(c("av", "series")), fam))
}

test_that("the kind scanner finds a kind named in a string literal", {
  f <- tempfile(fileext = ".R")
  on.exit(unlink(f))
  writeLines(c("f <- function(x) {", "  # \"gm\" in a comment is not code",
               "  if (x == \"gm\") 1 else if (x == \"filter:lp1\") 2 else \"gmx\"", "}"), f)
  hits <- kind_literals(f, effect_names())
  expect_equal(hits$literal, c("gm", "filter:lp1"))
  expect_equal(hits$line, c(3L, 3L))
})

test_that("no effect kind is named outside the catalogue files", {
  d <- r_dir()
  skip_if(is.null(d), "the package's R sources are not at hand")
  # the catalogue, its entries and the modules an entry delegates to
  allowed <- function(f) {
    grepl("^(catalogue|effect-.*|filter-noise|resonance|spectrum|nonstationary)[.]R$", f)
  }
  # the same strings where they are not effect kinds (or not yet asked of
  # the catalogue), each with its reason
  not_kinds <- list(
    "allan.R" = "N",        # attribute: the number of samples
    "hat.R" = "N",          # attribute: the number of samples
    "fit-input.R" = "N",    # attribute: the number of samples
    "report.R" = "N",       # attribute: the number of samples
    "avfit.R" = "steps")    # the avfit object's `steps` field
  files <- list.files(d, pattern = "[.]R$", full.names = TRUE)
  files <- files[!allowed(basename(files))]
  hits <- do.call(rbind, lapply(files, kind_literals, names = effect_names()))
  ok <- vapply(seq_len(nrow(hits)), function(i) {
    hits$literal[i] %in% not_kinds[[hits$file[i]]]
  }, NA)
  hits <- hits[!ok, , drop = FALSE]
  found <- if (nrow(hits)) paste0(hits$file, ":", hits$line, ": \"", hits$literal, "\"")
    else character()
  expect_equal(found, character())
})

test_that("the closed loop has no `<<-` and avrefine() stays short", {
  d <- r_dir()
  skip_if(is.null(d), "the package's R sources are not at hand")
  loop <- file.path(d, c("avrefine.R", "trace.R", list.files(d, "^refine-.*[.]R$")))
  for (f in loop) {
    expect_false(any(grepl("<<-", readLines(f), fixed = TRUE)), label = basename(f))
  }
  expect_lte(length(deparse(body(avrefine))), 60L)
})
