#' Command-line entry point: CSV in, plot, datasheet and imu.yaml out
#'
#' For people who do not write R. From a shell:
#'
#' ```
#' Rscript -e 'allanvar::allanvar_cli()' --args imu.csv --out results
#' $(Rscript -e 'cat(system.file("bin/allanvar", package = "allanvar"))') imu.csv --out results
#' ```
#'
#' Each CSV is read with [read_imu()] (the Kalibr/EuRoC layout is
#' recognized; other layouts via the options), analysed with
#' [analyze_imu()], and the output directory receives the Allan deviation
#' plot (`allan_deviation.png`), the datasheet table (`datasheet.csv`, also
#' printed), the Kalibr `imu.yaml` and the discrete-time filter parameters
#' (`filter_params.csv`). With several input files each output name is
#' prefixed by the file's name.
#'
#' Options:
#' * `--out DIR` output directory (default `allanvar-out`);
#' * `--rate HZ` sampling rate (required without a time column);
#' * `--time-col NAME`, `--no-time`, `--time-unit auto|s|ms|us|ns`;
#' * `--gyro-cols A,B,C`, `--accel-cols D,E,F` data columns;
#' * `--gyro-units U`, `--accel-units U` input units (see [av_units()]);
#' * `--sep C` field separator (`,` default; `tab`, `space`, `;`);
#' * `--gap segments|error|ignore` what to do with time gaps;
#' * `--terms N,B,K` terms to fit; `--no-refine` skip [avrefine()];
#' * `--axis max|mean` which value goes into imu.yaml; `--average` adds the
#'   mean of the axes to the datasheet;
#' * `--workers N` analyse channels in N parallel R sessions
#'   (`future::plan(multisession)`);
#' * `--quiet` no progress messages; `--help`.
#'
#' @param args Character vector of command-line arguments (default: those
#'   after `--args`).
#' @return Invisibly, a list with the analyses and the paths written. Errors
#'   are signalled as R errors, so that `Rscript` exits with status 1.
#' @export
#' @examples
#' allanvar_cli("--help")
allanvar_cli <- function(args = commandArgs(trailingOnly = TRUE)) {
  # Errors propagate: Rscript then prints "Error: ..." and exits with 1.
  invisible(cli_run(as.character(args)))
}

cli_usage <- function() {
  paste(
    "Usage: allanvar FILE.csv [FILE2.csv ...] [options]",
    "Allan deviation analysis of IMU recordings: writes allan_deviation.png,",
    "datasheet.csv, imu.yaml (Kalibr) and filter_params.csv.",
    "",
    "Options:",
    "  --out DIR              output directory (default allanvar-out)",
    "  --rate HZ              sampling rate (needed without a time column)",
    "  --time-col NAME        timestamp column (default: detected)",
    "  --no-time              the file has no timestamp column (give --rate)",
    "  --time-unit U          auto, s, ms, us or ns (default auto)",
    "  --gyro-cols A,B,C      gyroscope columns",
    "  --accel-cols D,E,F     accelerometer columns",
    "  --gyro-units U         e.g. rad/s (default), deg/s, deg/h",
    "  --accel-units U        e.g. m/s^2 (default), g, mg",
    "  --sep C                field separator: , (default), tab, space, ;",
    "  --gap G                segments (default), error or ignore",
    "  --terms N,B,K          noise terms to fit (default N,B,K)",
    "  --no-refine            do not add missing effects (avrefine)",
    "  --axis max|mean        value written to imu.yaml (default max: worst axis)",
    "  --average              add the mean of the axes to the datasheet",
    "  --workers N            parallel R sessions (future multisession)",
    "  --quiet                no progress messages",
    "  --help                 this text",
    sep = "\n")
}

cli_parse <- function(args) {
  flags <- c("--no-time", "--no-refine", "--average", "--quiet", "--help")
  valued <- c("--out", "--rate", "--time-col", "--time-unit", "--gyro-cols",
              "--accel-cols", "--gyro-units", "--accel-units", "--sep",
              "--gap", "--terms", "--axis", "--workers")
  # `Rscript -e 'allanvar::allanvar_cli()' --args ...` passes "--args" on.
  args <- args[args != "--args"]
  opt <- list(files = character())
  i <- 1L
  while (i <= length(args)) {
    a <- args[[i]]
    if (grepl("^--[a-z-]+=", a)) {
      kv <- regmatches(a, regexpr("=", a), invert = TRUE)[[1L]]
      args <- append(args, kv[2L], after = i)
      a <- kv[1L]
    }
    if (a %in% flags) {
      opt[[sub("^--", "", a)]] <- TRUE
    } else if (a %in% valued) {
      if (i == length(args)) abort("option ", a, " needs a value.")
      opt[[sub("^--", "", a)]] <- args[[i + 1L]]
      i <- i + 1L
    } else if (startsWith(a, "--")) {
      abort("unknown option ", a, "; see --help.")
    } else {
      opt$files <- c(opt$files, a)
    }
    i <- i + 1L
  }
  opt
}

