# Monte Carlo coverage of allan()'s 68.3% and 95% confidence intervals, by statistic,
# noise type and averaging factor, with generators written here (not the
# package's simulator):
#  * white FM: rnorm; random-walk FM: cumsum(rnorm);
#  * flicker FM: Kasdin & Walter's fractional integration (h_k = h_{k-1}
#    (k - 1.5)/(k - 1), applied by FFT);
#  * white and flicker PM: first differences of white or flicker phase.
# The truth at each row is the ensemble mean of the estimator over the
# replicates. Rows whose median EDF is below 2 are not shown (one or two
# terms). Prints one table; a row "ok" when the 68% coverage is in
# 0.60-0.76 and the 95% one (`coverage95`) in 0.92-0.975 (MC_OUT=file.csv
# writes it);
# `cov_alpha` (ok_alpha) is the coverage with the EDF of the true noise
# type, `edf_mc` the Monte Carlo EDF 2 E^2 / Var of the uncorrected
# estimate, `edf_alpha` the formula's at the true type.
#
#   [ALLANVAR_NOISE_ID=rule] [MC_NOISES=fpm,wpm] Rscript tools/mc-coverage.R [replicates] [N] [types]
#   e.g. Rscript tools/mc-coverage.R 300 1024 overlapping,modified,tdev
mc_generators <- function(N) {
  filters <- list()  # the filter's transform, built once per length
  flicker <- function(n) {
    key <- as.character(n)
    # zero-padded to a length FFT likes (2 (N + 1) can be twice a prime)
    len <- stats::nextn(2 * n)
    if (is.null(filters[[key]])) {
      h <- numeric(n)
      h[1] <- 1
      for (k in 2:n) h[k] <- h[k - 1] * (k - 1.5) / (k - 1)
      filters[[key]] <<- stats::fft(c(h, rep(0, len - n)))
    }
    Re(stats::fft(filters[[key]] * stats::fft(c(stats::rnorm(n), rep(0, len - n))),
                  inverse = TRUE))[1:n] / len
  }
  list(wfm = function() stats::rnorm(N), ffm = function() flicker(N),
       rwfm = function() cumsum(stats::rnorm(N)),
       wpm = function() diff(stats::rnorm(N + 1)),
       fpm = function() diff(flicker(N + 1)))
}

# The EDF allan() gives a row of `type` when the noise exponent is alpha
# (the internal formulas, for the column that leaves identification out).
mc_edf <- function(type, m, n, L, alpha) {
  ns <- asNamespace("allanvar")
  a <- rep(as.integer(alpha), length(m))
  if (type %in% c("overlapping", "standard", "modified", "hadamard",
                  "ohadamard", "total", "tdev")) {
    base <- if (type == "tdev") "modified" else type
    vapply(seq_along(m), function(i) {
      ns$allan_edf_direct(base, m[i], n[i], L, a[i])
    }, 0)
  } else {
    ns$extra_edf(type, m, L, a, n)
  }
}

# Coverage by row: `coverage` with allan()'s own intervals (for the
# bias-corrected types, of the true variance: see below); `cov_alpha` with
# the EDF of the generator's true noise exponent (`alpha_true`) and, for the
# bias-corrected types, the uncorrected estimate, so the EDF formula is
# tested apart from the noise identification (the correction is a constant
# factor once the type is known, and leaves coverage unchanged).
mc_coverage <- function(type, gen, reps, taus = "octave", alpha_true = NULL,
                        L = NULL) {
  # the same record at 68.3% and at 95%
  both <- lapply(seq_len(reps), function(i) {
    y <- gen()
    list(allan(y, 1, taus = taus, type = type),
         allan(y, 1, taus = taus, type = type, conf = 0.95))
  })
  res <- lapply(both, `[[`, 1L)
  r95 <- lapply(both, `[[`, 2L)
  ms <- Reduce(intersect, lapply(res, function(a) a$m))
  get <- function(col, r = res) sapply(r, function(a) a[[col]][match(ms, a$m)])
  av <- get("avar")
  truth <- sqrt(rowMeans(av))
  hits <- get("lower") <= truth & truth <= get("upper")
  cover95 <- function(t) rowMeans(get("lower", r95) <= t & t <= get("upper", r95))
  out <- data.frame(m = ms, coverage = rowMeans(hits), coverage95 = cover95(truth),
                    edf = apply(get("edf"), 1, stats::median),
                    alpha = apply(get("alpha"), 1, function(a) {
                      t <- table(a, useNA = "ifany")
                      names(t)[which.max(t)]
                    }))
  if (!is.null(alpha_true)) {
    ns <- asNamespace("allanvar")
    raw <- av
    if (type %in% c("mtotdev", "ttotdev", "htotdev", "theo1")) {
      al <- get("alpha")
      for (j in seq_len(ncol(av))) {
        raw[, j] <- av[, j] / ns$debias_factor(type, al[, j], ms)
      }
    }
    n1 <- res[[1]]$n[match(ms, res[[1]]$m)]
    e <- mc_edf(type, ms, n1, L, alpha_true)
    t2 <- sqrt(rowMeans(raw))
    ci <- lapply(seq_len(ncol(raw)), function(j) ns$allan_ci(raw[, j], e, 0.683))
    lo <- sapply(ci, function(c) c$lower)
    hi <- sapply(ci, function(c) c$upper)
    out$cov_alpha <- rowMeans(lo <= t2 & t2 <= hi)
    if (!identical(raw, av)) {
      # a bias-corrected type estimates the variance itself: the truth is
      # the mean uncorrected estimate times the true type's correction (the
      # ensemble mean of corrected estimates is pulled away from it by the
      # few replicates whose type, and so correction, was misread)
      tb <- sqrt(rowMeans(raw) * ns$debias_factor(type, rep(alpha_true, length(ms)), ms))
      out$coverage <- rowMeans(get("lower") <= tb & tb <= get("upper"))
      out$coverage95 <- cover95(tb)
    }
    out$edf_alpha <- e
    out$edf_mc <- 2 * rowMeans(raw)^2 / apply(raw, 1, stats::var)
  }
  out
}

