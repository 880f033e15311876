# The Theo1 kernels of src/theo.cpp against the direct evaluation of
# NIST SP 1065 eq. (30) in R (ref_theo1, helper-types-ref.R). The noise is
# made here from rnorm(): white PM, white FM (its sum), random-walk FM (the
# double sum), and white FM on a large offset and quadratic drift.

theo_T_ref <- function(x, m) ref_theo1(x, m) * 0.75 * (length(x) - m) * m^2

theo_sets <- function(N, seed) {
  set.seed(seed)
  w <- rnorm(N)
  list(wpm = w, wfm = cumsum(w), rwfm = cumsum(cumsum(w)),
       drift = cumsum(w) + 1e6 + 0.01 * seq_len(N)^2)
}

test_that("fast blocked Theo1 sums agree with the direct evaluation to 1e-10", {
  for (N in c(257L, 1000L, 2001L)) {
    top <- 2 * ((N - 1) %/% 2)
    m <- unique(c(2, 4, 6, 2 * (N %/% 8), 2 * (N %/% 6), 2 * (N %/% 4),
                  2 * (N %/% 3), top - 2, top))
    for (nm in names(theo_sets(N, N))) {
      x <- theo_sets(N, N)[[nm]]
      ref <- vapply(m, function(mm) theo_T_ref(x, mm), 0)
      fast <- theo1_sums_cpp(x, FALSE, m, 1L, 2L)
      direct <- theo1_sums_cpp(x, FALSE, m, 1L, 1L)
      lab <- paste(nm, N)
      expect_lt(max(abs(fast / ref - 1)), 1e-10, label = lab)
      expect_lt(max(abs(direct / ref - 1)), 1e-10, label = lab)
    }
  }
})

test_that("fast Theo1 sums from rate input match those from its phase", {
  set.seed(5)
  y <- cumsum(rnorm(999))  # random-walk FM as frequency
  x <- c(0, cumsum(y))
  m <- c(2, 100, 332, 600, 998)
  expect_equal(theo1_sums_cpp(y, TRUE, m, 1L, 2L),
               vapply(m, function(mm) theo_T_ref(x, mm), 0), tolerance = 1e-10)
})

test_that("allan() picks the fast path at long records and stays exact", {
  N <- 20000L
  for (nm in c("wpm", "rwfm")) {
    x <- theo_sets(N, 9)[[nm]]
    a <- allan(x, 1, type = "theo1", input = "integrated", debias = FALSE)
    expect_equal(a$m, 2^(1:14))
    # the largest m take the fast path (cost model); the direct C++ stencil
    # (itself checked against ref_theo1 above) is the reference here
    m <- a$m[a$m >= 512]
    T <- theo1_sums_cpp(x, FALSE, m, 2L, 1L)
    ref <- T / (0.75 * (N - m) * m^2)
    expect_lt(max(abs(a$avar[a$m >= 512] / ref - 1)), 1e-10, label = nm)
  }
})
