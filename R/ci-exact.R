# Exact confidence limits at few averages. Where N/m is
# small the Allan-family estimate over its expectation is far from a
# chi-square with the two-moment EDF: it is a generalized chi-square,
# sum_i lambda_i chi2_1, the lambda the eigenvalues of its terms'
# covariance under the power-law noise (src/gchisq.cpp), skewed when a few
# dominate. Its quantiles (Imhof's integral) give the interval
# [adev / sqrt(q_{1-p}), adev / sqrt(q_p)].
#
# The noise type is read from the data at each tau, and at a few averages
# that reading is weak; so a row rests on the reading at many averages
# where the curve has one, else on the union of the intervals of the types
# its own reading leaves plausible (exact_sets()); for values corrected by
# the type read, on the shortest interval holding every such type
# (exact_minimax()).
#
# Which rows: N/m <= getOption("allanvar.ci_exact", 32) (N rate samples);
# Inf makes every row exact, 0 none. Types: the Allan and Hadamard families
# (standard, overlapping, modified, hadamard, ohadamard; tdev through
# modified, TheoH's Allan rows through overlapping) and PDEV; the total family and
# Theo1 by their dense quadratic forms (R/ci-exact-forms.R), the catalogue
# entries' `exact_form`.
#
# Cost: an eigenproblem of the terms (at most `exact_nmax` of them) and two
# Imhof quantiles per (type, m, n, alpha, conf), cached for the session.
# Larger problems are scaled down: the terms of non-overlapping types at
# m > exact_mcap are taken at m = exact_mcap (the same n; for FM noise the
# correlation of the terms is that of the continuous-time limit within a
# few 1e-3 there, for white PM it does not depend on m, for flicker PM
# slowly through ln m); overlapping types keep n/m at m' = min(m,
# exact_mcap, m nmax / n). Under PM noise the overlapping estimators' EDF
# grows with m at fixed N/m, which that scaling would lose: they are
# computed as they are up to exact_nmax_pm terms (0.3 s at 900), and
# beyond keep the chi-square interval, whose EDF there is large (white PM
# about N/2; flicker PM 20 at N/m = 4, m = 1000).

#' @name allan
#' @rdname allan
#' @section Exact intervals at few averages:
#' Where a row has few averages, \eqn{N/m \le 32} (\eqn{N} rate samples),
#' the limits of the Allan and Hadamard types (`"standard"`,
#' `"overlapping"`, `"modified"`, `"hadamard"`, `"ohadamard"`, and so
#' `"tdev"`; `"pdev"`; the total family `"total"`, `"mtotdev"`, `"ttotdev"`,
#' `"htotdev"`; and `"theo1"`) are not the chi-square ones: the estimate
#' over its expectation
#' is a generalized chi-square, \eqn{\sum_i \lambda_i \chi^2_1} with
#' \eqn{\lambda_i} the eigenvalues of the covariance of its terms under
#' discrete power-law noise of the row's noise type (\eqn{x = (1 -
#' B)^{-(2 - \alpha)/2} e}; for the total family and Theo1, whose terms
#' come from a reflected or detrended record, the eigenvalues of their
#' quadratic form in the phase under that noise started at rest), and the
#' interval is
#' \eqn{[\sigma / \sqrt{q_{1-p}}, \sigma / \sqrt{q_p}]} with its quantiles
#' \eqn{q} (Imhof's integral). `"theobr"`, and TheoH's TheoBR rows, are Theo1 times
#' the bias factor estimated from the same record: their law is Theo1's
#' with the factor's spread joined in log scale (a normal variable with the
#' factor's EDF, correlated with \eqn{\log} Theo1 as the Monte Carlo
#' tables of its EDF give), where the chi-square with their two-moment EDF
#' was too skewed (68% coverage 0.79-0.93 at \eqn{N/m \le 4}). The noise type read at a few averages is
#' weak (B1 from a handful of averages reads an FM type as its whiter
#' neighbour in a third to all of the records), so a row rests on the
#' type read at the nearest shorter tau with \eqn{N/m \ge 64} (the lag-1
#' autocorrelation from 64 or more averages) where that is an FM type,
#' joined with the row's own reading and its redder neighbour only where
#' the own reading is redder (the type may turn redder at long tau).
#' Without such a row, or where it reads PM, the interval is the union
#' over the types the row's own reading leaves plausible: an FM type and
#' its redder neighbour; below \eqn{N/m = 8}, where flicker PM and white
#' FM can no longer be told apart, the type read at the nearest shorter tau
#' with \eqn{N/m \ge 8}. Where the value carries the bias correction of
#' the type read (`"mtotdev"`, `"ttotdev"`, `"htotdev"`, `"theo1"`), a
#' whiter own reading joins too, each candidate type moves the interval by
#' the ratio of its correction to the one applied, and the limits are the
#' shortest interval that holds the level under every candidate type
#' rather than the union (which over-covered: 0.78 at 68%, `"htotdev"`
#' under random-walk FM at \eqn{N/m = 32}). The total type's rows take the noise type as
#' `"overlapping"` reads it (its own reading leans to white FM at long
#' tau). So the limits of a row at few averages depend on
#' the taus computed with it: a curve's default grid has the rows at many
#' averages. The threshold is 32: with the type read at a single point,
#' chi-square limits at \eqn{N/m = 17-32} covered 0.917-0.920 (95%) of
#' random-walk FM records (overlapping, TDEV, TheoH; 1000 records of 1024,
#' `tools/mc-coverage.R`). `options(allanvar.ci_exact = k)` moves the threshold
#' \eqn{N/m \le k} (`Inf`: every row, `0`: chi-square everywhere). The
#' `edf` column keeps the two-moment EDF. Series with missing values
#' (`gaps = "skip"`) keep the chi-square limits (their terms are not a
#' stationary sequence). Each (type, \eqn{m}, terms,
#' type of noise, level) is computed once per session; large problems are
#' scaled to at most 300 terms at \eqn{m \le 64} with the same
#' \eqn{N/m} (FM noise), or, under PM noise on the overlapping types
#' beyond 1000 terms, keep the chi-square interval. The total family and
#' Theo1 take their law at the same \eqn{N/m} on at most 513 phase points
#' under FM noise and, under PM noise, as it is up to 1100 points (beyond,
#' the chi-square interval); such a problem costs about a second the first
#' time (Theo1's union over plausible types several). On a dense grid of an
#' overlapping type (`taus = "all"`) the factors are computed at knots 5%
#' apart in \eqn{m} and in the number of terms and interpolated in
#' \eqn{\log m} between them (within 1% of each row's own).
NULL

