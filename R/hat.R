#' Individual stability of three sources from their pairwise comparisons
#'
#' `three_cornered_hat()` and `groslambert()` estimate the Allan-family
#' variance of each of three sources (clocks, oscillators, sensors) that can
#' only be observed against each other, from three simultaneous pairwise
#' comparisons.
#'
#' @section Comparisons and signs:
#' Each column of `x` is one comparison, named in `pairs` as `"P-Q"`: the
#' phase (for `input = "integrated"`) or the frequency or rate (for
#' `input = "rate"`) of source P minus that of source Q, sampled at the same
#' instants as the other comparisons. Source names are free text without
#' `"-"`. Any orientation can be given (`"A-B"`, `"B-C"`, `"C-A"` or
#' `"A-B"`, `"A-C"`, `"B-C"`, ...): the three-cornered hat does not depend on
#' it, and `groslambert()` uses it to orient every product so that it
#' estimates \eqn{+\sigma^2} of the common source.
#'
#' @section Three-cornered hat:
#' With independent sources, \eqn{\sigma^2_{AB} = \sigma^2_A + \sigma^2_B}
#' for every estimator of [allan()] (each is a mean of squares of linear
#' combinations of the data), so (Gray and Allan, 28th Annual Symposium on
#' Frequency Control, 1974)
#' \deqn{\hat\sigma^2_A = (\hat\sigma^2_{AB} + \hat\sigma^2_{AC} -
#'   \hat\sigma^2_{BC}) / 2,}
#' and likewise for B and C, at every tau of the pairwise curves (computed by
#' [allan()] with the given `type`; MTIE and TIE are not variances and are
#' refused). When the other two sources dominate, the estimate can come out
#' negative: it is then not reported as a number. `avar`, `adev` and the
#' limits are `NA`, `status` is `"negative"` and `reason` says which pairwise
#' variances made it so.
#'
#' @section Groslambert covariance:
#' `groslambert()` estimates source A from the two comparisons that contain
#' it alone: the mean of the products of their differences (the same terms
#' and normalisation as the Allan variance of `type`),
#' \deqn{\hat c_A = \frac{1}{2\tau^2 n}\sum_k s_{AB} s_{AC}\,
#'   \Delta x_{AB,k}\,\Delta x_{AC,k},}
#' with \eqn{s = +1} where A is the first source of the comparison and
#' \eqn{-1} where it is the second. The other sources' noise and any noise of
#' the two measurement systems that is uncorrelated between them average
#' out (Vernotte et al., "The three-cornered hat method: an attempt to
#' identify some clock correlations", IEEE UFFC 2016; Lantz et al., "KLTS: a
#' rigorous method to compute the confidence intervals for the three-cornered
#' hat and for Groslambert covariance", IEEE UFFC 66(12), 2019); the same
#' estimator as SigmaTheta's `GCoDev` and allantools' `gcodev` for the
#' overlapping type. When the third comparison closes the loop exactly
#' (\eqn{x_{AB} + x_{BC} + x_{CA} = 0}), it equals the three-cornered hat.
#' \eqn{\hat c_A} is a covariance and can be negative where A's noise is
#' small against the others': it is always reported, signed, in `gcov`, but
#' is read as A's variance (`avar`, `adev`, limits) only where positive;
#' elsewhere those are `NA`, `status` is `"negative"` and `reason` says so.
#' With two comparisons only, the one source they share is estimated.
#'
#' @section Confidence intervals:
#' Both estimators are linear in the pairwise statistics, whose variances
#' follow from their EDFs \eqn{\nu} (from [allan()]): \eqn{Var(\hat\sigma^2)
#' = 2\sigma^4/\nu}. Two comparisons that share source X covary through X
#' alone; for Gaussian noise that covariance is \eqn{2\sigma^4_X/\nu}, taken
#' with \eqn{\nu = \sqrt{\nu_1\nu_2}} of the two comparisons (exact when the
#' sources share a noise type). So, for the hat,
#' \deqn{Var(\hat\sigma^2_A) = \frac{1}{2}\left(\frac{\sigma^4_{AB}}{\nu_{AB}}
#'   + \frac{\sigma^4_{AC}}{\nu_{AC}} + \frac{\sigma^4_{BC}}{\nu_{BC}} +
#'   \frac{2\sigma^4_A}{\nu_{AB,AC}} - \frac{2\sigma^4_B}{\nu_{AB,BC}} -
#'   \frac{2\sigma^4_C}{\nu_{AC,BC}}\right),}
#' and, from Isserlis' theorem for the products, for the Groslambert
#' covariance \eqn{Var(\hat c_A) = (\sigma^2_{AB}\sigma^2_{AC} +
#' \sigma^4_A)/\nu_{AB,AC}}; both equal \eqn{(2\sigma^4_A + \sigma^2_A
#' \sigma^2_B + \sigma^2_B\sigma^2_C + \sigma^2_C\sigma^2_A)/\nu} when all
#' \eqn{\nu} are equal (our derivation, in the spirit of Ekstrom and
#' Koppang, "Error bars for three-cornered hats", IEEE UFFC 53(5), 2006).
#' The estimates stand in for the unknown variances (negative ones as 0).
#' The estimate is a difference of (nearly) chi-square variables, not a
#' chi-square variable: a chi-square interval built from its EDF misses the
#' truth for a source much quieter than the others (in our simulations of
#' three white-FM clocks with levels 1, 3 and 0.1, it never covered the
#' quiet one). The interval of the variance is therefore the normal one,
#' \eqn{\hat\sigma^2 \pm z\,\sqrt{Var}}, the lower limit at least 0, at
#' level `conf`; `lower` and `upper` are its square roots. In the same
#' simulations (and with levels 3, 0.3, 0.3) it covers 65-74% of the time at
#' the nominal 68.3% wherever the EDF exceeds 2, and more (up to 90%) below
#' (conditional on a positive estimate). The
#' reported `edf`, \eqn{2\hat\sigma^4_A / Var(\hat\sigma^2_A)}, says how
#' firm an estimate is: below a few degrees of freedom the interval is an
#' approximation (Lantz et al. 2019 above give the exact Bayesian
#' treatment, KLTS, which this package does not implement).
#'
#' @param x The comparisons: a matrix, data frame or list of numeric vectors
#'   of the same length (or a multi-column `ts`), one comparison per column;
#'   three for the hat, two or three for `groslambert()`.
#' @param freq Sampling frequency in Hz; taken from `x` when it is a `ts`
#'   and `freq` is missing.
#' @param pairs The comparisons as `"P-Q"` (P minus Q), one per column of
#'   `x`. `NULL` takes the column names when they all have that form, else
#'   `c("A-B", "B-C", "C-A")` (`c("A-B", "A-C")` for two columns).
#' @param taus,input,conf As in [allan()].
#' @param type For `three_cornered_hat()`, any variance type of [allan()]
#'   (default `"overlapping"`); for `groslambert()` one of `"overlapping"`,
#'   `"standard"`, `"modified"`, `"hadamard"`, `"ohadamard"`.
#' @return A data frame of class `c("allan_sources", "data.frame")`, one row
#'   per source and tau: `source`, `tau`, `m`, `n`, (for `groslambert()`
#'   `gcov`, the signed covariance estimate), `avar` (the source's variance,
#'   `NA` where the estimate is not positive), `adev`, `lower`, `upper`,
#'   `edf`, `status` (`"ok"` or `"negative"`) and `reason` (`NA` or why the
#'   variance is missing). Attributes: `method`, `pairs`, `freq`, `type`,
#'   `input`, `N`, `conf` and `comparisons`, the [allan()] result of the
#'   comparisons. Methods: `print()`, `summary()`, `plot()` (the deviation
#'   of each source against tau with its interval, the comparisons dashed,
#'   negative estimates marked by a triangle on the lower axis) and
#'   `as.data.frame()`.
#' @export
#' @examples
#' # three clocks: white FM of levels 1, 2 and 4 (fractional frequency)
#' set.seed(1)
#' n <- 20000
#' a <- rnorm(n, sd = 1); b <- rnorm(n, sd = 2); c <- rnorm(n, sd = 4)
#' cmp <- cbind("A-B" = a - b, "B-C" = b - c, "C-A" = c - a)
#' hat <- three_cornered_hat(cmp, freq = 1)
#' hat
#' plot(hat)
#' # with independent noise of the two counters that measure A
#' meas <- cbind("A-B" = a - b + rnorm(n, sd = 3), "A-C" = a - c + rnorm(n, sd = 3))
#' groslambert(meas, freq = 1, taus = "decade")
three_cornered_hat <- function(x, freq, pairs = NULL, taus = "octave",
                               type = "overlapping", input = "rate",
                               conf = 0.683) {
  check_present(missing(x), "x", "the three pairwise comparisons")
  if (missing(freq)) freq <- hat_ts_freq(x)
  e <- if (is.character(type) && length(type) == 1L && !is.na(type)) stat_entry(type)
  if (!is.null(e) && !e$variance) {
    abort("`type` must be a variance for the three-cornered hat; \"", type,
          "\" is a time-error statistic.", class = "argument")
  }
  cmp <- hat_comparisons(x, pairs, n_allowed = 3L)
  cv <- hat_curves(cmp, freq, taus, type, input, conf)
  av <- cv$av
  S <- cv$S
  nu <- cv$nu
  tau1 <- cv$tau1
  rows <- lapply(cmp$sources, function(src) {
    r <- hat_roles(cmp, src)
    est <- (S[, r$i] + S[, r$j] - S[, r$k]) / 2
    list(src = src, r = r, est = est)
  })
  ests <- vapply(rows, function(z) z$est, numeric(nrow(S)))
  ests <- matrix(ests, nrow(S))
  colnames(ests) <- cmp$sources
  pos <- pmax(ests, 0)
  out <- lapply(rows, function(z) {
    r <- z$r
    g <- function(a, b) sqrt(nu[, a] * nu[, b])
    v <- 0.5 * (S[, r$i]^2 / nu[, r$i] + S[, r$j]^2 / nu[, r$j] +
                  S[, r$k]^2 / nu[, r$k] +
                  2 * pos[, z$src]^2 / g(r$i, r$j) -
                  2 * pos[, r$other[1L]]^2 / g(r$i, r$k) -
                  2 * pos[, r$other[2L]]^2 / g(r$j, r$k))
    # equal-EDF form where unequal EDFs push the sum below it
    nu_all <- exp(rowMeans(log(nu[, c(r$i, r$j, r$k), drop = FALSE])))
    v_eq <- (2 * pos[, z$src]^2 + pos[, z$src] * pos[, r$other[1L]] +
               pos[, r$other[1L]] * pos[, r$other[2L]] +
               pos[, r$other[2L]] * pos[, z$src]) / nu_all
    v <- ifelse(is.finite(v) & v > 0, v, v_eq)
    why <- sprintf(paste0("sigma^2(%s) = %s exceeds sigma^2(%s) + ",
                          "sigma^2(%s) = %s"), cmp$pairs[r$k],
                   format(signif(S[, r$k], 4)), cmp$pairs[r$i],
                   cmp$pairs[r$j], format(signif(S[, r$i] + S[, r$j], 4)))
    hat_rows(z$src, tau1, z$est, v, conf, why, gcov = NULL)
  })
  hat_result(out, "three-cornered hat", cmp, av, freq)
}

