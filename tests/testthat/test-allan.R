# allan(): estimators against published NIST values, an exact
# quadruple-precision reference, and the compatibility functions.

nbs14_1000 <- function() {
  n <- numeric(1000)
  n[1] <- 1234567890
  for (i in 2:1000) n[i] <- (16807 * n[i - 1]) %% 2147483647
  n / 2147483647
}

# Relative error of allan()'s avar against the exact reference numerators.
ref_rel_error <- function(y, type, input = "rate", taus = "octave") {
  a <- allan(y, 1, taus = taus, type = type, input = input)
  r <- allan_reference_cpp(y, a$m, allan_type_code(type), input == "rate")
  norm <- switch(type, modified = 2 * a$m^4, hadamard = , ohadamard = 6 * a$m^2,
                 2 * a$m^2)
  expect_equal(a$n, r$n)
  max(abs(a$avar / (r$sums / (norm * r$n)) - 1))
}

test_that("NBS14 1000-point set: every published digit of NIST SP 1065", {
  y <- nbs14_1000()
  expect_equal(y[2:4] * 2147483647, c(395529916, 1209410747, 633705974))
  expect_equal(signif(mean(y), 7), 0.4897745)
  published <- list(
    standard = c(2.922319e-01, 9.965736e-02, 3.897804e-02),
    overlapping = c(2.922319e-01, 9.159953e-02, 3.241343e-02),
    modified = c(2.922319e-01, 6.172376e-02, 2.170921e-02),
    total = c(2.922319e-01, 9.134743e-02, 3.406530e-02),
    hadamard = c(2.943883e-01, 1.052754e-01, 3.910860e-02),
    ohadamard = c(2.943883e-01, 9.581083e-02, 3.237638e-02)
  )
  for (type in names(published)) {
    a <- allan(y, 1, taus = c(1, 10, 100), type = type)
    expect_equal(a$tau, c(1, 10, 100))
    got <- signif(a$adev, 7)
    want <- published[[type]]
    if (type == "hadamard") {
      # The exact HDEV(100) is 0.039108605597 (it matches the quadruple-
      # precision reference to 1e-15), which rounds to 3.910861e-2; the
      # published 3.910860e-2 is 0.56 units of its 7th digit away.
      expect_equal(got[1:2], want[1:2], tolerance = 0, info = type)
      expect_equal(signif(a$adev[3], 6), signif(want[3], 6))
      expect_lt(abs(a$adev[3] / want[3] - 1), 1.5e-7)
    } else {
      expect_equal(got, want, tolerance = 0, info = type)
    }
  }
})

test_that("NBS14 10-point set", {
  y <- c(892, 809, 823, 798, 671, 644, 883, 903, 677)
  expect_equal(signif(allan(y, 1, taus = c(1, 2), type = "standard")$adev, 7),
               c(91.22945, 115.8082), tolerance = 0)
  expect_equal(signif(allan(y, 1, taus = c(1, 2))$adev, 7),
               c(91.22945, 85.95287), tolerance = 0)
  expect_equal(signif(allan(y, 1, taus = I(2), type = "modified")$adev, 7),
               74.78849, tolerance = 0)
})

test_that("standard octave equals avar() to 1e-13 on several inputs", {
  set.seed(11)
  inputs <- list(
    white = rnorm(5000),
    biased_walk = 100 + cumsum(rnorm(4097)),
    odd = rnorm(1001, sd = 1e-3),
    integer = sample(-1000:1000, 3000, replace = TRUE)
  )
  for (nm in names(inputs)) {
    y <- inputs[[nm]]
    a <- allan(y, 10, type = "standard")
    b <- avar(y, 10)
    expect_equal(nrow(a), nrow(b), info = nm)
    expect_equal(a$tau, b$time, info = nm)
    expect_lt(max(abs(a$avar / b$av - 1)), 1e-13)
  }
})

test_that("standard octave equals avar() on gyroz", {
  skip_if_no_shared()
  g <- readRDS(shared_file("gyroz.rds"))
  a <- allan(g, frequency(g), type = "standard")
  b <- avar(g, frequency(g))
  expect_equal(a$tau, b$time)
  expect_lt(max(abs(a$avar / b$av - 1)), 1e-13)
})