exact_nmax <- 300L
exact_mcap <- 64L
exact_nmax_pm <- 1000L
exact_read_min <- 8
exact_read_sure <- 64
exact_cache <- new.env(parent = emptyenv())

# Types with exact limits, by allan()'s names.

# The rows whose limits are exact: N/m at or below the option's threshold.
exact_rows <- function(m, L) {
  lim <- getOption("allanvar.ci_exact", 32)
  if (!is.numeric(lim) || length(lim) != 1L || is.na(lim)) {
    abort("`options(allanvar.ci_exact)` must be a single number (N/m at ",
          "or below which limits are exact; Inf for every row), not ",
          format(lim)[1L], ".", class = "argument")
  }
  (L - 1) / m <= lim
}

# Lower and upper factors (times the deviation) of the exact interval for
# one problem: type code, cluster size m, n terms, noise exponent alpha
# (integer), level conf. NA where it does not apply (see above).
exact_factors_one <- function(code, m, n, alpha, conf) {
  pr <- exact_problem_one(code, m, n, alpha)
  if (is.null(pr)) return(c(NA_real_, NA_real_))
  key <- paste(code, pr[1L], pr[2L], alpha, format(conf, digits = 15),
               sep = ":")
  hit <- exact_cache[[key]]
  if (!is.null(hit)) return(hit)
  out <- gchisq_factors(exact_weights_one(code, pr, alpha), conf)
  assign(key, out, envir = exact_cache)
  out
}

# The problem a row is computed as: c(m, n) scaled as described above, or
# NULL where the exact route does not apply.
exact_problem_one <- function(code, m, n, alpha) {
  ov <- Find(function(s) s$code == code, stat_catalogue())$overlapping
  if (ov && alpha >= 1L) {
    # PM: no scaling (the EDF grows with m at fixed N/m); the problem as it
    # is up to exact_nmax_pm terms
    if (n > exact_nmax_pm) return(NULL)
    return(c(m, n))
  }
  if (ov) {
    mp <- min(m, exact_mcap, max(1, floor(m * exact_nmax / n)))
    return(c(mp, max(1, round(n * mp / m))))
  }
  c(min(m, exact_mcap), n)
}

