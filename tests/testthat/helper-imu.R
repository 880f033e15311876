# Writes a Kalibr-layout CSV (timestamp in ns, rad/s, m/s^2) with exact
# integer nanosecond stamps: `off_ns` are offsets from an epoch of 1.4e9 s.
write_kalibr_csv <- function(m, file, freq = 100,
                             off_ns = round((seq_len(nrow(m)) - 1) * 1e9 / freq),
                             header = c("timestamp", "omega_x", "omega_y",
                                        "omega_z", "alpha_x", "alpha_y",
                                        "alpha_z")) {
  sec <- 1403636579 + off_ns %/% 1e9
  stamp <- sprintf("%.0f%09.0f", sec, off_ns %% 1e9)
  body <- do.call(paste, c(list(stamp), lapply(seq_len(ncol(m)), function(j)
    formatC(m[, j], digits = 17, format = "g")), sep = ","))
  writeLines(c(paste(header, collapse = ","), body), file)
  invisible(file)
}

# TRUE when the tests run against an installed allanvar (tools/test.sh,
# R CMD check), FALSE under pkgload::load_all().
# (load_all() marks the namespace it builds with `.__DEVTOOLS__`.)
installed_allanvar <- function() {
  !exists(".__DEVTOOLS__", envir = asNamespace("allanvar"), inherits = FALSE)
}
