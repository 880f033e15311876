# Catalogue entries of the further statistics of allan(), each with a kernel
# of its own: time deviation, the Total family (src/totals.cpp), Theo1,
# TheoBR and TheoH (src/theo.cpp), the time interval errors (src/tie.cpp)
# and the parabolic deviation (src/pdev.cpp). The kernels' shared pieces
# (Theo grids, TheoBR's factor, the noise type from an Allan-family
# statistic) are in R/allan-types.R; their EDF rules in R/edf.R.

stats_further <- function() {
  refused <- function(name) {
    paste0("`gaps = \"skip\"` is not defined for type \"", name, "\" (",
           "missing values in `x`); use one of \"standard\", ",
           "\"overlapping\", \"modified\", \"hadamard\", \"ohadamard\" or ",
           "\"tdev\", or fill the gaps.")
  }
  further <- function(name, title, time = FALSE, gaps = refused(name), ...) {
    new_stat(name, title = title,
             ylab = paste0(title, if (time) " (s)" else ""), gaps = gaps, ...)
  }
  mod_max <- function(L) floor(L / 3)
  mod_n <- function(m, L, theo_row = NULL) L - 3 * m + 1
  theo_n <- function(m, L, theo_row = NULL) (L - m) * m / 2
  list(
    further("tdev", "time deviation TDEV", time = TRUE,
            max_m = mod_max, nterms = mod_n, kernel = kernel_tdev,
            edf = "engine_modified", id_base = "modified",
            gaps = stat_tdev_gaps),
    further("mtotdev", "modified total deviation",
            max_m = mod_max, nterms = mod_n,
            kernel = kernel_total_modified(time = FALSE), edf = "mtot",
            id_base = "modified", debias = debias_mtot, exact_ci = TRUE,
            exact_form = "exact_form_mtot"),
    further("ttotdev", "time total deviation TTOT", time = TRUE,
            max_m = mod_max, nterms = mod_n,
            kernel = kernel_total_modified(time = TRUE), edf = "mtot",
            id_base = "modified", debias = debias_mtot, exact_ci = TRUE,
            exact_form = "exact_form_mtot"),
    further("htotdev", "Hadamard total deviation",
            max_m = function(L) floor((L - 1) / 3),
            nterms = function(m, L, theo_row = NULL) {
              ifelse(m == 1, L - 3, L - 3 * m)
            },
            kernel = kernel_htot, edf = "htot", alpha_range = c(-4L, 2L),
            id_base = "ohadamard", debias = debias_htot, exact_ci = TRUE,
            exact_form = "exact_form_htot"),
    further("theo1", "Theo1 deviation",
            max_m = function(L) L - 1, nterms = theo_n,
            taus = stat_taus_theo, kernel = kernel_theo(own_type = TRUE),
            edf = "theo1", id_base = "overlapping", debias = debias_theo1,
            exact_ci = TRUE, exact_form = "exact_form_theo1"),
    further("theobr", "bias-removed Theo1 deviation (TheoBR)",
            max_m = function(L) L - 1, nterms = theo_n,
            taus = stat_taus_theo, kernel = kernel_theo(own_type = FALSE),
            edf = "theobr", id_base = "overlapping", theo = theo_defaults()),
    further("theoh", "TheoH deviation (Allan, then TheoBR)",
            max_m = function(L) L - 1,
            nterms = function(m, L, theo_row) {
              ifelse(theo_row, (L - m) * m / 2, L - 2 * m)
            },
            taus = stat_taus_theoh, kernel = kernel_theo(own_type = FALSE),
            edf = "theobr", id_base = "overlapping", theo = theo_defaults()),
    further("mtie", "maximum time interval error MTIE", time = TRUE,
            max_m = function(L) L - 1,
            nterms = function(m, L, theo_row = NULL) L - m,
            kernel = kernel_mtie, variance = FALSE),
    further("tierms", "rms time interval error TIE rms", time = TRUE,
            max_m = function(L) L - 1,
            nterms = function(m, L, theo_row = NULL) L - m,
            kernel = kernel_tierms, variance = FALSE),
    further("pdev", "parabolic deviation",
            max_m = function(L) floor((L - 1) / 2),
            nterms = function(m, L, theo_row = NULL) {
              ifelse(m == 1, L - 2, L - 2 * m)
            },
            kernel = kernel_pdev, edf = "terms", exact_ci = TRUE,
            id_base = "modified")
  )
}

