# Monte Carlo coverage of allan()'s 68.3% confidence intervals, by statistic,
# noise type and averaging factor, with generators written here (not the
# package's simulator):
#  * white FM: rnorm; random-walk FM: cumsum(rnorm);
#  * flicker FM: Kasdin & Walter's fractional integration (h_k = h_{k-1}
#    (k - 1.5)/(k - 1), applied by FFT);
#  * white and flicker PM: first differences of white or flicker phase.
# The truth at each row is the ensemble mean of the estimator over the
# replicates. Rows whose median EDF is below 2 are not shown (one or two
# terms). Prints one table; a row "ok" when coverage is in 0.60-0.76.
#
#   Rscript tools/mc-coverage.R [replicates] [N] [types]
#   e.g. Rscript tools/mc-coverage.R 300 1024 overlapping,modified,tdev
mc_generators <- function(N) {
  flicker <- function(n) {
    h <- numeric(n)
    h[1] <- 1
    for (k in 2:n) h[k] <- h[k - 1] * (k - 1.5) / (k - 1)
    Re(stats::fft(stats::fft(c(h, rep(0, n))) *
                    stats::fft(c(stats::rnorm(n), rep(0, n))),
                  inverse = TRUE))[1:n] / (2 * n)
  }
  list(wfm = function() stats::rnorm(N), ffm = function() flicker(N),
       rwfm = function() cumsum(stats::rnorm(N)),
       wpm = function() diff(stats::rnorm(N + 1)),
       fpm = function() diff(flicker(N + 1)))
}

mc_coverage <- function(type, gen, reps, taus = "octave") {
  res <- lapply(seq_len(reps), function(i) allan(gen(), 1, taus = taus,
                                                 type = type))
  ms <- Reduce(intersect, lapply(res, function(a) a$m))
  get <- function(col) sapply(res, function(a) a[[col]][match(ms, a$m)])
  truth <- sqrt(rowMeans(get("avar")))
  hits <- get("lower") <= truth & truth <= get("upper")
  data.frame(m = ms, coverage = rowMeans(hits),
             edf = apply(get("edf"), 1, stats::median),
             alpha = apply(get("alpha"), 1, function(a) {
               t <- table(a, useNA = "ifany")
               names(t)[which.max(t)]
             }))
}

if (sys.nframe() == 0L) {
  args <- commandArgs(TRUE)
  reps <- if (length(args) >= 1) as.integer(args[1]) else 300L
  N <- if (length(args) >= 2) as.integer(args[2]) else 1024L
  types <- if (length(args) >= 3) strsplit(args[3], ",")[[1]] else
    c("overlapping", "standard", "modified", "total", "tdev", "mtotdev",
      "theo1")
  if (file.exists("DESCRIPTION") && requireNamespace("pkgload", quietly = TRUE)) {
    pkgload::load_all(".", quiet = TRUE)
  } else {
    library(allanvar)
  }
  options(allanvar.threads = 1)
  set.seed(8)
  gens <- mc_generators(N)
  out <- list()
  for (type in types) for (g in names(gens)) {
    d <- mc_coverage(type, gens[[g]], reps)
    d <- d[d$edf >= 2, ]
    out[[length(out) + 1L]] <- cbind(type = type, noise = g, N_over_m = N / d$m, d)
  }
  tab <- do.call(rbind, out)
  tab$ok <- tab$coverage >= 0.60 & tab$coverage <= 0.76
  tab$coverage <- round(tab$coverage, 3)
  tab$edf <- signif(tab$edf, 3)
  print(tab, row.names = FALSE)
  cat(sprintf("%d of %d rows with coverage in 0.60-0.76 (%d replicates, N = %d)\n",
              sum(tab$ok), nrow(tab), reps, N))
}