test_that("every type is exact to 1e-12 with a large bias and drift (1e6 samples)", {
  skip_on_cran()
  set.seed(3)
  N <- 1e6
  y <- 1e6 + 1e-3 * seq_len(N) + rnorm(N)  # bias 1e6 sigma, drift 1e3 sigma
  taus <- c(1, 3, 10, 100, 1000, 1e4, 1e5, 3e5)
  ref <- allan_reference_cpp(1, 1, 0L, TRUE)
  skip_if_not(ref$quad, "no quadruple precision for the reference")
  for (type in allan_types) {
    expect_lt(ref_rel_error(y, type, taus = taus), 1e-12)
  }
  # the standard octave path (pairwise cluster sums) too
  expect_lt(ref_rel_error(y, "standard"), 1e-12)
  # integrated input with a huge offset and slope
  theta <- 1e9 + cumsum(y)
  for (type in c("overlapping", "standard", "modified", "hadamard", "total")) {
    expect_lt(ref_rel_error(theta, type, "integrated", taus = taus), 1e-12)
  }
})

test_that("a random walk of 1e6 samples is exact to 1e-12 for every type", {
  skip_on_cran()
  skip_if_not(allan_reference_cpp(1, 1, 0L, TRUE)$quad)
  set.seed(4)
  y <- 5e3 + cumsum(rnorm(1e6))
  for (type in allan_types) {
    expect_lt(ref_rel_error(y, type, taus = c(1, 2, 10, 1000, 1e5)), 1e-12)
  }
})

test_that("overlapping at 1e7 samples with bias and drift is exact to 1e-12", {
  skip_on_cran()
  skip_if_not(allan_reference_cpp(1, 1, 0L, TRUE)$quad)
  set.seed(5)
  N <- 1e7
  y <- 1e6 + 1e-4 * seq_len(N) + rnorm(N)
  expect_lt(ref_rel_error(y, "overlapping", taus = c(1, 1000, 1e6)), 1e-12)
})

test_that("integrated input equals rate input on the same phase", {
  set.seed(6)
  y <- rnorm(3000, 2)
  theta <- c(0, cumsum(y)) / 50
  for (type in allan_types) {
    a <- allan(y, 50, type = type)
    b <- allan(theta, 50, type = type, input = "integrated")
    expect_equal(b$m, a$m)
    expect_equal(b$avar, a$avar, tolerance = 1e-12)
  }
})

test_that("integrated overlapping equals avari()", {
  set.seed(7)
  theta <- cumsum(rnorm(2000)) / 100
  b <- avari(theta, 100)
  a <- allan(theta, 100, taus = b$time, input = "integrated")
  expect_equal(a$tau, b$time)
  expect_lt(max(abs(a$avar / b$av - 1)), 1e-12)
})

test_that("avarn(exact = FALSE) gives avarn()'s rows through the engine", {
  set.seed(8)
  for (y in list(rnorm(1500), 3 + cumsum(rnorm(999)), rnorm(2))) {
    e <- avarn(y, 20)
    f <- avarn(y, 20, exact = FALSE)
    expect_identical(names(f), names(e))
    expect_identical(class(f), class(e))
    expect_equal(f$time, e$time)
    expect_equal(f$error, e$error)
    expect_lt(max(abs(f$av / e$av - 1)), 1e-12)
  }
})

test_that("the result has the documented structure", {
  set.seed(9)
  y <- ts(rnorm(4096), frequency = 128)
  a <- allan(y)
  expect_s3_class(a, c("allan", "data.frame"))
  expect_named(a, c("tau", "m", "n", "avar", "adev", "lower", "upper", "edf",
                    "alpha"))
  expect_type(a$m, "integer")
  expect_equal(a$tau, a$m / 128)
  expect_equal(a$m, 2^(0:11))
  expect_equal(a$n, 4097 - 2 * a$m)
  expect_equal(a$adev, sqrt(a$avar))
  expect_true(all(a$lower < a$adev & a$adev < a$upper))
  expect_equal(attr(a, "freq"), 128)
  expect_equal(attr(a, "type"), "overlapping")
  expect_equal(attr(a, "input"), "rate")
  expect_equal(attr(a, "N"), 4096)
  expect_equal(attr(a, "conf"), 0.683)
  d <- as.data.frame(a)
  expect_identical(class(d), "data.frame")
  expect_null(attr(d, "freq"))
})

