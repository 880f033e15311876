# The further statistics of allan(): time deviation, the Total family,
# Theo1 and its bias-removed and hybrid forms, the time interval errors and
# the parabolic deviation (their catalogue entries and kernels:
# R/stat-further.R). allan() checks its arguments and hands these types to
# allan_extra(), which runs the entry's kernel and returns the same data
# frame as for the other types.

#' @name allan
#' @rdname allan
#' @section Further statistics:
#' The phase \eqn{x} is as above (for `input = "rate"`, in the rate unit
#' times seconds: seconds for fractional-frequency input), \eqn{L} its number
#' of points, \eqn{\tau = m\tau_0}.
#' * `"tdev"`: time deviation, \eqn{\tau \cdot}MDEV\eqn{/\sqrt 3} (NIST SP
#'   1065 eq. 15), in the phase unit; EDF and noise type of `"modified"`.
#' * `"mtotdev"`, `"ttotdev"`, `"htotdev"`: the modified, time and Hadamard
#'   total deviations (SP 1065 eqs. 27-29): for each window of \eqn{3m}
#'   phase points (frequency values for `"htotdev"`) the line through the
#'   means of its halves is removed, the window is extended at both ends by
#'   even reflection, and the modified (Hadamard) second (third) differences
#'   of all \eqn{6m} positions are averaged; \eqn{L - 3m + 1} windows
#'   (\eqn{L - 3m} for `"htotdev"`, which is the overlapping Hadamard
#'   deviation at \eqn{m = 1}). `"ttotdev"` is \eqn{\tau/\sqrt3} times
#'   `"mtotdev"`, in the phase unit. Largest \eqn{m}: \eqn{L/3}.
#' * `"theo1"`: Theo1 (SP 1065 eq. 30), defined at even \eqn{m}, for the
#'   averaging time \eqn{\tau = 0.75\,m\tau_0}, which is what the `tau`
#'   column reports (`m` keeps the averaging factor). Grids (`"octave"`,
#'   `"decade"`, `"all"`) keep their even \eqn{m} (octave: 2, 4, 8, ...;
#'   \eqn{m \le L - 1}); a number of points per decade is rounded to even
#'   \eqn{m}; tau in seconds are Theo1 averaging times, \eqn{m = 2\,
#'   \mathrm{round}(\tau f / 1.5)}. `n` is the number of squared terms,
#'   \eqn{(L - m) m / 2}.
#' * `"theobr"`: Theo1 times TheoBR's bias-removal factor (SP 1065 eq. 33),
#'   the mean of \eqn{\mathrm{AVAR}(9 + 3i) / \mathrm{Theo1}(12 + 4i)} over
#'   \eqn{i = 0, \dots, \lfloor L/6 - 3 \rfloor} (or \eqn{\lfloor 0.1 L/3 -
#'   3 \rfloor}: `theo = list(ladder = "N/30")`): an estimate of the Allan
#'   variance to \eqn{\tau = 0.75 (L-1)\tau_0} without a noise model
#'   (Howe & Tasset 2004; as Stable32). Above \eqn{10^5} phase points the
#'   factor comes by default from the phase averaged over blocks of
#'   \eqn{r} points (\eqn{L/r \le 32768}; Taylor & Howe's "Fast TheoBR"),
#'   times the ratio of the factor's expected values on the full and on the
#'   averaged ladder for the noise type identified along the ladder
#'   (from the type's generalized covariance: white and flicker PM, white,
#'   flicker and random-walk FM). Measured against the exact factor (bench/
#'   README.md) the deviation differs by well under 1\% for each pure
#'   noise type; a record whose noise type changes along the ladder gets
#'   the correction of one type only.
#' * `"theoh"`: the hybrid of SP 1065 sec. 5.2.17: the overlapping Allan
#'   deviation at \eqn{m \le 0.2 (L - 1)}, then TheoBR at the even \eqn{m}
#'   whose \eqn{0.75 m} exceeds the last Allan \eqn{m} (so the `tau` column
#'   jumps from \eqn{m\tau_0} to \eqn{0.75 m\tau_0}). Numeric `taus` up to
#'   \eqn{0.2 (L-1)\tau_0} select Allan rows, longer ones TheoBR rows.
#' * `"mtie"`: the largest peak-to-peak phase excursion in any window of
#'   \eqn{m + 1} points (SP 1065 sec. 5.2.18; Stable32's MTIE); `n` is the
#'   number of windows, \eqn{L - m}.
#' * `"tierms"`: \eqn{\sqrt{\langle (x_{i+m} - x_i)^2 \rangle}} over the
#'   \eqn{L - m} pairs (SP 1065 sec. 5.2.19).
#' * `"pdev"`: the parabolic deviation of Vernotte et al. (2016), from the
#'   least-squares frequency estimates over two adjacent intervals;
#'   \eqn{L - 2m} terms; equal to `"overlapping"` at \eqn{m = 1}.
#'
#' For `"mtie"` and `"tierms"` the `adev` column holds the time error
#' itself (`avar` its square) and there is no interval (`lower`, `upper`,
#' `edf` and `alpha` are `NA`); for `"tdev"` and `"ttotdev"` it is a time
#' deviation. `print()` says the unit and `plot()` labels its axis.
#'
#' **Bias corrections** (`debias = TRUE`, the default, NIST SP 1065's
#' convention and that of its NBS14 table): `"mtotdev"` and `"ttotdev"`
#' variances are divided by 0.94, 0.83, 0.73, 0.70, 0.69 for noise
#' exponents \eqn{\alpha = 2, \dots, -2}; `"htotdev"` (for \eqn{m > 1}) by
#' \eqn{1 + a}, \eqn{a} = -0.005, -0.149, -0.229, -0.283, -0.321 for
#' \eqn{\alpha = 0, \dots, -4}; `"theo1"` is multiplied by
#' \eqn{a + b/(0.75m)^c}, Howe & Tasset's ratio of the Allan variance to
#' Theo1 (1 for white FM). The noise type is the one identified at each
#' tau (column `alpha`); where it cannot be identified (`alpha` `NA`) the
#' value is left uncorrected. `debias = FALSE` gives the raw estimators, as
#' Stable32 1.60 reports MTOT and TTOT (Stable32 1.53 corrected them, and
#' corrects HTOT; Python allantools never corrects). `"theobr"` and
#' `"theoh"` are bias-removed by construction.
#'
#' **Intervals** use the EDF approximations published for each statistic:
#' MTOT and TTOT \eqn{b L/m - c} (SP 1065 Table 11; at \eqn{m = 1, 2},
#' where it overstates the EDF up to fourfold, the modified Allan EDF), HTOT
#' \eqn{(L/m)/(b_0 + b_1 m/L)} for FM noise from \eqn{m = 16} (Howe et al.
#' 2000) and the overlapping Allan EDF below it; for white and flicker PM,
#' where none is published (Stable32 uses the overlapping Allan EDF, 0.47-0.89
#' of the true one), fits to Monte Carlo EDFs in \eqn{N = L - 1}:
#' \eqn{N/(1.337 + 0.621/m + 1.152 m/N)} and
#' \eqn{(N/m)(0.713 + 0.5725 \ln m)^2/(1 + 1.344 m/N)} (within 11% of
#' Monte Carlo up to \eqn{m = N/4}; beyond, where the terms fall to a few,
#' times a factor in their number); at \eqn{m = 1}, where HTOT is the
#' overlapping Hadamard variance, its EDF. Theo1 uses Howe and
#' Peppler's formulas in \eqn{0.75 m} (at least 1), PDEV its terms' exact
#' EDF. TheoBR (and TheoH's TheoBR rows) is Theo1 times a factor
#' \eqn{\kappa} estimated from the same record, one random factor on every
#' row: its EDF is \eqn{1/\nu = 1/\nu_T + 1/\nu_\kappa +
#' 2\rho/\sqrt{\nu_T \nu_\kappa}}, \eqn{\nu_T} Theo1's EDF,
#' \eqn{\nu_\kappa = 2/\mathrm{Var}\log\kappa} (13-30 for FM noise on the
#' N/6 ladder whatever \eqn{L}, 100-370 on the N/30 one, more for PM noise)
#' and \eqn{\rho} the correlation of \eqn{\log\kappa} with
#' \eqn{\log}Theo1(\eqn{m}) (up to 0.9 near the ladder's long end), both
#' from an offline Monte Carlo by noise type, ladder and its record length
#' (the averaged phase's on the fast path), at the type read along the
#' ladder (as Theo1's slope reads it at five points of the ladder). Theo1's
#' EDF alone ignored \eqn{\kappa}: 68% coverage 0.10-0.35 under FM noise,
#' 7 of 50 Monte Carlo rows (N = 1024, five noise types) inside both bands
#' (68% in 0.60-0.76, 95% in 0.92-0.975); with this EDF 41 of 46, the
#' misses at \eqn{N/m \le 4}, all over-covering; with the exact law at
#' \eqn{N/m \le 32} (see "Exact intervals at few averages" in [allan()])
#' 46 of 46 (1000 records). The noise type of a Theo1 or
#' TheoBR row starts from the
#' overlapping Allan variance's at \eqn{0.75 m}, or at \eqn{(L - 1)/3}
#' beyond it (no fewer than three cluster averages; TheoBR there: the
#' ladder's type). Its type, which for
#' Theo1 picks its bias correction
#' (up to 2.7-fold apart between adjacent types), also uses Theo1's own
#' slope from \eqn{m' = 2\,\mathrm{round}(m/4)} (\eqn{m = 2}: 4) to
#' \eqn{m}, against each type's expected slope with its correction: among
#' the FM types the slope's type; between white and flicker PM, R(n) at
#' \eqn{0.75 m} where it can be read, else the Allan variance's type; where
#' the slope and the Allan variance disagree on phase against frequency
#' noise, the Allan variance's type. The interval is the union of the
#' corrected chi-square intervals of the types whose expected slope lies
#' within one standard error of the nearest (wider where the type is
#' ambiguous). With the Allan variance's type alone 25 of 50 Monte Carlo
#' rows (N = 1024, five noise types) covered 0.60-0.76; now 40 of 48 (the
#' misses at N/m <= 4, covering 0.78-0.90).
#'
#' **Cost**: MTIE builds a table of window extremes level by level
#' (\eqn{O(L \log L)} for a whole grid); TIE rms, TDEV and PDEV cost
#' \eqn{O(L)} per tau (PDEV at octave \eqn{m} a few operations per term,
#' by a doubling recursion from \eqn{m} to \eqn{2m}); the Total family \eqn{O(L)} per tau (each
#' window's quadratic form in closed form, from prefix sums over blocks of
#' \eqn{4m} windows; directly, \eqn{O(L m)}, below \eqn{m = 8}); Theo1 per
#' tau the cheaper of its definition (\eqn{O(L m)}) and an expansion into
#' FFT correlations over blocks of the phase (\eqn{O(L \log^2 m)}, agreeing
#' with the definition to about \eqn{10^{-12}}); TheoBR's factor, which
#' needs Theo1 at about \eqn{L/6} averaging times, and Theo1 at more than
#' 40 taus by a recurrence over \eqn{m} on squared phase increments
#' (structure functions by FFT of locally detrended blocks, the pairs near
#' the ends of the record added as \eqn{m} grows; \eqn{O(L \log^2 L +
#' m_{max}^2)}, agreeing with the definition to about \eqn{10^{-11}}), so
#' the exact `"theobr"` and `"theoh"` take seconds at \eqn{10^5} samples and
#' minutes at \eqn{10^6}; the fast factor (the default above \eqn{10^5}
#' phase points) takes seconds at \eqn{10^6}.
#' @param debias For `"mtotdev"`, `"ttotdev"`, `"htotdev"` and `"theo1"`:
#'   apply NIST SP 1065's noise-dependent bias correction (default `TRUE`);
#'   see "Further statistics". Ignored by the other types.
#' @examples
#' # clock phase (seconds) sampled at 1 Hz: time deviation and MTIE
#' set.seed(2)
#' x <- cumsum(rnorm(2000, sd = 1e-9))
#' allan(x, 1, type = "tdev", input = "integrated")
#' allan(x, 1, type = "mtie", input = "integrated")
#' allan(x, 1, type = "theo1", input = "integrated", taus = "decade")
#' # TheoBR with Howe's shorter ladder; the fast factor asked for explicitly
#' allan(x, 1, type = "theobr", input = "integrated", taus = "decade",
#'       theo = list(ladder = "N/30"))
#' allan(x, 1, type = "theobr", input = "integrated", taus = "decade",
#'       theo = list(method = "fast", fast_points = 500))
NULL