# ---- taus ----

# Theo1 and TheoBR: even m (allan_theo_taus()), every row a Theo row.
stat_taus_theo <- function(taus, freq, L, maxm) {
  m <- allan_theo_taus(taus, freq, maxm)
  list(m = m, theo_row = rep(TRUE, length(m)))
}

# TheoH: Allan rows, then TheoBR rows (allan_theoh_taus()).
stat_taus_theoh <- function(taus, freq, L, maxm) {
  parts <- allan_theoh_taus(taus, freq, L)
  list(m = c(parts$avar, parts$theo),
       theo_row = rep(c(FALSE, TRUE), c(length(parts$avar),
                                        length(parts$theo))))
}

# ---- bias factors (NIST SP 1065; multiply the variance by them) ----
#  * MTOT and TTOT: Table 12 (Howe & Vernotte, PTTI 1999), divide by it;
#  * HTOT: 1 + a, Table 13 (Howe et al., PTTI 2000), divide by it, m > 1;
#  * Theo1: AVAR/Theo1 = a + b / (0.75 m)^c (Howe & Tasset, EFTF 2004,
#    Table 1), multiply by it.

debias_mtot <- function(alpha, m) {
  a <- pmin(2L, pmax(-2L, as.integer(alpha)))
  1 / c(0.69, 0.70, 0.73, 0.83, 0.94)[a + 3L]
}

debias_htot <- function(alpha, m) {
  ah <- pmin(2L, pmax(-4L, as.integer(alpha)))
  corr <- c(-0.321, -0.283, -0.229, -0.149, -0.005, 0, 0)[ah + 5L]
  ifelse(m == 1, 1, 1 / (1 + corr))
}

debias_theo1 <- function(alpha, m) {
  a <- pmin(2L, pmax(-2L, as.integer(alpha)))
  tab <- rbind(c(2.70, -1.53, 0.85), c(1.87, -1.05, 0.79), c(1, 0, 0),
               c(0.14, 0.82, 0.30), c(0.09, 0.74, 0.40))
  p <- tab[a + 3L, , drop = FALSE]
  p[, 1] + p[, 2] / (0.75 * m)^p[, 3]
}

# ---- kernels: function(ctx) -> list(av, alpha, edf, ...) ----

# TDEV: tau/sqrt(3) MDEV, with MDEV's terms, EDF, noise type and limits.
kernel_tdev <- function(ctx) {
  a <- allan(ctx$v, ctx$freq, taus = I(ctx$m / ctx$freq), type = "modified",
             input = ctx$input, conf = ctx$conf, ci = ctx$ci,
             unbiased = ctx$unbiased)
  k <- (ctx$m / ctx$freq)^2 / 3
  list(n = a$n, av = a$avar * k, adev = a$adev * sqrt(k),
       limits = list(rows = rep(TRUE, length(ctx$m)),
                     lower = a$lower * sqrt(k), upper = a$upper * sqrt(k)),
       edf = a$edf, alpha = a$alpha)
}

# TDEV with gaps: the modified variance with gaps (same taus, kept terms,
# EDF and noise type), times tau^2/3.
stat_tdev_gaps <- function(x, freq, taus, input, conf, ci, unbiased) {
  a <- allan(x, freq, taus = taus, type = "modified", input = input,
             conf = conf, gaps = "skip", ci = ci, unbiased = unbiased)
  k <- a$tau^2 / 3
  a$avar <- a$avar * k
  a$adev <- a$adev * sqrt(k)
  a$lower <- a$lower * sqrt(k)
  a$upper <- a$upper * sqrt(k)
  attr(a, "type") <- "tdev"
  a
}

