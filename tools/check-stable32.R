# Compares allan() with every Stable32 reference run in a checkout of python
# allantools' test suite (values, noise types and confidence limits).
#
#   ALLANVAR_PEER_DATA=/path/to/allantools Rscript tools/check-stable32.R
#
# ALLANVAR_NOISE_ID=stable32 (or coverage) sets options(allanvar.noise_id)
# (R/taus.R noise_id_rules(), src/noise_id.h). Counts on allantools' suite:
# 383 of 402 rows' limits by default, 387 with "stable32", 384 "coverage".
#
# The reference files (tests/*/...txt) are Stable32 tables: AF, tau, number of
# terms, alpha, min sigma, sigma, max sigma. They are fetched, never
# committed. A limit "agrees" when it is within 25% of Stable32's half-width
# of Stable32's limit; a value when it equals Stable32's to the printed
# digits (5 significant). Types allan() does not offer are counted as
# skipped. Run from the package's source tree (loads it with pkgload) or
# with allanvar installed. tests/testthat/test-edf.R runs it when
# ALLANVAR_PEER_DATA is set.

# Stable32's "Sigma Type" line -> allan(type = ).
stable32_types <- c(
  "Allan" = "standard", "Overlapping Allan" = "overlapping",
  "Modified Allan" = "modified", "Hadamard" = "hadamard",
  "Overlapping Hadamard" = "ohadamard", "Total" = "total",
  "Time" = "tdev", "Modified Total" = "mtotdev", "Time Total" = "ttotdev",
  "Hadamard Total" = "htotdev", "Theo1" = "theo1", "TheoH" = "theoh"
)

# The data set behind each reference file, by folder: file name and whether
# it holds phase ("integrated") or fractional frequency ("rate"), and for
# frequency in Hz the nominal frequency (y = (f - f0) / f0, as allantools'
# frequency2fractional()).
stable32_data <- list(
  phasedat = c("PHASE.DAT", "integrated"),
  Cs5071A = c("5071A_phase.txt.gz", "integrated"),
  Keysight53230A_ti_noise_floor = c("tic_phase.txt", "integrated"),
  gps = c("gps_1pps_phase_data.txt.gz", "integrated"),
  ocxo = c("ocxo_frequency.txt", "rate", 1e7),  # Hz about 10 MHz
  pink_frequency = c("pink_frequency.txt", "rate")
)

read_stable32 <- function(f) {
  head <- readLines(f, n = 20)
  st <- sub("^#\\s*Sigma Type:\\s*", "", grep("Sigma Type", head, value = TRUE))
  rng <- regmatches(head, regexpr("Points 1 thru [0-9]+", head))
  npts <- as.numeric(sub("Points 1 thru ", "", rng))
  tab <- utils::read.table(f, comment.char = "#", header = FALSE)
  if (ncol(tab) < 7) return(NULL)
  names(tab)[1:7] <- c("af", "tau", "n", "alpha", "lo", "dev", "hi")
  src <- sub("^#.*STATISTICS FOR FILE:\\s*", "",
             grep("STATISTICS FOR FILE", head, value = TRUE))
  list(sigma_type = trimws(st), points = npts, source = trimws(src),
       tab = tab[, 1:7])
}

# One reference file against allan(): a data frame of its rows.
compare_stable32 <- function(f, x, input) {
  r <- read_stable32(f)
  if (is.null(r) || !r$sigma_type %in% names(stable32_types)) return(NULL)
  type <- stable32_types[[r$sigma_type]]
  # the six Allan types; the further ones (and their bias conventions) are
  # checked by tools/check-stable32-types.R
  if (!type %in% c("standard", "overlapping", "modified", "hadamard",
                   "ohadamard", "total")) {
    return(NULL)
  }
  tab <- r$tab
  tau0 <- tab$tau[1] / tab$af[1]
  x <- x[seq_len(min(length(x), r$points))]
  a <- tryCatch(
    suppressWarnings(allan(x, 1 / tau0, taus = tab$af * tau0, type = type,
                           input = input, conf = 0.683)),
    error = function(e) e)
  # The OCXO's *_octave.txt runs were made on a differently scaled copy of
  # the data ("ocxo_frequency.001": values differ by up to 1e-3); their
  # limits are compared, their values are not counted.
  same <- !identical(r$source, "ocxo_frequency.001")
  base <- data.frame(file = f, type = type, same_data = same, af = tab$af,
                     s32_alpha = tab$alpha,
                     s32_dev = tab$dev, s32_lo = tab$lo, s32_hi = tab$hi)
  if (inherits(a, "error")) {
    base$status <- "skipped"
    base$dev <- base$lo <- base$hi <- base$alpha <- base$edf <- NA_real_
    base$n <- base$L <- NA_real_
    return(base)
  }
  i <- match(tab$af, a$m)
  base$status <- ifelse(is.na(i), "missing", "ok")
  base$dev <- a$adev[i]
  base$lo <- a$lower[i]
  base$hi <- a$upper[i]
  base$alpha <- a$alpha[i]
  base$edf <- a$edf[i]
  base$n <- a$n[i]
  base$L <- if (input == "rate") length(x) + 1 else length(x)
  base
}

