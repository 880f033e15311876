#' Allan variance and its relatives, with confidence intervals
#'
#' Computes an Allan-family variance of one or several channels at a grid of
#' averaging times, with chi-square confidence intervals of the deviation.
#' The estimators follow NIST SP 1065 (and agree with Stable32 and Python
#' `allantools`); all are evaluated from compensated prefix sums, so the
#' result is accurate to about \eqn{10^{-13}} relative even for long records
#' with a large bias or drift.
#'
#' @section Estimators:
#' With phase points \eqn{x_0, \dots, x_{L-1}} (for `input = "rate"`:
#' \eqn{x_0 = 0}, \eqn{x_k = \tau_0 \sum_{i \le k} y_i}, \eqn{L = N + 1};
#' for `input = "integrated"` the values themselves, \eqn{L = N}) and
#' \eqn{\tau = m\tau_0}:
#' * `"standard"`: non-overlapping AV, terms
#'   \eqn{(x_{k+2m} - 2x_{k+m} + x_k)^2} at stride \eqn{m},
#'   \eqn{n = \lfloor (L-1)/m \rfloor - 1} terms, divided by \eqn{2\tau^2 n}.
#'   For rate input this is exactly the estimator of [avar()] (clusters from
#'   the first sample, a trailing partial cluster dropped). Largest \eqn{m}:
#'   \eqn{\lfloor (L-1)/2 \rfloor}.
#' * `"overlapping"`: the same terms at stride 1, \eqn{n = L - 2m}; largest
#'   \eqn{m}: \eqn{\lfloor (L-1)/2 \rfloor}.
#' * `"modified"`: the square of the sum of \eqn{m} consecutive overlapping
#'   second differences, \eqn{n = L - 3m + 1}, divided by
#'   \eqn{2 m^2 \tau^2 n}; largest \eqn{m}: \eqn{\lfloor L/3 \rfloor}.
#' * `"hadamard"` and `"ohadamard"`: third differences
#'   \eqn{x_{k+3m} - 3x_{k+2m} + 3x_{k+m} - x_k} at stride \eqn{m}
#'   (\eqn{n = \lfloor (L-1)/m \rfloor - 2}) or 1 (\eqn{n = L - 3m}), divided
#'   by \eqn{6\tau^2 n}; largest \eqn{m}: \eqn{\lfloor (L-1)/3 \rfloor}.
#' * `"total"`: second differences centred on every inner point of the phase
#'   extended at both ends by point reflection,
#'   \eqn{x^*_{-j} = 2x_0 - x_j}, \eqn{x^*_{L-1+j} = 2x_{L-1} - x_{L-1-j}}
#'   (NIST SP 1065 eq. 25), \eqn{n = L - 2}; largest \eqn{m}: \eqn{L - 1}.
#'
#' Cluster sizes without a single term are dropped.
#'
#' @section Confidence intervals:
#' The interval for the deviation at level `conf` is the chi-square interval
#' \eqn{[\sqrt{\nu \hat\sigma^2/\chi^2_{1-p}(\nu)},
#' \sqrt{\nu \hat\sigma^2/\chi^2_{p}(\nu)}]}, \eqn{p = (1 - conf)/2}, with
#' \eqn{\nu} the equivalent degrees of freedom (`edf`). The noise type
#' (power-law exponent \eqn{\alpha} of the rate PSD) is identified at every
#' tau from that tau's data alone, as NIST SP 1065 (section 5.6) and Stable32
#' do it:
#' * while the decimated series has at least 64 points (cluster averages of
#'   rate input, linearly detrended; every m-th phase point of integrated
#'   input, as it is, as Stable32 reads it), Riley and Greenhall's lag-1
#'   autocorrelation method over the whole series, differencing at most
#'   twice (three times for Hadamard types). Stable32 and allantools start
#'   at 30 points; between 30 and 63 the lag-1 autocorrelation misreads
#'   flicker PM often enough that TOTDEV's 68% intervals cover 0.55 of it
#'   at N/m = 32 (Monte Carlo, N = 1024), so B1 and R(n) are used there
#'   (no limit compared with Stable32's changes). Where it reads phase
#'   noise at \eqn{m \ge 4} within two standard errors of the white/flicker
#'   PM boundary, R(n) over the whole record chooses between the two (it
#'   read flicker PM as white PM in 25-47% of records at N = 1024, m =
#'   4-16; the 68% intervals of the total family covered 0.58-0.63 there,
#'   now 0.67-0.73);
#' * below that, Barnes' B1 ratio (standard over Allan variance of the
#'   cluster averages) against its expected values for N = the statistic's
#'   number of terms and Howe et al.'s (2000) boundaries, as Stable32.
#'   For `"total"` random-walk against flicker FM is told with N = the
#'   number of cluster averages: with Stable32's N random walk is out of
#'   reach at long tau, and TOTDEV's 68% intervals cover only 0.57-0.59 of
#'   random-walk FM at N/m = 4 (Monte Carlo, N = 1024 and 4096; the Allan
#'   types stay at 0.60-0.65). Where B1 points to phase noise, the ratio
#'   R(n) of the modified to the Allan variance picks among white and
#'   flicker PM and the three FM types (Stable32 asks it only between white
#'   and flicker PM for the modified family, which types NIST SP 1065's
#'   white-FM NBS14 set flicker PM at m = 100 where SP 1065 corrects MTOT's
#'   bias as white FM's). Where B1 says white FM, R(n) may still say white
#'   PM (from 4 cluster averages: its ratio \eqn{1/m} is far below every
#'   FM type's) or flicker PM (from 8): B1 from so few averages reads PM as
#'   white FM in 21-60% of records, and the 68% intervals of overlapping
#'   ADEV covered 0.77-0.89 of white and flicker PM at N/m = 4-16 (now
#'   0.68-0.75; Monte Carlo, N = 1024). Not for `"total"`, whose EDF for
#'   white PM at long tau (Stable32's, NIST SP 1065 Table 5) is itself
#'   2-12 times too high;
#' * with fewer than three cluster averages (or phase noise that R(n) cannot
#'   check), the type is unknown: `alpha` is `NA` and the EDF is the
#'   smallest over the admissible types (the widest interval).
#'
#' `options(allanvar.noise_id = "stable32")` applies Stable32's rules
#' throughout (also for `"total"` and R(n); flicker PM where R(n) cannot be
#' read), for comparisons with Stable32's tables;
#' `options(allanvar.noise_id = "coverage")` the rules of allanvar before
#' (random walk told with the number of cluster averages for every type),
#' whose 68% intervals cover random-walk FM at 0.65-0.72 where Stable32's
#' cover 0.60-0.65.
#'
#' Then:
#' * for white (\eqn{\alpha = 0}) or random-walk (\eqn{\alpha = -2}) rate
#'   noise and \eqn{m \le 64}, the EDF is exact for the discrete process,
#'   from the Gaussian fourth moments (Isserlis) of the estimator's terms.
#'   Greenhall's algorithm models continuous-time noise and overstates the
#'   EDF of sampled white noise at small \eqn{m} (782 instead of 666 at
#'   \eqn{m = 1}, \eqn{N = 1000}), which would make the intervals too short;
#' * otherwise, Greenhall and Riley's general algorithm (2004, PTTI);
#' * for `"total"`: white and flicker PM, NIST SP 1065 Table 5 (as Stable32);
#'   white, flicker and random-walk FM, the larger of the overlapping EDF and
#'   SP 1065 Table 7's \eqn{b (L-1)/m - c} for \eqn{m \ge 8}, the
#'   overlapping EDF below (at \eqn{m = 1} the Total terms are the
#'   overlapping ones, so Table 7's 1500 at \eqn{L = 1001} would overstate
#'   the EDF 666 of sampled white FM).
#'
#' Long grids (more than 200 taus) identify the noise and evaluate the EDF at
#' every \eqn{m \le 64} and 40 taus per decade above; the other rows take
#' the type of the nearest such tau and a log-log interpolation of its EDF.
#'
#' @section Gaps:
#' With `gaps = "skip"`, a term is kept only when every value it is made of
#' is present: for rate input the samples it spans (\eqn{[k, k+2m)} for the
#' Allan types, \eqn{[k, k+3m)} for Hadamard, \eqn{[k, k+3m-1)} for the
#' modified type: the frequency-to-phase conversion never integrates across
#' a gap); for integrated input the phase points it uses (\eqn{x_k, x_{k+m},
#' x_{k+2m}}, and \eqn{x_{k+3m}} for Hadamard; all of \eqn{x_k \dots
#' x_{k+3m-1}} for the modified type). The variance is the mean square of
#' the kept terms, `n` counts them, and the attribute `missing` gives the
#' number of missing values per channel (print shows the total). Cluster
#' sizes with no complete term are left out with a warning. The noise type
#' is identified on the longest run without a gap (`NA` where that run is
#' too short), and the EDF uses the kept terms and the present points.
#' `"tdev"` (\eqn{\tau/\sqrt3} MDEV) follows the modified rule. The other
#' types are not defined with gaps and are refused (an error of class
#' `allanvar_error_gaps`): `"total"`, `"mtotdev"`, `"ttotdev"` and
#' `"htotdev"` (their reflection would carry a gap to the far end of the
#' extended window), `"theo1"`, `"theobr"`, `"theoh"`, `"mtie"`, `"tierms"`
#' and `"pdev"` (no published gap rule; fill the gaps first).
#'
#' @section Methods:
#' `print()` shows a header line and the table (`digits`, default 4);
#' `summary()` gives, per channel, the tau range and the minimum ADEV with
#' its interval; `plot(x, col = NULL, main = NULL, xlab, ylab, legend = TRUE,
#' ...)` draws ADEV against tau on log-log axes with the confidence bars, one
#' colour per channel and a legend when there are several;
#' `as.data.frame()` drops the class and attributes.
#'
#' @section Cost:
#' The phase is accumulated once per channel as a pair of double arrays
#' (hi on a fixed grid, lo the remainder), \eqn{16 N} bytes, besides at most
#' one copy of the input (integer or data-frame input is converted). Work
#' buffers of 2-256 MiB are kept for the next call (at most two, 320 MiB in
#' all): the system would otherwise zero every fresh page, a fifth of an
#' overlapping variance's time at \eqn{10^7} samples. The
#' standard and Hadamard types at octave cluster sizes need no prefix arrays
#' at all: they build the cluster sums pairwise in one pass over the data,
#' which also gathers what the noise identification of the limits needs
#' (for every type at octave taus of rate data). Stride-1
#' types cost \eqn{O(N)} per tau (so `taus = "all"` is \eqn{O(N^2)} for
#' them), stride-\eqn{m} types \eqn{O(N/m)}. Channels are shared between
#' `getOption("allanvar.threads", 2)` threads; a single channel splits its
#' work between them.
#'
#' @param x Numeric vector, `ts`, matrix or data frame of samples; one curve
#'   per column. Rate samples (angular rate, acceleration, fractional
#'   frequency) with `input = "rate"`; angle, velocity or clock phase with
#'   `input = "integrated"`.
#' @param freq Sampling frequency in Hz. Taken from `x` when it is a `ts`
#'   and `freq` is missing.
#' @param taus The averaging times: `"octave"` (\eqn{m = 1, 2, 4, \dots}),
#'   `"decade"` (\eqn{m = 1, 2, 4, 10, 20, 40, \dots}), `"all"` (every
#'   \eqn{m}; note that overlapping types then cost \eqn{O(N^2)}), a single
#'   whole number (that many log-spaced points per decade), or a numeric
#'   vector of tau in seconds (rounded to whole clusters; wrap a single tau
#'   in [I()]). Reported tau is \eqn{m / freq}.
#' @param type One of `"overlapping"` (default), `"standard"`,
#'   `"modified"`, `"hadamard"`, `"ohadamard"`, `"total"`, or a further
#'   statistic (`"tdev"`, `"mtotdev"`, `"ttotdev"`, `"htotdev"`, `"theo1"`,
#'   `"theobr"`, `"theoh"`, `"mtie"`, `"tierms"`, `"pdev"`; see "Further
#'   statistics"). allantools' names are accepted too: `"adev"`, `"oadev"`,
#'   `"mdev"`, `"hdev"`, `"ohdev"`, `"totdev"`.
#' @param input `"rate"` (default) or `"integrated"`.
#' @param conf Confidence level of the interval, in (0, 1); the default
#'   0.683 is one sigma.
#' @param gaps What NA/NaN in `x` mean: `"skip"` (the default): they are
#'   missing samples (or phase points), and every term that touches one is
#'   left out, as Stable32 and allantools' `gradev` do (see the section Gaps;
#'   the count of missing values is printed and kept in the attribute
#'   `missing`); or `"error"`: refuse them. `Inf` is always an error.
#' @param ci `TRUE` (default): confidence limits, which need the noise type
#'   identified at every tau and its EDF. `FALSE`: the values alone, without
#'   noise identification (faster: for the standard and Hadamard types at
#'   octave taus the one pass over the data is all): the columns stay, `lower`, `upper`,
#'   `edf` and `alpha` are `NA` (the bias-corrected `"mtotdev"`,
#'   `"ttotdev"`, `"htotdev"` and `"theo1"` still identify the type their
#'   correction needs, and report it in `alpha`). `print()` says there are
#'   no intervals and `plot()` draws no bars.
#' @param unbiased `FALSE` (default): `adev` is the square root of the
#'   unbiased variance estimate, which underestimates the deviation at small
#'   EDF (its mean is \eqn{c_4(\nu)\sigma}). `TRUE`: `adev` is divided by
#'   \eqn{c_4(\nu) = E\sqrt{\chi^2_\nu/\nu} = \sqrt{2/\nu}\,
#'   \Gamma((\nu+1)/2)/\Gamma(\nu/2)} at the row's EDF \eqn{\nu}, an
#'   unbiased estimate of the deviation (as SigmaTheta reports it); `avar`
#'   is unchanged, and so are `lower` and `upper`: they are a confidence
#'   interval for the true deviation, which the unbiased value estimates
#'   (scaling them too would lower their coverage). Needs the EDF, so the
#'   noise type is identified even with `ci = FALSE`. Statistics without an
#'   EDF (`"mtie"`, `"tierms"`) ignore it.
#' @param theo For `"theobr"` and `"theoh"` only: `NULL` (default) or a
#'   list of some of
#'   * `ladder`: the length of TheoBR's bias-factor ladder, `"N/6"`
#'     (default; \eqn{n = \lfloor L/6 - 3 \rfloor}, Stable32's Run and
#'     Plot) or `"N/30"` (\eqn{n = \lfloor 0.1 L/3 - 3 \rfloor}, Howe's
#'     TheoH papers, Riley's TheoBR code, Stable32's "Sigma" calculations;
#'     it leaves out the Allan variances at the fewest averages);
#'   * `method`: `"auto"` (default: the exact factor up to
#'     \eqn{10^5} phase points, the fast one above, with a message of class
#'     `allanvar_message_theo_fast`), `"exact"` or `"fast"`: the factor from
#'     the phase averaged over blocks of \eqn{r = \lceil L /
#'     \mathrm{fast\_points} \rceil} points, with a correction for the
#'     noise type identified along the ladder (Taylor & Howe, "Fast
#'     TheoBR", IEEE TUFFC 57(9), 2010; see "Further statistics");
#'   * `fast_points`: the length the averaged phase keeps (default 32768).
#'
#'   The Theo1 values themselves are exact on either path.
#' @return A data frame of class `c("allan", "data.frame")` with columns
#'   `tau` (s), `m` (cluster size), `n` (number of terms), `avar`, `adev`,
#'   `lower` and `upper` (confidence limits of `adev`), `edf`, then, when `x`
#'   has several columns, `channel` (the column name; rows stacked channel by
#'   channel), and last `alpha` (the integer noise exponent behind the EDF;
#'   `NA` where too few points identify it).
#'   Attributes: `freq`, `type`, `input`, `N` (samples per channel), `conf`;
#'   `ci = FALSE` and `unbiased = TRUE` when those were asked for.
#' @seealso [avar()], [avarn()] and [avari()] for the results of
#'   'allanvar' 1.1.
#' @export
#' @examples
#' set.seed(1)
#' y <- ts(rnorm(1e4, sd = 0.1), frequency = 100)
#' av <- allan(y)
#' av
#' plot(av)
#' allan(cbind(x = y, z = 2 * y), type = "modified", taus = "decade")
allan <- function(x, freq, taus = "octave", type = "overlapping",
                  input = "rate", conf = 0.683, gaps = "skip",
                  debias = TRUE, ci = TRUE, unbiased = FALSE, theo = NULL) {
  check_present(missing(x), "x", "the samples")
  if (missing(freq)) {
    if (!stats::is.ts(x)) {
      abort("`freq` is missing; give the sampling frequency in Hz ",
            "(or pass `x` as a ts).")
    }
    freq <- stats::frequency(x)
  }
  freq <- check_freq(freq)
  e <- stat_entry(check_choice(type, stat_names(), "type"))
  type <- e$name
  input <- check_choice(input, c("rate", "integrated"), "input")
  conf <- check_number(conf, "conf", 0, 1, open = TRUE)
  gaps <- check_choice(gaps, c("skip", "error"), "gaps")
  debias <- check_true_false(debias, "debias")
  ci <- check_true_false(ci, "ci")
  unbiased <- check_true_false(unbiased, "unbiased")
  theo <- check_theo(theo, e)
  if (!identical(e$kernel, "sums")) {
    return(allan_extra(x, freq, taus, e, input, conf, debias, gaps, ci,
                       unbiased, theo))
  }
  ch <- allan_channels(x, min_n = if (input == "rate") 2L else 3L)
  N <- ch$N
  rate <- input == "rate"
  L <- if (rate) N + 1 else N
  maxm <- e$max_m(L)
  m <- e$taus(taus, freq, L, maxm)$m
  if (length(m) == 0L) {
    abort("No averaging time in `taus` has a term for type \"", type,
          "\" with ", N, " samples (largest cluster size: ", maxm, ").")
  }
  nterms <- e$nterms(m, L)
  octave <- e$octave_pass && rate && length(m) <= 64L &&
    all(m == 2^round(log2(m)))
  # the noise type is identified only where the EDF is asked for
  sub <- if (ci || unbiased) allan_subset(m) else integer(0)
  res <- allan_call_kernel(allan_sums_cpp(ch$values, N, m, nterms, m[sub],
                                          allan_opts(type, rate, octave)),
                           N, ch$nc)
  if (any(res$bad > 0)) {
    # the kernel finds NA/NaN in the pass it makes anyway (no anyNA() pass
    # over every call's data)
    if (gaps == "skip" && anyNA(ch$values)) {
      return(allan_gaps(ch, freq, m, e, input, conf, ci, unbiased))
    }
    col <- which(res$bad > 0)[1L]
    row <- res$bad[col]
    bad <- ch$values[[(col - 1) * N + row]]
    abort("`x` must contain only finite numbers; found ", format(bad),
          " at position ", row, if (ch$nc > 1L) paste0(" of column ", col),
          if (is.na(bad)) paste0(" (gaps = \"skip\" skips the terms that ",
                                 "touch missing values)"), ".",
          class = "values")
  }
  # the estimator's divisor: one vector (a long curve's temporaries cost
  # more in page faults than in arithmetic)
  den <- e$divisor(m) * nterms
  # Sums that overflowed (or underflowed) in a channel of huge (tiny) but
  # finite numbers: that channel again on x 2^-e (exact), scaled back.
  sc <- rep(0, ch$nc)
  for (j in seq_len(ch$nc)) {
    # min() and max() of the column: no copies of a long curve
    sj <- if (ch$nc == 1L) res$sums else res$sums[, j]
    if (is.finite(max(sj)) && min(sj) >= 2^-900) next
    xj <- if (ch$nc == 1L) ch$values else ch$values[(j - 1) * N + seq_len(N)]
    ex <- range_exponent(xj)
    # zero sums of a constant channel are right as they are
    if (ex == 0 || (all(sj == 0) && diff(range(xj)) == 0)) next
    rj <- allan_call_kernel(allan_sums_cpp(times_pow2(as.double(xj), -ex), N,
                                           m, nterms, m[sub],
                                           allan_opts(type, rate, octave)),
                            N, 1L)
    res$sums[, j] <- rj$sums[, 1L]
    res$alpha_int[, j] <- rj$alpha_int[, 1L]
    sc[j] <- ex
  }
  out <- vector("list", ch$nc)
  for (j in seq_len(ch$nc)) {
    av <- res$sums[, j] / den
    if (!rate && sc[j] == 0) {
      av <- times_freq2(av, freq)
    } else if (sc[j] != 0) {
      # one product of powers of two: 2^2e and freq^2 = a^2 2^2b
      b <- if (rate) 0 else floor(log2(freq))
      a <- if (rate) 1 else freq / 2^b
      av <- times_pow2(av * a * a, 2 * sc[j] + 2 * b)
    }
    check_representable(av, nonzero = res$sums[, j] > 0)
    # the rows at few averages may rest on another statistic's reading
    # (the entry's exact_id; R/ci-exact.R)
    ex_alpha <- NULL
    if (ci && !is.na(e$exact_id) && any(exact_rows(m, L))) {
      xj <- ch$values
      if (ch$nc > 1L) xj <- xj[(j - 1) * N + seq_len(N)]
      ex_alpha <- exact_id_alpha(as.double(xj), freq, m, e$exact_id,
                                 if (rate) "rate" else "integrated", L,
                                 max(-res$range[1L, j], res$range[2L, j]))
    }
    lim <- stat_limits(e, av, m, nterms, L, res$alpha_int[, j], sub, conf,
                       ci, unbiased, ex_alpha)
    out[[j]] <- allan_rows(m, nterms, av, lim, freq, ch, j)
  }
  out <- if (ch$nc == 1L) out[[1L]] else do.call(rbind, out)
  if (ch$nc > 1L) rownames(out) <- NULL
  structure(out, class = c("allan", "data.frame"), freq = freq, type = type,
            input = input, N = N, conf = conf, ci = allan_ci_attr(ci),
            unbiased = allan_unbiased_attr(e, unbiased))
}

