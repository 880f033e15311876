# Issue 9's Done-when checks on the 18 measured ADIS16405 axes, one axis at
# a time: the loop from N, B, K with the raw data given, and one row per
# axis appended to bench/adis16405/adis16405-check.txt as soon as it is done (so
# that a partial run on a loaded machine still reports what it measured).
# Derived figures only; the recordings stay in ../shared/data.
#
# Run from the package root:  Rscript bench/adis16405/adis16405-check.R
# (data-raw/adis16405.R sources this file for check_axis() alone).

# Issue 9's Done-when checks for one axis: contradicted steps, the filter
# term (present where the lag-1 ACF is positive; its noise-equivalent
# bandwidth), the 0.55 Hz line, chi2/dof, and N against the white level
# read where the ADEV slope is -1/2 (local slope within 0.1 of it, tau
# 0.04-10 s: beyond the filter's bend), as the median of adev * sqrt(tau).
check_axis <- function(x, freq, av, dg, ref) {
  tau <- av$tau; adev <- av$adev
  sl <- c(NA, diff(log(adev)) / diff(log(tau)))
  ok <- is.finite(sl) & abs(sl + 0.5) < 0.1 & tau >= 0.04 & tau <= 10
  n_ref <- if (any(ok)) stats::median(adev[ok] * sqrt(tau[ok])) else NA_real_
  cf <- coef(ref)
  has_filter <- any(grepl("^filter", ref$terms))
  n_fit <- if ("N" %in% names(cf)) cf[["N"]] else if (has_filter)
    cf[[grep("Nf$", names(cf), value = TRUE)[1]]] else NA_real_
  enbw <- NA_real_
  if (has_filter) {
    # the family the loop chose: "filter" (moving average) or "filter:lp1/lp2"
    v <- split_term(grep("^filter", ref$terms, value = TRUE)[1])$variant
    if (!nzchar(v)) v <- "ma"
    p <- if (v == "ma") "L" else "fc"
    val <- unname(cf[grep(paste0("\\.", p, "$"), names(cf), value = TRUE)[1]])
    if (length(val) && is.finite(val)) {
      nl <- stats::setNames(list(val), p)
      enbw <- filter_bandwidth(filter_spec_of(v, nl, 1 / freq), 1 / freq)$enbw
    }
  }
  f0 <- cf[grepl("\\.f0$", names(cf))]
  st <- ref$steps
  data.frame(acf1 = dg$acf1, filter = has_filter, enbw = enbw,
             line_055 = any(f0 > 0.5 & f0 < 0.6),
             sinusoids = paste(signif(sort(f0), 3), collapse = " "),
             contradicted = sum(st$confirmed %in% FALSE),
             chi2 = ref$chi2, n_fit = n_fit, n_ref = n_ref,
             n_err = 100 * (n_fit / n_ref - 1),
             converged = isTRUE(ref$convergence$converged),
             unexplained = NROW(ref$unexplained),
             tau_from = if (is.null(ref$refine$tau_range)) min(ref$data$tau)
               else ref$refine$tau_range[1],
             effects = if (nrow(st)) paste(st$effect, collapse = ",") else "",
             stringsAsFactors = FALSE)
}

if (!exists("adis_check_define_only")) {
  pkgload::load_all(".", quiet = TRUE)
  shared <- Sys.getenv("ALLANVAR_SHARED_DATA", "../shared/data")
  if (!dir.exists(shared)) shared <- "/work/shared/data"
  options(allanvar.threads = 1L)
  out <- "bench/adis16405/adis16405-check.txt"
  # every sensor type early, then the rest
  order <- expand.grid(unit = 1:3, axis = c("gyro_x", "accel_z", "gyro_z",
                                            "accel_x", "gyro_y", "accel_y"),
                       stringsAsFactors = FALSE)
  # ADIS_AXES="1:gyro_y,3:accel_x" runs a subset and appends its rows (so a
  # loaded machine can rerun a few axes); the commit column says which code
  # produced each row.
  only <- Sys.getenv("ADIS_AXES", "")
  append <- nzchar(only)
  if (append) {
    want <- strsplit(strsplit(only, ",")[[1]], ":")
    order <- data.frame(unit = as.integer(vapply(want, `[`, "", 1)),
                        axis = vapply(want, `[`, "", 2),
                        stringsAsFactors = FALSE)
  }
  commit <- tryCatch(system2("git", c("rev-parse", "--short", "HEAD"),
                             stdout = TRUE), error = function(e) "?")
  cols <- c("unit", "axis", "acf1", "filter", "enbw", "line_055", "sinusoids",
            "contradicted", "chi2", "n_fit", "n_ref", "n_err", "converged",
            "unexplained", "tau_from", "effects", "seconds", "commit")
  if (!append || !file.exists(out)) writeLines(paste(cols, collapse = "\t"), out)
  cache <- list()
  for (i in seq_len(nrow(order))) {
    k <- order$unit[i]; axis <- order$axis[i]
    m <- readRDS(file.path(shared, sprintf("adis16405_unit%d.rds", k)))
    freq <- attr(m, "freq")
    x <- m[, axis]
    rm(m)
    t0 <- Sys.time()
    av <- allan(x, freq, taus = 10, type = "overlapping")
    dg <- avdiagnose(x, freq)
    fit0 <- avfit(av, terms = c("N", "B", "K"))
    ref <- suppressMessages(avrefine(fit0, data = x, max_steps = 5))
    row <- check_axis(x, freq, av, dg, ref)
    row$seconds <- as.numeric(Sys.time() - t0, units = "secs")
    row$commit <- commit[1]
    # ADIS_SAVE=dir keeps each refined fit for inspection (outside the tree)
    if (nzchar(Sys.getenv("ADIS_SAVE"))) {
      saveRDS(list(datasheet = fit0, refined = ref),
              file.path(Sys.getenv("ADIS_SAVE"), sprintf("fits_%d_%s.rds", k, axis)))
    }
    row <- cbind(data.frame(unit = k, axis = axis), row)
    fmt <- function(v) if (is.numeric(v)) format(signif(v, 4)) else as.character(v)
    cat(paste(vapply(row[cols], fmt, ""), collapse = "\t"), "\n", sep = "",
        file = out, append = TRUE)
    cat(sprintf("unit%d/%-8s chi2 %7.2f  filter %s  enbw %5.1f  N err %+.1f%%  [%s]  %.0f s\n",
                k, axis, row$chi2, row$filter, row$enbw, row$n_err, row$effects,
                row$seconds))
  }
}