#' @rdname three_cornered_hat
#' @export
groslambert <- function(x, freq, pairs = NULL, taus = "octave",
                        type = "overlapping", input = "rate", conf = 0.683) {
  check_present(missing(x), "x", "two or three pairwise comparisons")
  if (missing(freq)) freq <- hat_ts_freq(x)
  type <- check_choice(type, dyn_types, "type")
  cmp <- hat_comparisons(x, pairs, n_allowed = 2:3)
  cv <- hat_curves(cmp, freq, taus, type, input, conf)
  av <- cv$av
  S <- cv$S
  nu <- cv$nu
  tau1 <- cv$tau1
  m <- tau1$m
  nt <- tau1$n
  rate <- input == "rate"
  norm <- dyn_norm(type, m) * nt / (if (rate) 1 else attr(av, "freq")^2)
  out <- lapply(cmp$sources, function(src) {
    r <- hat_roles(cmp, src)
    sums <- dynamic_sums_cpp(cmp$values[, r$i], cmp$values[, r$j], m, nt,
                             dyn_opts(type, rate, step = 1, nwin = 1))
    g <- r$sign * as.vector(sums) / norm
    pos <- pmax(g, 0)
    v <- (S[, r$i] * S[, r$j] + pos^2) / sqrt(nu[, r$i] * nu[, r$j])
    why <- sprintf("the covariance of %s and %s is %s at this tau",
                   cmp$pairs[r$i], cmp$pairs[r$j], format(signif(g, 4)))
    hat_rows(src, tau1, g, v, conf, why, gcov = g)
  })
  hat_result(out, "Groslambert covariance", cmp, av, freq)
}

