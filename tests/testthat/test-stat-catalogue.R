# The catalogue of statistics (R/stat-catalogue.R, stat-allan.R,
# stat-further.R), allan()'s `ci` and `unbiased`.

test_that("no file of allan() and its helpers switches on statistic names", {
  dir <- testthat::test_path("..", "..", "R")
  skip_if_not(dir.exists(dir), "the R sources are not at hand")
  files <- file.path(dir, c("allan.R", "allan-types.R", "theo1-type.R",
                            "taus.R", "edf.R", "dynamic.R", "fit-weights.R",
                            "hat.R"))
  files <- c(files, list.files(dir, "^stat-.*[.]R$", full.names = TRUE))
  expect_true(all(file.exists(files)))
  names <- stat_names()
  quoted <- paste0("\"(", paste(names, collapse = "|"), ")\"")
  # `type`, `base` or a field of that name (`x$type`)
  pats <- c("switch\\(([A-Za-z_.]+\\$)?(type|base)\\b",
            paste0("\\b(type|base)\\s*(==|!=)\\s*", quoted),
            "\\b(type|base)\\s*%in%\\s*c\\(",
            paste0("identical\\(([A-Za-z_.]+\\$)?(type|base),\\s*", quoted))
  catalogue <- grepl("/stat-[^/]*[.]R$", files)
  hits <- character()
  for (f in files[!catalogue]) {
    code <- sub("#.*$", "", readLines(f, warn = FALSE))
    for (p in pats) {
      i <- grep(p, code)
      if (length(i)) hits <- c(hits, paste0(basename(f), ":", i, ": ", code[i]))
    }
  }
  expect_identical(hits, character())
  # the grep finds what it is meant to find
  expect_true(grepl(pats[1], "  switch(type, standard = 1)"))
  expect_true(grepl(pats[1], "  switch(x$type, standard = 1)"))
  expect_true(grepl(pats[2], "if (type == \"theo1\") 1"))
  expect_true(grepl(pats[3], "type %in% c(\"mtie\", \"tierms\")"))
  expect_true(grepl(pats[4], "identical(type, \"overlapping\")"))
})

test_that("every statistic of src/types.h has one entry, and back", {
  tab <- allan_type_table_cpp(TRUE)
  cat <- stat_catalogue()
  expect_setequal(names(cat), tab$name)
  for (e in cat) {
    i <- match(e$name, tab$name)
    expect_identical(e$code, tab$code[i])
    expect_identical(e$d, tab$d[i])
  }
  # the sums kernel's statistics are the Allan family of the C++ table
  expect_setequal(stat_sums_names(), allan_type_table()$name)
  expect_identical(stat_sums_names(), allan_types)
  # aliases resolve; unknown names do not
  for (a in names(allan_type_aliases)) {
    expect_identical(stat_canonical(a), allan_type_aliases[[a]])
  }
  expect_null(stat_entry("avar"))
  # statistics with a bias correction in C++ have a `debias` field
  for (e in cat) expect_identical(!is.null(e$debias), e$has_debias, info = e$name)
})

test_that("a malformed entry is refused with a classed error", {
  ok <- stat_entry("overlapping")
  bad <- ok
  bad$divisor <- NULL
  expect_error(validate_stat(bad), class = "allanvar_error_catalogue")
  bad <- ok
  bad$edf <- "nonsense"
  expect_error(validate_stat(bad), class = "allanvar_error_catalogue")
  bad <- ok
  bad$kernel <- 3
  expect_error(validate_stat(bad), class = "allanvar_error_catalogue")
  expect_identical(validate_stat(ok), ok)
})

test_that("the divisor field is the estimator's (against direct sums)", {
  set.seed(3)
  y <- rnorm(200)
  x <- c(0, cumsum(y))
  m <- 4
  L <- length(x)
  d2 <- x[(1 + 2 * m):L] - 2 * x[(1 + m):(L - m)] + x[1:(L - 2 * m)]
  d3 <- x[(1 + 3 * m):L] - 3 * x[(1 + 2 * m):(L - m)] +
    3 * x[(1 + m):(L - 2 * m)] - x[1:(L - 3 * m)]
  e <- stat_entry("overlapping")
  expect_equal(allan(y, 1, taus = I(m))$avar,
               sum(d2^2) / (e$divisor(m) * e$nterms(m, L)), tolerance = 1e-12)
  e <- stat_entry("ohadamard")
  expect_equal(allan(y, 1, taus = I(m), type = "ohadamard")$avar,
               sum(d3^2) / (e$divisor(m) * e$nterms(m, L)), tolerance = 1e-12)
})