# A single TRUE or FALSE.
check_true_false <- function(x, arg) {
  if (!is.logical(x) || length(x) != 1L || is.na(x)) {
    abort("`", arg, "` must be TRUE or FALSE, not ",
          if (is.logical(x) && length(x) == 1L) "NA" else describe_type(x), ".",
          class = "argument")
  }
  x
}


# NIST SP 1065's noise-dependent bias factor of a statistic (its entry's
# `debias`; 1 for the others); no correction where the noise type is
# unknown (alpha NA).
debias_factor <- function(type, alpha, m) {
  f <- debias_factor_known(type, alpha, m)
  ifelse(is.na(f), 1, f)
}

debias_factor_known <- function(type, alpha, m) {
  f <- stat_entry(type)$debias
  if (is.null(f)) rep(1, length(m)) else f(alpha, m)
}

# The cluster sizes of a Theo1 curve: even m (Theo1 is defined at even m
# only). Grids keep their even members (octave: 2, 4, 8, ...), a number of
# points per decade is rounded to even m; tau in seconds are Theo1
# averaging times, tau = 0.75 m / freq, so m = 2 round(tau freq / 1.5).
allan_theo_taus <- function(taus, freq, maxm) {
  maxm <- 2 * floor(maxm / 2)
  if (maxm < 2) return(numeric(0))
  if (is.character(taus) || (is.numeric(taus) && length(taus) == 1L &&
                             !inherits(taus, "AsIs"))) {
    m <- allan_taus(taus, freq, maxm)
    if (is.character(taus)) return(m[m %% 2 == 0])
    return(sort(unique(pmax(2, 2 * round(m / 2)))))
  }
  m0 <- suppressWarnings(allan_taus(taus, freq, .Machine$integer.max))  # validates
  if (!length(m0)) return(numeric(0))
  m <- 2 * round(as.double(taus) * freq / 1.5)
  bad <- m < 2 | m > maxm
  if (any(bad)) {
    warn(sum(bad), " of the requested tau values lie outside [",
         format(1.5 / freq), ", ", format(0.75 * maxm / freq),
         "] s (Theo1 averaging times 0.75 m / freq, m even in 2..", maxm,
         ") and were dropped.", class = "taus_dropped")
  }
  sort(unique(m[!bad]))
}