# The attributes `ci` and `unbiased`: present only where they differ from
# the default (the default call's attributes stay as they were).
allan_ci_attr <- function(ci) if (!ci) FALSE
allan_unbiased_attr <- function(e, unbiased) if (unbiased && e$unbiased) TRUE

# ---- gaps: allan(gaps = "skip") ----
# NA/NaN are missing samples (rate) or phase points (integrated). A term is
# kept only when every value it is made of is present (src/allan.cpp,
# allan_gap_sums_cpp); `n` counts the kept terms. The noise type comes from
# the longest run without a gap; the EDF from the kept terms and the
# present points. Inf stays an error; the total type is not defined.
allan_gaps <- function(ch, freq, m, e, input, conf, ci = TRUE,
                       unbiased = FALSE) {
  N <- ch$N
  rate <- input == "rate"
  L <- if (rate) N + 1 else N
  type <- e$name
  if (!identical(e$gaps, "sums")) abort(e$gaps, class = "gaps")
  inf <- which(is.infinite(ch$values))
  if (length(inf)) {
    col <- (inf[1] - 1L) %/% N + 1L
    abort("`x` must contain only finite numbers or NA; found ",
          format(ch$values[[inf[1]]]), " at position ", (inf[1] - 1L) %% N + 1L,
          if (ch$nc > 1L) paste0(" of column ", col), ".", class = "values")
  }
  norm <- e$divisor(m)
  opts <- allan_opts(type, rate, FALSE)
  out <- vector("list", ch$nc)
  missing <- integer(ch$nc)
  dropped <- NULL
  for (j in seq_len(ch$nc)) {
    xj <- as.double(if (ch$nc == 1L) ch$values else
      ch$values[(j - 1) * N + seq_len(N)])
    miss <- is.na(xj)
    missing[j] <- sum(miss)
    g <- allan_call_kernel(allan_gap_sums_cpp(xj, m, opts), N, 1L)
    keep <- g$n > 0
    if (!all(keep)) dropped <- c(dropped, m[!keep])
    mj <- m[keep]
    nj <- g$n[keep]
    av <- g$sums[keep] / (norm[keep] * nj)
    if (!rate) av <- times_freq2(av, freq)
    check_representable(av, nonzero = g$sums[keep] > 0)
    # noise type from the longest run without a gap
    r <- rle(!miss)
    end <- cumsum(r$lengths)
    best <- which.max(ifelse(r$values, r$lengths, -1L))
    run <- seq.int(end[best] - r$lengths[best] + 1L, end[best])
    alpha <- rep(NA_integer_, length(mj))
    if ((ci || unbiased) && r$values[best] &&
        length(run) >= (if (rate) 2L else 3L)) {
      Lr <- if (rate) length(run) + 1 else length(run)
      ok <- mj <= e$max_m(Lr)
      if (any(ok)) {
        rr <- allan_call_kernel(allan_sums_cpp(
          xj[run], length(run), mj[ok], e$nterms(mj[ok], Lr),
          mj[ok], opts), length(run), 1L)
        alpha[ok] <- rr$alpha_int[, 1L]
      }
    }
    lim <- stat_limits(e, av, mj, nj, L - missing[j], alpha,
                       if (ci || unbiased) seq_along(mj) else integer(0),
                       conf, ci, unbiased)
    out[[j]] <- allan_rows(mj, nj, av, lim, freq, ch, j)
  }
  if (length(dropped)) {
    warn("No complete term at cluster size(s) ",
         paste(sort(unique(dropped)), collapse = ", "),
         " (every term touches a gap); those rows are left out.",
         class = "gaps")
  }
  out <- if (ch$nc == 1L) out[[1L]] else do.call(rbind, out)
  if (ch$nc > 1L) rownames(out) <- NULL
  names(missing) <- ch$names
  structure(out, class = c("allan", "data.frame"), freq = freq, type = type,
            input = input, N = N, conf = conf, missing = missing,
            ci = allan_ci_attr(ci), unbiased = allan_unbiased_attr(e, unbiased))
}