test_that("several channels: one curve per column, in parallel, same numbers", {
  set.seed(10)
  m <- cbind(gx = rnorm(3000), gy = cumsum(rnorm(3000)), gz = rnorm(3000, 5))
  for (type in c("overlapping", "standard", "total")) {
    a <- allan(m, 100, type = type)
    expect_named(a, c("tau", "m", "n", "avar", "adev", "lower", "upper", "edf",
                      "channel", "alpha"))
    expect_equal(unique(a$channel), colnames(m))
    for (j in colnames(m)) {
      s <- allan(m[, j], 100, type = type)
      rows <- a[a$channel == j, ]
      expect_equal(rows$avar, s$avar, tolerance = 1e-14)
      expect_equal(rows$edf, s$edf)
    }
  }
  df <- as.data.frame(m)
  expect_equal(allan(df, 100)$avar, allan(m, 100)$avar)
  expect_equal(unique(allan(unname(m), 100)$channel), c("V1", "V2", "V3"))
})

test_that("arguments are checked with clear messages", {
  expect_error(allan(), "`x` is missing",
    class = "allanvar_error_missing_argument")
  expect_error(allan(rnorm(10)), "`freq` is missing", class = "allanvar_error")
  expect_error(allan(rnorm(10), -1), "`freq` must be a single positive number",
    class = "allanvar_error_argument")
  expect_error(allan(c(1, NA, 3), 1, gaps = "error"),
               "finite numbers; found NA at position 2",
               class = "allanvar_error_values")
  expect_error(allan(cbind(a = 1:5, b = c(1, 2, Inf, 4, 5)), 1),
               "position 3 of column 2", class = "allanvar_error_values")
  expect_error(allan(letters, 1), "must be a numeric vector",
    class = "allanvar_error")
  expect_error(allan(rnorm(10), 1, type = "fast"), "`type` must be one of",
    class = "allanvar_error_argument")
  expect_error(allan(rnorm(10), 1, input = "angle"), "`input` must be one of",
    class = "allanvar_error_argument")
  expect_error(allan(rnorm(10), 1, conf = 1), "`conf` must be a single number",
    class = "allanvar_error_argument")
  expect_error(allan(1, 1), "at least 2 samples", class = "allanvar_error")
  expect_error(allan(rnorm(10), 1, taus = "weekly"), "`taus` must be",
    class = "allanvar_error")
  expect_error(allan(rnorm(10), 1, taus = -1), "`taus` must be",
    class = "allanvar_error")
  expect_error(allan(data.frame(a = 1:3, b = letters[1:3]), 1),
               "only numeric columns", class = "allanvar_error")
  expect_warning(a <- allan(rnorm(100), 1, taus = c(1, 10, 1000)),
                 "1 of the requested tau values")
  expect_equal(a$m, c(1L, 10L))
})

test_that("print, summary and plot work and leave par() alone", {
  set.seed(12)
  a <- allan(cbind(a = rnorm(2000), b = rnorm(2000, sd = 2)), 10)
  out <- capture.output(print(a))
  expect_match(out[1], "<allan> overlapping variance of rate input: N = 2,000 at 10 Hz, 2 channels")
  s <- summary(a)
  expect_equal(s$channel, c("a", "b"))
  expect_equal(s$adev_min, c(min(a$adev[a$channel == "a"]),
                             min(a$adev[a$channel == "b"])))
  expect_output(print(s), "adev_min")
  f <- tempfile(fileext = ".pdf")
  grDevices::pdf(f)
  op <- graphics::par(no.readonly = TRUE)
  expect_invisible(plot(a))
  expect_equal(graphics::par(no.readonly = TRUE)[c("mfrow", "mar", "oma")],
               op[c("mfrow", "mar", "oma")])
  grDevices::dev.off()
  unlink(f)
})