hat_ts_freq <- function(x) {
  if (!stats::is.ts(x)) {
    abort("`freq` is missing; give the sampling frequency in Hz ",
          "(or pass `x` as a ts).", class = "missing_argument")
  }
  stats::frequency(x)
}

# The comparisons as a numeric matrix with one column per pair, the parsed
# pairs and the sources in order of appearance; checks that they form what
# the method needs.
hat_comparisons <- function(x, pairs, n_allowed) {
  if (is.list(x) && !is.data.frame(x)) {
    lens <- vapply(x, length, 1L)
    if (length(x) == 0L || any(lens != lens[1L])) {
      abort("`x` must hold comparisons of the same length; got lengths ",
            paste(lens, collapse = ", "), ".", class = "argument")
    }
    ok <- vapply(x, function(v) is.numeric(v) && !is.factor(v), TRUE)
    if (!all(ok)) {
      abort("`x` must hold numeric vectors; element ", which(!ok)[1L], " is ",
            describe_type(x[[which(!ok)[1L]]]), ".", class = "argument")
    }
    nm <- names(x)
    x <- do.call(cbind, lapply(x, as.double))
    colnames(x) <- nm
  }
  if (is.data.frame(x)) {
    ok <- vapply(x, function(v) is.numeric(v) && !is.factor(v), TRUE)
    if (!all(ok)) {
      abort("`x` must have only numeric columns; column `", names(x)[!ok][1L],
            "` is ", describe_type(x[[which(!ok)[1L]]]), ".",
            class = "argument")
    }
    nm <- names(x)
    x <- as.matrix(x)
    colnames(x) <- nm
  }
  want <- if (length(n_allowed) == 1L) n_allowed else
    paste(n_allowed, collapse = " or ")
  if (!is.matrix(x) || !is.numeric(x)) {
    abort("`x` must be a matrix, data frame or list of ", want,
          " comparisons, not ", describe_type(x), ".", class = "argument")
  }
  if (!ncol(x) %in% n_allowed) {
    abort("`x` must have ", want, " columns (one per comparison), not ",
          ncol(x), ".", class = "argument")
  }
  if (is.null(pairs)) {
    cn <- colnames(x)
    pairs <- if (!is.null(cn) && all(hat_is_pair(cn))) cn else
      if (ncol(x) == 3L) c("A-B", "B-C", "C-A") else c("A-B", "A-C")
  }
  if (!is.character(pairs) || length(pairs) != ncol(x) || anyNA(pairs)) {
    abort("`pairs` must be a character vector naming the ", ncol(x),
          " comparisons as \"P-Q\", not ",
          if (is.character(pairs)) paste0("of length ", length(pairs)) else
            describe_type(pairs), ".", class = "argument")
  }
  bad <- !hat_is_pair(pairs)
  if (any(bad)) {
    abort("`pairs` must name each comparison as \"P-Q\" (source P minus ",
          "source Q, two different names without \"-\"); ",
          encodeString(pairs[bad][1L], quote = '"'), " is not.",
          class = "argument")
  }
  parts <- strsplit(pairs, "-", fixed = TRUE)
  first <- trimws(vapply(parts, `[`, "", 1L))
  second <- trimws(vapply(parts, `[`, "", 2L))
  if (any(first == second)) {
    abort("`pairs` must compare two different sources; ",
          encodeString(pairs[first == second][1L], quote = '"'),
          " compares a source with itself.", class = "argument")
  }
  key <- paste(pmin(first, second), pmax(first, second))
  if (anyDuplicated(key)) {
    abort("`pairs` must not compare the same two sources twice; ",
          encodeString(pairs[duplicated(key)][1L], quote = '"'),
          " repeats an earlier comparison.", class = "argument")
  }
  sources <- unique(as.vector(rbind(first, second)))
  if (ncol(x) == 3L && length(sources) != 3L) {
    abort("`pairs` must compare three sources with each other (each in two ",
          "comparisons, e.g. \"A-B\", \"B-C\", \"C-A\"); got sources ",
          paste0("\"", sources, "\"", collapse = ", "), ".",
          class = "argument")
  }
  if (ncol(x) == 2L) {
    shared <- intersect(c(first[1L], second[1L]), c(first[2L], second[2L]))
    if (length(shared) != 1L) {
      abort("`pairs` must share one source between the two comparisons ",
            "(e.g. \"A-B\", \"A-C\"); ", paste0("\"", pairs, "\"",
            collapse = " and "), " share none.", class = "argument")
    }
    sources <- shared
  }
  pretty_pairs <- paste0(first, "-", second)
  colnames(x) <- pretty_pairs
  storage.mode(x) <- "double"
  bad <- which(!is.finite(x), arr.ind = TRUE)
  if (nrow(bad) > 0L) {
    abort("`x` must contain only finite numbers; found ",
          format(x[bad[1L, 1L], bad[1L, 2L]]), " at position ", bad[1L, 1L],
          " of comparison \"", pretty_pairs[bad[1L, 2L]], "\".",
          class = "argument")
  }
  list(values = x, pairs = pretty_pairs, first = first, second = second,
       sources = sources)
}