# The law's weights of problem `pr` (exact_problem_one()), cached.
exact_weights_one <- function(code, pr, alpha) {
  key <- paste(code, pr[1L], pr[2L], alpha, "w", sep = ":")
  hit <- exact_cache[[key]]
  if (!is.null(hit)) return(hit)
  lam <- gchisq_weights_cpp(as.integer(code), pr[1L], pr[2L],
                            as.integer(alpha))
  assign(key, lam, envir = exact_cache)
  lam
}

# The interval's factors c(lower, upper) on the deviation from the law's
# weights `lam` (sum lam_i chi2_1 over its mean) at confidence `conf`.
gchisq_factors <- function(lam, conf) {
  p <- (1 - conf) / 2
  if (gchisq_equal(lam)) {
    nu <- length(lam)  # equal weights: the chi-square itself
    q <- stats::qchisq(c(p, 1 - p), nu) / nu
  } else {
    q <- gchisq_quantile_cpp(lam, c(p, 1 - p))
  }
  c(sqrt(1 / q[2L]), sqrt(1 / q[1L]))
}

# Whether the weights are equal (the law is a chi-square with length(lam)
# degrees of freedom).
gchisq_equal <- function(lam) {
  length(lam) == 1L || max(lam) - min(lam) < 1e-12 * max(lam)
}

# The CDF of the law with weights `lam` (over their sum; mean 1): the
# chi-square where they are equal.
gchisq_cdf_fun <- function(lam) {
  if (gchisq_equal(lam)) {
    nu <- length(lam)
    return(function(q) stats::pchisq(q * nu, nu))
  }
  function(q) gchisq_cdf_cpp(lam, q)
}

# The shortest interval that holds `conf` under each of several laws. Under
# law k, sigma_hat^2 s_k / sigma^2 has the CDF cdfs[[k]] (mean 1), s_k the
# ratio of law k's bias correction to the one applied; `f` holds the laws'
# equal-tailed factors (2 x k). Their union holds `conf` under each law
# too, but where the corrections shift the laws against each other it
# spends each law's far tail on nothing (HTOT under random-walk FM, N =
# 1024, N/m = 32: 68% coverage 0.779). Each CDF is evaluated at 25 points
# of the variance ratio v spanning the union and interpolated as
# qnorm(P) against log v (monotone spline; within 1e-4 of the CDF itself
# on HTOT's laws at N/m = 4-32); for each lower end t the least upper end
# w that holds every law; the shortest w / t wins. Returns factors
# c(lower, upper) on the deviation, never wider than the union.
exact_minimax <- function(cdfs, s, f, conf) {
  union <- c(min(f[1L, ]), max(f[2L, ]))
  lv <- seq(-2 * log(union[2L]) - 0.02, -2 * log(union[1L]) + 0.02,
            length.out = 25L)
  tl <- seq(lv[1L], lv[length(lv)], length.out = 2001L)
  Pt <- vapply(seq_along(cdfs), function(k) {
    p <- cummax(pmin(pmax(cdfs[[k]](s[k] * exp(lv)), 1e-12), 1 - 1e-12))
    stats::pnorm(stats::splinefun(lv, stats::qnorm(p), method = "monoH.FC")(tl))
  }, numeric(length(tl)))
  w <- rep(-Inf, length(tl))
  for (k in seq_along(cdfs)) {
    target <- Pt[, k] + conf
    wk <- rep(Inf, length(tl))
    ok <- target <= Pt[length(tl), k]
    if (any(ok)) {
      wk[ok] <- stats::approx(Pt[, k], tl, target[ok], ties = min)$y
    }
    w <- pmax(w, wk)
  }
  j <- which.min(w - tl)
  if (!length(j) || !is.finite(w[j]) ||
      w[j] - tl[j] >= 2 * log(union[2L] / union[1L])) {
    return(union)
  }
  exp(-c(w[j], tl[j]) / 2)
}

# The noise exponents whose intervals are joined at a row, from the row's
# own reading (exact_alpha()). At N/m <= 16 B1 with Stable32's count errs
# toward the whiter neighbour under FM noise (Monte Carlo, N = 1024,
# overlapping, 2000 records: random-walk FM read as random walk in at most
# 1 record, mostly as flicker FM; flicker FM read right in 26-33%, else as
# white FM), while white PM is read right in 95-100% of records at N/m >= 4
# and flicker PM in 90-100%. So: an FM reading joins its redder neighbour
# (alpha - 1); a PM reading stands alone.
exact_alts <- function(alpha, lo) {
  if (is.na(alpha)) return(lo:2L)
  if (alpha >= 1L) return(alpha)
  max(lo, alpha - 1L):alpha
}