check_stable32 <- function(root) {
  out <- list()
  for (dir in names(stable32_data)) {
    d <- file.path(root, "tests", dir)
    if (!dir.exists(d)) next
    spec <- stable32_data[[dir]]
    x <- as.numeric(utils::read.table(file.path(d, spec[1]),
                                      comment.char = "#")[[1]])
    if (length(spec) > 2) {
      f0 <- as.numeric(spec[3])
      x <- (x - f0) / f0
    }
    files <- list.files(d, pattern = "\\.txt$", full.names = TRUE)
    for (f in files) {
      if (basename(f) == spec[1]) next
      res <- compare_stable32(f, x, spec[2])
      if (!is.null(res)) out[[f]] <- res
    }
  }
  res <- do.call(rbind, out)
  rownames(res) <- NULL
  res$value_ok <- res$status == "ok" & res$same_data &
    signif(res$dev, 5) == signif(res$s32_dev, 5)
  has_ci <- res$s32_lo > 0 & res$s32_hi > 0
  res$has_ci <- has_ci
  tol <- 0.25
  res$lo_ok <- abs(res$lo - res$s32_lo) <= tol * (res$s32_dev - res$s32_lo)
  res$hi_ok <- abs(res$hi - res$s32_hi) <= tol * (res$s32_hi - res$s32_dev)
  res$limits_ok <- res$lo_ok & res$hi_ok
  res$alpha_ok <- res$alpha == res$s32_alpha
  # the EDF engine alone: limits from Stable32's own noise type
  # (the Allan family only: allan_edf_direct() has no kernel for the
  # further types, which tools/check-stable32-types.R checks)
  ok <- res$status == "ok" & has_ci &
    res$type %in% c("standard", "overlapping", "modified", "hadamard",
                    "ohadamard", "total")
  res$lo2 <- res$hi2 <- NA_real_
  for (i in which(ok)) {
    e <- allan_edf_direct(res$type[i], res$af[i], res$n[i], res$L[i],
                          res$s32_alpha[i])
    ci <- allan_ci(res$dev[i]^2, e, 0.683)
    res$lo2[i] <- ci$lower
    res$hi2[i] <- ci$upper
  }
  res$limits2_ok <-
    abs(res$lo2 - res$s32_lo) <= tol * (res$s32_dev - res$s32_lo) &
    abs(res$hi2 - res$s32_hi) <= tol * (res$s32_hi - res$s32_dev)
  res
}

summarise_stable32 <- function(res) {
  ok <- res$status == "ok"
  ci <- ok & res$has_ci
  cat(sprintf("reference rows: %d (%d for types allan() offers, %d skipped)\n",
              nrow(res), sum(ok), sum(res$status == "skipped")))
  cat(sprintf("values equal to the printed digits: %d of %d\n",
              sum(res$value_ok[ok], na.rm = TRUE), sum(ok & res$same_data)))
  cat(sprintf("noise type (alpha) equal: %d of %d\n",
              sum(res$alpha_ok[ok], na.rm = TRUE), sum(ok)))
  cat(sprintf("rows with both limits within 25%% of the half-width: %d of %d\n",
              sum(res$limits_ok[ci], na.rm = TRUE), sum(ci)))
  cat(sprintf(paste0("rows with both limits within 25%% given Stable32's ",
                     "noise type (EDF engine alone): %d of %d\n"),
              sum(res$limits2_ok[ci], na.rm = TRUE), sum(ci)))
  cat(sprintf("single limits within 25%%: %d of %d\n",
              sum(res$lo_ok[ci], na.rm = TRUE) + sum(res$hi_ok[ci], na.rm = TRUE),
              2 * sum(ci)))
  by <- split(res[ci, ], basename(dirname(res$file[ci])))
  for (nm in names(by)) {
    b <- by[[nm]]
    cat(sprintf("  %-32s limits %4d of %4d, alpha %4d of %4d\n", nm,
                sum(b$limits_ok, na.rm = TRUE), nrow(b),
                sum(b$alpha_ok, na.rm = TRUE), nrow(b)))
  }
  invisible(res)
}

if (sys.nframe() == 0L) {
  # ALLANVAR_NOISE_ID: the noise-identification rules (default, stable32,
  # coverage)
  if (nzchar(Sys.getenv("ALLANVAR_NOISE_ID"))) {
    options(allanvar.noise_id = Sys.getenv("ALLANVAR_NOISE_ID"))
  }
  root <- Sys.getenv("ALLANVAR_PEER_DATA")
  if (!nzchar(root)) stop("set ALLANVAR_PEER_DATA to an allantools checkout")
  if (file.exists("DESCRIPTION") && requireNamespace("pkgload", quietly = TRUE)) {
    pkgload::load_all(".", quiet = TRUE)
  } else {
    library(allanvar)
  }
  allan_edf_direct <- utils::getFromNamespace("allan_edf_direct", "allanvar")
  allan_ci <- utils::getFromNamespace("allan_ci", "allanvar")
  res <- check_stable32(root)
  summarise_stable32(res)
  if (nzchar(Sys.getenv("ALLANVAR_STABLE32_OUT"))) {
    utils::write.csv(res, Sys.getenv("ALLANVAR_STABLE32_OUT"), row.names = FALSE)
  }
}