# TheoH's two parts (NIST SP 1065 sec. 5.2.17): the overlapping Allan
# variance at m <= 0.2 (L - 1) (up to 20% of the record), then TheoBR at the
# even m whose Theo1 averaging time 0.75 m lies beyond the last Allan m.
allan_theoh_taus <- function(taus, freq, L) {
  k <- floor(0.2 * (L - 1))
  if (is.numeric(taus) && (length(taus) > 1L || inherits(taus, "AsIs"))) {
    m0 <- suppressWarnings(allan_taus(taus, freq, .Machine$integer.max))
    if (!length(m0)) return(list(avar = numeric(0), theo = numeric(0)))
    t <- as.double(taus) * freq
    ma <- round(t[t <= k])
    mt <- 2 * round(t[t > k] / 1.5)
    bad <- ma < 1 | mt > L - 1 | mt < 2
    mt <- mt[mt >= 2 & mt <= L - 1]
    ma <- ma[ma >= 1]
    if (length(t) > length(ma) + length(mt)) {
      warn(length(t) - length(ma) - length(mt),
           " of the requested tau values lie outside the TheoH range and ",
           "were dropped.", class = "taus_dropped")
    }
    return(list(avar = sort(unique(ma)), theo = sort(unique(mt))))
  }
  m <- allan_taus(taus, freq, L - 1)
  ma <- m[m <= k]
  last <- if (length(ma)) max(ma) else 0
  mt <- m[m > k]
  mt <- sort(unique(2 * ceiling(mt / 2)))
  mt <- mt[0.75 * mt > last & mt <= L - 1]
  list(avar = ma, theo = mt)
}