# The noise exponent each row's own reading gives. Below N/m = 8 the
# reading of flicker PM against white FM fails (overlapping, N = 1024:
# flicker PM read right in 98% of records at N/m = 8, 34-37% at 4-6; at
# N/m = 2-3 every noise reads as white FM or nothing), so such rows, and
# rows without a reading, take the reading of the nearest shorter tau with
# N/m >= `min_avg` (one octave back on an octave grid); NA where there is
# none.
exact_alpha <- function(m, L, alpha, min_avg = exact_read_min) {
  own <- ifelse((L - 1) / m >= min_avg, alpha, NA_integer_)
  o <- order(m)
  a <- own[o]
  last <- NA_integer_
  for (i in seq_along(a)) {
    if (is.na(a[i])) a[i] <- last else last <- a[i]
  }
  out <- integer(length(m))
  out[o] <- a
  out
}

# The reading of another statistic (`base`, the entry's exact_id) at the
# rows exact_sets() reads: the exact rows, those with N/m below
# exact_read_sure, and the longest tau at or above it (the fill-forward
# stops there when it reads a type); NA elsewhere. At stride 1 each row
# costs a pass over the samples, so reading the whole curve doubled the
# total type's cost at 1e7. Where that row reads nothing, or the curve is
# long enough that extra_alpha() identifies through allan(), every row is
# read, as before.
# `mx`: max(abs(v)) where the caller has it (NA: read here).
exact_id_alpha <- function(v, freq, m, base, input, L, mx = NA) {
  few <- (L - 1) / m < exact_read_sure | exact_rows(m, L)
  keep <- few
  if (any(!few)) keep[which(!few)[which.max(m[!few])]] <- TRUE
  if (all(keep) || length(unique(m)) > 200L) {
    return(extra_alpha(v, freq, m, base, input, L, mx))
  }
  out <- rep(NA_integer_, length(m))
  out[keep] <- extra_alpha(v, freq, m[keep], base, input, L, mx)
  if (any(!few) && anyNA(out[keep & !few])) {
    return(extra_alpha(v, freq, m, base, input, L, mx))
  }
  out
}

# The noise exponents a row's interval rests on. Where the curve has a row
# with N/m >= exact_read_sure at a shorter tau (the lag-1 ACF reading from
# 64 or more averages: right in 97-100% of records under white FM and,
# for the Allan types, random-walk FM (83% for the Hadamard types); in
# about half under flicker FM, whose neighbours' intervals are close at
# these N/m), a row at few
# averages takes that reading, and joins the types its own weak reading
# leaves plausible (exact_alts()) only when that reading is redder (the
# type may turn redder at long tau: random-walk FM after white FM). Its own
# reading alone, joined with the redder neighbour, covered white FM at
# 0.74-0.76 (68%) and random-walk FM at 0.92 (95%, N/m = 3) on the
# overlapping types (2000 records, N = 1024), since B1 from a few
# averages cannot tell an FM type from its neighbour. Without such a row,
# or where it reads PM: the union over the own reading's plausible types
# (the ACF of cluster averages reads white PM as flicker PM in a quarter of
# records at 64 averages, where R(n), in the own reading, tells them apart:
# white PM's 68% coverage was 0.75-0.77 on the ACF's reading), joined with
# the PM reading (and the types between) where the own one differs: under
# flicker PM (Theo1, N = 1024, N/m = 8) 2% of records read white FM at the
# row, and their FM-only intervals never covered (95%: 0.927 over all
# records; 0.947 with the PM reading joined, white PM unchanged). Monte Carlo
# (tools/mc-coverage-exact.R, curves with the octave taus below the rows,
# 2000 records, N = 1024): 190 of 190 rows in both bands.
# `join_own`: a whiter own reading joins too (the types between), for the
# types whose value carries the bias correction of the type read: the
# shorter tau's reading alone moved the interval by the ratio of the two
# corrections (HTOT under flicker FM at N/m = 32, where 64 averages read
# random-walk FM in some records: 95% coverage 0.912, N = 1024).
exact_sets <- function(m, L, alpha, lo, join_own = FALSE) {
  own <- exact_alpha(m, L, alpha)
  sure <- exact_alpha(m, L, alpha, exact_read_sure)
  lapply(seq_along(m), function(i) {
    weak <- exact_alts(own[i], lo)
    if (is.na(sure[i])) return(weak)
    if (sure[i] >= 1L) {
      if (!is.na(own[i]) && own[i] != sure[i]) {
        return(seq.int(min(weak, sure[i]), max(weak, sure[i])))
      }
      return(weak)
    }
    if (!is.na(own[i]) && own[i] < sure[i]) {
      return(sort(unique(c(weak, sure[i]))))
    }
    if (join_own && !is.na(own[i]) && own[i] > sure[i]) {
      return(seq.int(sure[i], own[i]))
    }
    sure[i]
  })
}

