# Equivalent degrees of freedom (EDF) and chi-square confidence intervals
# for allan(). The noise type at each tau comes from the C++ kernel (Riley's
# lag-1 autocorrelation identification); this file turns it into an EDF
# (computed in src/edf.cpp):
#  * exact Gaussian moments (Isserlis) for discrete white or random-walk
#    noise at small m, where Greenhall's continuous-time model overstates
#    the EDF (782 instead of 666 for white noise, m = 1, N = 1000);
#  * Greenhall & Riley (2004) general algorithm otherwise;
#  * NIST SP 1065 Tables 5 and 7 for the total variance (src/edf.cpp);
#  * PDEV: the exact moments of its terms under discrete power-law noise.

# Where the noise id and the EDF are evaluated directly: every row of a
# short curve; for long ones ("all"), every m <= 64 plus 40 points per
# decade. The rest take the noise type of the nearest such m (in log tau)
# and a log-log interpolation of the EDF.
allan_subset <- function(m) {
  if (length(m) <= 200L) return(seq_along(m))
  first <- findInterval(64, m) + 1L  # m is sorted: the first m > 64
  if (first > length(m)) return(seq_along(m))
  t <- 10^seq(log10(m[first]), log10(m[length(m)]), by = 1 / 40)
  # t[1] may round to just below m[first]: findInterval() then gives the
  # row before it, 0 when first = 1 (no row 0: alpha and m would misalign)
  sort(unique(c(seq_len(first - 1L), pmax(1L, findInterval(t, m)), first,
                length(m))))
}

# EDF for every row of a curve. alpha_int: identified noise exponent at the
# rows `sub`; NA where the data were too few to tell (fewer than three
# averaged frequencies): such a row gets the smallest EDF over the exponents
# the type admits (the widest interval) and alpha NA. No row takes its type
# from another row.
allan_edf <- function(type, m, n, L, alpha_int, sub = seq_along(m)) {
  e <- if (is.list(type)) type else stat_entry(type)
  rule <- stat_edf_rules()[[e$edf]]
  lo <- e$alpha_range[1L]
  a <- pmin(2L, pmax(lo, as.integer(alpha_int)))
  es <- rep(NA_real_, length(sub))
  known <- !is.na(a)
  if (any(known)) {
    es[known] <- rule(e, m[sub][known], n[sub][known], L, a[known])
  }
  for (i in which(!known)) {
    es[i] <- min(vapply(lo:2L, function(al) {
      rule(e, m[sub][i], n[sub][i], L, al)
    }, 0))
  }
  if (length(sub) == length(m)) {
    return(list(edf = pmax(es, 1e-3), alpha = a))
  }
  # m[1] is always in sub, so every row has an evaluated row at or below it.
  edf_interpolate_cpp(as.double(m), as.integer(sub), as.double(es),
                      as.integer(a))
}

# EDF at the rows where it is evaluated directly (src/edf.cpp): type
# "standard", "overlapping", ... (allan()'s names), cluster sizes m, terms n,
# L phase points, integer noise exponents alpha. Where no formula gives a
# positive finite EDF the entry's `edf_fallback` is used (the number of
# terms; the total type: 1.5 (L - 1)/m, NIST SP 1065 Table 7's white-FM
# value).
allan_edf_direct <- function(type, m, n, L, alpha) {
  alpha <- rep_len(as.integer(alpha), length(m))
  n <- rep_len(as.double(n), length(m))
  exact <- alpha %in% c(0L, -2L) & m <= 64
  s <- stat_entry(type)
  e <- allan_edf_cpp(s$code, as.double(m), as.double(n),
                     as.double(L), alpha, exact)
  fl <- s$name != "total" & alpha %in% c(-1L, 1L) & is.finite(e) & e > 0
  if (any(fl)) e[fl] <- edf_flicker(s, m[fl], n[fl], alpha[fl], e[fl])
  # the total type under flicker PM: edf_total() gives the overlapping
  # type's Greenhall EDF, 15-20% below the Monte Carlo EDF at N/m = 16-256
  # (N = 1024: 285 for 346 at N/m = 128; 95% coverage 0.977), which the
  # overlapping type's exact EDF follows (336, 232, 151, 92 for 346, 237,
  # 154, 92 at N/m = 128 .. 16). Below N/m = 16 the 2(m - 1) reflected
  # terms weigh in (N/m = 8: exact 52, Monte Carlo 42, Greenhall 45).
  ft <- s$name == "total" & alpha == 1L & (L - 1) / m >= 16 &
    is.finite(e) & e > 0
  if (any(ft)) {
    e[ft] <- edf_flicker(stat_entry("overlapping"), m[ft],
                         pmax(L - 2 * m[ft], 1), alpha[ft], e[ft])
  }
  ifelse(is.finite(e) & e > 0, e, s$edf_fallback(m, n, L))
}

