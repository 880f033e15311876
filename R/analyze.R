# Orchestration: analyze_imu() runs, for every axis of one or more
# recordings, allan() -> avfit() -> avrefine() -> readings, one future per
# axis, and assembles the analysis (datasheet, guidance).

#' Analyse IMU recordings axis by axis
#'
#' For every channel (axis) of one or more recordings: the Allan deviation
#' curve on one tau grid ([allan()]), a noise-model fit ([avfit()] with
#' `terms`), the closed-loop refinement ([avrefine()], when `refine = TRUE`),
#' the datasheet readings N, B, K and the guidance on record length
#' ([imu_guidance()]). Axes are never averaged (see `average` in
#' [datasheet()]).
#'
#' Channels are analysed in parallel with [future.apply::future_lapply()],
#' one future per axis, with `future.seed = TRUE`: results do not depend on
#' how they are run. They run on whatever [future::plan()] is set
#' (`multisession`, a cluster, ...). Under the sequential plan (future's
#' default) a record large enough to pay for it (at least 2 axes and
#' 200,000 samples in all) runs its axes in `workers` forked processes,
#' started once for the call (a fork cluster, where the platform can fork:
#' not on Windows, not in RStudio; elsewhere background R sessions), each
#' kernel then on one thread. In a session that also starts processes
#' through 'processx' (as 'callr' does), set the environment variable
#' `PROCESSX_NOTIFY_OLD_SIGCHLD=true` before it loads: otherwise its signal
#' handler can keep the finished workers of a fork (this call's, or
#' [parallel::mclapply()]'s) from being reaped, and R waits 10 s at exit.
#'
#' Readings (typed columns `source`, `is_bound`, `folded`; the `method`
#' column says the same in words): N is
#' the fitted white-noise coefficient, the -1/2 line's value at tau = 1 s;
#' Gauss-Markov terms the refinement added with Tc < 0.1 s are white noise
#' at tau >= 1 s (their AV tends to 2 sigma^2 Tc / tau) and are folded in,
#' N = sqrt(N^2 + sum 2 sigma^2 Tc). K is the fitted rate random walk (the
#' +1/2 line's value at tau = 3 s) and B the fitted bias instability,
#' reported with the tau where it is read: the minimum of the fitted Allan
#' deviation (the flat region), or without a fit the minimum of the
#' measured one among the taus with at least 10 degrees of freedom.
#' A term the fit lacks or sets to 0 (for K: or whose standard error
#' exceeds it) is read by the IEEE 952 slope lines
#' instead: N and K from the tangent lines of slope -1/2 and +1/2,
#' B = min ADEV / 0.664; with no +1/2 region, K is given as the upper bound
#' min over tau of upper(tau) sqrt(3 / tau) (see [imu_guidance()]).
#'
#' @param x An [imu_record()] (from [read_imu()]), a list of them, or a
#'   character vector of file paths (read with [read_imu()] and `read_args`).
#' @param taus,type Passed to [allan()]: the tau grid (the same for every
#'   channel of a record) and the estimator.
#' @param terms Terms to fit, passed to [avfit()]; `NULL` (default) for the
#'   datasheet model N, B, K.
#' @param refine Run [avrefine()] on each fit to identify effects the model
#'   misses (logical).
#' @param segment Which gap-free segment to use: `"longest"` (default),
#'   `"each"` (every segment analysed as its own record) or a number.
#' @param channels Optional channel names to analyse (default: all).
#' @param progress Report progress. In interactive sessions a progress bar
#'   (through 'progressr', also across 'future' workers; 'cli' draws it
#'   when installed), elsewhere one message per axis. Default: on in
#'   interactive sessions unless `options(allanvar.progress = FALSE)`. With
#'   `progress = FALSE` the steps are still signalled to 'progressr', so
#'   `progressr::with_progress(analyze_imu(...))` shows them (outside
#'   interactive sessions when `options(progressr.enable = TRUE)`).
#' @param read_args A list of arguments for [read_imu()] when `x` holds
#'   file paths.
#' @param refine_args A list of further arguments for [avrefine()] (for
#'   example `candidates` or `max_steps`).
#' @param remove Non-stationary effects to take out of each axis before its
#'   Allan deviation is computed (see [detect_series_effects()]): e.g.
#'   `c("spikes", "steps")`, or `"all"`; none by default. What was found
#'   and removed is kept in each channel's `series` (without its series `x`).
#' @param workers Forked processes for the axes under the sequential plan:
#'   `NULL` (default) for `getOption("allanvar.threads", 2)` where the
#'   platform can fork and the record is large enough; `1` runs the axes
#'   one after another (or on the plan that is set); a number above 1
#'   forks that many (or, where the platform cannot fork, runs them in as
#'   many background R sessions). A plan other than sequential is used as
#'   set unless `workers` is given.
#' @param ... Further arguments passed to [avfit()].
#' @return For one recording, an object of class `"imu_analysis"`: a list
#'   with `name`, `freq`, `n` (samples used), `duration` (s), `record` (the
#'   record's `problems`, `segments`, `units`, `file`), `channels` (one entry
#'   per axis: `channel`, `sensor`, `unit`, `curve` (the [allan()] result),
#'   `fit` (the [avfit()]/[avrefine()] result or `NULL`), `fit_error` (the
#'   message of a fit or refinement that failed, its condition in
#'   `fit_condition`), `coef` (SI), `readings` (data frame `term`, `value`,
#'   `unit`, `tau`, `method`, `source` (`"fit"`, `"slope"`, `"bound"` or
#'   `"none"`), `is_bound`, `folded` (fitted terms folded into the value),
#'   `role`, `slope`, `adev`) and `guidance`), and `datasheet`
#'   ([datasheet()]). For
#'   several recordings, a list of those, of class `"imu_analysis_list"`.
#' @seealso [plot.imu_analysis()], [datasheet()], [write_kalibr_yaml()],
#'   [kalman_params()], [allanvar_cli()].
#' @export
#' @examples
#' \donttest{
#' set.seed(1)
#' m <- cbind(gyro_x = rnorm(1e4, sd = 0.01), accel_x = rnorm(1e4, sd = 0.002))
#' r <- imu_record(m, freq = 100)
#' a <- analyze_imu(r, refine = FALSE, progress = FALSE)
#' a
#' }
analyze_imu <- function(x, taus = "octave", type = "overlapping",
                        terms = NULL, refine = TRUE,
                        segment = "longest", channels = NULL,
                        progress = interactive() &&
                          isTRUE(getOption("allanvar.progress", TRUE)),
                        read_args = list(), refine_args = list(),
                        remove = character(), workers = NULL, ...) {
  check_present(missing(x), "x", "an imu_record, a list of them or file paths")
  if (!is.null(workers) &&
      !(is.numeric(workers) && !is.object(workers) && length(workers) == 1L &&
        is.finite(workers) && workers >= 1 && workers == round(workers))) {
    abort("`workers` must be NULL or a whole number of at least 1, not ",
          if (length(workers) == 1L && is.atomic(workers)) format_value(workers)
          else describe_type(workers), ".", class = "argument")
  }
  remove <- check_series_kinds(remove, "remove", c(effect_kinds("series"), "all"))
  if (!is.logical(refine) || length(refine) != 1L || is.na(refine)) {
    abort("`refine` must be TRUE or FALSE, not ", format_value(refine), ".",
          class = "argument")
  }
  if (!is.logical(progress) || length(progress) != 1L || is.na(progress)) {
    abort("`progress` must be TRUE or FALSE, not ", format_value(progress), ".",
          class = "argument")
  }
  if (!is.list(refine_args) || (length(refine_args) && is.null(names(refine_args)))) {
    abort("`refine_args` must be a named list of avrefine() arguments, not ",
          describe_type(refine_args), ".", class = "argument")
  }
  if (!(is.character(segment) && length(segment) == 1L &&
        segment %in% c("longest", "each")) &&
      !(is.numeric(segment) && !is.object(segment) && length(segment) == 1L &&
        is.finite(segment) && segment >= 1 && segment == round(segment))) {
    abort("`segment` must be \"longest\", \"each\" or a segment number, not ",
          if (length(segment) == 1L && is.atomic(segment)) format_value(segment)
          else describe_type(segment), ".", class = "argument")
  }
  if (!is.null(channels) && (!is.character(channels) || !length(channels) ||
                             anyNA(channels))) {
    abort("`channels` must be a character vector of channel names, not ",
          describe_type(channels), ".", class = "argument")
  }
  records <- as_record_list(x, read_args)
  records <- split_segments(records, segment)
  single <- length(records) == 1L

  # One job per (record, channel): the unit of parallel work.
  jobs <- list()
  for (i in seq_along(records)) {
    r <- records[[i]]
    ch <- colnames(r$data)
    if (!is.null(channels)) {
      miss <- setdiff(channels, ch)
      if (length(miss)) {
        abort("`channels`: ", paste(miss, collapse = ", "), " not in ",
              r$name, " (", paste(ch, collapse = ", "), ").", class = "argument")
      }
      ch <- channels
    }
    rec_jobs <- lapply(ch, function(chn) list(
      record = i, name = r$name, channel = chn, sensor = r$sensors[[chn]],
      unit = r$si_units[[chn]], x = r$data[, chn], freq = r$freq))
    # Every axis dead: nothing to analyse. One dead axis among live ones is
    # reported by analyze_channel() and the others are analysed.
    # (max == min: one pass over the column, nothing allocated)
    dead <- vapply(rec_jobs, function(j) isTRUE(max(j$x) == min(j$x)), NA)
    if (length(dead) && all(dead)) {
      abort("`x`: every channel of ", r$name, " is constant (dead or ",
            "saturated axes); there is no noise to analyse.", class = "argument")
    }
    jobs <- c(jobs, rec_jobs)
  }
  n_jobs <- length(jobs)
  for (k in seq_along(jobs)) jobs[[k]]$label <- sprintf("[%d/%d] %s: %s", k,
                                                        n_jobs, jobs[[k]]$name,
                                                        jobs[[k]]$channel)
  opts <- list(taus = taus, type = type, terms = terms, refine = refine,
               progress = progress, fit_args = list(...),
               refine_args = refine_args, remove = remove)
  # One future per axis: axes differ in cost (the refinement), so this
  # balances the workers, and progress arrives as each axis finishes.
  # future.seed = TRUE can leave the caller's RNG kind at L'Ecuyer-CMRG
  # (when no seed existed yet): the caller's RNG state is restored.
  restore <- save_rng()
  on.exit(restore(), add = TRUE)
  # Progress goes through progressr: each finished axis signals one step,
  # from whichever future worker ran it. Interactive sessions with
  # `progress = TRUE` get a bar (cli when installed); elsewhere
  # `progress = TRUE` writes one message per axis (for logs), and the
  # signals reach only a handler the caller set up (progressr::handlers(),
  # with_progress()), so that the default stays silent.
  bar <- isTRUE(progress) && interactive()
  if (bar) opts$progress <- FALSE
  w <- axis_workers(workers, n_jobs, sum(vapply(jobs, function(j) length(j$x), 1)))
  if (w > 1L) {
    # Two levels of threads would oversubscribe the cores: the workers
    # run their kernels on one thread each.
    opts$threads <- 1L
    restore_plan <- axis_plan(w)
    on.exit(restore_plan(), add = TRUE)
  }
  run <- function() {
    p <- progressr::progressor(steps = n_jobs)
    # run_axis() lives in the namespace: a closure made here would carry
    # this frame (every axis's data) to each worker that is not a fork
    future.apply::future_lapply(jobs, run_axis, opts = opts, p = p,
                                future.seed = TRUE, future.scheduling = Inf)
  }
  results <- if (bar) {
    progressr::with_progress(run(), handlers = progress_handlers())
  } else {
    run()
  }
  failed <- Filter(function(r) inherits(r, "axis_failure"), results)
  if (length(failed)) stop(failed[[1L]]$condition)

  out <- lapply(seq_along(records), function(i) {
    r <- records[[i]]
    res <- results[vapply(jobs, function(j) j$record == i, logical(1))]
    names(res) <- vapply(res, function(z) z$channel, "")
    a <- list(name = r$name, freq = r$freq, n = nrow(r$data),
              duration = nrow(r$data) / r$freq,
              record = list(file = r$file, problems = r$problems,
                            segments = r$segments, units = r$units,
                            sampling = r$sampling, unit_checks = r$unit_checks),
              channels = res, call = match.call())
    class(a) <- "imu_analysis"
    a$datasheet <- datasheet(a)
    dead <- Filter(function(ch) !is.null(ch$dead), res)
    if (length(dead)) {
      warn(r$name, ": ", paste(names(dead), collapse = ", "),
           if (length(dead) == 1L) " is a dead axis" else " are dead axes",
           " (constant signal): reported, not analysed; the other axes are.",
           class = "dead_axis")
    }
    g <- imu_guidance(a)
    g <- g[!g$channel %in% names(dead), , drop = FALSE]
    if (nrow(g) && isTRUE(progress)) {
      # one line: the notes themselves are printed with the analysis
      message(structure(class = c("allanvar_guidance", "allanvar_message",
                                  "message", "condition"),
                        list(message = sprintf(
                          "%s: %d guidance note(s) on the record and its readings; print the analysis or see imu_guidance().\n",
                          r$name, nrow(g)), call = NULL)))
    }
    a
  })
  if (single) return(out[[1L]])
  names(out) <- vapply(out, function(a) a$name, "")
  class(out) <- "imu_analysis_list"
  out
}

