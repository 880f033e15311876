# Monte Carlo coverage of allan()'s 68.3% and 95% intervals at few averages
# (N/m = 2 .. 16, where the limits are the exact generalized chi-square
# ones, R/ci-exact.R), by type and noise, with the generators of
# tools/mc-coverage.R (written here, not avsim()): white, flicker (Kasdin &
# Walter) and random-walk FM, white and flicker PM. The truth at each row
# is the ensemble mean of the variance over the replicates. `cov68`,
# `cov95`: with the noise type allan() identifies (the union over its
# neighbours); `true68`, `true95`: the exact interval of the generator's
# own type alone (allan_limits_exact() with that type, no union);
# `set_true`: the share of records whose interval's set of noise types
# (exact_sets()) holds the true one. Each record's curve has the octave
# taus below the rows (as allan()'s default grid), whose readings at many
# averages the rows' limits rest on. A row is ok when cov68 is in
# 0.60-0.76 and cov95 in 0.92-0.975.
#
#   [ALLANVAR_CI_EXACT=0] [MC_ROWS_ALONE=1] Rscript tools/mc-coverage-exact.R [replicates] [N] [types]
source(file.path("tools", "mc-coverage.R"), local = TRUE)  # mc_generators()

mc_exact <- function(type, gen, reps, m, alpha_true) {
  ns <- asNamespace("allanvar")
  N <- length(gen())
  L <- N + 1
  av <- lo68 <- hi68 <- lo95 <- hi95 <- rd <- matrix(NA, length(m), reps)
  t68 <- t95 <- list()
  n <- NULL
  base <- if (type == "tdev") "modified" else type
  lo <- ns$stat_entry(base)$alpha_range[1L]
  # the rows asked for with the octave grid below them, as allan()'s
  # default taus give a curve (the reading at many averages: exact_sets())
  # (MC_ROWS_ALONE=1: the rows alone, their own readings only)
  mall <- if (nzchar(Sys.getenv("MC_ROWS_ALONE"))) m else
    sort(unique(c(2^(0:floor(log2(min(m)))), m)))
  for (i in seq_len(reps)) {
    y <- gen()
    a <- allan(y, 1, taus = I(mall), type = type, conf = 0.683)
    b <- allan(y, 1, taus = I(mall), type = type, conf = 0.95)
    r <- match(m, a$m)
    av[, i] <- a$avar[r]
    lo68[, i] <- a$lower[r]; hi68[, i] <- a$upper[r]
    lo95[, i] <- b$lower[r]; hi95[, i] <- b$upper[r]
    n <- a$n[r]
    # does the set of types the limits rest on hold the true one?
    sets <- ns$exact_sets(a$m, L, a$alpha, lo)[r]
    rd[, i] <- vapply(sets, function(s) alpha_true %in% s, TRUE)
  }
  # the true type's exact factors (no union): every row of the type
  one <- function(conf) {
    t(vapply(seq_along(m), function(j) {
      f <- ns$exact_factors_one(ns$allan_type_code(base), m[j], n[j],
                                alpha_true, conf)
      if (anyNA(f)) {
        e <- ns$allan_edf_direct(base, m[j], n[j], L, alpha_true)
        f <- sqrt(e / stats::qchisq(c(1 - (1 - conf) / 2, (1 - conf) / 2), e))
      }
      f
    }, numeric(2)))
  }
  f68 <- one(0.683); f95 <- one(0.95)
  truth <- sqrt(rowMeans(av))
  dev <- sqrt(av)
  cover <- function(lo, hi) rowMeans(lo <= truth & truth <= hi)
  data.frame(m = m, N_over_m = round(N / m, 2), n = n,
             cov68 = cover(lo68, hi68), cov95 = cover(lo95, hi95),
             true68 = cover(dev * f68[, 1], dev * f68[, 2]),
             true95 = cover(dev * f95[, 1], dev * f95[, 2]),
             set_true = rowMeans(rd))
}

if (sys.nframe() == 0L) {
  args <- commandArgs(TRUE)
  reps <- if (length(args) >= 1) as.integer(args[1]) else 1000L
  N <- if (length(args) >= 2) as.integer(args[2]) else 1024L
  types <- if (length(args) >= 3) strsplit(args[3], ",")[[1]] else
    c("standard", "overlapping", "modified", "hadamard", "ohadamard", "tdev")
  if (file.exists("DESCRIPTION") && requireNamespace("pkgload", quietly = TRUE) &&
      !nzchar(Sys.getenv("MC_INSTALLED"))) {
    pkgload::load_all(".", quiet = TRUE)
  } else {
    library(allanvar)
  }
  options(allanvar.threads = 1)
  # ALLANVAR_CI_EXACT=0: the chi-square limits, for comparison
  if (nzchar(Sys.getenv("ALLANVAR_CI_EXACT"))) {
    options(allanvar.ci_exact = as.numeric(Sys.getenv("ALLANVAR_CI_EXACT")))
  }
  set.seed(29)
  gens <- mc_generators(N)
  alphas <- c(wfm = 0L, ffm = -1L, rwfm = -2L, wpm = 2L, fpm = 1L)
  out <- list()
  for (type in types) {
    # N/m = 2, 3, 4, 6, 8, 12, 16 where the type has at least one term
    k <- c(2, 3, 4, 6, 8, 12, 16)
    m <- sort(unique(floor(N / k)))  # allan() returns rows by m
    m <- m[allanvar:::allan_nterms(if (type == "tdev") "modified" else type,
                                   m, N + 1) >= 1]
    for (g in names(gens)) {
      d <- mc_exact(type, gens[[g]], reps, m, alphas[[g]])
      out[[length(out) + 1L]] <- cbind(type = type, noise = g, d)
      cat(".", file = stderr())
    }
  }
  tab <- do.call(rbind, out)
  tab$ok <- tab$cov68 >= 0.60 & tab$cov68 <= 0.76 &
    tab$cov95 >= 0.92 & tab$cov95 <= 0.975
  tab$ok_true <- tab$true68 >= 0.60 & tab$true68 <= 0.76 &
    tab$true95 >= 0.92 & tab$true95 <= 0.975
  old <- options(width = 200)
  print(tab, row.names = FALSE, digits = 3)
  options(old)
  cat(sprintf(paste0("%d of %d rows ok (68%% in 0.60-0.76 and 95%% in ",
                     "0.92-0.975; %d replicates, N = %d); %d with the true ",
                     "type's exact interval\n"),
              sum(tab$ok), nrow(tab), reps, N, sum(tab$ok_true)))
}