# "P-Q": exactly one "-" between two non-blank names.
hat_is_pair <- function(p) {
  vapply(strsplit(p, "-", fixed = TRUE), function(s) {
    length(s) == 2L && all(nzchar(trimws(s)))
  }, TRUE) & !grepl("-$", p)
}

# For source src: the two comparisons i, j that contain it, the third k
# (if any), the other two sources (the one shared with i, with j), and the
# sign that orients the product of i and j to +sigma^2(src).
hat_roles <- function(cmp, src) {
  has <- which(cmp$first == src | cmp$second == src)
  i <- has[1L]
  j <- has[2L]
  k <- setdiff(seq_along(cmp$pairs), has)
  other <- function(p) if (cmp$first[p] == src) cmp$second[p] else cmp$first[p]
  sgn <- function(p) if (cmp$first[p] == src) 1 else -1
  list(i = i, j = j, k = if (length(k)) k else NA_integer_,
       other = c(other(i), other(j)), sign = sgn(i) * sgn(j))
}

# The comparisons' curves: the allan() result `av`, its variances `S` and
# EDFs `nu` as tau x comparison matrices, and the first comparison's rows
# `tau1` (the taus, m and n the estimates are reported at).
hat_curves <- function(cmp, freq, taus, type, input, conf) {
  av <- allan(cmp$values, freq = freq, taus = taus, type = type,
              input = input, conf = conf)
  d <- as.data.frame(av)
  list(av = av, S = hat_by_tau(av, "avar", cmp), nu = hat_by_tau(av, "edf", cmp),
       tau1 = d[d$channel == colnames(cmp$values)[1L], ])
}

