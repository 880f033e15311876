# How well can a record tell a Gauss-Markov term's tc at all? For each GM
# case of bench/battery-loop.R (its runs kept with BATTERY_RUNS=dir), the
# Cramer-Rao bound of log tc at the loop's final model with that GM's tc
# set to the realised one (N or the filter's white level, B, K and every
# GM, all amplitudes and time constants unknown), and what it implies for
# the battery's 25% tolerance:
#   crb       the bound's SD of log tc (the periodogram's asymptotic
#             information, sum over Fourier frequencies of grad log S
#             grad log S', from the catalogue's psd() of each term; B has
#             no state-space form, so the exact av_information() cannot
#             take it; without B the two agree, checked below)
#   v_real    the variance of log tc of the realised value itself (the
#             least-squares AR(1) of the injected GM alone: 2 tc / T)
#   sd_diff   sqrt(crb^2 - v_real): the SD of log(estimate / realised) of
#             an efficient estimator
#   p25       the probability that such an estimator lands within 25% of
#             the realised tc
#   loop_se   the loop's own standard error of log tc (vcov())
#   z         log(loop tc / realised) / sd_diff
#
#   BATTERY_RUNS=/tmp/runs Rscript bench/battery-loop.R <data> "GM" a   (and b ... g)
#   R_LIBS=/tmp/lib Rscript bench/gm-tc-information.R /tmp/runs
suppressPackageStartupMessages(library(allanvar))
ns <- asNamespace("allanvar")
args <- commandArgs(TRUE)
dir <- if (length(args)) args[1L] else stop("give the BATTERY_RUNS directory")
freq <- 100

# Columns d S / d log(parameter) of the two-sided rate PSD at f, and S.
# Amplitudes enter as a^2 psd(f); a GM's tc by central differences of its
# catalogue psd() in log tc.
psd_grad <- function(f, white, B, K, gs, gt) {
  ps <- function(kind, nl = list()) ns$effect_entry(kind)$psd(f, nl)
  cols <- list(N = 2 * white^2 * ps("N"))
  S <- white^2 * ps("N")
  if (B > 0) { cols$B <- 2 * B^2 * ps("B"); S <- S + B^2 * ps("B") }
  if (K > 0) { cols$K <- 2 * K^2 * ps("K"); S <- S + K^2 * ps("K") }
  h <- 1e-4
  for (i in seq_along(gt)) {
    g <- ps("gm", list(tc = gt[i]))
    cols[[paste0("gm", i, ".sigma")]] <- 2 * gs[i]^2 * g
    cols[[paste0("gm", i, ".tc")]] <- gs[i]^2 *
      (ps("gm", list(tc = gt[i] * exp(h))) - ps("gm", list(tc = gt[i] * exp(-h)))) / (2 * h)
    S <- S + gs[i]^2 * g
  }
  list(cols = do.call(cbind, cols), S = S)
}
# the SD of every log-parameter an unbiased estimator can at best reach
crb_whittle <- function(n, white, B = 0, K = 0, gs = numeric(), gt = numeric()) {
  f <- seq_len(floor((n - 1) / 2)) * freq / n
  g <- psd_grad(f, white, B, K, gs, gt)
  sqrt(diag(solve(crossprod(g$cols / g$S))))
}

# check against the exact information where both apply (no B)
for (p in list(c(0.002, 35, 5e5), c(0.003, 20, 1e6), c(0.004, 8, 1e6))) {
  exact <- av_information(c(N = 0.0012, K = 5e-5, gm1.sigma = p[1], gm1.tc = p[2]),
                          n = p[3], freq = freq)$bound
  w <- crb_whittle(p[3], 0.0012, 0, 5e-5, p[1], p[2])[["gm1.tc"]]
  cat(sprintf("check: tc %g s, n %g: exact %.4f, periodogram %.4f\n", p[2], p[3],
              exact$rel_se[exact$parameter == "gm1.tc"], w))
}

rows <- list()
for (fn in list.files(dir, pattern = "\\.rds$", full.names = TRUE)) {
  s <- readRDS(fn)
  gm <- Filter(function(e) identical(e[[1L]], "gm"), s$expect)
  if (!length(gm)) next
  real <- gm[[1L]][[2L]]
  cf <- coef(s$r)
  nm <- names(cf)
  gt <- cf[grepl("^gm[0-9]*\\.tc$", nm)]
  gs <- cf[grepl("^gm[0-9]*\\.sigma$", nm)]
  n <- length(s$x)
  v_real <- 2 * real / (n / freq)
  if (!length(gt)) {
    rows[[length(rows) + 1L]] <- data.frame(case = sub("\\.rds$", "", basename(fn)),
      realised = signif(real, 3), loop = NA, crb = NA, sd_diff = NA, p25 = NA,
      loop_se = NA, z = NA, within = FALSE)
    next
  }
  k <- which.min(abs(log(gt / real)))
  white <- cf[grepl("^N$|^filter[^.]*\\.Nf$", nm)][1L]
  at <- gt
  at[k] <- real
  crb <- crb_whittle(n, white, if ("B" %in% nm) cf[["B"]] else 0,
                     if ("K" %in% nm) cf[["K"]] else 0, gs, at)[[paste0("gm", k, ".tc")]]
  sd_diff <- sqrt(max(crb^2 - v_real, 1e-6))
  se <- tryCatch(sqrt(diag(vcov(s$r)))[[names(gt)[k]]] / gt[[k]], error = function(e) NA_real_)
  rows[[length(rows) + 1L]] <- data.frame(
    case = sub("\\.rds$", "", basename(fn)), realised = signif(real, 3),
    loop = signif(gt[[k]], 3), crb = round(crb, 3), sd_diff = round(sd_diff, 3),
    p25 = round(stats::pnorm(log(1.25) / sd_diff) - stats::pnorm(log(0.8) / sd_diff), 2),
    loop_se = round(se, 3), z = round(log(gt[[k]] / real) / sd_diff, 2),
    within = abs(gt[[k]] / real - 1) <= 0.25)
}
tab <- do.call(rbind, rows)
options(width = 200)
print(tab, row.names = FALSE, right = FALSE)
cat(sprintf("\n%d GM cases: the loop within 25%% in %d; an efficient estimator's expected count %.1f\n",
            nrow(tab), sum(tab$within), sum(tab$p25, na.rm = TRUE)))
cat(sprintf("cases whose bound lets 25%% be 2 SD or more (sd_diff <= %.3f): %d\n",
            log(1.25) / 2, sum(tab$sd_diff <= log(1.25) / 2, na.rm = TRUE)))
cat(sprintf("|z| > 2: %d; mean z %.2f; the loop's 95%% interval (+-1.96 loop_se) holds the realised tc in %d of %d\n",
            sum(abs(tab$z) > 2, na.rm = TRUE), mean(tab$z, na.rm = TRUE),
            sum(abs(log(tab$loop / tab$realised)) <= 1.96 * tab$loop_se, na.rm = TRUE),
            sum(is.finite(tab$loop_se))))