# Flicker FM and PM: the exact two-moment EDF of the terms under discrete
# power-law noise (terms_edf_cpp(), as PDEV's) up to m = 128. Greenhall's
# continuous-time EDF `eg` is 0.80-0.92 of it at m = 1 and, under flicker
# PM, 0.85 of it on the overlapping types from m = 8 on; the Monte Carlo
# EDF (tools/mc-coverage.R, N = 1024, own Kasdin generator) follows the
# exact one (overlapping, flicker PM, m = 8 .. 128: 1.12-1.22 x
# Greenhall's; exact 1.14-1.19 x), and the overlapping Hadamard limits
# over-covered (0.979 at 95%). Beyond m = 128, where the exact sum is
# costly, Greenhall's EDF times their ratio at m = 128 on a long record.
edf_flicker <- function(s, m, n, alpha, eg) {
  out <- eg
  small <- m <= edf_flicker_mcap
  if (any(small)) {
    out[small] <- terms_edf_cpp(s$code, as.double(m[small]),
                                as.double(n[small]), alpha[small])
  }
  for (i in which(!small)) out[i] <- eg[i] * edf_flicker_ratio(s, alpha[i])
  # a quadratic form's EDF, (sum lambda)^2 / sum lambda^2, is at least 1
  ifelse(is.finite(out) & out > 0, pmax(out, 1), eg)
}
edf_flicker_mcap <- 128

# The exact EDF over Greenhall's at m = 128 on 2^18 + 1 phase points, once
# per (statistic, alpha) and session.
edf_flicker_ratio <- function(s, alpha) {
  key <- paste(s$code, alpha)
  hit <- edf_flicker_cache[[key]]
  if (!is.null(hit)) return(hit)
  m <- edf_flicker_mcap
  L <- 2^18 + 1
  n <- s$nterms(m, L)
  eg <- allan_edf_cpp(s$code, m, n, L, as.integer(alpha), FALSE)
  r <- terms_edf_cpp(s$code, m, n, as.integer(alpha)) / eg
  if (!is.finite(r) || r <= 0) r <- 1
  assign(key, r, envir = edf_flicker_cache)
  r
}
edf_flicker_cache <- new.env(parent = emptyenv())

# EDF of the rows of a statistic with a kernel of its own, by its entry's
# rule; an unknown noise type (alpha NA) gets the smallest EDF over the
# admissible ones (the widest interval), as allan_edf() does. `...`: what
# a rule takes beyond its five arguments (TheoBR's: its factor's ladder).
extra_edf <- function(type, m, L, alpha, n, ...) {
  s <- stat_entry(type)
  rule <- stat_edf_rules()[[s$edf]]
  a <- as.integer(alpha)
  unknown <- is.na(a)
  e <- rep(NA_real_, length(m))
  if (any(!unknown)) {
    e[!unknown] <- rule(s, m[!unknown], n[!unknown], L, a[!unknown], ...)
  }
  lo <- s$alpha_range[1L]
  for (i in which(unknown)) {
    e[i] <- min(vapply(lo:2L, function(al) rule(s, m[i], n[i], L, al, ...),
                       0))
  }
  e
}

# ---- the EDF rules of the statistics ----
# Each statistic's entry names its rule (`edf`); a rule is
# function(e, m, n, L, alpha): the EDF of rows with a known integer noise
# exponent alpha (the curve-level helpers allan_edf() and extra_edf() deal
# with unknown types). A new rule (Greenhall's exact EDF, ...) is one more
# element here.
stat_edf_rules <- function() {
  list(engine = edf_rule_engine, engine_modified = edf_rule_modified,
       mtot = edf_rule_mtot, htot = edf_rule_htot, theo1 = edf_rule_theo1,
       theobr = edf_rule_theobr, terms = edf_rule_terms)
}

# The one engine (src/edf.cpp) for the statistic itself.
edf_rule_engine <- function(e, m, n, L, alpha) {
  allan_edf_direct(e$name, m, n, L, alpha)
}

# Where no formula gives a positive finite EDF, the number of terms.
edf_floor_terms <- function(e, n) ifelse(is.finite(e) & e > 0, e, pmax(1, n))

