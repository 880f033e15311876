# Issue 27 point 4, a record (not package code): a Gauss-Markov tc read by
# the exact Gaussian likelihood of the record's block means, beside what the
# model already carries, against the curve's reading. On the battery's GM
# cases saved by bench/battery-loop.R (BATTERY_RUNS=dir):
#   curve   avrefine()'s value
#   ml      block means at dt = a tenth of the smallest GM's tc (at most
#           30000 blocks), the model's periodogram lines taken out first;
#           the state-space model: white per block (the filter, bands,
#           resonances and quantization average into it), a random walk
#           (diffuse level: the intercept), a flicker floor when the model
#           has B (AR(1)s of equal variance every half decade from dt to a
#           quarter of the record: one amplitude), and every GM of the
#           model as an AR(1) with its variance and tc free; the Kalman
#           filter's likelihood (the warm-up's, R/nonstationary.R), maximised
#           from the curve's values and from each GM's tc x 1/2 and x 2.
#   ml_nob  the same without the flicker floor
#   ml_fix  the same with the random walk and flicker held at the curve's K, B
#   gm_wn   the same likelihood on the added GM alone plus white noise of
#           the axis's level (what it reads with nothing else to trade
#           with); cases with one GM added only
# and whether each is within 25% of the realised tc.
#
#   BATTERY_RUNS=/tmp/runs Rscript bench/battery-loop.R <data> "GM" a  (b, c, d)
#   Rscript bench/gm-tc-ml.R /tmp/runs
suppressPackageStartupMessages(library(allanvar))
ns <- asNamespace("allanvar")
dir <- commandArgs(TRUE)[1L]
freq <- 100

gm_ml <- function(x, fit, flicker = NULL, fixed_slow = FALSE) {
  cf <- coef(fit)
  kinds <- ns$split_term(fit$terms)$kind
  tcs <- unname(cf[grepl("^gm[0-9]*\\.tc$", names(cf))])
  sig <- unname(cf[grepl("^gm[0-9]*\\.sigma$", names(cf))])
  f0 <- cf[grepl("^sinusoid[0-9]*\\.f0$", names(cf))]
  if (length(f0)) x <- ns$remove_lines(x, freq, unname(f0))
  n <- length(x)
  b <- max(1L, floor(min(tcs) * freq / 10), ceiling(n / 30000))
  y <- ns$block_avg(x, b)
  nb <- length(y)
  dt <- b / freq
  sy <- stats::sd(y)
  y <- (y - mean(y)) / sy
  # the curve's random walk and flicker in block units (two-sided PSDs
  # K^2 / (2 pi f)^2 and B^2 / (2 pi f); an AR(1) sum of variance v every
  # half decade has v / (2 ln(10^0.5) f))
  Kc <- if ("K" %in% names(cf)) cf[["K"]] else 0
  Bc <- if ("B" %in% names(cf)) cf[["B"]] else 0
  q_fix <- Kc^2 * dt / sy^2
  v_fix <- log(10^0.5) * Bc^2 / pi / sy^2
  if (is.null(flicker)) flicker <- "B" %in% kinds || fixed_slow
  fphi <- if (flicker) exp(-dt / 10^seq(log10(dt), log10(nb * dt / 4), by = 0.5)) else numeric(0)
  k <- length(tcs)
  # th: log q, [log B], log tc_i, log s_i (relative to the white per block)
  unpack <- function(th) {
    i <- 1L
    if (fixed_slow) {
      # th: log h, log tc_i, log s_i (absolute, block units)
      return(list(h = exp(th[1L]), q = q_fix, B = v_fix, tc = exp(th[1L + seq_len(k)]),
                  s = exp(th[1L + k + seq_len(k)])))
    }
    q <- exp(th[i]); i <- i + 1L
    B <- if (flicker) { v <- exp(th[i]); i <- i + 1L; v } else 0
    list(h = 1, q = q, B = B, tc = exp(th[i - 1L + seq_len(k)]), s = exp(th[i - 1L + k + seq_len(k)]))
  }
  fit_ll <- function(th) {
    p <- unpack(th)
    mod <- list(h = p$h, q = p$q, phi = c(fphi, exp(-dt / p$tc)),
                s = c(rep(p$B, length(fphi)), p$s))
    E <- ns$warmup_whiten(matrix(y), mod)
    e <- E[, 1L]
    m <- length(e)
    if (fixed_slow) return(-attr(E, "logdet") - sum(e^2) / 2)
    -attr(E, "logdet") - m / 2 * log(sum(e^2) / m) - m / 2
  }
  nll <- function(th) { v <- fit_ll(th); if (is.finite(v)) -v else 1e300 }
  h0 <- max(stats::var(diff(y)) / 2, 1e-6)
  s0 <- pmax(sig^2 / stats::var(ns$block_avg(x, b)) / h0, 1e-4)
  best <- NULL
  for (mult in list(rep(1, k), rep(0.5, k), rep(2, k))) {
    th0 <- c(log(1e-4), if (flicker) log(1e-3), log(tcs * mult), log(s0))
    # a GM's tc stays between 2 blocks and the record
    lo <- c(-25, if (flicker) -25, rep(log(2 * dt), k), rep(-25, k))
    hi <- c(25, if (flicker) 25, rep(log(nb * dt), k), rep(25, k))
    if (fixed_slow) {
      th0 <- c(log(h0), log(tcs * mult), log(s0 * h0))
      lo <- lo[-2L]; hi <- hi[-2L]
    }
    o <- stats::optim(pmin(pmax(th0, lo), hi), nll, method = "L-BFGS-B", lower = lo, upper = hi)
    if (is.null(best) || o$value < best$value) best <- o
  }
  list(tc = unpack(best$par)$tc, curve = tcs, dt = dt, nb = nb)
}

