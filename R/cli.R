#' Command-line entry point: CSV in, plot, datasheet and imu.yaml out
#'
#' For people who do not write R. From a shell:
#'
#' ```
#' Rscript -e 'allanvar::allanvar_cli()' --args imu.csv --out results
#' $(Rscript -e 'cat(system.file("bin/allanvar", package = "allanvar"))') imu.csv --out results
#' ```
#'
#' Each file (CSV, ROS1 `.bag`, ROS2 `.db3` or `.mcap`) is read with
#' [read_imu()] (the Kalibr/EuRoC layout is recognized; other layouts via
#' the options), analysed with [analyze_imu()], and the output directory
#' receives the Allan deviation plot (`allan_deviation.png`), the datasheet
#' table (`datasheet.csv`, also printed), the Kalibr `imu.yaml` and the
#' discrete-time filter parameters (`filter_params.csv`) and the HTML report
#' of the whole analysis (`report.html`, see [write_report()]; `--no-report`
#' leaves it out). With several input
#' files each output name is prefixed by the file's name.
#'
#' Outputs are all or nothing: they are written into a temporary directory
#' and moved into `--out` only when every file has been read, analysed and
#' written, so a failed run leaves no partial set. `--out` must name a
#' directory (not an empty string, not an existing file). Errors and
#' warnings name the command-line flags to use (`--rate`, `--gyro-units`,
#' `--time-col`, ...), not R's argument names.
#'
#' Options:
#' * `--out DIR` output directory (default `allanvar-out`);
#' * `--rate HZ` sampling rate (required without a time column);
#' * `--time-col NAME`, `--no-time`, `--time-unit auto|s|ms|us|ns`;
#' * `--gyro-cols A,B,C`, `--accel-cols D,E,F` data columns;
#' * `--gyro-units U`, `--accel-units U` input units (see [av_units()]);
#' * `--sep C` field separator (`,` default; `tab`, `space`, `;`);
#'   `--dec C` decimal mark (`.` default, or `,`);
#' * `--topic NAME` the IMU topic of a bag (listed when not given and the
#'   bag has several);
#' * `--gap segments|error|ignore` what to do with time gaps;
#' * `--terms N,B,K` terms to fit (of [av_terms()]: Q, N, B, K, R, gm,
#'   sinusoid); `--no-refine` skip [avrefine()];
#' * `--remove spikes,steps` non-stationary effects to take out of each
#'   axis first (see [detect_series_effects()]; `all` for every kind);
#' * `--width PX`, `--height PX` size of the PNG (default 700 per sensor
#'   by 600);
#' * `--axis max|mean` which value goes into imu.yaml; `--average` adds the
#'   mean of the axes to the datasheet;
#' * `--workers N` analyse the axes in N processes (`workers` of
#'   [analyze_imu()]; by default as many as `allanvar.threads`, 2, where
#'   the platform can fork; `--workers 1` one after another);
#' * `--no-report` do not write `report.html`;
#' * `--quiet` no progress messages; `--help`.
#'
#' * `--units-checked` the units are right although they fail the checks
#'   (gravity for accelerometers, plausible white noise for gyroscopes).
#'
#' Exit status of the launcher (`allanvar`): 0 when every file was read,
#' analysed and written; 1 on an error (nothing written); 3 when the files
#' were written but the units failed their checks (every file carries the
#' warning) and `--units-checked` was not given. Through `Rscript -e` the
#' last case is an error too (status 1).
#'
#' @param args Character vector of command-line arguments (default: those
#'   after `--args`).
#' @return Invisibly, a list with the analyses and the paths written. Errors
#'   are signalled as R errors, so that `Rscript` exits with status 1; units
#'   that fail their checks end the run with an error of class
#'   `allanvar_error_units_unchecked` after the files are written.
#' @export
#' @examples
#' allanvar_cli("--help")
allanvar_cli <- function(args = commandArgs(trailingOnly = TRUE)) {
  # Errors propagate: Rscript then prints "Error: ..." and exits with 1.
  if (!is.character(args) || anyNA(args)) {
    abort("`args` must be a character vector of command-line arguments, not ",
          if (is.character(args)) "one holding NA" else describe_type(args), ".",
          class = "argument")
  }
  invisible(cli_run(args))
}

