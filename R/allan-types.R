# The further statistics of allan() (issue 10): time deviation, the Total
# family, Theo1 and its bias-removed and hybrid forms, the time interval
# errors and the parabolic deviation; and allantools' names for the six
# Allan-family types. allan() checks its arguments and hands these types to
# allan_extra(), which returns the same data frame as for the other types.

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
#'   \eqn{i = 0, \dots, \lfloor L/6 - 3 \rfloor}: an estimate of the Allan
#'   variance to \eqn{\tau = 0.75 (L-1)\tau_0} without a noise model
#'   (Howe & Tasset 2004; as Stable32).
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
#' overlapping Hadamard variance, its EDF. Theo1 and TheoBR use Howe and
#' Peppler's formulas in \eqn{0.75 m} (at least 1), PDEV the modified Allan
#' EDF. The noise type of a TheoBR row is the overlapping Allan variance's at
#' \eqn{0.75 m}, or at \eqn{(L - 1)/3} beyond it (no fewer than three
#' cluster averages). A Theo1 row's type, which picks its bias correction
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
#' `"theobr"` and `"theoh"` take seconds at \eqn{10^5} samples and minutes
#' at \eqn{10^6}.
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
NULL

# The further types, in the order the documentation lists them.
allan_extra_types <- c("tdev", "mtotdev", "ttotdev", "htotdev", "theo1",
                       "theobr", "theoh", "mtie", "tierms", "pdev")

# allantools' names for the types allan() always had.
allan_type_aliases <- c(adev = "standard", oadev = "overlapping",
                        mdev = "modified", hdev = "hadamard",
                        ohdev = "ohadamard", totdev = "total")

# Every name `type` accepts.
allan_type_names <- function() {
  c(allan_types, allan_extra_types, names(allan_type_aliases))
}

# What each further type's deviation column holds, for print() and plot().
allan_type_title <- function(type) {
  switch(type,
    tdev = "time deviation TDEV",
    mtotdev = "modified total deviation",
    ttotdev = "time total deviation TTOT",
    htotdev = "Hadamard total deviation",
    theo1 = "Theo1 deviation",
    theobr = "bias-removed Theo1 deviation (TheoBR)",
    theoh = "TheoH deviation (Allan, then TheoBR)",
    mtie = "maximum time interval error MTIE",
    tierms = "rms time interval error TIE rms",
    pdev = "parabolic deviation",
    type
  )
}

# The header print() shows for a further type: the statistic, its unit for
# the time-error types, the bias convention.
allan_extra_header <- function(x) {
  a <- attributes(x)
  type <- a$type
  nch <- if ("channel" %in% names(x)) length(unique(x$channel)) else 1L
  time <- identical(allan_type_prop(type, "unit"), "time")
  sprintf("<allan> %s of %s input: N = %s at %s Hz%s%s%s%s",
          allan_type_title(type), a$input, format(a$N, big.mark = ","),
          format(a$freq), if (nch > 1L) sprintf(", %d channels", nch) else "",
          if (type %in% c("mtie", "tierms")) "" else
            sprintf("; %s%% intervals", format(100 * a$conf)),
          if (time) paste0("; `adev` is a time in the phase unit (seconds ",
                           "for phase in s or fractional-frequency input)")
          else "",
          if (isTRUE(a$debias)) "; bias-corrected (NIST SP 1065)" else
            if (identical(a$debias, FALSE)) "; not bias-corrected" else "")
}

# The y-axis label plot() uses for a further type.
allan_extra_ylab <- function(type) {
  time <- identical(allan_type_prop(type, "unit"), "time")
  paste0(allan_type_title(type), if (time) " (s)" else "")
}

# The canonical name of a type (aliases resolved).
allan_canonical_type <- function(type) {
  if (type %in% names(allan_type_aliases)) allan_type_aliases[[type]] else type
}

# A single TRUE or FALSE.
check_true_false <- function(x, arg) {
  if (!is.logical(x) || length(x) != 1L || is.na(x)) {
    abort("`", arg, "` must be TRUE or FALSE, not ",
          if (is.logical(x) && length(x) == 1L) "NA" else describe_type(x), ".",
          class = "argument")
  }
  x
}