# Channel `j`'s rows of an allan() result at cluster sizes `m` with `n`
# terms each, variances `av` and their limits `lim` (stat_limits()): a
# data frame built without copies.
allan_rows <- function(m, n, av, lim, freq, ch, j) {
  d <- list(tau = m / freq, m = as.integer(m), n = n, avar = av,
            adev = lim$adev, lower = lim$lower, upper = lim$upper,
            edf = lim$edf)
  if (ch$nc > 1L) d$channel <- rep(ch$names[j], length(m))
  d$alpha <- lim$alpha
  structure(d, class = "data.frame", row.names = .set_row_names(length(m)))
}

# ---- range: series near 1e300 or 1e-300, sampling rates near 1e300 ----
# A power of two scales exactly, so a kernel run on x * 2^-e gives the
# variance of x times 2^-2e with every bit kept; results are scaled back
# with times_pow2() and must be representable doubles.

# v * 2^e without an intermediate overflow (2^e alone may not exist).
times_pow2 <- function(v, e) {
  while (any(e > 1000)) {
    k <- e > 1000
    v[k] <- v[k] * 2^1000
    e[k] <- e[k] - 1000
  }
  while (any(e < -1000)) {
    k <- e < -1000
    v[k] <- v[k] * 2^-1000
    e[k] <- e[k] + 1000
  }
  v * 2^e
}