# TDEV: the modified Allan EDF (TDEV is tau^2/3 MVAR).
edf_rule_modified <- function(e, m, n, L, alpha) {
  a <- as.integer(alpha)
  edf_floor_terms(allan_edf_direct("modified", m, L - 3 * m + 1, L,
                                   pmin(2L, pmax(-2L, a))), n)
}

# PDEV: the exact two-moment EDF of its terms, a stationary sequence of
# parabolic phase filters, under discrete power-law noise (src/edf.cpp
# terms_edf_cpp()). The modified Allan EDF it borrowed before is 16-35%
# below it (N = 1024: 0.65-0.84 of it at m = 2 .. 64, 0.50-0.74 at 128
# and 256), and the limits over-covered (0.74-0.79 at 68%, bench/README.md).
edf_rule_terms <- function(e, m, n, L, alpha) {
  a <- pmin(2L, pmax(-2L, as.integer(alpha)))
  edf_floor_terms(terms_edf_cpp(e$code, as.double(m), as.double(n), a), n)
}

# MTOT and TTOT: b N/m - c (NIST SP 1065 Table 11) from m = 4, the modified
# Allan EDF at m = 1, 2.
edf_rule_mtot <- function(e, m, n, L, alpha) {
  N <- L
  a <- as.integer(alpha)
  a <- pmin(2L, pmax(-2L, a))
  b <- c(0.75, 0.85, 1.10, 1.20, 1.90)[a + 3L]
  cc <- c(0.31, 0.50, 1.20, 1.40, 2.10)[a + 3L]
  out <- b * N / m - cc
  # At m = 1 and 2 Table 11 overstates the EDF (N = 1024, Monte Carlo
  # 2 E^2/Var: white PM 510 and 620 where it gives 1950 and 972,
  # flicker PM 600 for 1230, white FM 600-760 for 1130: coverage
  # 0.40-0.60); the windows of 3 and 6 points are (nearly) MVAR's terms,
  # and the modified Allan EDF (526, 651, 682 at m = 1) fits, as it does
  # Stable32's printed limits (implied EDF 485, 243, 120 at m = 2, 4, 8
  # of PHASE.DAT, white FM; MVAR's 504, 247, 120)
  small <- m < 4
  if (any(small)) {
    out[small] <- allan_edf_direct("modified", m[small],
                                   L - 3 * m[small] + 1, L, a[small])
  }
  # short windows: the exact two-moment EDF (R/edf-windows.R), 0.95-1.09
  # of the Monte Carlo EDF at m = 1-16 (N = 1024, five noises) where these
  # were 0.77-1.20 of it
  out <- edf_windows_over(out, "window_form_mtot", m, L - 3 * m + 1, a)
  edf_floor_terms(out, n)
}

# `out` with the rows the window engine reaches replaced by its EDF.
edf_windows_over <- function(out, form, m, M, alpha, rows = TRUE) {
  rows <- rep_len(rows, length(m)) & M >= 1
  if (any(rows)) {
    w <- windows_edf_rows(form, m[rows], M[rows], alpha[rows])
    out[rows] <- ifelse(is.finite(w) & w > 0, w, out[rows])
  }
  out
}