test_that("the thread count changes nothing but the last bits", {
  set.seed(13)
  y <- 3 + cumsum(rnorm(2e5))
  for (type in c("standard", "overlapping", "hadamard")) {
    old <- options(allanvar.threads = 1)
    a1 <- allan(y, 1, type = type)
    options(allanvar.threads = 2)
    a2 <- allan(y, 1, type = type)
    options(old)
    expect_equal(a2$avar, a1$avar, tolerance = 1e-14, info = type)
  }
})

# ---- interrupts and memory errors, in child R processes ----

# Child processes and memory limits: run by tools/test.sh (CI), not under
# R CMD check.
skip_in_check <- function() {
  if (nzchar(Sys.getenv("_R_CHECK_PACKAGE_NAME_"))) skip("under R CMD check")
}

# The library holding the installed allanvar (the one these tests run
# against), or a skip when the package is only loaded from source.
installed_lib <- function() {
  path <- tryCatch(find.package("allanvar"), error = function(e) "")
  if (!nzchar(path) || !dir.exists(file.path(path, "Meta"))) {
    skip("allanvar is not installed (loaded from source)")
  }
  dirname(path)
}

# Starts `run` in a child R process after `setup`, sends SIGINT `wait`
# seconds after the child reports that setup is done, and returns the
# seconds from the signal to the child catching the interrupt.
interrupt_delay <- function(setup, run, wait = 4) {
  skip_if_not_installed("callr")
  lib <- installed_lib()
  ready <- tempfile()
  done <- tempfile()
  on.exit(unlink(c(ready, done)), add = TRUE)
  p <- callr::r_bg(function(setup, run, ready, done, lib) {
    library(allanvar, lib.loc = lib)
    options(allanvar.threads = 2L)
    set.seed(1)
    env <- new.env()
    eval(parse(text = setup), env)
    writeLines("ready", ready)
    t <- tryCatch({
      eval(parse(text = run), env)
      NA_real_
    }, interrupt = function(e) as.numeric(Sys.time()))
    writeLines(format(t, digits = 16), done)
  }, args = list(setup = setup, run = run, ready = ready, done = done,
                 lib = lib))
  on.exit(p$kill(), add = TRUE)
  deadline <- Sys.time() + 120
  while (!file.exists(ready) && p$is_alive() && Sys.time() < deadline) {
    Sys.sleep(0.05)
  }
  expect_true(file.exists(ready))
  Sys.sleep(wait)
  sent <- as.numeric(Sys.time())
  p$interrupt()
  p$wait(60000)
  expect_true(file.exists(done))
  as.numeric(readLines(done)) - sent
}

test_that("Ctrl-C stops a long allan() within a second", {
  skip_on_cran()
  skip_in_check()
  # before: 460 s for the first, 11.6 s for two channels
  d <- interrupt_delay("x <- rnorm(1e7)",
                       "allan(x, 100, taus = 'all', type = 'overlapping')")
  expect_false(is.na(d))  # interrupted, not finished
  expect_lt(d, 1)
  d <- interrupt_delay("x <- matrix(rnorm(6e5), ncol = 2)",
                       "allan(x, 100, taus = 'all', type = 'overlapping')")
  expect_false(is.na(d))
  expect_lt(d, 1)
  d <- interrupt_delay("x <- matrix(rnorm(6e5), ncol = 2)",
                       "allan(x, 100, taus = 'all', type = 'total')")
  expect_false(is.na(d))
  expect_lt(d, 1)
  # a further type (src/totals.cpp): minutes of work, most of it in the
  # O(m) plans built before the parallel loop; before: no poll there
  d <- interrupt_delay("x <- rnorm(1e5)",
                       "allan(x, 1, taus = 'all', type = 'mtotdev')", wait = 2)
  expect_false(is.na(d))
  expect_lt(d, 1)
})