# The user's progressr handlers when set, else cli's bar when installed,
# else a text bar.
progress_handlers <- function() {
  h <- getOption("progressr.handlers")
  if (length(h)) return(h)
  if (requireNamespace("cli", quietly = TRUE)) progressr::handler_cli()
  else progressr::handler_txtprogressbar()
}

# How many processes analyze_imu() starts for `n_jobs` axes of `n`
# samples in all (1: none, the axes run on the plan that is set). By
# default only under the sequential plan, where forking is possible and
# the record large enough to pay for the workers' start.
axis_workers <- function(workers, n_jobs, n) {
  if (!is.null(workers)) return(as.integer(min(workers, n_jobs)))
  if (n_jobs < 2L || n < 2e5 || !inherits(future::plan(), "sequential") ||
      !future::supportsMulticore()) {
    return(1L)
  }
  as.integer(max(1L, min(allanvar_threads(), n_jobs, future::availableCores())))
}

# Sets the plan for `w` axis workers and returns the function that puts
# the caller's plan back. Where the platform can fork, the workers are a
# fork cluster started once: future's multicore forks a fresh process per
# axis, and each fresh fork pays again for copying the parent's memory
# pages as R's collector and allocator first write them (on a 6-axis
# ADIS16405 record, about 1.5 s of CPU per axis: the two workers were no
# faster than one process). Elsewhere (or if the local sockets cannot be
# opened), multicore or multisession.
axis_plan <- function(w) {
  cl <- if (future::supportsMulticore()) {
    tryCatch(parallel::makeForkCluster(w), error = function(e) NULL)
  }
  old <- if (!is.null(cl)) {
    # (no trial future at set-up: 0.3-0.4 s a call; the axes' futures
    # meet any fault of the workers themselves)
    future::plan(future::cluster, workers = cl, .init = FALSE)
  } else if (future::supportsMulticore()) {
    future::plan(future::multicore, workers = w)
  } else {
    future::plan(future::multisession, workers = w)
  }
  function() {
    future::plan(old)
    if (!is.null(cl)) parallel::stopCluster(cl)
  }
}

