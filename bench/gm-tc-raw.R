# Issue 27 point 4, a record (not package code): can the raw series read a
# Gauss-Markov tc better than the curve? On the battery's GM cases saved
# by bench/battery-loop.R (BATTERY_RUNS=dir), each accepted GM's tc as
#   curve   avrefine()'s value, with its standard error from vcov()
#   acf     the block-mean ACF the GM entry's evidence reads (acf_exponential())
#   raw     a local Whittle likelihood of the record's periodogram below
#           `mult` x the smallest GM's corner 1/(2 pi tc): the model's other
#           terms (their catalogue psd(), white always) with amplitudes free
#           and >= 0, lines masked by using the block means of the series,
#           every GM's tc profiled (coordinate sweeps), 95% profile interval
#   joint   the raw profile plus the curve's log-normal (its se) in log tc
# and whether each is within 25% of the realised tc.
#
#   BATTERY_RUNS=/tmp/runs Rscript bench/battery-loop.R <data> "GM" a  (and b, c)
#   Rscript bench/gm-tc-raw.R /tmp/runs
suppressPackageStartupMessages(library(allanvar))
ns <- asNamespace("allanvar")
dir <- commandArgs(TRUE)[1L]
freq <- 100

# columns of the model's two-sided PSD per squared amplitude at f: white,
# then each non-GM term with a psd() that is not flat
model_cols <- function(fit, f) {
  cf <- coef(fit)
  labs <- ns$term_labels(fit$terms)
  kinds <- ns$split_term(fit$terms)$kind
  cols <- list(white = rep(1, length(f)))
  for (i in seq_along(fit$terms)) {
    e <- ns$effect_entry(kinds[i])
    if (kinds[i] == "gm" || is.null(e$psd)) next
    v <- tryCatch(e$psd(f, as.list(ns$instance_params(cf, fit$layout, labs[i]))),
                  error = function(err) NULL)
    if (is.null(v) || any(!is.finite(v)) || all(v == 1)) next
    cols[[labs[i]]] <- v
  }
  do.call(cbind, cols)
}
# Whittle negative log-likelihood of bin means y (k periodogram ordinates
# each) under X a, a >= 0, by iteratively reweighted least squares
whittle_nll <- function(X, y, k) {
  S <- rep(mean(y), length(y))
  for (it in 1:30) {
    w <- sqrt(k) / S
    act <- rep(TRUE, ncol(X))
    a <- numeric(ncol(X))
    while (any(act)) {
      sol <- qr.coef(qr(X[, act, drop = FALSE] * w), y * w)
      sol[is.na(sol)] <- 0
      if (all(sol >= 0)) { a[act] <- sol; break }
      act[which(act)[sol < 0]] <- FALSE
    }
    Sn <- pmax(drop(X %*% a), 1e-300)
    done <- max(abs(Sn / S - 1)) < 1e-6
    S <- Sn
    if (done) break
  }
  sum(k * (log(S) + y / S))
}
gm_raw <- function(x, fit, mult, f_lo = 3, bins = 40) {
  cf <- coef(fit)
  tcs <- cf[grepl("^gm[0-9]*\\.tc$", names(cf))]
  se <- sqrt(diag(vcov(fit)))[names(tcs)] / tcs
  fhi <- min(freq / 20, mult / (2 * pi * min(tcs)))
  # block means: the record's slow part at a fraction of the cost; the
  # lines and the filter fold into the flat (white) column
  m <- max(1L, floor(freq / (8 * fhi)))
  rp <- ns$record_periodogram(ns$block_means(x, m), freq / m)
  keep <- rp$f >= f_lo * rp$res & rp$f <= fhi
  f <- rp$f[keep]
  p <- rp$psd[keep] / 2
  g <- floor(log10(f) * bins)
  # Blackman-Harris: about 2 record bins per independent ordinate
  k <- as.numeric(table(g)) * rp$df / rp$res / 2
  fb <- as.numeric(tapply(f, g, mean))
  pb <- as.numeric(tapply(p, g, mean))
  H2 <- if (m > 1L) (sin(pi * fb * m / freq) / (m * sin(pi * fb / freq)))^2 else 1
  X0 <- model_cols(fit, fb)
  X0[, -1L] <- X0[, -1L] * H2
  gm <- function(t) H2 * 2 * t / (1 + (2 * pi * fb * t)^2)
  nll <- function(tv) whittle_nll(cbind(X0, vapply(tv, gm, fb)), pb, k)
  grid <- 10^seq(-1, 1, by = 0.05)
  est <- tcs
  prof <- list()
  for (s in seq_len(if (length(tcs) > 1L) 2L else 1L)) for (j in seq_along(est)) {
    v <- vapply(grid, function(r) { tv <- est; tv[j] <- tcs[j] * r; nll(tv) }, 0)
    est[j] <- tcs[j] * grid[which.min(v)]
    prof[[j]] <- v
  }
  data.frame(curve = tcs, se = se, raw = est,
             lo = vapply(prof, function(v) min(grid[v - min(v) <= 1.92]), 0) * tcs,
             hi = vapply(prof, function(v) max(grid[v - min(v) <= 1.92]), 0) * tcs,
             joint = vapply(seq_along(prof), function(j) {
               s <- if (is.finite(se[j]) && se[j] > 0) se[j] else Inf
               tcs[j] * grid[which.min(prof[[j]] + 0.5 * (log(grid) / s)^2)]
             }, 0))
}

ok <- function(v, real) if (is.finite(v) && abs(v / real - 1) <= 0.25) "ok" else "X"
rows <- list()
for (fn in list.files(dir, pattern = "GM_tc|GMs", full.names = TRUE)) {
  s <- readRDS(fn)
  real <- s$expect[[1L]][[2L]]
  for (mult in c(30, 100)) {
    t0 <- proc.time()
    w <- gm_raw(s$x, s$r, mult)
    cpu <- sum((proc.time() - t0)[1:2])
    j <- which.min(abs(log(w$curve / real)))
    a <- ns$acf_exponential(s$x, freq, w$curve[j])$tc
    rows[[length(rows) + 1L]] <- data.frame(
      case = sub("\\.rds$", "", basename(fn)), mult = mult, realised = signif(real, 3),
      curve = sprintf("%s +-%s%% %s", signif(w$curve[j], 3), round(100 * w$se[j]), ok(w$curve[j], real)),
      acf = sprintf("%s %s", signif(a, 3), ok(a, real)),
      raw = sprintf("%s [%s, %s] %s", signif(w$raw[j], 3), signif(w$lo[j], 3),
                    signif(w$hi[j], 3), ok(w$raw[j], real)),
      joint = sprintf("%s %s", signif(w$joint[j], 3), ok(w$joint[j], real)),
      cpu = round(cpu, 2))
  }
}
tab <- do.call(rbind, rows)
options(width = 200)
print(tab, row.names = FALSE, right = FALSE)
for (col in c("curve", "acf", "raw", "joint")) for (mult in c(30, 100)) {
  cat(sprintf("%-6s mult %3d: %d of %d within 25%%\n", col, mult,
              sum(grepl(" ok$", tab[[col]][tab$mult == mult])), sum(tab$mult == mult)))
}
