# Monte Carlo coverage of the Stable32 reference rows whose 68.3% limits
# allan() does not match within 25% of Stable32's half-width
# (tools/check-stable32.R). For each such row the record is simulated with
# the file's length and input (phase or frequency), once for every noise
# type in question (Stable32's printed alpha and the one allan() reads),
# with tools/mc-coverage.R's generators (white, flicker by Kasdin &
# Walter's filter, random-walk FM; white and flicker PM as their
# differences), never avsim(). Each replicate runs allan() on the file's whole tau grid,
# as check-stable32.R does; the row's truth is the ensemble mean of the
# variance. `ours`: coverage of allan()'s interval; `s32`: coverage of
# Stable32's interval, a chi-square one with the EDF its printed limits
# imply (the hi/lo ratio). In band: 0.60-0.76.
#
#   ALLANVAR_PEER_DATA=/path/to/allantools Rscript tools/stable32-rows-mc.R [replicates]
#
# Prints one line per row and noise type; ALLANVAR_STABLE32_MC_OUT=file.csv
# writes it; ALLANVAR_STABLE32_MC_FILES=regex keeps the reference files whose
# path matches (to rerun only the rows a change touched).
source(file.path("tools", "check-stable32.R"), local = TRUE)

# Frequency noise y of exponent alpha (S_y ~ f^alpha), n samples, from
# tools/mc-coverage.R's generators (one set per length, so each flicker
# filter is built once).
source(file.path("tools", "mc-coverage.R"), local = TRUE)  # mc_generators()
mc_noise <- local({
  sets <- list()
  names_of <- c("2" = "wpm", "1" = "fpm", "0" = "wfm", "-1" = "ffm", "-2" = "rwfm")
  function(alpha, n) {
    key <- as.character(n)
    if (is.null(sets[[key]])) sets[[key]] <<- mc_generators(n)
    g <- names_of[[as.character(alpha)]]
    sets[[key]][[g]]()
  }
})

# The EDF of a 68.3% chi-square interval from its lower and upper limits.
edf_of_limits <- function(lo, hi, conf = 0.683) {
  p <- c((1 - conf) / 2, 1 - (1 - conf) / 2)
  target <- log(hi / lo)
  f <- function(le) {
    e <- exp(le)
    0.5 * log(stats::qchisq(p[2], e) / stats::qchisq(p[1], e)) - target
  }
  exp(stats::uniroot(f, c(log(0.05), log(1e9)), tol = 1e-10)$root)
}

stable32_rows_mc <- function(res, reps) {
  ci <- res$status == "ok" & res$has_ci
  bad <- res[ci & !res$limits_ok, ]
  out <- list()
  for (f in unique(bad$file)) {
    rows <- bad[bad$file == f, ]
    dir <- basename(dirname(f))
    spec <- stable32_data[[dir]]
    r <- read_stable32(f)
    tab <- r$tab
    tau0 <- tab$tau[1] / tab$af[1]
    input <- spec[2]
    npts <- r$points
    ny <- if (input == "integrated") npts - 1L else npts
    alphas <- sort(unique(stats::na.omit(c(rows$s32_alpha, rows$alpha))),
                   decreasing = TRUE)
    nu32 <- mapply(function(lo, hi) edf_of_limits(lo, hi), rows$s32_lo,
                   rows$s32_hi)
    for (al in alphas) {
      av <- lo <- hi <- matrix(NA_real_, nrow(rows), reps)
      for (i in seq_len(reps)) {
        y <- mc_noise(al, ny)
        x <- if (input == "integrated") c(0, cumsum(y)) else y
        a <- suppressWarnings(allan(x, 1 / tau0, taus = tab$af * tau0,
                                    type = rows$type[1], input = input,
                                    conf = 0.683))
        k <- match(rows$af, a$m)
        av[, i] <- a$avar[k]
        lo[, i] <- a$lower[k]
        hi[, i] <- a$upper[k]
      }
      truth <- sqrt(rowMeans(av))
      dev <- sqrt(av)
      f32 <- t(vapply(nu32, function(e) {
        sqrt(e / stats::qchisq(c(1 - 0.1585, 0.1585), e))
      }, numeric(2)))
      out[[length(out) + 1L]] <- data.frame(
        file = paste(dir, basename(f), sep = "/"), type = rows$type,
        af = rows$af, N_over_m = round(npts / rows$af, 1),
        s32_alpha = rows$s32_alpha, our_alpha = rows$alpha, sim_alpha = al,
        s32_edf = signif(nu32, 3), our_edf = signif(rows$edf, 3),
        ours = rowMeans(lo <= truth & truth <= hi, na.rm = TRUE),
        s32 = rowMeans(dev * f32[, 1] <= truth & truth <= dev * f32[, 2]))
      message(basename(f), " alpha ", al, " done")
    }
  }
  do.call(rbind, out)
}

if (sys.nframe() == 0L) {
  args <- commandArgs(TRUE)
  reps <- if (length(args) >= 1) as.integer(args[1]) else 400L
  root <- Sys.getenv("ALLANVAR_PEER_DATA")
  if (!nzchar(root)) stop("set ALLANVAR_PEER_DATA to an allantools checkout")
  if (file.exists("DESCRIPTION") && requireNamespace("pkgload", quietly = TRUE) &&
      !nzchar(Sys.getenv("MC_INSTALLED"))) {
    pkgload::load_all(".", quiet = TRUE)
  } else {
    library(allanvar)
  }
  allan_edf_direct <- utils::getFromNamespace("allan_edf_direct", "allanvar")
  allan_ci <- utils::getFromNamespace("allan_ci", "allanvar")
  set.seed(20261128)
  res <- check_stable32(root)
  keep <- Sys.getenv("ALLANVAR_STABLE32_MC_FILES")
  if (nzchar(keep)) res <- res[grepl(keep, res$file), ]
  tab <- stable32_rows_mc(res, reps)
  tab$ours_ok <- tab$ours >= 0.60 & tab$ours <= 0.76
  tab$s32_ok <- tab$s32 >= 0.60 & tab$s32 <= 0.76
  old <- options(width = 220)
  print(tab, row.names = FALSE, digits = 3)
  options(old)
  cat(sprintf("%d replicates; rows x noise types: ours in band %d of %d, Stable32's %d of %d\n",
              reps, sum(tab$ours_ok), nrow(tab), sum(tab$s32_ok), nrow(tab)))
  if (nzchar(Sys.getenv("ALLANVAR_STABLE32_MC_OUT"))) {
    utils::write.csv(tab, Sys.getenv("ALLANVAR_STABLE32_MC_OUT"), row.names = FALSE)
  }
}