# One axis on a future worker, with its progress step. An axis's error
# comes back as a value, so that every axis's future is collected (none
# cancelled half-way, no worker left behind) before the first error is
# signalled again, as it was raised.
run_axis <- function(job, opts, p) {
  res <- tryCatch(analyze_channel(job, opts),
                  error = function(e) structure(list(condition = e),
                                                class = "axis_failure"))
  p(job$label)
  res
}

# The work for one axis; runs on a future worker, so it only uses its
# arguments and the package's namespace.
analyze_channel <- function(job, opts) {
  if (!is.null(opts$threads)) {
    old <- options(allanvar.threads = opts$threads)
    on.exit(options(old), add = TRUE)
  }
  if (isTRUE(opts$progress)) message("allanvar: analysing ", job$label)
  # The series pass runs on every axis: its effects mark the readings they
  # change; those the user asked to remove go before the curve (R/series.R).
  # (a record too short for the pass skips it, unless effects are to be
  # removed: then the pass's own error says why it cannot)
  series <- if (length(job$x) >= 256L || length(opts$remove))
    detect_series_effects(job$x, job$freq, remove = opts$remove)
  if (!is.null(series)) job$x <- series$x
  curve <- allan(job$x, job$freq, taus = opts$taus, type = opts$type)
  if (!any(is.finite(curve$adev) & curve$adev > 0)) {
    # A dead (constant) axis has nothing to fit or read: it is reported,
    # and the other axes are analysed.
    reason <- "dead axis: constant signal (Allan variance 0 at every tau), not analysed"
    return(list(channel = job$channel, sensor = job$sensor, unit = job$unit,
                freq = job$freq, n = length(job$x), curve = curve, fit = NULL,
                fit_error = reason, fit_condition = NULL, coef = numeric(),
                readings = dead_readings(job$sensor, reason), dead = reason,
                guidance = paste0(reason, ": check the sensor and the column.")))
  }
  fit <- NULL
  failure <- NULL
  # A fit or refinement that fails is kept in the result (fit_error,
  # fit_condition) and reported by the guidance; the readings then come
  # from the slope lines (or the unrefined fit).
  fit <- tryCatch(
    do.call(avfit, c(list(curve, terms = opts$terms), opts$fit_args)),
    error = function(e) {
      failure <<- list(message = conditionMessage(e), condition = e)
      NULL
    })
  if (!is.null(fit) && opts$refine) {
    # The series pass run above is handed on, not run again on its output.
    refine_args <- opts$refine_args
    if (!is.null(series) && is.null(refine_args$remove) && is.null(refine_args$series)) {
      refine_args$series <- series
    }
    # The raw series lets avrefine() confirm an effect in the data itself.
    fit <- tryCatch(
      do.call(avrefine, c(list(fit, data = job$x), refine_args)),
      error = function(e) {
        failure <<- list(message = paste("avrefine():", conditionMessage(e)),
                         condition = e)
        fit
      })
  }
  coef <- if (is.null(fit)) numeric() else fit$coefficients
  readings <- channel_readings(curve, coef, job$sensor, se = fit_se(fit),
                               fitted = if (!is.null(fit)) fit$data,
                               series = if (!is.null(fit$series)) fit$series else series,
                               unexplained = fit$unexplained,
                               alternatives = model_alternatives(fit))
  res <- list(channel = job$channel, sensor = job$sensor, unit = job$unit,
              freq = job$freq, n = length(job$x), curve = curve, fit = fit,
              fit_error = failure$message, fit_condition = failure$condition,
              coef = coef, readings = readings, series = series_kept(series))
  res$guidance <- imu_guidance(res)
  res
}

