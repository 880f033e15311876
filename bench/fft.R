# Does the package's own FFT (src/fft.h, radix-2, for the Theo kernels'
# correlations) pay against a maintained one? Eigen's unsupported FFT
# (kissfft back end; RcppEigen is already a LinkingTo dependency) on the
# same job: the correlation of two real blocks, as src/theo.cpp asks for it
# (a block of 6k-12k points against one 4k longer, lags < 4k, transform
# size a power of two), at the sizes a Theo1 call on 1e3-1e7 points uses;
# and a bare complex forward + inverse transform. One run, medians of
# `reps` repetitions each; the relative difference of the two correlations
# shows they compute the same thing.
#
# Run from the repository root: Rscript bench/fft.R  (about a minute)
src <- normalizePath("src")
Sys.setenv(PKG_CPPFLAGS = paste0("-I", src, " -DEIGEN_NO_DEBUG"))
Rcpp::sourceCpp(file.path("bench", "fft.cpp"), rebuild = TRUE)
set.seed(1)
options(width = 200)
rows <- list()
for (lg in seq(10, 22, by = 2)) {
  n <- 2^lg
  k <- n / 16  # theo_block_len(): B + 4k fills n with B = 12k at most
  B <- n - 4 * k
  a <- rnorm(B)
  b <- rnorm(B + 4 * k)
  reps <- max(5L, min(201L, as.integer(2^24 / n)))
  r <- bench_correlation(a, b, as.integer(4 * k), reps)
  cx <- bench_complex(as.integer(n), reps)
  rows[[length(rows) + 1L]] <- data.frame(
    n = sprintf("2^%d", lg), reps = reps,
    corr_own_ms = signif(1e3 * r$own, 3), corr_eigen_ms = signif(1e3 * r$eigen, 3),
    corr_ratio = round(r$eigen / r$own, 2),
    cplx_own_ms = signif(1e3 * cx$own, 3), cplx_eigen_ms = signif(1e3 * cx$eigen, 3),
    cplx_ratio = round(cx$eigen / cx$own, 2),
    rel_diff = signif(r$rel_diff, 2))
}
tab <- do.call(rbind, rows)
cat(sprintf("Machine: %s; load average at the end: %s\n", R.version$platform,
            paste(readLines("/proc/loadavg", warn = FALSE), collapse = " ")))
print(tab, row.names = FALSE, right = FALSE)