# One column of the stacked allan() result as a tau x comparison matrix.
hat_by_tau <- function(av, col, cmp) {
  d <- as.data.frame(av)
  vapply(colnames(cmp$values), function(p) d[[col]][d$channel == p],
         numeric(sum(d$channel == colnames(cmp$values)[1L])))
}

# The rows of one source: estimate `est` (variance, or the signed
# covariance) with variance `v`; NA and flagged where not positive. The
# limits of the variance are est -/+ z sd (the lower one at least 0).
hat_rows <- function(src, tau1, est, v, conf, why, gcov) {
  ok <- is.finite(est) & est > 0 & is.finite(v) & v > 0
  z <- stats::qnorm(1 - (1 - conf) / 2)
  sd <- sqrt(v)
  avar <- ifelse(ok, est, NA_real_)
  d <- data.frame(source = rep(src, length(est)), tau = tau1$tau, m = tau1$m,
                  n = tau1$n, stringsAsFactors = FALSE)
  if (!is.null(gcov)) d$gcov <- gcov
  d$avar <- avar
  d$adev <- sqrt(avar)
  d$lower <- NA_real_
  d$upper <- NA_real_
  d$edf <- NA_real_
  d$lower[ok] <- sqrt(pmax(est[ok] - z * sd[ok], 0))
  d$upper[ok] <- sqrt(est[ok] + z * sd[ok])
  d$edf[ok] <- 2 * est[ok]^2 / v[ok]
  d$status <- ifelse(ok, "ok", "negative")
  d$reason <- ifelse(ok, NA_character_, why)
  d
}