as_record_list <- function(x, read_args) {
  if (inherits(x, "imu_record")) return(list(x))
  if (is.character(x)) {
    if (!length(x)) {
      abort("`x` is an empty character vector; give file paths.",
            class = "argument")
    }
    return(lapply(x, function(f) do.call(read_imu, c(list(f), read_args))))
  }
  if (is.list(x) && length(x) && all(vapply(x, inherits, logical(1), "imu_record"))) {
    nm <- names(x)
    if (!is.null(nm)) for (i in seq_along(x)) if (nzchar(nm[i])) x[[i]]$name <- nm[i]
    return(unname(x))
  }
  abort("`x` must be an imu_record (see read_imu() and imu_record()), a list ",
        "of them, or file paths; not ", describe_type(x), ".",
        class = "argument")
}

split_segments <- function(records, segment) {
  out <- list()
  for (r in records) {
    if (identical(segment, "each") && nrow(r$segments) > 1L) {
      for (i in seq_len(nrow(r$segments))) {
        s <- r
        s$data <- record_segment(r, i)
        s$name <- sprintf("%s[segment %d]", r$name, i)
        s$segments <- r$segments[i, , drop = FALSE]
        out[[length(out) + 1L]] <- s
      }
    } else {
      seg <- if (identical(segment, "each")) "longest" else segment
      s <- r
      s$data <- record_segment(r, seg)
      out[[length(out) + 1L]] <- s
    }
  }
  nm <- vapply(out, function(r) r$name, "")
  if (anyDuplicated(nm)) {
    for (i in seq_along(out)) out[[i]]$name <- sprintf("%s#%d", nm[i], i)
  }
  out
}

#' @export
print.imu_analysis <- function(x, ...) {
  cat(sprintf("<imu_analysis> %s: %d channels, %d samples at %.6g Hz (%.3g h)\n",
              x$name, length(x$channels), x$n, x$freq, x$duration / 3600))
  if (nrow(x$record$problems)) {
    cat("record problems: ", paste(x$record$problems$type, collapse = ", "),
        " (see $record$problems)\n", sep = "")
  }
  print(x$datasheet)
  g <- guidance_lines(imu_guidance(x))
  if (length(g)) {
    cat("\nGuidance:\n")
    cat(paste0("  - ", g, "\n"), sep = "")
  }
  invisible(x)
}

#' @export
print.imu_analysis_list <- function(x, ...) {
  cat(sprintf("<imu_analysis_list> %d recordings\n\n", length(x)))
  for (a in x) {
    print(a)
    cat("\n")
  }
  invisible(x)
}