test_that("ci = FALSE: the same values, no identification, NA limits", {
  set.seed(4)
  y <- rnorm(4000)
  for (type in c(allan_types, "tdev", "pdev", "theobr", "mtie")) {
    a <- allan(y, 1, type = type)
    b <- allan(y, 1, type = type, ci = FALSE)
    expect_identical(b$avar, a$avar, info = type)
    expect_identical(b$adev, a$adev, info = type)
    expect_true(all(is.na(b$lower) & is.na(b$upper) & is.na(b$edf)), info = type)
    expect_true(all(is.na(b$alpha)), info = type)
    expect_identical(attr(b, "ci"), FALSE)
  }
  # the bias-corrected statistics identify the type their correction needs
  a <- allan(y, 1, type = "mtotdev")
  b <- allan(y, 1, type = "mtotdev", ci = FALSE)
  expect_identical(b$avar, a$avar)
  expect_identical(b$alpha, a$alpha)
  expect_true(all(is.na(b$lower)))
  # the default call carries no `ci` attribute
  expect_null(attr(allan(y, 1), "ci"))
  expect_match(capture.output(print(b))[1], "no intervals \\(ci = FALSE\\)")
  pdf(NULL)
  on.exit(grDevices::dev.off())
  expect_silent(plot(allan(y, 1, ci = FALSE)))
  expect_error(allan(y, 1, ci = NA), class = "allanvar_error_argument")
  expect_error(allan(y, 1, unbiased = "yes"), class = "allanvar_error_argument")
})

test_that("stat_c4() is E sqrt(chi2_nu / nu) (exact formula, series, integral)", {
  nu <- c(1, 2, 3, 7, 10.5, 100)
  exact <- sqrt(2 / nu) * gamma((nu + 1) / 2) / gamma(nu / 2)
  expect_equal(stat_c4(nu), exact, tolerance = 1e-14)
  # by numerical integration of sqrt(q / nu) against the chi-square density
  for (v in c(1.5, 4, 30)) {
    int <- stats::integrate(function(q) sqrt(q / v) * stats::dchisq(q, v),
                            0, Inf, rel.tol = 1e-10)$value
    expect_equal(stat_c4(v), int, tolerance = 1e-8)
  }
  # the series above 1e4 against Rmpfr-free long arithmetic: lgamma at 1e4
  # still holds ~1e-12, and both sides of the switch agree
  v <- c(9999.999, 1e4)
  expect_equal(stat_c4(v[1]), stat_c4(v[2]), tolerance = 1e-9)
  expect_equal(stat_c4(1e4),
               sqrt(2 / 1e4) * exp(lgamma(5000.5) - lgamma(5000)),
               tolerance = 1e-11)
  expect_true(all(diff(stat_c4(10^(0:8))) > 0))
  expect_lt(1 - stat_c4(1e8), 3e-9)
  expect_true(is.na(stat_c4(NA_real_)))
})

test_that("unbiased = TRUE divides adev by c4(edf); limits and avar stay", {
  set.seed(5)
  y <- rnorm(3000)
  for (type in c("overlapping", "standard", "hadamard", "total", "tdev",
                 "mtotdev", "theo1", "theoh", "pdev")) {
    a <- allan(y, 1, type = type)
    u <- allan(y, 1, type = type, unbiased = TRUE)
    c4 <- sqrt(2 / a$edf) * exp(lgamma((a$edf + 1) / 2) - lgamma(a$edf / 2))
    expect_equal(u$adev, a$adev / c4, tolerance = 1e-13, info = type)
    expect_identical(u$avar, a$avar, info = type)
    expect_identical(u$lower, a$lower, info = type)
    expect_identical(u$upper, a$upper, info = type)
    expect_true(isTRUE(attr(u, "unbiased")), info = type)
  }
  # without limits it still needs (and reports) the EDF
  u <- allan(y, 1, unbiased = TRUE, ci = FALSE)
  a <- allan(y, 1)
  expect_equal(u$edf, a$edf)
  expect_true(all(is.na(u$lower)))
  # no EDF, nothing to correct
  expect_identical(allan(y, 1, type = "mtie", unbiased = TRUE)$adev,
                   allan(y, 1, type = "mtie")$adev)
})

test_that("unbiased deviation: mean within its Monte Carlo error of the truth", {
  skip_on_cran()
  # white FM of our own (rnorm), N = 512, standard ADEV at m = 64: 7 terms,
  # EDF 7 (independent terms); the plain ADEV is low by 1 - c4(7) = 3.6%
  set.seed(2029)
  R <- 1500
  N <- 512
  m <- 64
  s <- 0.3
  truth <- s / sqrt(m)
  got <- t(vapply(seq_len(R), function(i) {
    y <- rnorm(N, sd = s)
    u <- allan(y, 1, type = "standard", taus = I(m), unbiased = TRUE)
    c(u$adev, sqrt(u$avar))
  }, c(0, 0)))
  se <- apply(got, 2, stats::sd) / sqrt(R)
  expect_lt(abs(mean(got[, 1]) - truth), 3 * se[1])
  # the plain deviation is biased low, beyond its Monte Carlo error
  expect_gt(truth - mean(got[, 2]), 3 * se[2])
})

test_that("long grids starting above m = 64 evaluate real rows (no row 0)", {
  u <- sort(unique(round(0.75 * seq(602, 1334, by = 2))))
  s <- allan_subset(u)
  expect_true(all(s >= 1L & s <= length(u)))
  set.seed(6)
  y <- rnorm(3000)
  a <- expect_silent(allan(y, 1, taus = I(u)))
  expect_true(all(a$alpha %in% -2:2 | is.na(a$alpha)))
  b <- allan(y, 1, taus = I(u[u >= 600]))
  expect_true(all(b$alpha %in% -2:2 | is.na(b$alpha)))
})