# v * f^2 for a sampling rate f that may be near the double range.
times_freq2 <- function(v, f) {
  if (is.finite(f^2) && f^2 > 0) return(v * f^2)
  b <- floor(log2(f))
  a <- f / 2^b
  times_pow2(v * a * a, 2 * b)
}

# The exponent e with max |x| = m 2^e, m in [0.5, 1), of the finite values.
range_exponent <- function(x) {
  mx <- max(abs(x[is.finite(x)]), 0)
  if (mx == 0) return(0)
  floor(log2(mx)) + 1
}

# Stops when variances cannot be represented (ADEV beyond 1.3e154, or a
# non-zero variance below the smallest double); `nonzero`: where the
# variance is known to be positive.
check_representable <- function(av, nonzero = FALSE, what = "`x`") {
  # variances are >= 0: min() and max() settle long curves without
  # temporaries (range() copies its argument)
  if (length(av) > 0L && is.finite(max(av)) && min(av) >= .Machine$double.xmin) {
    return(av)
  }
  if (any(!is.finite(av))) {
    abort("The variance of ", what, " exceeds the largest double (",
          format(.Machine$double.xmax, digits = 3), "); divide the data by ",
          "a power of ten (e.g. x / 1e150) and scale the result back.",
          class = "overflow")
  }
  if (any(nonzero & av < .Machine$double.xmin)) {
    abort("The variance of ", what, " is below the smallest double (",
          format(.Machine$double.xmin, digits = 3), "); multiply the data ",
          "by a power of ten (e.g. x * 1e150) and scale the result back.",
          class = "underflow")
  }
  av
}