if (sys.nframe() == 0L) {
  args <- commandArgs(TRUE)
  reps <- if (length(args) >= 1) as.integer(args[1]) else 300L
  N <- if (length(args) >= 2) as.integer(args[2]) else 1024L
  types <- if (length(args) >= 3) strsplit(args[3], ",")[[1]] else
    c("overlapping", "standard", "modified", "hadamard", "ohadamard", "tdev",
      "total", "mtotdev", "ttotdev", "htotdev", "theo1", "theobr", "theoh",
      "pdev")
  if (file.exists("DESCRIPTION") && requireNamespace("pkgload", quietly = TRUE) &&
      !nzchar(Sys.getenv("MC_INSTALLED"))) {
    pkgload::load_all(".", quiet = TRUE)
  } else {
    library(allanvar)
  }
  options(allanvar.threads = 1)
  # the noise-identification rules (see allan()): "default", "stable32",
  # "coverage"
  if (nzchar(Sys.getenv("ALLANVAR_NOISE_ID"))) {
    options(allanvar.noise_id = Sys.getenv("ALLANVAR_NOISE_ID"))
  }
  set.seed(8)
  gens <- mc_generators(N)
  # MC_NOISES=fpm,wpm runs only those generators
  if (nzchar(Sys.getenv("MC_NOISES"))) {
    gens <- gens[strsplit(Sys.getenv("MC_NOISES"), ",")[[1]]]
  }
  alphas <- c(wfm = 0L, ffm = -1L, rwfm = -2L, wpm = 2L, fpm = 1L)
  out <- list()
  for (type in types) for (g in names(gens)) {
    d <- mc_coverage(type, gens[[g]], reps, alpha_true = alphas[[g]],
                     L = N + 1)
    d <- d[d$edf >= 2, ]
    out[[length(out) + 1L]] <- cbind(type = type, noise = g, N_over_m = N / d$m, d)
  }
  tab <- do.call(rbind, out)
  tab$ok68 <- tab$coverage >= 0.60 & tab$coverage <= 0.76
  tab$ok95 <- tab$coverage95 >= 0.92 & tab$coverage95 <= 0.975
  tab$ok <- tab$ok68 & tab$ok95
  tab$ok_alpha <- tab$cov_alpha >= 0.60 & tab$cov_alpha <= 0.76
  for (k in c("coverage", "coverage95", "cov_alpha")) tab[[k]] <- round(tab[[k]], 3)
  for (k in c("edf", "edf_alpha", "edf_mc")) tab[[k]] <- signif(tab[[k]], 3)
  old <- options(width = 200)
  print(tab, row.names = FALSE)
  options(old)
  cat(sprintf(paste0("%d of %d rows with 68%% coverage in 0.60-0.76 and 95%% in ",
                     "0.92-0.975 (68%%: %d, 95%%: %d; %d replicates, N = %d); ",
                     "68%% with the true noise type's EDF: %d\n"),
              sum(tab$ok), nrow(tab), sum(tab$ok68), sum(tab$ok95), reps, N,
              sum(tab$ok_alpha)))
  for (ty in types) {
    s <- tab[tab$type == ty, ]
    cat(sprintf("  %-12s %3d of %3d rows (68%%: %3d, 95%%: %3d); true type 68%%: %3d\n",
                ty, sum(s$ok), nrow(s), sum(s$ok68), sum(s$ok95), sum(s$ok_alpha)))
  }
  if (nzchar(Sys.getenv("MC_OUT"))) utils::write.csv(tab, Sys.getenv("MC_OUT"), row.names = FALSE)
}