cli_usage <- function() {
  paste(
    "Usage: allanvar FILE [FILE2 ...] [options]",
    "Allan deviation analysis of IMU recordings (CSV, ROS1 .bag, ROS2 .db3, .mcap):",
    "writes allan_deviation.png, datasheet.csv, imu.yaml (Kalibr), filter_params.csv and report.html.",
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
    "  --dec C                decimal mark: . (default) or ,",
    "  --topic NAME           IMU topic of a bag (default: its only IMU topic)",
    "  --gap G                segments (default), error or ignore",
    "  --terms N,B,K          noise terms to fit (default N,B,K; also Q, R, gm, sinusoid)",
    "  --no-refine            do not add missing effects (avrefine)",
    "  --remove K1,K2         take effects out first: spikes, warmup, steps, transients, all",
    "  --axis max|mean        value written to imu.yaml (default max: worst axis)",
    "  --average              add the mean of the axes to the datasheet",
    "  --width PX             PNG width (default 700 per sensor)",
    "  --height PX            PNG height (default 600)",
    "  --workers N            processes for the axes (default 2 where R can fork)",
    "  --no-report            do not write report.html",
    "  --units-checked        the units are right though they fail the checks",
    "                         (else such a run writes marked files and exits with 3)",
    "  --quiet                no progress messages",
    "  --help                 this text",
    sep = "\n")
}

cli_flags <- c("--no-time", "--no-refine", "--average", "--quiet", "--help",
               "--no-report", "--units-checked")
cli_valued <- c("--out", "--rate", "--time-col", "--time-unit", "--gyro-cols",
                "--accel-cols", "--gyro-units", "--accel-units", "--sep", "--dec",
                "--topic", "--gap", "--terms", "--remove", "--axis", "--workers", "--width",
                "--height")

cli_parse <- function(args) {
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
    if (a %in% cli_flags) {
      opt[[sub("^--", "", a)]] <- TRUE
    } else if (a %in% cli_valued) {
      if (i == length(args)) abort("option ", a, " needs a value.", class = "cli")
      opt[[sub("^--", "", a)]] <- args[[i + 1L]]
      i <- i + 1L
    } else if (startsWith(a, "--")) {
      abort("unknown option ", a, "; see --help.", class = "cli")
    } else {
      opt$files <- c(opt$files, a)
    }
    i <- i + 1L
  }
  opt
}

# R argument names in read_imu()'s messages, said as the CLI's flags.
cli_words <- function(msg) {
  subs <- c(
    "`freq = `" = "--rate", "`freq`" = "--rate",
    "`time = `" = "--time-col (or --no-time)", "`time`" = "--time-col",
    "time_unit = \"([a-z]+)\"" = "--time-unit \\1", "`time_unit`" = "--time-unit",
    "units = c\\(gyro = \"([^\"]+)\"\\)" = "--gyro-units \\1",
    "units = c\\(accel = \"([^\"]+)\"\\)" = "--accel-units \\1",
    "\\(CLI: [^)]*\\) " = "",
    "`units`" = "--gyro-units / --accel-units",
    "`columns = ` \\(and `sensors = `\\)" = "--gyro-cols / --accel-cols",
    "`sensors = c\\(([^ ]+) = \"gyro\"\\)` \\(or \"accel\"\\)" = "--gyro-cols \\1 (or --accel-cols \\1)",
    "`columns = `" = "--gyro-cols / --accel-cols", "`columns`" = "--gyro-cols / --accel-cols",
    "`sensors`" = "--gyro-cols / --accel-cols",
    "sep = \";\", dec = \",\"" = "--sep ';' --dec ,", "dec = \",\"" = "--dec ,",
    "`sep`" = "--sep", "`dec`" = "--dec",
    "`topic = `" = "--topic", "`topic`" = "--topic",
    "gap = \"([a-z]+)\"" = "--gap \\1",
    "`file`" = "the input file")
  for (k in seq_along(subs)) msg <- gsub(names(subs)[k], subs[[k]], msg)
  msg
}

# Runs `expr` with read_imu()'s conditions said in the CLI's words: errors
# keep their classes, warnings and messages go to stderr.
cli_speak <- function(expr) {
  withCallingHandlers(
    tryCatch(expr, allanvar_error = function(e) {
      e$message <- cli_words(conditionMessage(e))
      e$call <- NULL
      stop(e)
    }),
    allanvar_warning = function(w) {
      message("allanvar: warning: ", cli_words(conditionMessage(w)))
      invokeRestart("muffleWarning")
    },
    message = function(m) {
      if (!startsWith(conditionMessage(m), "allanvar: ")) {
        message("allanvar: ", cli_words(sub("\n$", "", conditionMessage(m))))
        invokeRestart("muffleMessage")
      }
    })
}