#' Exact limits of the rows at few averages (internal)
#'
#' The hook of allan()'s limits: lower and upper factors (multiply the
#' deviation) of the generalized chi-square interval, the union over the
#' plausible noise types, for the rows where they apply (`exact_rows()`),
#' `NA` elsewhere. The law comes from the stationary terms (Allan and
#' Hadamard families) or, for an entry with an `exact_form`, from its dense
#' quadratic form (R/ci-exact-forms.R).
#' @param type allan()'s type name.
#' @param m,n,L cluster sizes, numbers of terms, phase points.
#' @param alpha identified integer noise exponents (`NA`: unknown).
#' @param conf confidence level.
#' @param sets the noise exponents to join at each row (a list), or `NULL`:
#'   `exact_sets()`.
#' @param debias whether the deviation carries the bias correction of the
#'   type read (`alpha`): a candidate type's interval then takes its own.
#' @return A list of numeric vectors `lower` and `upper`, one per row.
#' @noRd
allan_limits_exact <- function(type, m, n, L, alpha, conf, sets = NULL,
                               debias = FALSE) {
  k <- length(m)
  lower <- upper <- rep(NA_real_, k)
  e <- stat_entry(type)
  if (!isTRUE(e$exact_ci)) return(list(lower = lower, upper = upper))
  rows <- which(exact_rows(m, L) & n >= 1)
  if (!length(rows)) return(list(lower = lower, upper = upper))
  dense <- !is.null(e$exact_form)
  code <- allan_type_code(type)
  lo <- e$alpha_range[1L]
  alpha <- rep_len(as.integer(alpha), k)
  if (is.null(sets)) sets <- exact_sets(m, L, alpha, lo, join_own = debias)
  rule <- stat_edf_rules()[[e$edf]]
  one <- function(i, a) {
    if (dense) {
      exact_dense_factors(e$exact_form, m[i], L, a, conf)
    } else {
      exact_factors_one(code, m[i], n[i], a, conf)
    }
  }
  tab <- exact_factor_table(rows, sets, m, n, one,
                            smooth = dense || isTRUE(e$overlapping))
  # the CDF of row i's law under alpha a (NULL: left to chi-square)
  law <- function(i, a) {
    if (dense) {
      pr <- exact_dense_problem(m[i], L, a)
      if (is.null(pr)) return(NULL)
      return(gchisq_cdf_fun(exact_dense_weights(e$exact_form, pr[1L],
                                                pr[2L], a)))
    }
    pr <- exact_problem_one(code, m[i], n[i], a)
    if (is.null(pr)) NULL else gchisq_cdf_fun(exact_weights_one(code, pr, a))
  }
  for (i in rows) {
    f <- vapply(sets[[i]], function(a) {
      f1 <- tab[[as.character(a)]][, match(i, rows)]
      if (anyNA(f1)) {
        # a type the exact route leaves to chi-square: its interval
        ed <- rule(e, m[i], n[i], L, a)
        f1 <- sqrt(ed / stats::qchisq(c(1 - (1 - conf) / 2, (1 - conf) / 2),
                                      ed))
      }
      if (debias) {
        f1 <- f1 * sqrt(debias_factor(type, a, m[i]) /
                          debias_factor(type, alpha[i], m[i]))
      }
      f1
    }, numeric(2))
    if (debias && length(sets[[i]]) > 1L) {
      # laws shifted by their corrections: the shortest interval holding
      # every one (exact_minimax()), not the union
      a <- sets[[i]]
      key <- paste(type, m[i], n[i], L, paste(a, collapse = ","), alpha[i],
                   format(conf, digits = 15), paste(format(f, digits = 15),
                                                    collapse = ","),
                   "minimax", sep = ":")
      hit <- exact_cache[[key]]
      if (is.null(hit)) {
        s <- debias_factor(type, a, rep(m[i], length(a))) /
          debias_factor(type, alpha[i], m[i])
        cdfs <- lapply(a, function(al) {
          cdf <- law(i, al)
          if (!is.null(cdf)) return(cdf)
          ed <- rule(e, m[i], n[i], L, al)
          function(q) stats::pchisq(q * ed, ed)
        })
        hit <- exact_minimax(cdfs, s, f, conf)
        assign(key, hit, envir = exact_cache)
      }
      f <- matrix(hit, 2L)
    }
    lower[i] <- min(f[1L, ])
    upper[i] <- max(f[2L, ])
  }
  list(lower = lower, upper = upper)
}