hat_result <- function(out, method, cmp, av, freq) {
  d <- do.call(rbind, out)
  rownames(d) <- NULL
  structure(d, class = c("allan_sources", "data.frame"), method = method,
            pairs = cmp$pairs, freq = attr(av, "freq"), type = attr(av, "type"),
            input = attr(av, "input"), N = attr(av, "N"),
            conf = attr(av, "conf"), comparisons = av)
}

hat_header <- function(x) {
  a <- attributes(x)
  sprintf(paste0("<allan_sources> %s (%s variance) of %s input from %s: ",
                 "N = %s at %s Hz; %s%% intervals"),
          a$method, a$type, a$input, paste(a$pairs, collapse = ", "),
          format(a$N, big.mark = ","), format(a$freq), format(100 * a$conf))
}

#' @export
print.allan_sources <- function(x, digits = 4, ...) {
  cat(hat_header(x), "\n", sep = "")
  d <- as.data.frame(x)
  d$reason <- NULL
  # the variance repeats the positive covariances
  if (!is.null(d$gcov)) d$avar <- NULL
  num <- vapply(d, is.double, TRUE) & names(d) != "n"
  d[num] <- lapply(d[num], signif, digits = digits)
  print(d, row.names = FALSE, ...)
  neg <- sum(x$status == "negative")
  if (neg > 0L) {
    cat(neg, " estimate", if (neg > 1L) "s are" else " is",
        " not positive: no variance is reported there (see `reason`).\n",
        sep = "")
  }
  invisible(x)
}

#' @export
as.data.frame.allan_sources <- function(x, ...) {
  for (a in c("method", "pairs", "freq", "type", "input", "N", "conf",
              "comparisons")) {
    attr(x, a) <- NULL
  }
  class(x) <- "data.frame"
  x
}