# The further types (see allan()): `e` their entry. Arguments are checked
# by allan().
allan_extra <- function(x, freq, taus, e, input, conf, debias,
                        gaps = "skip", ci = TRUE, unbiased = FALSE,
                        theo = e$theo) {
  rate <- input == "rate"
  type <- e$name
  ch <- allan_channels(x, min_n = if (rate) 2L else 3L)
  if (gaps == "skip" && anyNA(ch$values)) {
    # TDEV is tau/sqrt(3) MDEV: the modified gap rule (R/allan.R) carries
    # over. The others are not defined with gaps: MTIE/TIE and the Theo
    # family need every phase point of their spans, the Total family
    # reflects each window (a gap would be copied to its far end).
    if (is.function(e$gaps)) {
      return(e$gaps(x, freq, taus, input, conf, ci, unbiased))
    }
    abort(e$gaps, class = "gaps")
  }
  N <- ch$N
  L <- if (rate) N + 1 else N
  col <- function(j) {
    if (ch$nc == 1L) ch$values else ch$values[(j - 1) * N + seq_len(N)]
  }
  for (j in seq_len(ch$nc)) {
    v <- col(j)
    bad <- first_nonfinite(v)
    if (bad > 0) {
      abort("`x` must contain only finite numbers; found ", format(v[bad]),
            " at position ", bad,
            if (ch$nc > 1L) paste0(" of column ", j), ".", class = "argument")
    }
  }
  maxm <- e$max_m(L)
  grid <- e$taus(taus, freq, L, maxm)
  m <- grid$m
  if (length(m) == 0L) {
    abort("No averaging time in `taus` has a term for type \"", type,
          "\" with ", N, " samples (largest cluster size: ", maxm, ").",
          class = "argument")
  }
  out <- vector("list", ch$nc)
  for (j in seq_len(ch$nc)) {
    d <- extra_channel(col(j), freq, m, grid$theo_row, e, rate, L, conf,
                       debias, ci, unbiased, theo)
    if (ch$nc > 1L) d$channel <- rep(ch$names[j], length(m))
    d$alpha <- d$alpha_
    d$alpha_ <- NULL
    out[[j]] <- structure(d, class = "data.frame",
                          row.names = .set_row_names(length(m)))
  }
  out <- if (ch$nc == 1L) out[[1L]] else do.call(rbind, out)
  if (ch$nc > 1L) rownames(out) <- NULL
  structure(out, class = c("allan", "data.frame"), freq = freq, type = type,
            input = input, N = N, conf = conf,
            debias = if (e$has_debias) isTRUE(debias),
            ci = allan_ci_attr(ci), unbiased = allan_unbiased_attr(e, unbiased))
}