kernel_mtie <- function(ctx) {
  av <- (mtie_cpp(ctx$v, ctx$rate, ctx$m) / if (ctx$rate) ctx$freq else 1)^2
  list(av = av)
}

kernel_tierms <- function(ctx) {
  av <- tierms_sums_cpp(ctx$v, ctx$rate, ctx$m, ctx$threads) /
    (ctx$L - ctx$m) * ctx$sc_time
  list(av = av)
}

kernel_pdev <- function(ctx) {
  m <- ctx$m
  n <- ctx$n
  s <- pdev_sums_cpp(ctx$v, ctx$rate, m, ctx$threads)
  av <- ifelse(m == 1, s / (2 * n), 18 * s / (n * m^6)) * ctx$sc_rate
  list(av = av, alpha = ctx$identify(m))
}

# MTOT, and TTOT (time = TRUE: times tau^2/3, in the phase unit).
kernel_total_modified <- function(time) {
  function(ctx) {
    m <- ctx$m
    s <- total_sums_cpp(ctx$v, ctx$rate, m, FALSE, ctx$threads)
    av <- s / (12 * m^5 * ctx$n) * ctx$sc_rate
    alpha <- ctx$identify(m)
    if (ctx$debias) av <- av * debias_factor(ctx$entry$name, alpha, m)
    if (time) av <- av * (m / ctx$freq)^2 / 3
    list(av = av, alpha = alpha)
  }
}

kernel_htot <- function(ctx) {
  m <- ctx$m
  s <- total_sums_cpp(ctx$v, ctx$rate, m, TRUE, ctx$threads)
  av <- s / (36 * m^3 * ctx$n) * ctx$sc_rate
  if (any(m == 1)) {
    # at m = 1 HTOT is the overlapping Hadamard variance
    av[m == 1] <- allan(ctx$v, ctx$freq, taus = I(1 / ctx$freq),
                        type = "ohadamard", input = ctx$input,
                        ci = FALSE)$avar
  }
  alpha <- ctx$identify(m)
  if (ctx$debias) av <- av * debias_factor(ctx$entry$name, alpha, m)
  list(av = av, alpha = alpha)
}