cli_run <- function(args) {
  opt <- cli_parse(args)
  if (isTRUE(opt$help)) {
    cat(cli_usage(), "\n")
    return(invisible(NULL))
  }
  if (!length(opt$files)) abort("no input file given.\n", cli_usage())
  out <- if (is.null(opt$out)) "allanvar-out" else opt$out
  dir.create(out, showWarnings = FALSE, recursive = TRUE)
  num <- function(v, what) {
    x <- suppressWarnings(as.numeric(v))
    if (is.na(x)) abort("--", what, " must be a number, not \"", v, "\".")
    x
  }
  split <- function(v) trimws(strsplit(v, ",", fixed = TRUE)[[1L]])
  sep <- if (is.null(opt$sep)) "," else switch(opt$sep, tab = "\t",
                                               space = "", opt$sep)
  columns <- NULL
  sensors <- NULL
  if (!is.null(opt$`gyro-cols`) || !is.null(opt$`accel-cols`)) {
    g <- if (is.null(opt$`gyro-cols`)) character() else split(opt$`gyro-cols`)
    a <- if (is.null(opt$`accel-cols`)) character() else split(opt$`accel-cols`)
    columns <- c(g, a)
    sensors <- stats::setNames(c(rep("gyro", length(g)), rep("accel", length(a))),
                               columns)
  }
  units <- c(gyro = opt$`gyro-units`, accel = opt$`accel-units`)
  read_args <- list(
    time = if (isTRUE(opt$`no-time`)) FALSE else opt$`time-col`,
    time_unit = if (is.null(opt$`time-unit`)) "auto" else opt$`time-unit`,
    columns = columns, sensors = sensors,
    units = if (length(units)) units else NULL, sep = sep,
    gap = if (is.null(opt$gap)) "segments" else opt$gap,
    freq = if (is.null(opt$rate)) NULL else num(opt$rate, "rate"))
  if (!is.null(opt$workers)) {
    w <- num(opt$workers, "workers")
    if (!requireNamespace("future", quietly = TRUE)) {
      abort("--workers needs the 'future' package; install it or drop --workers.")
    }
    old <- future::plan(future::multisession, workers = w)
    on.exit(future::plan(old), add = TRUE)
  }
  progress <- !isTRUE(opt$quiet)
  analyses <- list()
  written <- character()
  several <- length(opt$files) > 1L
  for (f in opt$files) {
    if (progress) message("allanvar: reading ", f)
    rec <- do.call(read_imu, c(list(f), read_args))
    if (progress) print(rec)
    # The guidance is printed below; no need to repeat it as a warning.
    a <- withCallingHandlers(analyze_imu(
      rec, terms = if (is.null(opt$terms)) c("N", "B", "K") else split(opt$terms),
      refine = !isTRUE(opt$`no-refine`), progress = progress),
      allanvar_guidance = function(w) invokeRestart("muffleWarning"))
    prefix <- if (several) paste0(sub("\\.[^.]*$", "", basename(f)), "_") else ""
    path <- function(name) file.path(out, paste0(prefix, name))
    png_file <- path("allan_deviation.png")
    n_s <- length(unique(vapply(a$channels, function(cc) cc$sensor, "")))
    grDevices::png(png_file, width = 700 * n_s, height = 600, res = 96)
    tryCatch(plot(a), finally = grDevices::dev.off())
    ds <- datasheet(a, average = isTRUE(opt$average))
    write_datasheet(ds, path("datasheet.csv"))
    write_kalibr_yaml(a, path("imu.yaml"),
                      axis = if (is.null(opt$axis)) "max" else opt$axis)
    utils::write.csv(filter_params(a), path("filter_params.csv"),
                     row.names = FALSE)
    cat("\n", a$name, "\n", sep = "")
    print(ds)
    g <- imu_guidance(a)
    if (nrow(g)) {
      cat("Guidance:\n")
      cat(paste0("  - ", g$channel, ": ", g$message, "\n"), sep = "")
    }
    files <- c(png_file, path("datasheet.csv"), path("imu.yaml"),
               path("filter_params.csv"))
    cat("Written: ", paste(files, collapse = ", "), "\n", sep = "")
    written <- c(written, files)
    analyses[[f]] <- a
  }
  invisible(list(analyses = analyses, files = written))
}