# One channel of a further type: the entry's kernel, then the EDF by its
# rule and the limits (alpha as `alpha_`, placed last by the caller). The
# noise type is identified where the limits, the unbiased deviation or the
# bias correction need it.
extra_channel <- function(v, freq, m, theo_row, e, rate, L, conf, debias,
                          ci = TRUE, unbiased = FALSE, theo = e$theo) {
  input <- if (rate) "rate" else "integrated"
  limits <- ci && stat_has_limits(e)
  unbiased <- unbiased && e$unbiased
  need_id <- limits || unbiased || (debias && !is.null(e$debias))
  ctx <- list(v = v, freq = freq, m = m, theo_row = theo_row, rate = rate,
              L = L, n = e$nterms(m, L, theo_row), conf = conf,
              debias = debias, ci = limits, unbiased = unbiased,
              input = input, entry = e, threads = allanvar_threads(),
              theo = theo,
              sc_rate = if (rate) 1 else freq^2,   # fractional frequency
              sc_time = if (rate) 1 / freq^2 else 1,  # squared phase
              identify = function(mm) {
                if (!need_id || is.na(e$id_base)) {
                  return(rep(NA_integer_, length(mm)))
                }
                extra_alpha(v, freq, mm, e$id_base, input, L)
              })
  r <- e$kernel(ctx)
  av <- r$av
  n <- if (is.null(r$n)) ctx$n else r$n
  na <- rep(NA_real_, length(m))
  alpha <- if (is.null(r$alpha)) rep(NA_integer_, length(m)) else r$alpha
  edf <- if (!is.null(r$edf)) r$edf else if (limits || unbiased) {
    extra_edf(e$name, m, L, alpha, n)
  } else na
  lim <- stat_interval(av, edf, conf, limits, unbiased)
  lower <- lim$lower
  upper <- lim$upper
  if (limits && !is.null(r$limits)) {
    lower[r$limits$rows] <- r$limits$lower
    upper[r$limits$rows] <- r$limits$upper
  }
  adev <- if (is.null(r$adev)) lim$adev else r$adev
  if (limits && isTRUE(e$exact_ci)) {
    # rows at few averages: the exact law (R/ci-exact.R)
    ex <- allan_limits_exact(e$name, m, n, L, alpha, conf, r$exact_sets,
                             debias && !is.null(e$debias))
    ok <- which(!is.na(ex$lower))
    lower[ok] <- sqrt(av[ok]) * ex$lower[ok]
    upper[ok] <- sqrt(av[ok]) * ex$upper[ok]
  }
  if (!stat_has_limits(e) || !(limits || unbiased)) edf <- na
  list(tau = ifelse(theo_row, 0.75, 1) * m / freq, m = as.integer(m), n = n,
       avar = av, adev = adev, lower = lower, upper = upper, edf = edf,
       alpha_ = as.integer(alpha))
}