# Every type's row of the table of src/types.h (allan_type_table() has the
# Allan-family types of the sums kernel only), read once.
allan_type_table_all <- local({
  table <- NULL
  function() {
    if (is.null(table)) table <<- allan_type_table_cpp(TRUE)
    table
  }
})

# A property of a type from that table.
allan_type_prop <- function(type, prop) {
  tab <- allan_type_table_all()
  tab[[prop]][match(type, tab$name)]
}

# Largest m with a term, for L phase points.
allan_extra_max_m <- function(type, L) {
  switch(type,
    tdev = , mtotdev = , ttotdev = floor(L / 3),
    htotdev = floor((L - 1) / 3),
    theo1 = , theobr = , theoh = , mtie = , tierms = L - 1,
    pdev = floor((L - 1) / 2)
  )
}

# Terms behind each value (Stable32's "#" column).
allan_extra_nterms <- function(type, m, L) {
  switch(type,
    tdev = , mtotdev = , ttotdev = L - 3 * m + 1,
    htotdev = ifelse(m == 1, L - 3, L - 3 * m),
    theo1 = , theobr = (L - m) * m / 2,
    mtie = , tierms = L - m,
    pdev = ifelse(m == 1, L - 2, L - 2 * m)
  )
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

# NIST SP 1065 bias factors (the expected ratio of the estimator to the
# variance it estimates, by noise exponent alpha):
#  * MTOT and TTOT: Table 12 (Howe & Vernotte, PTTI 1999), divide by it;
#  * HTOT: 1 + a, Table 13 (Howe et al., PTTI 2000), divide by it, m > 1;
#  * Theo1: AVAR/Theo1 = a + b / (0.75 m)^c (Howe & Tasset, EFTF 2004,
#    Table 1), multiply by it.
debias_factor <- function(type, alpha, m) {
  f <- debias_factor_known(type, alpha, m)
  # no correction where the noise type is unknown (alpha NA)
  ifelse(is.na(f), 1, f)
}

debias_factor_known <- function(type, alpha, m) {
  a <- pmin(2L, pmax(-2L, as.integer(alpha)))
  switch(type,
    mtotdev = , ttotdev = 1 / c(0.69, 0.70, 0.73, 0.83, 0.94)[a + 3L],
    htotdev = {
      ah <- pmin(2L, pmax(-4L, as.integer(alpha)))
      corr <- c(-0.321, -0.283, -0.229, -0.149, -0.005, 0, 0)[ah + 5L]
      ifelse(m == 1, 1, 1 / (1 + corr))
    },
    theo1 = {
      tab <- rbind(c(2.70, -1.53, 0.85), c(1.87, -1.05, 0.79), c(1, 0, 0),
                   c(0.14, 0.82, 0.30), c(0.09, 0.74, 0.40))
      p <- tab[a + 3L, , drop = FALSE]
      p[, 1] + p[, 2] / (0.75 * m)^p[, 3]
    },
    rep(1, length(m))
  )
}

# EDF of the further types from their published approximations (NIST SP
# 1065 sec. 5.3.3; W.J. Riley, "Confidence intervals and bias corrections
# for the Stable32 variance functions", 2000):
#  * MTOT and TTOT: b N/m - c (Table 11) from m = 4, the modified Allan
#    EDF at m = 1, 2;
#  * HTOT: (N/m) / (b0 + b1 m/N) for the FM noises from m = 16 (Howe et
#    al. 2000, Table 1, rows alpha = 0, -1, ..., -4: the mapping Stable32's
#    limits confirm), the overlapping Allan EDF below (as Stable32), fits
#    to Monte Carlo EDFs for white and flicker PM (tools/htot-pm-edf.R);
#  * Theo1 (and TheoBR): Howe & Peppler's formulas in tau = 0.75 m;
#  * PDEV: the modified Allan EDF (the estimators share their overlapping
#    structure; Vernotte et al. 2016 give no closed form).
# N is the number of phase points; alpha the noise exponent of each row.
extra_edf <- function(type, m, L, alpha, n) {
  a <- as.integer(alpha)
  unknown <- is.na(a)
  e <- rep(NA_real_, length(m))
  if (any(!unknown)) {
    e[!unknown] <- extra_edf_known(type, m[!unknown], L, a[!unknown],
                                   n[!unknown])
  }
  # an unknown noise type: the smallest EDF over the admissible ones (the
  # widest interval), as allan() does for the other types
  lo <- if (type == "htotdev") -4L else -2L
  for (i in which(unknown)) {
    e[i] <- min(vapply(lo:2L, function(al) {
      extra_edf_known(type, m[i], L, al, n[i])
    }, 0))
  }
  e
}

extra_edf_known <- function(type, m, L, alpha, n) {
  N <- L
  a <- as.integer(alpha)
  e <- switch(type,
    mtotdev = , ttotdev = {
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
      out
    },
    htotdev = {
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
      out
    },
    theo1 = , theobr = {
      a <- pmin(2L, pmax(-2L, a))
      t <- 0.75 * m
      ifelse(a == 2, 0.86 * (N + 1) * (N - 4 * t / 3) / (N - t) * t / (t + 1.14),
      ifelse(a == 1, (4.798 * N^2 - 6.374 * N * t + 12.387 * t) /
                       (sqrt(t + 36.6) * (N - t)) * t / (t + 0.3),
      ifelse(a == 0, ((4.1 * N + 0.8) / t - (3.1 * N + 6.5) / N) *
                       t^1.5 / (t^1.5 + 5.2),
      ifelse(a == -1, (2 * N^2 - 1.3 * N * t - 3.5 * t) / (N * t) *
                        t^3 / (t^3 + 2.3),
             (4.4 * N - 2) / (2.9 * t) *
               ((4.4 * N - 1)^2 - 8.6 * t * (4.4 * N - 1) + 11.4 * t^2) /
               (4.4 * N - 3)^2))))
    },
    pdev = allan_edf_direct("modified", m, L - 3 * m + 1, L,
                            pmin(2L, pmax(-2L, a)))
  )
  # Outside its range an approximation can fall to or below 0; Theo1's
  # random-walk one does for 0.75 m > 0.63 N (a root of its quadratic), and
  # is tiny just before it. There one degree of freedom (Theo1's term count
  # is ~N m / 2, far from the truth); elsewhere the number of terms.
  if (type %in% c("theo1", "theobr")) return(ifelse(is.finite(e) & e >= 1, e, 1))
  ifelse(is.finite(e) & e > 0, e, pmax(1, n))
}

# The further types (see allan()). Arguments are checked by allan().
allan_extra <- function(x, freq, taus, type, input, conf, debias,
                        gaps = "skip") {
  rate <- input == "rate"
  ch <- allan_channels(x, min_n = if (rate) 2L else 3L)
  if (gaps == "skip" && anyNA(ch$values)) {
    # TDEV is tau/sqrt(3) MDEV: the modified gap rule (R/allan.R) carries
    # over. The others are not defined with gaps: MTIE/TIE and the Theo
    # family need every phase point of their spans, the Total family
    # reflects each window (a gap would be copied to its far end).
    if (type == "tdev") return(allan_tdev_gaps(x, freq, taus, input, conf))
    abort("`gaps = \"skip\"` is not defined for type \"", type, "\" (",
          "missing values in `x`); use one of \"standard\", \"overlapping\", ",
          "\"modified\", \"hadamard\", \"ohadamard\" or \"tdev\", or fill ",
          "the gaps.", class = "gaps")
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
  if (type == "theoh") {
    parts <- allan_theoh_taus(taus, freq, L)
    m <- c(parts$avar, parts$theo)
    theo_row <- rep(c(FALSE, TRUE), c(length(parts$avar), length(parts$theo)))
    maxm <- L - 1
  } else {
    maxm <- allan_extra_max_m(type, L)
    m <- if (type %in% c("theo1", "theobr")) {
      allan_theo_taus(taus, freq, maxm)
    } else {
      allan_taus(taus, freq, maxm)
    }
    theo_row <- rep(type %in% c("theo1", "theobr"), length(m))
  }
  if (length(m) == 0L) {
    abort("No averaging time in `taus` has a term for type \"", type,
          "\" with ", N, " samples (largest cluster size: ", maxm, ").",
          class = "argument")
  }
  out <- vector("list", ch$nc)
  for (j in seq_len(ch$nc)) {
    v <- col(j)
    d <- extra_channel(v, freq, m, theo_row, type, rate, L, conf, debias)
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
            debias = if (allan_type_prop(type, "debias")) isTRUE(debias))
}

# TDEV with gaps: the modified variance with gaps (same taus, kept terms,
# EDF and noise type), times tau^2/3.
allan_tdev_gaps <- function(x, freq, taus, input, conf) {
  a <- allan(x, freq, taus = taus, type = "modified", input = input,
             conf = conf, gaps = "skip")
  k <- a$tau^2 / 3
  a$avar <- a$avar * k
  a$adev <- a$adev * sqrt(k)
  a$lower <- a$lower * sqrt(k)
  a$upper <- a$upper * sqrt(k)
  attr(a, "type") <- "tdev"
  a
}

# One channel of a further type: the columns of the result (alpha as
# `alpha_`, placed last by the caller).
extra_channel <- function(v, freq, m, theo_row, type, rate, L, conf, debias) {
  input <- if (rate) "rate" else "integrated"
  sc_rate <- if (rate) 1 else freq^2      # variances of fractional frequency
  sc_time <- if (rate) 1 / freq^2 else 1  # squared phase
  threads <- allanvar_threads()
  tau <- ifelse(theo_row, 0.75, 1) * m / freq
  n <- if (type == "theoh") {
    ifelse(theo_row, (L - m) * m / 2, L - 2 * m)
  } else {
    allan_extra_nterms(type, m, L)
  }
  alpha <- rep(NA_integer_, length(m))
  edf <- rep(NA_real_, length(m))
  union <- NULL
  switch(type,
    tdev = {
      a <- allan(v, freq, taus = I(m / freq), type = "modified", input = input,
                 conf = conf)
      k <- (m / freq)^2 / 3
      return(list(tau = tau, m = as.integer(m), n = a$n, avar = a$avar * k,
                  adev = a$adev * sqrt(k), lower = a$lower * sqrt(k),
                  upper = a$upper * sqrt(k), edf = a$edf, alpha_ = a$alpha))
    },
    mtie = {
      av <- (mtie_cpp(v, rate, m) / if (rate) freq else 1)^2
    },
    tierms = {
      av <- tierms_sums_cpp(v, rate, m, threads) / (L - m) * sc_time
    },
    pdev = {
      s <- pdev_sums_cpp(v, rate, m, threads)
      av <- ifelse(m == 1, s / (2 * n), 18 * s / (n * m^6)) * sc_rate
      alpha <- extra_alpha(v, freq, m, "modified", input, L)
      edf <- extra_edf(type, m, L, alpha, n)
    },
    mtotdev = , ttotdev = {
      s <- total_sums_cpp(v, rate, m, FALSE, threads)
      av <- s / (12 * m^5 * n) * sc_rate
      alpha <- extra_alpha(v, freq, m, "modified", input, L)
      if (debias) av <- av * debias_factor(type, alpha, m)
      if (type == "ttotdev") av <- av * (m / freq)^2 / 3
      edf <- extra_edf(type, m, L, alpha, n)
    },
    htotdev = {
      s <- total_sums_cpp(v, rate, m, TRUE, threads)
      av <- s / (36 * m^3 * n) * sc_rate
      if (any(m == 1)) {
        av[m == 1] <- allan(v, freq, taus = I(1 / freq), type = "ohadamard",
                            input = input)$avar
      }
      alpha <- extra_alpha(v, freq, m, "ohadamard", input, L)
      if (debias) av <- av * debias_factor(type, alpha, m)
      edf <- extra_edf(type, m, L, alpha, n)
    },
    theo1 = , theobr = , theoh = {
      av <- rep(NA_real_, length(m))
      mt <- m[theo_row]
      if (length(mt)) {
        # many m: the recurrence over k (O(L log^2 L + kmax^2)) beats
        # m-by-m sums
        T <- if (length(mt) > 40L) {
          theo1_many(v, rate, mt, threads)
        } else {
          theo1_sums_cpp(v, rate, mt, threads)
        }
        t1 <- T / (0.75 * (L - mt) * mt^2) * sc_rate
        alpha[theo_row] <- extra_alpha(v, freq, round(0.75 * mt), "overlapping",
                                       input, L)
        if (type == "theo1") {
          ta <- theo1_alpha(v, rate, L, mt, t1 / sc_rate, alpha[theo_row],
                            threads)
          alpha[theo_row] <- as.integer(ta)
          union <- theo1_union(t1, mt, L, attr(ta, "alts"), n[theo_row],
                               conf, debias)
        }
        if (type == "theo1") {
          if (debias) t1 <- t1 * debias_factor("theo1", alpha[theo_row], mt)
        } else {
          kf <- theobr_factor(v, freq, rate, L, threads)
          if (!is.finite(kf)) {
            abort("TheoBR needs at least 19 phase points (", L, " given).",
                  class = "argument")
          }
          t1 <- t1 * kf
        }
        av[theo_row] <- t1
        edf[theo_row] <- extra_edf("theo1", mt, L, alpha[theo_row],
                                   n[theo_row])
      }
      if (any(!theo_row)) {
        a <- allan(v, freq, taus = I(m[!theo_row] / freq),
                   type = "overlapping", input = input, conf = conf)
        av[!theo_row] <- a$avar
        alpha[!theo_row] <- a$alpha
        edf[!theo_row] <- a$edf
      }
    }
  )
  if (type %in% c("mtie", "tierms")) {
    lower <- upper <- rep(NA_real_, length(m))
  } else {
    ci <- allan_ci(av, edf, conf)
    lower <- ci$lower
    upper <- ci$upper
    if (type == "theo1" && any(theo_row)) {
      lower[theo_row] <- union$lower
      upper[theo_row] <- union$upper
    }
  }
  list(tau = tau, m = as.integer(m), n = n, avar = av, adev = sqrt(av),
       lower = lower, upper = upper, edf = edf, alpha_ = as.integer(alpha))
}

# Noise exponent at cluster sizes m from the noise identification of
# allan() for a related type. The m beyond the largest one it can identify
# (that type's range, and 3 averaged frequencies for B1) take the
# identification there: a function of the data alone, whatever taus are
# asked. (Theo1 reaches 0.75 m = 0.75 (N - 1), where the Allan variance has
# 1 or 2 averaged frequencies and no type could be read; with no type the
# widest interval gave limits decades wide where Stable32 prints EDF ~ 4.)
extra_alpha <- function(v, freq, m, base, input, L) {
  top <- min(allan_max_m(base, L), max(1, floor((L - 1) / 3)))
  mm <- pmax(1, pmin(m, top))
  u <- sort(unique(mm))
  mx <- max(-min(v), max(v))  # finite here; range() would copy v
  if (length(u) <= 200L && mx > 1e-100 && mx < 1e100) {
    # the kernel's noise identification, as allan() calls it (the term
    # counts are part of the identification), without allan()'s limits:
    # allan() identifies every row itself up to 200 rows and rescales only
    # data whose sums over- or underflow, kept out by the range above.
    res <- allan_call_kernel(
      allan_sums_cpp(v, length(v), u, allan_nterms(base, u, L), u,
                     allan_opts(base, input == "rate", sums = FALSE)),
      length(v), 1L)
    tab <- allan_type_table()
    lo <- if (tab$d[match(base, tab$name)] == 3) -4L else -2L
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

# TheoBR's bias-removal factor (NIST SP 1065 eq. 33): the mean over
# i = 0..n, n = floor(N/6 - 3), of AVAR(m = 9 + 3i) / Theo1(m = 12 + 4i),
# two estimates at the same averaging time. Theo1 at every needed m comes
# from theo1_many(), AVAR from the overlapping estimator. NA when the record
# is too short (N < 19 phase points).
theobr_factor <- function(v, freq, rate, L, threads = 1L) {
  n <- floor(L / 6 - 3)
  if (n < 0) return(NA_real_)
  i <- 0:n
  mt <- 12 + 4 * i
  ma <- 9 + 3 * i
  ok <- mt <= L - 1 & ma <= floor((L - 1) / 2)
  if (!any(ok)) return(NA_real_)
  mt <- mt[ok]
  ma <- ma[ok]
  T <- theo1_many(v, rate, mt, threads)
  th <- T / (0.75 * (L - mt) * mt^2)
  input <- if (rate) "rate" else "integrated"
  a <- allan(v, 1, taus = I(ma), type = "overlapping", input = input)
  mean(a$avar / th)
}
