# Theo1's noise type, which picks its bias correction, and its limits when
# the type is ambiguous (allan(type = "theo1"), R/allan-types.R).

# The noise type of Theo1 rows, for its bias correction: from Theo1's own
# slope over an octave. The correction AVAR/Theo1 changes up to 2.7-fold
# between adjacent types (SP 1065 Table; Howe & Tasset 2004), so a type
# misread in one record of three (the Allan variance's identification at
# 0.75 m reads flicker FM right in 21-69% of records at m = 8-256, N =
# 1024, random walk in 0-7% from m = 32) moves the corrected value out of
# its interval: 68% coverage 0.15-0.57 there. Theo1 itself, with EDF in the
# hundreds at mid tau, tells the types by its slope: E Theo1(m) =
# AVAR(0.75 m) / F(alpha, m), AVAR ~ tau^mu (mu = -alpha - 1 for FM, -2
# for white PM, -2 times SP 1065's log factor for flicker PM), compared
# between m and m' = m/2 (m = 2: m' = 4) rounded to even, a function of m
# alone. The type whose expected log ratio is nearest is taken (Monte
# Carlo, N = 1024, 300 records: flicker FM read right in 86-100% of
# records up to m = 128, random walk 91-100%); NA where Theo1 is not
# positive: then the Allan variance's type (`alpha0`).
theo1_alpha <- function(v, rate, L, m, t1, alpha0, threads) {
  mp <- 2 * round(m / 4)
  mp[mp < 2] <- 4
  ok <- mp <= L - 1
  alts <- as.list(alpha0)
  if (!any(ok)) return(structure(alpha0, alts = alts))
  need <- sort(unique(mp[ok & !(mp %in% m)]))
  tp <- t1[match(mp, m)]
  if (length(need)) {
    Tn <- if (length(need) > 40L) {
      theo1_many(v, rate, need, threads)
    } else {
      theo1_sums_cpp(v, rate, need, threads)
    }
    tn <- Tn / (0.75 * (L - need) * need^2)
    tp[is.na(tp)] <- tn[match(mp[is.na(tp)], need)]
  }
  lr <- log(t1 / tp)
  mu <- function(a, k) {
    if (a <= 0) return((-a - 1) * log(k))
    if (a == 2) return(-2 * log(k))
    -2 * log(k) + log(1.038 + 3 * log(pi * k))
  }
  ex <- vapply(-2:2, function(a) {
    (mu(a, m) - mu(a, mp)) - log(debias_factor_known("theo1", a, m) /
                                   debias_factor_known("theo1", a, mp))
  }, numeric(length(m)))
  ex <- matrix(ex, nrow = length(m))
  dist <- abs(ex - lr)
  a <- alpha0
  # white against flicker PM: the slopes differ by a slowly varying log
  # factor only; R(n) = MVAR/AVAR at k = 0.75 m (SP 1065 5.6.1: 1/k against
  # flicker PM's ~0.2) tells them apart where MVAR has >= 4 cluster spans
  # and the two ratios differ by 1.3 or more (k >= 3; m = 2 reads it at
  # k = 3: there the Allan variance's reading took flicker PM for white PM
  # in 5.6% of records (N = 1024), whose corrected values then missed their
  # intervals, 95% coverage 0.91)
  k <- pmax(3, round(0.75 * m))
  rn <- rep(NA_real_, length(m))
  kk <- sort(unique(k[4 * k <= L - 1]))
  if (length(kk)) {
    input <- if (rate) "rate" else "integrated"
    r <- allan(v, 1, taus = I(kk), type = "modified", input = input)$avar /
      allan(v, 1, taus = I(kk), type = "overlapping", input = input)$avar
    rn <- r[match(k, kk)]
  }
  fpm_rn <- 3 * log(256 / 27) / (2 * (1.038 + 3 * log(pi * k)))
  rn_pm <- ifelse(rn < sqrt(fpm_rn / k), 2L, 1L)
  rows <- which(ok & is.finite(lr))
  sl <- apply(dist, 1, which.min) - 3L
  # types within one standard error of the slope (from the EDF at m and m'
  # of the type read, correlation ignored) of the nearest
  se <- rep(NA_real_, length(m))
  if (length(rows)) {
    one <- rep(1, length(rows))
    se[rows] <- sqrt(2 / extra_edf("theo1", m[rows], L, sl[rows], one) +
                       2 / extra_edf("theo1", mp[rows], L, sl[rows], one))
  }
  for (i in rows) {
    s <- sl[i]
    near <- which(dist[i, ] <= dist[i, s + 3L] + se[i]) - 3L
    a0 <- alpha0[i]
    if (is.na(a0)) {
      a[i] <- s
      alts[[i]] <- near
    } else if (a0 <= 0L && s <= 0L) {
      # both FM: the slope's type (the Allan variance's misreads flicker FM
      # in up to 79% of records), its FM neighbours within reach
      a[i] <- s
      alts[[i]] <- near[near <= 0L]
    } else if (a0 >= 1L && s >= 1L) {
      # both PM: R(n) where read, else the Allan variance's
      a[i] <- if (is.finite(rn[i])) rn_pm[i] else a0
      alts[[i]] <- sort(unique(c(a[i], near[near <= 0L])))
    } else {
      # the two methods disagree on phase against frequency noise: the
      # Allan variance's type (Stable32's reading), the interval spanning
      # both
      a[i] <- a0
      alts[[i]] <- sort(unique(c(a0, s, near)))
    }
  }
  structure(as.integer(a), alts = alts)
}

# Theo1 limits when its noise type is ambiguous (theo1_alpha()): the union
# of the chi-square intervals of the candidate types, each with its bias
# correction and EDF. raw: uncorrected Theo1; n: terms.
theo1_union <- function(raw, m, L, alts, n, conf, debias) {
  a <- vapply(alts, function(x) x[1L], 1L)
  e <- extra_edf("theo1", m, L, a, n)
  f <- if (debias) debias_factor("theo1", a, m) else 1
  ci <- allan_ci(raw * f, e, conf)
  lo <- ci$lower
  hi <- ci$upper
  amb <- which(lengths(alts) > 1L)
  if (length(amb)) {
    # every (row, candidate type) pair at once
    row <- rep(amb, lengths(alts[amb]))
    al <- unlist(alts[amb], use.names = FALSE)
    e <- extra_edf("theo1", m[row], L, al, n[row])
    f <- if (debias) debias_factor("theo1", al, m[row]) else 1
    ci <- allan_ci(raw[row] * f, e, conf)
    lo[amb] <- vapply(split(ci$lower, row), min, 0)
    hi[amb] <- vapply(split(ci$upper, row), max, 0)
  }
  list(lower = lo, upper = hi)
}