# Noise exponent at cluster sizes m from the noise identification of
# allan() for a related type. The m beyond the largest one it can identify
# (that type's range, and 3 averaged frequencies for B1) take the
# identification there: a function of the data alone, whatever taus are
# asked. (Theo1 reaches 0.75 m = 0.75 (N - 1), where the Allan variance has
# 1 or 2 averaged frequencies and no type could be read; with no type the
# widest interval gave limits decades wide where Stable32 prints EDF ~ 4.)
# `mx`: max(abs(v)) where the caller has it (allan()'s kernel read the
# range; two passes of min() and max() cost 24 ms at 1e7), NA: read here.
extra_alpha <- function(v, freq, m, base, input, L, mx = NA) {
  top <- min(allan_max_m(base, L), max(1, floor((L - 1) / 3)))
  mm <- pmax(1, pmin(m, top))
  u <- sort(unique(mm))
  # finite here; range() would copy v
  if (is.na(mx)) mx <- max(-min(v), max(v))
  if (length(u) <= 200L && mx > 1e-100 && mx < 1e100) {
    # the kernel's noise identification, as allan() calls it (the term
    # counts are part of the identification), without allan()'s limits:
    # allan() identifies every row itself up to 200 rows and rescales only
    # data whose sums over- or underflow, kept out by the range above.
    res <- allan_call_kernel(
      allan_sums_cpp(v, length(v), u, allan_nterms(base, u, L), u,
                     allan_opts(base, input == "rate", sums = FALSE)),
      length(v), 1L)
    lo <- stat_entry(base)$alpha_range[1L]
    a <- pmin(2L, pmax(lo, as.integer(res$alpha_int[, 1L])))
    return(a[match(mm, u)])
  }
  a <- allan(v, freq, taus = I(u / freq), type = base, input = input)
  a$alpha[match(mm, a$m)]
}

# Theo1's sums T_k (src/theo.cpp) at many even m: per m sums below m = 64
# and above L - 64, where they cost little and the recurrence would cancel
# most (about L / m for random-walk FM, L / (L - m) near the top); the
# squared-increment recurrence for the rest.
theo1_many <- function(v, rate, m, threads) {
  T <- rep(NA_real_, length(m))
  L <- length(v) + rate
  small <- m < 64 | m > L - 64
  if (any(small)) T[small] <- theo1_sums_cpp(v, rate, m[small], threads)
  if (any(!small)) T[!small] <- theo1_incr_cpp(v, rate, m[!small] / 2, threads)
  T
}