# Evaluates a kernel call; a C++ allocation failure (in any thread) becomes
# a classed error that says what to do.
allan_call_kernel <- function(expr, N, nc) {
  tryCatch(expr, error = function(e) {
    if (!identical(conditionMessage(e), "allanvar_out_of_memory")) stop(e)
    abort("Not enough memory for ", nc, if (nc > 1L) " channels" else
            " channel", " of ", format(N, big.mark = ","), " samples ",
          "(about ", format(ceiling(24 * N * min(nc, allanvar_threads()) / 2^20)),
          " MiB of work space); analyse fewer channels at once or a ",
          "shorter record.", class = "memory")
  })
}

# The samples as one double vector (columns stacked; no copy for a double
# vector or matrix), with the number of rows and the channel names.
allan_channels <- function(x, min_n) {
  if (is.data.frame(x)) {
    ok <- vapply(x, function(v) is.numeric(v) && !is.factor(v), TRUE)
    if (!all(ok)) {
      abort("`x` must have only numeric columns; column `",
            names(x)[!ok][1L], "` is ", describe_type(x[[which(!ok)[1L]]]), ".")
    }
    nm <- names(x)
    x <- as.matrix(x)
    colnames(x) <- nm
  }
  if (is.matrix(x)) {
    if (!is.numeric(x)) {
      abort("`x` must be numeric, not ", describe_type(x), ".")
    }
    nc <- ncol(x)
    N <- nrow(x)
    nm <- colnames(x)
    if (is.null(nm)) nm <- paste0("V", seq_len(nc))
    if (nc == 0L) abort("`x` has no columns.")
  } else {
    if (is.null(x) || is.factor(x) || is.list(x) ||
        !(is.double(x) || is.integer(x))) {
      abort("`x` must be a numeric vector, ts, matrix or data frame, not ",
            describe_type(x), ".")
    }
    nc <- 1L
    N <- length(x)
    nm <- "x"
  }
  if (N < min_n) {
    abort("`x` must have at least ", min_n, " samples per channel, not ", N, ".")
  }
  if (!is.double(x)) storage.mode(x) <- "double"
  # passed to C++ as is (attributes such as ts or dim cost no copy); the
  # kernel checks finiteness in the pass it makes anyway
  list(values = x, N = N, nc = nc, names = nm)
}