#' @export
summary.allan_sources <- function(object, ...) {
  d <- as.data.frame(object)
  rows <- lapply(split(d, factor(d$source, unique(d$source))), function(s) {
    ok <- s$status == "ok"
    i <- if (any(ok)) which(ok)[which.min(s$adev[ok])] else NA_integer_
    data.frame(source = s$source[1L], taus = nrow(s), negative = sum(!ok),
               adev_first = s$adev[1L], adev_min = s$adev[i],
               tau_at_min = s$tau[i], lower_at_min = s$lower[i],
               upper_at_min = s$upper[i], stringsAsFactors = FALSE)
  })
  structure(do.call(rbind, rows), header = hat_header(object),
            class = c("summary.allan_sources", "data.frame"))
}

#' @export
print.summary.allan_sources <- function(x, digits = 4, ...) {
  print_summary_table(x, digits, ...)
}

#' @export
plot.allan_sources <- function(x, col = NULL, comparisons = TRUE,
                               main = NULL, xlab = "tau (s)", ylab = NULL,
                               legend = TRUE, ...) {
  d <- as.data.frame(x)
  srcs <- unique(d$source)
  if (is.null(col)) {
    col <- c("black", "#D55E00", "#0072B2", "#009E73", "#CC79A7", "#E69F00")
  }
  col <- rep_len(col, length(srcs))
  cmpd <- as.data.frame(attr(x, "comparisons"))
  vals <- c(d$adev, d$lower, d$upper, if (comparisons) cmpd$adev)
  vals <- vals[is.finite(vals) & vals > 0]
  yl <- if (length(vals)) range(vals) else c(1, 10)
  yl[1] <- yl[1] / 1.5  # room for the markers of negative estimates
  if (is.null(ylab)) ylab <- stat_entry(attr(x, "type"))$ylab %||% "deviation"
  if (is.null(main)) main <- attr(x, "method")
  if (legend) {
    lab <- srcs
    lc <- col
    lt <- rep(1, length(srcs))
    pc <- rep(20, length(srcs))
    if (comparisons) {
      lab <- c(lab, "comparisons")
      lc <- c(lc, "grey55")
      lt <- c(lt, 2)
      pc <- c(pc, NA)
    }
    if (any(d$status != "ok")) {
      lab <- c(lab, "not positive")
      lc <- c(lc, "grey30")
      lt <- c(lt, NA)
      pc <- c(pc, 25)
    }
    leg <- list(legend = lab, col = lc, lty = lt, pch = pc, pt.bg = lc)
    op <- reserve_legend(leg, cex = 0.8)
    on.exit(graphics::par(op))
  }
  graphics::plot(range(d$tau), yl, type = "n", log = "xy", xlab = xlab,
                 ylab = ylab, main = main, ...)
  graphics::grid(equilogs = FALSE)
  if (comparisons) {
    for (p in unique(cmpd$channel)) {
      s <- cmpd[cmpd$channel == p, ]
      graphics::lines(s$tau, s$adev, lty = 2, col = "grey55")
    }
  }
  for (k in seq_along(srcs)) {
    s <- d[d$source == srcs[k], ]
    ok <- s$status == "ok"
    graphics::lines(s$tau[ok], s$adev[ok], type = "b", pch = 20, col = col[k])
    bar <- ok & is.finite(s$lower) & is.finite(s$upper) & s$upper > s$lower
    if (any(bar)) {
      graphics::arrows(s$tau[bar], s$lower[bar], s$tau[bar], s$upper[bar],
                       angle = 90, code = 3, length = 0.03, col = col[k])
    }
    if (any(!ok)) {
      graphics::points(s$tau[!ok], rep(yl[1], sum(!ok)), pch = 25,
                       col = col[k], bg = col[k])
    }
  }
  if (legend) legend_beside(leg, cex = 0.8)
  invisible(x)
}