# Theo1 (own_type = TRUE: its noise type from its own slope, its bias
# correction, the union of the candidate types' intervals: R/theo1-type.R)
# or TheoBR (own_type = FALSE: Theo1 times the bias-removal factor; the
# Allan rows of TheoH from the overlapping statistic).
kernel_theo <- function(own_type) {
  function(ctx) {
    m <- ctx$m
    theo_row <- ctx$theo_row
    L <- ctx$L
    av <- rep(NA_real_, length(m))
    alpha <- rep(NA_integer_, length(m))
    edf <- rep(NA_real_, length(m))
    lower <- upper <- rep(NA_real_, length(m))  # with ctx$ci: the limits
    # TheoH's Allan rows first: their noise types serve the TheoBR rows'
    # exact limits below, and their limits are the overlapping type's (at
    # few averages its exact law over the plausible types: a chi-square
    # with the EDF of the type read covered 0.91 at 95% under random-walk
    # FM, read as flicker FM at N/m = 8-32)
    if (any(!theo_row)) {
      a <- allan(ctx$v, ctx$freq, taus = I(m[!theo_row] / ctx$freq),
                 type = "overlapping", input = ctx$input, conf = ctx$conf,
                 ci = ctx$ci)
      av[!theo_row] <- a$avar
      alpha[!theo_row] <- a$alpha
      edf[!theo_row] <- a$edf
      if (ctx$ci) {
        lower[!theo_row] <- a$lower
        upper[!theo_row] <- a$upper
      }
    }
    mt <- m[theo_row]
    if (length(mt)) {
      # many m: the recurrence over k (O(L log^2 L + kmax^2)) beats
      # m-by-m sums
      T <- if (length(mt) > 40L) {
        theo1_many(ctx$v, ctx$rate, mt, ctx$threads)
      } else {
        theo1_sums_cpp(ctx$v, ctx$rate, mt, ctx$threads)
      }
      t1 <- T / (0.75 * (L - mt) * mt^2) * ctx$sc_rate
      alpha[theo_row] <- ctx$identify(round(0.75 * mt))
      if (own_type) {
        ta <- theo1_alpha(ctx$v, ctx$rate, L, mt, t1 / ctx$sc_rate,
                          alpha[theo_row], ctx$threads)
        alpha[theo_row] <- as.integer(ta)
        if (ctx$ci) {
          u <- theo1_union(t1, mt, L, attr(ta, "alts"), ctx$n[theo_row],
                           ctx$conf, ctx$debias)
          lower[theo_row] <- u$lower
          upper[theo_row] <- u$upper
        }
        if (ctx$debias) {
          t1 <- t1 * debias_factor(ctx$entry$name, alpha[theo_row], mt)
        }
      } else {
        kf <- theobr_kernel_factor(ctx)
        if (!is.finite(kf)) {
          abort("TheoBR needs at least 19 phase points (", L, " given).",
                class = "argument")
        }
        t1 <- t1 * as.numeric(kf)
        if (ctx$ci || ctx$unbiased) {
          # TheoBR's slope is Theo1's (kappa is one factor): the row's type
          # as Theo1's (R/theo1-type.R), the interval the union over the
          # candidate types (R/theobr-edf.R). Beyond the Allan variance's
          # reach (three cluster averages; extra_alpha() repeats its type
          # there) the type read along the ladder starts it (white PM was
          # read as white FM at N/m <= 4 in half the records, N = 1024).
          a0 <- alpha[theo_row]
          top <- min(allan_max_m(ctx$entry$id_base, L),
                     max(1, floor((L - 1) / 3)))
          ka <- attr(kf, "kappa")$alpha
          if (!is.na(ka)) a0[round(0.75 * mt) > top] <- ka
          ta <- theo1_alpha(ctx$v, ctx$rate, L, mt,
                            t1 / as.numeric(kf) / ctx$sc_rate, a0,
                            ctx$threads)
          alpha[theo_row] <- as.integer(ta)
          if (ctx$ci) {
            u <- theobr_union(ctx$entry$name, t1, mt, L, attr(ta, "alts"),
                              ctx$n[theo_row],
                              ctx$conf, attr(kf, "kappa"))
            # rows at few averages: Theo1's exact law with the factor's
            # spread (R/theobr-exact.R), the types as Theo1's exact rows
            # take them (exact_sets(): a weak reading leans on a shorter
            # tau's; on TheoH's curve the Allan rows are such taus, at
            # Theo1's m of the same tau)
            m_eq <- ifelse(theo_row, m, m / 0.75)
            sets <- exact_sets(m_eq, L, alpha, -2L)[theo_row]
            ex <- theobr_limits_exact(sqrt(t1), mt, L, sets, ctx$conf,
                                      attr(kf, "kappa"))
            u$lower[ex$rows] <- ex$lower
            u$upper[ex$rows] <- ex$upper
            lower[theo_row] <- u$lower
            upper[theo_row] <- u$upper
          }
        }
      }
      av[theo_row] <- t1
      # TheoBR: the factor's uncertainty joins Theo1's (R/theobr-edf.R)
      edf[theo_row] <- if (own_type) {
        extra_edf(ctx$entry$name, mt, L, alpha[theo_row], ctx$n[theo_row])
      } else {
        extra_edf(ctx$entry$name, mt, L, alpha[theo_row], ctx$n[theo_row],
                  kappa = attr(kf, "kappa"))
      }
    }
    limits <- if (ctx$ci) {
      list(rows = rep(TRUE, length(m)), lower = lower, upper = upper)
    }
    list(av = av, alpha = alpha, edf = edf, limits = limits)
  }
}