#' @export
print.allan <- function(x, digits = 4, ...) {
  cat(allan_header(x), "\n", sep = "")
  d <- as.data.frame(x)
  # n is a count: rounding it to `digits` would misstate it.
  num <- vapply(d, is.double, TRUE) & names(d) != "n"
  d[num] <- lapply(d[num], signif, digits = digits)
  print(d, row.names = FALSE, ...)
  invisible(x)
}

# The header line: the statistic's title, the input, the missing values,
# the intervals (none for a statistic without limits or with ci = FALSE),
# the unit of a time statistic, the bias convention.
allan_header <- function(x) {
  a <- attributes(x)
  e <- stat_entry(a$type)
  nch <- if ("channel" %in% names(x)) length(unique(x$channel)) else 1L
  sprintf("<allan> %s of %s input: N = %s at %s Hz%s%s%s%s%s%s",
          e$title, a$input, format(a$N, big.mark = ","), format(a$freq),
          if (nch > 1L) sprintf(", %d channels", nch) else "",
          if (!is.null(a$missing)) sprintf(" (%s missing)",
                                           format(sum(a$missing), big.mark = ","))
          else "",
          if (!stat_has_limits(e)) "" else if (identical(a$ci, FALSE))
            "; no intervals (ci = FALSE)" else
            sprintf("; %s%% intervals", format(100 * a$conf)),
          if (isTRUE(a$unbiased)) "; unbiased deviation" else "",
          if (identical(e$unit, "time"))
            paste0("; `adev` is a time in the phase unit (seconds ",
                   "for phase in s or fractional-frequency input)")
          else "",
          if (isTRUE(a$debias)) "; bias-corrected (NIST SP 1065)" else
            if (identical(a$debias, FALSE)) "; not bias-corrected" else "")
}