# HTOT: (N/m) / (b0 + b1 m/N) for the FM noises from m = 16 (Howe et al.
# 2000, Table 1, rows alpha = 0, -1, ..., -4: the mapping Stable32's limits
# confirm), the overlapping Allan EDF below (as Stable32), fits to Monte
# Carlo EDFs for white and flicker PM (tools/htot-pm-edf.R).
edf_rule_htot <- function(e, m, n, L, alpha) {
  N <- L
  a <- as.integer(alpha)
  # Howe et al. (2000) Table 1 covers the FM noises (alpha 0 .. -4)
  # from m = 16; below it Stable32 uses the overlapping Allan EDF
  fm <- a <= 0L & m >= 16
  k <- 1L - pmax(-4L, pmin(0L, a))
  b0 <- c(0.559, 0.868, 0.938, 2.554, 3.149)[k]
  b1 <- c(1.004, 1.140, 1.696, 0.974, 1.276)[k]
  out <- (N / m) / (b0 + b1 * m / N)
  pm <- a >= 1L
  o <- !fm & !pm
  if (any(o)) {
    out[o] <- allan_edf_direct("overlapping", m[o], L - 2 * m[o], L,
                               pmin(2L, pmax(-2L, a[o])))
  }
  # White and flicker PM: no published EDF; Stable32's overlapping Allan
  # one is 0.47-0.89 of the Monte Carlo EDF (N = 1024: coverage up to 0.89).
  # Fitted, in Nf = L - 1 frequency values, to Monte Carlo EDFs 2 E^2/Var
  # of the uncorrected HTOT (tools/htot-pm-edf.R: own generators, 4000
  # replicates, seed 1065, Nf = 512, 2048, 4096, 8192, m = 2 .. Nf/4
  # octave; least squares in log EDF): white PM
  # Nf / (1.337 + 0.621/m + 1.152 m/Nf), rms error 4.4%, max 11%;
  # flicker PM (Nf/m) (0.713 + 0.5725 ln m)^2 / (1 + 1.344 m/Nf),
  # rms 3.4%, max 7.8% (at Nf = 256, 1024, seed 7: 0.91-1.09 and
  # 0.95-1.06 of Monte Carlo). Beyond m = Nf/4, as the n = L - 3m terms fall
  # to a few, the EDF drops (white PM, n = 2, Nf = 1024: 53, not 595)
  # by a factor in x = n/Nf: white PM 1 - exp(-x/0.021), flicker PM
  # min(1, (x/0.138)^0.137) (`tail` mode of the script, 2000 replicates,
  # seed 1066, Nf = 512, 2048, m = Nf/4 .. Nf/3: rms error 4.4% and
  # 6.8%, max 7.2% and 11%; at Nf = 256, 1024, seed 12, 0.88-1.14 and
  # 0.96-1.18 of Monte Carlo; a factor of 1 - 3e-5 or 1 at m = Nf/4).
  if (any(pm)) {
    nf <- L - 1
    mp <- m[pm]
    x <- (L - 3 * mp) / nf
    out[pm] <- ifelse(a[pm] >= 2L,
                      nf / (1.337 + 0.621 / mp + 1.152 * mp / nf) *
                        (1 - exp(-x / 0.021)),
                      nf / mp * (0.713 + 0.5725 * log(mp))^2 /
                        (1 + 1.344 * mp / nf) * pmin(1, (x / 0.138)^0.137))
  }
  # at m = 1 HTOT is the overlapping Hadamard variance (SP 1065 5.2.14),
  # and so is its EDF (Monte Carlo, N = 1024: 537, 601, 691, 416, 453
  # for white, flicker, random-walk FM, white, flicker PM; overlapping
  # Hadamard 526, 733, 682, 443, 521; overlapping Allan 682, 917, 1020,
  # 526, 651: coverage 0.57-0.60 under flicker and random-walk FM)
  one <- m == 1
  if (any(one)) {
    out[one] <- allan_edf_direct("ohadamard", 1, L - 3, L,
                                 pmin(2L, pmax(-4L, a[one])))
  }
  # short windows: the exact two-moment EDF (R/edf-windows.R)
  out <- edf_windows_over(out, "window_form_htot", m, L - 3 * m,
                          pmin(2L, pmax(-4L, a)), rows = m >= 2)
  edf_floor_terms(out, n)
}

# Theo1 (and TheoBR): Howe & Peppler's formulas in tau = 0.75 m. Outside
# its range an approximation can fall to or below 0; Theo1's random-walk
# one does for 0.75 m > 0.63 N (a root of its quadratic), and is tiny just
# before it. There one degree of freedom (Theo1's term count is ~N m / 2,
# far from the truth).
edf_rule_theo1 <- function(e, m, n, L, alpha) {
  N <- L
  a <- as.integer(alpha)
  a <- pmin(2L, pmax(-2L, a))
  t <- 0.75 * m
  out <- ifelse(a == 2, 0.86 * (N + 1) * (N - 4 * t / 3) / (N - t) * t / (t + 1.14),
  ifelse(a == 1, (4.798 * N^2 - 6.374 * N * t + 12.387 * t) /
                   (sqrt(t + 36.6) * (N - t)) * t / (t + 0.3),
  ifelse(a == 0, ((4.1 * N + 0.8) / t - (3.1 * N + 6.5) / N) *
                   t^1.5 / (t^1.5 + 5.2),
  ifelse(a == -1, (2 * N^2 - 1.3 * N * t - 3.5 * t) / (N * t) *
                    t^3 / (t^3 + 2.3),
         (4.4 * N - 2) / (2.9 * t) *
           ((4.4 * N - 1)^2 - 8.6 * t * (4.4 * N - 1) + 11.4 * t^2) /
           (4.4 * N - 3)^2))))
  # short windows (even m): the exact two-moment EDF (R/edf-windows.R);
  # under flicker PM at m = 2 Howe's formula gives 664 where the Monte
  # Carlo EDF is 567 (N = 1024) and the 95% interval covered 0.90
  out <- edf_windows_over(out, "window_form_theo1", m, L - m, a,
                          rows = m %% 2 == 0)
  ifelse(is.finite(out) & out >= 1, out, 1)
}