ok <- function(v, real) if (is.finite(v) && abs(v / real - 1) <= 0.25) "ok" else "X"
rows <- list()
for (fn in list.files(dir, pattern = "GM_tc|GMs", full.names = TRUE)) {
  s <- readRDS(fn)
  for (e in s$expect) {
    if (e[[1L]] != "gm") next
    real <- e[[2L]]
    t0 <- proc.time()
    w <- gm_ml(s$x, s$r)
    cpu <- sum((proc.time() - t0)[1:2])
    w2 <- gm_ml(s$x, s$r, flicker = FALSE)
    w3 <- gm_ml(s$x, s$r, fixed_slow = TRUE)
    j3 <- which.min(abs(log(w3$tc / real)))
    if (!length(w$curve)) next
    g <- s$x - s$base_x
    wn <- if (sum(vapply(s$expect, function(e) e[[1L]] == "gm", NA)) == 1L) {
      set.seed(1)
      gm_ml(g + stats::rnorm(length(g), sd = stats::sd(diff(s$base_x)) / sqrt(2)), s$r,
            flicker = FALSE)$tc
    } else NA_real_
    jw <- which.min(abs(log(wn / real)))
    j <- which.min(abs(log(w$curve / real)))
    jm <- which.min(abs(log(w$tc / real)))
    jb <- which.min(abs(log(w2$tc / real)))
    rows[[length(rows) + 1L]] <- data.frame(
      case = sub("\\.rds$", "", basename(fn)), realised = signif(real, 3),
      curve = sprintf("%s %s", paste(signif(w$curve, 3), collapse = "+"), ok(w$curve[j], real)),
      ml = sprintf("%s %s", paste(signif(w$tc, 3), collapse = "+"), ok(w$tc[jm], real)),
      ml_nob = sprintf("%s %s", paste(signif(w2$tc, 3), collapse = "+"), ok(w2$tc[jb], real)),
      ml_fix = sprintf("%s %s", paste(signif(w3$tc, 3), collapse = "+"), ok(w3$tc[j3], real)),
      gm_wn = sprintf("%s %s", paste(signif(wn, 3), collapse = "+"), ok(wn[jw], real)),
      dt = w$dt, nb = w$nb, cpu = round(cpu, 2))
  }
}
tab <- do.call(rbind, rows)
options(width = 200)
print(tab, row.names = FALSE, right = FALSE)
for (col in c("curve", "ml", "ml_nob", "ml_fix", "gm_wn")) {
  cat(sprintf("%-6s: %d of %d within 25%%\n", col, sum(grepl(" ok$", tab[[col]])), nrow(tab)))
}