#' @export
as.data.frame.allan <- function(x, ...) {
  attr(x, "freq") <- attr(x, "type") <- attr(x, "input") <- NULL
  attr(x, "N") <- attr(x, "conf") <- NULL
  attr(x, "ci") <- attr(x, "unbiased") <- NULL
  class(x) <- "data.frame"
  x
}

#' @export
summary.allan <- function(object, ...) {
  d <- as.data.frame(object)
  if (is.null(d$channel)) d$channel <- "x"
  rows <- lapply(split(d, factor(d$channel, unique(d$channel))), function(s) {
    i <- which.min(s$adev)
    data.frame(channel = s$channel[1], points = nrow(s), tau_min = min(s$tau),
               tau_max = max(s$tau), adev_first = s$adev[1],
               adev_min = s$adev[i], tau_at_min = s$tau[i],
               lower_at_min = s$lower[i], upper_at_min = s$upper[i])
  })
  structure(do.call(rbind, rows), header = allan_header(object),
            class = c("summary.allan", "data.frame"))
}

#' @export
print.summary.allan <- function(x, digits = 4, ...) {
  print_summary_table(x, digits, ...)
}

# The summaries of allan(), dynamic_allan() and three_cornered_hat(): a
# header line, then the table with its real numbers to `digits`.
print_summary_table <- function(x, digits, ...) {
  cat(attr(x, "header"), "\n", sep = "")
  d <- x
  attr(d, "header") <- NULL
  class(d) <- "data.frame"
  # n is a count: rounding it to `digits` would misstate it.
  num <- vapply(d, is.double, TRUE) & names(d) != "n"
  d[num] <- lapply(d[num], signif, digits = digits)
  print(d, row.names = FALSE, ...)
  invisible(x)
}