# The exact factors of `rows` under each noise exponent in their `sets`: a
# list by alpha of 2 x length(rows) matrices (NA: rows without that alpha,
# or where the exact route leaves it to chi-square). `one(i, a)` computes
# a row. On a dense grid of an overlapping type (taus = "all": thousands
# of rows, each its own problem, 17 s for N = 1001) the factors, smooth in
# m there, are computed at knots spaced by at most exact_knot_step in m
# (and in the number of terms) and interpolated linearly in log m between
# knots that both have them: within 3e-4 of each row's own on white PM,
# N = 1001, overlapping, 7e-3 on random-walk FM, ohadamard (where the
# scaled problems jitter by as much), 66 s -> 15 s and 161 s -> 92 s on a
# loaded machine (tests/testthat/test-ci-exact.R checks 1e-2); the
# non-overlapping types' problems are keyed by whole numbers of terms,
# few on any grid, and each row is computed.
exact_factor_table <- function(rows, sets, m, n, one, smooth) {
  alphas <- sort(unique(unlist(sets[rows])))
  out <- list()
  for (a in alphas) {
    f <- matrix(NA_real_, 2L, length(rows))
    r <- rows[vapply(sets[rows], function(s) a %in% s, NA)]
    r <- r[order(m[r])]
    col <- match(r, rows)
    if (!smooth || length(r) <= exact_knots_min) {
      f[, col] <- vapply(r, one, numeric(2), a = a)
    } else {
      k <- exact_knots(m[r], n[r])
      f[, col[k]] <- vapply(r[k], one, numeric(2), a = a)
      for (j in seq_along(k)[-1L]) {
        inner <- seq.int(k[j - 1L] + 1L, length.out = k[j] - k[j - 1L] - 1L)
        if (!length(inner)) next
        f1 <- f[, col[k[j - 1L]]]
        f2 <- f[, col[k[j]]]
        if (anyNA(c(f1, f2))) {
          f[, col[inner]] <- vapply(r[inner], one, numeric(2), a = a)
        } else {
          w <- log(m[r[inner]] / m[r[k[j - 1L]]]) /
            log(m[r[k[j]]] / m[r[k[j - 1L]]])
          f[, col[inner]] <- outer(f1, 1 - w) + outer(f2, w)
        }
      }
    }
    out[[as.character(a)]] <- f
  }
  out
}
exact_knots_min <- 24L
exact_knot_step <- 1.05

# Knots among sorted cluster sizes `ms` with their numbers of terms `ns`
# (falling as m grows): the first, the last, and each further one the
# largest m within exact_knot_step of the previous knot in both m and n
# (at least the next row; with few terms the law moves with each one).
exact_knots <- function(ms, ns) {
  k <- 1L
  len <- length(ms)
  while (k[length(k)] < len) {
    last <- k[length(k)]
    ok <- ms <= ms[last] * exact_knot_step &
      pmax(ns, ns[last]) <= pmin(ns, ns[last]) * exact_knot_step
    ok[seq_len(last)] <- TRUE
    nxt <- max(last + 1L, which.min(c(ok, FALSE)) - 1L)
    k <- c(k, min(len, nxt))
  }
  k
}

# allan()'s chi-square limits (allan_ci()) with the exact ones put in where
# allan_limits_exact() gave them.
exact_limits_merge <- function(ci, ex) {
  ok <- which(!is.na(ex$lower))
  if (length(ok)) {
    ci$lower[ok] <- ci$adev[ok] * ex$lower[ok]
    ci$upper[ok] <- ci$adev[ok] * ex$upper[ok]
  }
  ci
}