cli_terms <- function(v) {
  known <- unique(av_terms()$term)
  terms <- trimws(strsplit(v, ",", fixed = TRUE)[[1L]])
  # matched case-insensitively against the catalogue's terms
  hit <- match(tolower(terms), tolower(known))
  up <- ifelse(is.na(hit), terms, known[hit])
  bad <- setdiff(up, known)
  if (!length(terms) || length(bad)) {
    abort("--terms: ", if (length(bad)) paste0("unknown term(s) ",
                                               paste(bad, collapse = ", "))
          else "no term given", "; use a comma-separated list of ",
          paste(known, collapse = ", "), " (e.g. --terms N,B,K).", class = "cli")
  }
  up
}

# The output directory: a usable path (never "" = the filesystem root).
cli_out_dir <- function(out) {
  if (is.null(out)) return("allanvar-out")
  if (!nzchar(trimws(out))) {
    abort("--out must name a directory, not an empty string.", class = "cli")
  }
  if (file.exists(out) && !dir.exists(out)) {
    abort("--out \"", out, "\" is a file, not a directory.", class = "cli")
  }
  if (normalizePath(out, mustWork = FALSE) == normalizePath("/")) {
    abort("--out must not be the filesystem root; name a directory.", class = "cli")
  }
  out
}

cli_run <- function(args) {
  opt <- cli_parse(args)
  if (isTRUE(opt$help)) {
    cat(cli_usage(), "\n")
    return(invisible(NULL))
  }
  if (!length(opt$files)) abort("no input file given.\n", cli_usage(), class = "cli")
  out <- cli_out_dir(opt$out)
  num <- function(v, what, lo = 0, integer = FALSE) {
    x <- suppressWarnings(as.numeric(v))
    if (is.na(x) || !is.finite(x) || x <= lo || (integer && x != round(x))) {
      abort("--", what, " must be a ", if (integer) "whole " else "",
            "number above ", lo, ", not \"", v, "\".", class = "cli")
    }
    x
  }
  split <- function(v) trimws(strsplit(v, ",", fixed = TRUE)[[1L]])
  sep <- if (is.null(opt$sep)) "," else switch(opt$sep, tab = "\t",
                                               space = "", opt$sep)
  choice <- function(v, choices, flag) {
    if (!v %in% choices) {
      abort(flag, " must be one of ", paste(choices, collapse = ", "),
            ", not \"", v, "\".", class = "cli")
    }
    v
  }
  columns <- NULL
  sensors <- NULL
  if (!is.null(opt$`gyro-cols`) || !is.null(opt$`accel-cols`)) {
    g <- if (is.null(opt$`gyro-cols`)) character() else split(opt$`gyro-cols`)
    a <- if (is.null(opt$`accel-cols`)) character() else split(opt$`accel-cols`)
    columns <- c(g, a)
    sensors <- stats::setNames(c(rep("gyro", length(g)), rep("accel", length(a))),
                               columns)
  }
  for (u in c("gyro-units", "accel-units")) {
    if (!is.null(opt[[u]])) {
      s <- sub("-units", "", u)
      ok <- av_units(s, "rate")$unit
      if (!normalize_unit(opt[[u]]) %in% ok) {
        abort("--", u, " \"", opt[[u]], "\" is not a known ", s, " unit; use one of ",
              paste(ok, collapse = ", "), ".", class = "cli")
      }
    }
  }
  units <- c(gyro = opt$`gyro-units`, accel = opt$`accel-units`)
  # NULL: avfit()'s default, the catalogue's datasheet model
  terms <- if (is.null(opt$terms)) NULL else cli_terms(opt$terms)
  axis <- choice(if (is.null(opt$axis)) "max" else opt$axis, c("max", "mean"), "--axis")
  read_args <- list(
    time = if (isTRUE(opt$`no-time`)) FALSE else opt$`time-col`,
    time_unit = choice(if (is.null(opt$`time-unit`)) "auto" else opt$`time-unit`,
                       c("auto", "s", "ms", "us", "ns"), "--time-unit"),
    columns = columns, sensors = sensors,
    units = if (length(units)) units else NULL, sep = sep,
    dec = choice(if (is.null(opt$dec)) "." else opt$dec, c(".", ","), "--dec"),
    topic = opt$topic,
    gap = choice(if (is.null(opt$gap)) "segments" else opt$gap,
                 c("segments", "error", "ignore"), "--gap"),
    freq = if (is.null(opt$rate)) NULL else num(opt$rate, "rate"))
  width <- if (is.null(opt$width)) NULL else num(opt$width, "width", 99, TRUE)
  height <- if (is.null(opt$height)) 600 else num(opt$height, "height", 99, TRUE)
  workers <- if (is.null(opt$workers)) NULL else num(opt$workers, "workers", 0, TRUE)
  progress <- !isTRUE(opt$quiet)
  # Everything is written into `stage` first, and moved into `out` at the end.
  stage <- tempfile("allanvar-out-")
  dir.create(stage)
  on.exit(unlink(stage, recursive = TRUE), add = TRUE)
  analyses <- list()
  staged <- character()
  several <- length(opt$files) > 1L
  for (f in opt$files) {
    if (progress) message("allanvar: reading ", f)
    rec <- cli_speak(do.call(read_imu, c(list(f), read_args)))
    if (progress) print(rec)
    # The guidance is printed below; no need to repeat it as a warning.
    a <- withCallingHandlers(cli_speak(analyze_imu(
      rec, terms = terms, refine = !isTRUE(opt$`no-refine`), progress = progress,
      workers = workers,
      remove = if (is.null(opt$remove)) character()
               else trimws(strsplit(opt$remove, ",", fixed = TRUE)[[1L]]))),
      allanvar_guidance = function(m) invokeRestart("muffleMessage"))
    prefix <- if (several) paste0(sub("\\.[^.]*$", "", basename(f)), "_") else ""
    names_out <- paste0(prefix, c("allan_deviation.png", "datasheet.csv",
                                  "imu.yaml", "filter_params.csv",
                                  if (!isTRUE(opt$`no-report`)) "report.html"))
    path <- function(k) file.path(stage, names_out[k])
    n_s <- length(unique(vapply(a$channels, function(cc) cc$sensor, "")))
    grDevices::png(path(1), width = if (is.null(width)) 700 * n_s else width,
                   height = height, res = 96)
    tryCatch(plot(a), finally = grDevices::dev.off())
    ds <- datasheet(a, average = isTRUE(opt$average))
    write_datasheet(ds, path(2))
    tryCatch(write_kalibr_yaml(a, path(3), axis = axis),
             allanvar_error = function(e) {
               abort("\"", f, "\": imu.yaml cannot be written: ",
                     sub("^`x`: ", "", conditionMessage(e)),
                     class = "record_too_short")
             })
    utils::write.csv(kalman_params(a), path(4), row.names = FALSE)
    if (!isTRUE(opt$`no-report`)) write_report(a, path(5), record = rec)
    cat("\n", a$name, "\n", sep = "")
    print(ds)
    g <- guidance_lines(imu_guidance(a))
    if (length(g)) {
      cat("Guidance:\n")
      cat(paste0("  - ", g, "\n"), sep = "")
    }
    staged <- c(staged, names_out)
    analyses[[f]] <- a
  }
  written <- cli_commit(stage, staged, out)
  cat("Written: ", paste(written, collapse = ", "), "\n", sep = "")
  # Units that fail their checks: the files are written and marked, and the
  # run ends in an error (exit status 3 from the launcher) unless the user
  # says the units have been looked at.
  suspect <- Filter(function(a) nrow(unit_warnings(a)) > 0L, analyses)
  if (length(suspect) && !isTRUE(opt$`units-checked`)) {
    w <- do.call(rbind, lapply(suspect, function(a) {
      cbind(file = a$name, unit_warnings(a))
    }))
    abort("the units failed their checks (", paste0(w$file, " ", w$channel, ": ",
                                                     w$warning, collapse = "; "),
          "); the files were written and say so. Give the units with ",
          "--gyro-units / --accel-units, or pass --units-checked if they are right.",
          class = "units_unchecked")
  }
  invisible(list(analyses = analyses, files = written))
}

# Moves the staged outputs into `out` (created if needed): a rename where
# both are on one filesystem, else a copy.
cli_commit <- function(stage, files, out) {
  if (!dir.exists(out) && !dir.create(out, recursive = TRUE, showWarnings = FALSE)) {
    abort("cannot create the output directory \"", out, "\" (--out).", class = "cli")
  }
  dest <- file.path(out, files)
  for (k in seq_along(files)) {
    from <- file.path(stage, files[k])
    if (!suppressWarnings(file.rename(from, dest[k]))) {
      if (!file.copy(from, dest[k], overwrite = TRUE)) {
        abort("cannot write \"", dest[k], "\" (--out).", class = "cli")
      }
    }
  }
  dest
}