#' @export
plot.allan <- function(x, col = NULL, main = NULL, xlab = "tau (s)",
                       ylab = NULL, legend = TRUE, ...) {
  d <- as.data.frame(x)
  if (is.null(d$channel)) d$channel <- "x"
  chans <- unique(d$channel)
  if (is.null(col)) {
    col <- c("black", "#D55E00", "#0072B2", "#009E73", "#CC79A7", "#E69F00",
             "#56B4E9", "#999999")
  }
  col <- rep_len(col, length(chans))
  type <- attr(x, "type")
  e <- stat_entry(type)
  if (is.null(ylab)) ylab <- e$ylab
  if (is.null(main)) {
    main <- if (!stat_has_limits(e) || identical(attr(x, "ci"), FALSE)) type else
      paste0(type, " (", 100 * attr(x, "conf"), "% CI)")
  }
  ok <- is.finite(d$adev) & d$adev > 0
  ylim <- range(c(d$lower[ok], d$upper[ok], d$adev[ok]), finite = TRUE)
  leg <- list(legend = chans, col = col, lty = 1, pch = 20)
  if (legend && length(chans) > 1L) {
    op <- reserve_legend(leg)
    on.exit(graphics::par(op))
  }
  graphics::plot(d$tau[ok], d$adev[ok], type = "n", log = "xy", xlab = xlab,
                 ylab = ylab, main = main, ylim = ylim, ...)
  graphics::grid(equilogs = FALSE)
  for (k in seq_along(chans)) {
    s <- d[d$channel == chans[k] & ok, ]
    graphics::lines(s$tau, s$adev, type = "b", pch = 20, col = col[k])
    bar <- is.finite(s$lower) & is.finite(s$upper) & s$upper > s$lower
    if (any(bar)) {
      graphics::arrows(s$tau[bar], s$lower[bar], s$tau[bar], s$upper[bar],
                       angle = 90, code = 3, length = 0.03, col = col[k])
    }
  }
  if (legend && length(chans) > 1L) {
    legend_beside(leg)
  }
  invisible(x)
}