test_that("running out of memory in a worker thread is an R error, and R goes on", {
  skip_on_cran()
  skip_in_check()
  skip_on_os(c("windows", "mac"))
  if (nzchar(Sys.getenv("ALLANVAR_SANITIZE"))) skip("ASan: no ulimit -v")
  lib <- installed_lib()
  script <- tempfile(fileext = ".R")
  on.exit(unlink(script), add = TRUE)
  writeLines(c(
    sprintf("library(allanvar, lib.loc = '%s')", lib),
    "options(allanvar.threads = 2L)",
    "x <- tryCatch(matrix(rnorm(2e7), ncol = 2), error = function(e) NULL)",
    "if (is.null(x)) { cat('no-data\\n'); quit(status = 0) }",
    "r <- tryCatch(allan(x, 1, type = 'modified'), error = function(e) e)",
    "cat(class(r)[1], '\\n')",
    "cat('alive', sum(1:10), '\\n')"), script)
  rscript <- file.path(R.home("bin"), "Rscript")
  # 700 MB of address space: room for R and the data, not for the work
  # space of two channels at once
  out <- suppressWarnings(system2("bash", c("-c", shQuote(sprintf(
    "ulimit -v 700000; '%s' --vanilla '%s' 2>&1", rscript, script))),
    stdout = TRUE))
  if (any(grepl("no-data", out))) skip("the memory limit left no room for the data")
  if (any(grepl("^allan ", out))) skip("the limit left enough memory to finish")
  expect_true(any(grepl("allanvar_error_memory", out)), info = paste(out, collapse = "\n"))
  expect_true(any(grepl("alive 55", out)), info = paste(out, collapse = "\n"))
  expect_null(attr(out, "status"))  # exit status 0: R was not aborted
})

test_that("huge and tiny series: exact results by power-of-two scaling, or a classed error", {
  set.seed(14)
  z <- rnorm(5000)
  for (type in allan_types) {
    ref <- allan(z, 1, type = type)
    # 2^510: the squared differences overflow unless the kernel scales
    big <- allan(z * 2^510, 1, type = type)
    expect_equal(big$avar, ref$avar * 2^1020, tolerance = 1e-13, info = type)
    expect_true(all(is.finite(big$upper)), info = type)
    expect_equal(big$edf, ref$edf, info = type)
  }
  # integrated input at 1e300 Hz: phase 1e-290 s, AV about 1e20
  w <- cumsum(z)
  a <- allan(w * 1e-290, 1e300, input = "integrated")
  b <- allan(w, 1e10, input = "integrated")
  expect_equal(a$avar, b$avar, tolerance = 1e-13)
  # variances beyond the double range are refused, not returned as Inf or 0
  expect_error(allan(z * 1e200, 1), class = "allanvar_error_overflow")
  expect_error(allan(z * 1e-300, 1), class = "allanvar_error_underflow")
  expect_error(allan(w, 1e300, input = "integrated"),
               class = "allanvar_error_overflow")
  # a constant series near the top of the range has variance 0
  expect_equal(allan(rep(1e300, 100), 1)$avar, rep(0, 6))
})

# ---- gaps ----

# The gap rule written out term by term (allantools' gradev for the
# overlapping phase case): a term is kept when every value it uses is there.
gap_reference <- function(v, m, type, rate) {
  x <- if (rate) c(0, cumsum(ifelse(is.na(v), 0, v))) else v
  L <- length(x)
  d <- if (type %in% c("standard", "overlapping")) 2 else 3
  w <- if (d == 2) c(1, -2, 1) else c(-1, 3, -3, 1)
  step <- if (type %in% c("standard", "hadamard")) m else 1
  span <- if (type == "modified") 3 * m else d * m
  s <- 0
  n <- 0
  k <- 0
  last <- if (type == "modified") L - span else L - 1 - span  # last k
  while (k <= last) {
    if (rate) {
      # samples k .. k + span - 1 (modified: X_k .. X_{k+3m-1}, so one fewer)
      used <- v[(k + 1):(k + span - (type == "modified"))]
    } else if (type == "modified") {
      used <- v[(k + 1):(k + span)]             # points k .. k + 3m - 1
    } else {
      used <- v[k + 1 + (0:d) * m]
    }
    if (!anyNA(used)) {
      t <- if (type == "modified") {
        sum(vapply(0:(m - 1), function(j) sum(c(1, -2, 1) * x[k + j + 1 + (0:2) * m]), 0))
      } else {
        sum(w * x[k + 1 + (0:d) * m])
      }
      s <- s + t^2
      n <- n + 1
    }
    k <- k + step
  }
  norm <- switch(type, modified = 2 * m^4, hadamard = , ohadamard = 6 * m^2,
                 2 * m^2)
  c(avar = s / (norm * n), n = n)
}