# ---- limits ----

# The EDF, deviation and limits of a curve of a "sums" statistic (its
# entry `e`): the EDF by the entry's rule at the rows `sub` where the noise
# type was identified (alpha: those rows' exponents; exact_alpha: the
# exponents the exact rows rest on, when not those); with neither `ci` nor
# `unbiased` nothing is identified and edf, lower, upper and alpha are NA.
stat_limits <- function(e, av, m, n, L, alpha, sub, conf, ci = TRUE,
                        unbiased = FALSE, exact_alpha = NULL) {
  if (ci || unbiased) {
    ed <- allan_edf(e, m, n, L, alpha, sub)
  } else {
    ed <- list(edf = rep(NA_real_, length(m)),
               alpha = rep(NA_integer_, length(m)))
  }
  out <- stat_interval(av, ed$edf, conf, ci, FALSE)
  # rows at few averages: the exact generalized chi-square limits
  # (R/ci-exact.R) where the entry has them
  if (ci) {
    ea <- if (is.null(exact_alpha)) ed$alpha else exact_alpha
    out <- exact_limits_merge(out, allan_limits_exact(e$name, m, n, L, ea,
                                                      conf))
  }
  if (unbiased && e$unbiased) out$adev <- out$adev / stat_c4(ed$edf)
  out$edf <- ed$edf
  out$alpha <- ed$alpha
  out
}

# The deviation and its limits from the variance and its EDF: the
# chi-square interval (allan_ci()); ci = FALSE: no limits (NA). unbiased:
# the deviation divided by E[sqrt(chi2_nu / nu)] (stat_c4()), the limits as
# they are (an interval for the true deviation, which the unbiased
# deviation estimates). Another interval method (exact generalized
# chi-square) is one more branch here.
stat_interval <- function(av, edf, conf, ci = TRUE, unbiased = FALSE) {
  if (ci) {
    out <- allan_ci(av, edf, conf)
  } else {
    na <- rep(NA_real_, length(av))
    out <- list(lower = na, upper = na, adev = sqrt(av))
  }
  if (unbiased) out$adev <- out$adev / stat_c4(edf)
  out
}

# E[sqrt(chi2_nu / nu)] = sqrt(2 / nu) Gamma((nu + 1)/2) / Gamma(nu / 2),
# the mean of the deviation over the true one at EDF nu (below 1: the
# deviation is biased low). Its asymptotic series from nu = 1e4, where the
# difference of lgamma()s loses digits (series error below 1e-16).
stat_c4 <- function(nu) {
  out <- rep(NA_real_, length(nu))
  ok <- is.finite(nu) & nu > 0
  big <- ok & nu >= 1e4
  small <- ok & !big
  v <- nu[small]
  out[small] <- sqrt(2 / v) * exp(lgamma((v + 1) / 2) - lgamma(v / 2))
  v <- nu[big]
  out[big] <- 1 - 1 / (4 * v) + 1 / (32 * v^2) + 5 / (128 * v^3)
  out
}

# Chi-square confidence limits of the deviation (NIST SP 1065 eq. 45). For
# long curves the quantile factors come from cubic interpolation between
# 2000 exact values uniform in log(edf) (qchisq() with fractional df is
# slow); the interpolation error is below 1e-6 relative.
allan_ci <- function(avar, edf, conf) {
  p <- (1 - conf) / 2
  r <- c(min(edf), max(edf))  # range() would copy a long curve's edf
  if (length(edf) <= 2000L || r[2] <= r[1] * (1 + 1e-12)) {
    lo <- edf / stats::qchisq(1 - p, edf)
    hi <- edf / stats::qchisq(p, edf)
  } else {
    # half the log factor on a grid uniform in log(edf), interpolated in
    # one C++ pass (src/edf.cpp): one exp() per limit gives the deviation's
    lg <- seq(log(r[1]), log(r[2]), length.out = 2000L)
    g <- exp(lg)
    half_log <- function(q) 0.5 * log(g / stats::qchisq(q, g))
    # half_log() is Inf where qchisq() underflows (edf ~0.01): those grid
    # points lie below 0.05, where the C++ pass calls qchisq() itself
    return(ci_long_cpp(avar, edf, lg[1L], lg[2L] - lg[1L], half_log(1 - p),
                       half_log(p), p))
  }
  # sqrt of each factor: avar * hi may overflow where the limit does not
  adev <- sqrt(avar)
  list(lower = adev * sqrt(lo), upper = adev * sqrt(hi), adev = adev)
}