test_that("gaps = \"skip\": every term that touches a missing value is left out", {
  set.seed(16)
  v <- cumsum(rnorm(60))
  v[c(7, 20:22, 41)] <- NA
  v[33] <- NaN
  for (rate in c(TRUE, FALSE)) {
    for (type in c("overlapping", "standard", "modified", "hadamard", "ohadamard")) {
      a <- suppressWarnings(allan(v, 1, taus = "all", type = type,
                                  input = if (rate) "rate" else "integrated",
                                  gaps = "skip"))
      for (i in seq_len(nrow(a))) {
        ref <- gap_reference(v, a$m[i], type, rate)
        expect_equal(a$n[i], ref[["n"]], info = paste(type, rate, a$m[i]))
        expect_equal(a$avar[i], ref[["avar"]], tolerance = 1e-12,
                     info = paste(type, rate, a$m[i]))
      }
      expect_equal(attr(a, "missing"), c(x = 6L))
    }
  }
  # without gaps, "skip" changes nothing
  w <- rnorm(500)
  expect_equal(allan(w, 1, gaps = "skip"), allan(w, 1))
  # skipping is the default; gaps = "error" refuses NA and says what to do;
  # Inf is never a gap
  expect_equal(suppressWarnings(allan(v, 1)),
               suppressWarnings(allan(v, 1, gaps = "skip")))
  expect_error(allan(v, 1, gaps = "error"), class = "allanvar_error_values")
  expect_error(allan(v, 1, gaps = "error"), "gaps = \"skip\"",
    class = "allanvar_error_values")
  # tdev now has the modified gap rule (test-types.R); a type without one:
  expect_error(allan(v, 1, type = "mtotdev"), class = "allanvar_error_gaps")
  expect_error(allan(c(1, Inf, NA, 4, 5), 1, gaps = "skip"),
               "found Inf at position 2", class = "allanvar_error_values")
  expect_error(allan(v, 1, type = "total", gaps = "skip"),
               class = "allanvar_error_gaps")
  expect_output(print(suppressWarnings(allan(v, 1, gaps = "skip"))), "6 missing")
  # a cluster size whose every term spans a gap is left out, with a warning
  expect_warning(allan(c(1, 2, NA, 4, 5, 6, 7), 1, taus = "all", gaps = "skip"),
                 class = "allanvar_warning_gaps")
})

test_that("gaps against allantools' gradev reference data (optional)", {
  root <- Sys.getenv("ALLANVAR_PEER_DATA")
  skip_if_not(nzchar(root) && dir.exists(file.path(root, "tests", "gradev")),
              "ALLANVAR_PEER_DATA (an allantools checkout) is not set")
  d <- file.path(root, "tests", "gradev")
  y <- scan(file.path(d, "y.dat"), quiet = TRUE)
  yg <- scan(file.path(d, "y_gap.dat"), quiet = TRUE)
  expect_gt(sum(is.na(yg)), 0)
  m <- c(1, 2, 3, 5, 10, 20, 50, 100, 200)
  a <- suppressWarnings(allan(yg, 1, taus = m, input = "integrated",
                              gaps = "skip"))
  for (mm in m) {
    ref <- gap_reference(yg, mm, "overlapping", FALSE)
    if (ref[["n"]] == 0) {
      expect_false(mm %in% a$m)
      next
    }
    i <- match(mm, a$m)
    expect_equal(a$avar[i], ref[["avar"]], tolerance = 1e-12)
    expect_equal(a$n[i], ref[["n"]])
  }
  expect_gte(nrow(a), 5)
  # allantools' own check: the gap curve stays within e of the full one
  b <- allan(y, 1, taus = a$tau, input = "integrated")
  expect_true(all(abs(log(a$adev / b$adev)) < 1))
})
