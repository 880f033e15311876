# The report: one self-contained HTML page per analysis (record, per axis the
# curve, model, readings with their verdicts, the loop's story step by step,
# what stayed unexplained, series effects, guidance, other tools' parameters).
# Built with htmltools, so every text copied from a record is escaped; the
# figures are inline SVG (R/report-plots.R). The loop's story is read from
# the result object's fields (steps, rejected, unexplained, failures,
# series), never recomputed.

#' Write an HTML report of an analysis
#'
#' One self-contained HTML page (no network, no external files: styles,
#' figures and text inline) that shows a whole analysis and can be sent to a
#' colleague, opened offline and printed:
#' * the record: source file and format, sensors, duration, rate, gaps and
#'   timestamp jitter, the record's problems and the unit checks with their
#'   verdicts;
#' * per axis: the Allan deviation with its confidence intervals, the model
#'   and each of its components (drawn by [plot.avfit()], as `plot()` draws
#'   them), the readings (N, B, K) with their verdict (measured, upper or
#'   lower bound, not determined), why, and the tau range each rests on;
#' * the loop's story ([avrefine()]), one panel per accepted step: the
#'   residual it saw, the effect it added, chi-square per degree of freedom
#'   and RMS error before and after, and, when the raw series is at hand
#'   (`record`), the raw-data evidence drawn: the periodogram with the line
#'   or band marked (effects with a frequency), the autocorrelation of block
#'   means with the exponential of the correlation time (effects with a
#'   time constant), the short-lag autocorrelation of the samples (a
#'   filter's lag-1 excess);
#' * candidates rejected, refits that failed, what stayed unexplained;
#' * series effects (steps, warm-up, spikes, transients) on a time axis
#'   (the rate itself, thinned to its envelope, when `record` is given) and
#'   what each changes in the Allan deviation at the readings' tau;
#' * guidance on the record's length ([imu_guidance()]) and the readings in
#'   other tools' conventions ([tool_params()]).
#'
#' What is drawn is thinned (a trace to its envelope, a periodogram to the
#' largest value per log-spaced bin); what is computed is not.
#'
#' @param x An `imu_analysis` ([analyze_imu()]) or a list of them, an
#'   [avfit()] or [avrefine()] result, or an [allan()] curve.
#' @param file Path of the HTML file to write (its directory must exist).
#' @param record Optional: the [imu_record()] the analysis was made from
#'   ([read_imu()]); adds the unit checks, the raw-data evidence and the
#'   rate on the time axis. For an `avfit`, the raw rate series (numeric).
#' @param title Title of the page; default from the record's name.
#' @return `file`, invisibly.
#' @seealso [analyze_imu()], [allanvar_cli()] (writes `report.html`).
#' @export
#' @examples
#' \donttest{
#' set.seed(1)
#' m <- cbind(gyro_x = rnorm(2e4, sd = 1e-3), accel_x = rnorm(2e4, sd = 1e-2))
#' r <- imu_record(m, freq = 100, units = c(gyro = "rad/s", accel = "m/s^2"))
#' a <- suppressWarnings(analyze_imu(r, progress = FALSE))
#' f <- tempfile(fileext = ".html")
#' write_report(a, f, record = r)
#' file.size(f)
#' unlink(f)
#' }
write_report <- function(x, file, record = NULL, title = NULL) {
  check_present(missing(x), "x", "an imu_analysis, an avfit or an allan() curve")
  check_present(missing(file), "file", "the path of the HTML file to write")
  file <- check_output_path(file)
  if (!is.null(title)) title <- check_string(title, "title")
  raw <- NULL
  if (inherits(x, "avfit")) {
    if (!is.null(record)) {
      raw <- check_values(record, min_n = 256L, arg = "record")
      record <- NULL
    }
    x <- tryCatch(fit_analysis(x), error = function(e) {
      abort("`x`: this fit cannot be reported: ", conditionMessage(e),
            class = "argument")
    })
  }
  if (!is.null(record) && !inherits(record, "imu_record")) {
    abort("`record` must be the imu_record the analysis was made from (see ",
          "read_imu()), not ", describe_type(record), ".", class = "argument")
  }
  body <- if (inherits(x, "imu_analysis")) {
    title <- title %||% paste("Allan variance report:", x$name)
    report_analysis(x, record, raw)
  } else if (inherits(x, "imu_analysis_list")) {
    title <- title %||% paste("Allan variance report:", length(x), "recordings")
    rec_of <- function(a) {
      if (!is.null(record) && identical(record$name, a$name)) record
    }
    htmltools::tagList(lapply(x, function(a) report_analysis(a, rec_of(a), NULL)))
  } else if (inherits(x, "allan")) {
    title <- title %||% "Allan deviation report"
    report_curve(x)
  } else {
    abort("`x` must be an imu_analysis (analyze_imu()), an avfit, an avrefine ",
          "or an allan() curve, not ", describe_type(x), ".", class = "argument")
  }
  page <- report_page(title, body)
  # doRenderTags keeps <head> where it is (renderTags would hoist it away)
  html <- enc2utf8(c("<!DOCTYPE html>", as.character(htmltools::doRenderTags(page, indent = FALSE))))
  write_atomic(file, function(path) writeLines(html, path, useBytes = TRUE))
  invisible(file)
}

# ---- page --------------------------------------------------------------------

# Records load and script errors (and anything blocked by the page's
# content policy) into attributes of <html>, so that a headless browser's
# dumped DOM says whether the page loaded cleanly.
report_probe_js <- paste(
  "(function(){var d=document.documentElement,e=[];",
  "function rec(m){e.push(String(m));d.setAttribute('data-report-errors',e.join(' | '));}",
  "window.addEventListener('error',function(ev){rec(ev.message||('failed to load: '+((ev.target&&(ev.target.src||ev.target.href))||'?')));},true);",
  "document.addEventListener('securitypolicyviolation',function(ev){rec('blocked: '+ev.blockedURI);});",
  "var ce=console.error;console.error=function(){rec(Array.prototype.join.call(arguments,' '));return ce.apply(console,arguments);};",
  "window.addEventListener('load',function(){d.setAttribute('data-report-loaded','1');});})();")

report_page <- function(title, body) {
  css <- paste(readLines(system.file("report", "report.css", package = "allanvar"),
                         warn = FALSE), collapse = "\n")
  htmltools::tags$html(
    lang = "en",
    htmltools::tags$head(
      htmltools::tags$meta(charset = "utf-8"),
      # nothing is fetched: the page holds everything it shows
      htmltools::tags$meta(`http-equiv` = "Content-Security-Policy",
                           content = paste("default-src 'none'; img-src data:;",
                                           "style-src 'unsafe-inline';",
                                           "script-src 'unsafe-inline'")),
      htmltools::tags$meta(name = "viewport",
                           content = "width=device-width, initial-scale=1"),
      htmltools::tags$title(title),
      htmltools::tags$script(htmltools::HTML(report_probe_js)),
      htmltools::tags$style(htmltools::HTML(css))),
    htmltools::tags$body(
      htmltools::tags$header(
        class = "page-head",
        htmltools::tags$h1(title),
        htmltools::tags$p(class = "meta", sprintf(
          "allanvar %s, %s", utils::packageVersion("allanvar"),
          format(Sys.time(), "%Y-%m-%d %H:%M %Z")))),
      htmltools::tags$main(body)))
}

# ---- one analysis ------------------------------------------------------------

report_analysis <- function(a, record, raw) {
  chans <- a$channels
  raws <- report_raw_series(a, record, raw)
  htmltools::tags$article(
    class = "analysis", `data-record` = a$name,
    report_nav(a),
    report_record(a, record),
    report_summary(a),
    lapply(seq_along(chans), function(i) {
      report_axis(chans[[i]], i, raws[[chans[[i]]$channel]], a)
    }),
    report_exports(a))
}

# The raw series of each axis, when it is at hand and is the one analysed.
report_raw_series <- function(a, record, raw) {
  out <- list()
  if (!is.null(raw) && length(a$channels) == 1L) {
    out[[a$channels[[1L]]$channel]] <- raw
    return(out)
  }
  if (is.null(record)) return(out)
  # (the analysed segment: the whole record unless it has gaps)
  d <- if (NROW(record$data) == a$n) record$data
       else tryCatch(record_segment(record, "longest"), error = function(e) NULL)
  if (is.null(d)) return(out)
  for (ch in a$channels) {
    if (ch$channel %in% colnames(d) && nrow(d) == ch$n) {
      out[[ch$channel]] <- d[, ch$channel]
    }
  }
  out
}

report_nav <- function(a) {
  htmltools::tags$nav(
    class = "toc",
    htmltools::tags$a(href = "#record", "Record"), " ",
    htmltools::tags$a(href = "#summary", "Readings"), " ",
    lapply(seq_along(a$channels), function(i) {
      htmltools::tagList(htmltools::tags$a(href = paste0("#axis-", i),
                                           a$channels[[i]]$channel), " ")
    }),
    htmltools::tags$a(href = "#exports", "Other tools"))
}

report_record <- function(a, record) {
  s <- a$record$sampling
  fmt_s <- function(v) if (is.null(v) || !is.finite(v)) "not known" else
    if (v >= 3600) sprintf("%.4g s (%.3g h)", v, v / 3600) else sprintf("%.4g s", v)
  layout <- record$layout %||% a$record$layout
  topic <- record$topic %||% a$record$topic
  chans <- vapply(a$channels, function(ch) sprintf("%s (%s, %s)", ch$channel,
                                                   ch$sensor, ch$unit), "")
  gaps <- s$gaps
  rows <- list(
    c("Source", a$record$file %||% "not known"),
    if (!is.null(layout)) c("Format", layout),
    if (!is.null(topic)) c("Topic", topic),
    c("Channels", paste(chans, collapse = "; ")),
    c("Samples used", format(a$n, big.mark = ",")),
    c("Duration", fmt_s(a$duration)),
    c("Rate", if (is.null(a$freq)) "not known" else sprintf("%.6g Hz", a$freq)),
    if (!is.null(s)) c("Gaps", if (NROW(gaps)) sprintf("%d (longest %s)", nrow(gaps),
                                                       fmt_s(max(gaps$length)))
                       else "none"),
    if (!is.null(s)) c("Timestamp jitter", if (is.finite(s$jitter_rms %||% NA))
      sprintf("%.3g s RMS (%.3g%% of the step)", s$jitter_rms, 100 * s$jitter_rel)
      else "no timestamps (rate given)"),
    if (NROW(a$record$segments) > 1L) c("Segments", sprintf(
      "%d gap-free segments; the longest is analysed", nrow(a$record$segments))))
  rows <- do.call(rbind, rows[!vapply(rows, is.null, FALSE)])
  kv <- htmltools::tags$table(
    class = "kv", htmltools::tags$tbody(lapply(seq_len(nrow(rows)), function(i) {
      htmltools::tags$tr(htmltools::tags$th(rows[i, 1L]), htmltools::tags$td(rows[i, 2L]))
    })))
  probs <- a$record$problems
  uc <- record$unit_checks %||% a$record$unit_checks
  htmltools::tags$section(
    id = "record", class = "card",
    htmltools::tags$h2("Record"),
    kv,
    htmltools::tags$h3("Problems in the record"),
    if (NROW(probs)) report_table(probs[, intersect(c("type", "count", "detail", "action"),
                                                    names(probs)), drop = FALSE])
    else htmltools::tags$p(class = "ok", "None found."),
    htmltools::tags$h3("Unit checks"),
    if (NROW(uc)) {
      uc$verdict <- unit_verdict(uc$source)
      report_table(uc[, c("channel", "sensor", "unit", "verdict", "evidence")],
                   badge = "verdict")
    } else {
      htmltools::tags$p(class = "note", "Not kept in the analysis; pass the record ",
                        "(write_report(x, file, record = )) to show them.")
    })
}

# The unit checks' `source` said as a verdict.
unit_verdict <- function(source) {
  words <- c(given = "as given", gravity = "confirmed by gravity",
             noise = "plausible noise level", assumed = "assumed (not checked)",
             default = "assumed (not checked)")
  out <- unname(words[source])
  out[is.na(out)] <- source[is.na(out)]
  out
}

report_summary <- function(a) {
  rows <- do.call(rbind, lapply(a$channels, function(ch) {
    rd <- report_readings(ch)
    if (!nrow(rd)) return(NULL)
    data.frame(axis = ch$channel, term = rd$term, value = format_sig(rd$value),
               unit = rd$unit, verdict = rd$verdict,
               tau = tau_range_text(rd$tau_lo, rd$tau_hi), stringsAsFactors = FALSE)
  }))
  sensors <- unique(vapply(a$channels, function(ch) ch$sensor, ""))
  fig <- if (all(sensors %in% c("gyro", "accel"))) {
    report_svg(plot(a), width = 5.2 * length(sensors), height = 4.6,
               alt = "Allan deviation of every axis with the readings")
  }
  htmltools::tags$section(
    id = "summary", class = "card",
    htmltools::tags$h2("Readings of every axis"),
    fig,
    if (!is.null(rows)) report_table(rows, badge = "verdict"))
}

# ---- one axis ----------------------------------------------------------------

report_axis <- function(ch, i, x, a) {
  fit <- ch$fit
  htmltools::tags$section(
    id = paste0("axis-", i), class = "card axis", `data-axis` = ch$channel,
    htmltools::tags$h2(ch$channel, htmltools::tags$span(
      class = "sub", sprintf(" %s, %s", ch$sensor, ch$unit))),
    if (!is.null(ch$dead)) htmltools::tags$p(class = "warn", ch$dead),
    if (!is.null(ch$fit_error)) htmltools::tags$p(class = "warn", ch$fit_error),
    htmltools::tags$h3("Allan deviation and model"),
    if (!is.null(fit)) {
      report_svg(plot(fit), width = 7.5, height = 5.6,
                 alt = "Allan deviation, model and components, standardized residuals")
    } else {
      report_svg(plot(ch$curve), alt = "Allan deviation")
    },
    if (!is.null(fit)) report_model(fit),
    htmltools::tags$h3("Readings"),
    report_readings_table(ch),
    report_loop(ch, x),
    report_series(ch, x, a),
    report_guidance(ch))
}

report_model <- function(fit) {
  lay <- fit$layout
  se <- fit$se %||% rep(NA_real_, nrow(lay))
  d <- data.frame(coefficient = lay$name, value = format_sig(lay$value),
                  se = format_sig(se), unit = unit_label(lay$unit, fit),
                  held = ifelse(lay$fixed %in% TRUE, "held", ""),
                  stringsAsFactors = FALSE)
  conv <- fit$convergence
  htmltools::tagList(
    htmltools::tags$p(
      class = "model", "Model: ", htmltools::tags$code(paste(fit$terms, collapse = " + ")),
      sprintf("; chi2/dof %.3g, RMS error %.3g%%", fit$chi2, fit$rms),
      if (!is.null(conv) && !isTRUE(conv$converged)) {
        htmltools::tags$span(class = "warn", " (the fit did not converge)")
      }),
    report_table(d))
}

# Readings with their verdict, why, and the tau range they rest on. The
# columns come from the readings (verdict, why, tau_lo, tau_hi, biased_by,
# bias_change); readings made before those columns existed are given them
# from `source` and `is_bound`.
report_readings <- function(ch) {
  rd <- ch$readings
  if (!NROW(rd)) return(data.frame())
  n <- nrow(rd)
  col <- function(name, default) if (!is.null(rd[[name]])) rd[[name]] else default
  src <- col("source", rep("none", n))
  verdict <- col("verdict", ifelse(src %in% c("fit", "slope"), "measured",
                                   ifelse(src == "bound", "upper_bound",
                                          "not_determined")))
  why <- col("why", ifelse(verdict == "measured", "", rd$method))
  tau_fit <- if (!is.null(ch$fit$data$tau)) range(ch$fit$data$tau) else range(ch$curve$tau)
  if (!is.null(ch$fit$refine$tau_range)) tau_fit <- ch$fit$refine$tau_range
  tau_lo <- col("tau_lo", ifelse(src == "slope", rd$tau, tau_fit[1L]))
  tau_hi <- col("tau_hi", ifelse(src == "slope", rd$tau, tau_fit[2L]))
  data.frame(term = rd$term, value = rd$value, unit = rd$unit, tau = rd$tau,
             verdict = verdict, why = why, tau_lo = tau_lo, tau_hi = tau_hi,
             biased_by = col("biased_by", rep("", n)),
             bias_change = col("bias_change", rep(NA_real_, n)),
             method = rd$method, stringsAsFactors = FALSE)
}

report_readings_table <- function(ch) {
  rd <- report_readings(ch)
  if (!nrow(rd)) return(htmltools::tags$p(class = "note", "No readings."))
  bias <- ifelse(nzchar(rd$biased_by) & !is.na(rd$biased_by),
                 paste0(rd$biased_by, ifelse(is.finite(rd$bias_change),
                                             sprintf(" (%+.1f%%)", 100 * rd$bias_change), "")),
                 "")
  htmltools::tags$table(
    class = "readings",
    htmltools::tags$thead(htmltools::tags$tr(lapply(
      c("reading", "value", "unit", "verdict", "rests on tau", "why / how",
        "changed by"), htmltools::tags$th))),
    htmltools::tags$tbody(lapply(seq_len(nrow(rd)), function(j) {
      htmltools::tags$tr(
        class = "reading", `data-term` = rd$term[j], `data-verdict` = rd$verdict[j],
        htmltools::tags$td(htmltools::tags$b(rd$term[j])),
        htmltools::tags$td(class = "num", format_sig(rd$value[j])),
        htmltools::tags$td(rd$unit[j]),
        htmltools::tags$td(verdict_badge(rd$verdict[j])),
        htmltools::tags$td(tau_range_text(rd$tau_lo[j], rd$tau_hi[j])),
        htmltools::tags$td(if (nzchar(rd$why[j])) rd$why[j] else rd$method[j]),
        htmltools::tags$td(bias[j]))
    })))
}

verdict_badge <- function(v) {
  htmltools::tags$span(class = paste("badge", gsub("[^a-z_]", "", tolower(v))),
                       gsub("_", " ", v))
}

tau_range_text <- function(lo, hi) {
  ifelse(!is.finite(lo) | !is.finite(hi), "",
         ifelse(abs(hi / lo - 1) < 1e-9, sprintf("%s s", format_num(lo)),
                sprintf("%s to %s s", format_num(lo), format_num(hi))))
}

format_sig <- function(v, digits = 4) {
  vapply(v, function(z) if (!is.finite(z)) "" else format(signif(z, digits)), "")
}

# ---- the loop's story --------------------------------------------------------

report_loop <- function(ch, x) {
  fit <- ch$fit
  if (is.null(fit) || is.null(fit$refine)) {
    return(htmltools::tags$p(class = "note", "The loop (avrefine) was not run on this axis."))
  }
  steps <- fit$steps
  r <- fit$refine
  unit <- ch$unit
  # the periodogram is computed once per axis, when a step needs it
  psd_cache <- NULL
  psd <- function() {
    if (is.null(psd_cache) && !is.null(x) && length(x) >= 256L) {
      psd_cache <<- welch_psd(x, ch$freq)
    }
    psd_cache
  }
  panels <- lapply(seq_len(NROW(steps)), function(k) {
    report_step(steps[k, ], k, fit, ch, x, psd, unit)
  })
  rej <- r$rejected
  fails <- r$failures
  un <- fit$unexplained
  htmltools::tagList(
    htmltools::tags$h3("The loop, step by step"),
    htmltools::tags$p(sprintf(
      "Started from %s; %d effect%s added (criterion %s, least gain %g).",
      paste(r$start_terms %||% character(), collapse = " + "), NROW(steps),
      if (NROW(steps) == 1L) "" else "s", r$criterion %||% "?", r$min_gain %||% NA)),
    if (!NROW(steps)) htmltools::tags$p(class = "note", "No effect paid its way: nothing added."),
    panels,
    if (NROW(rej)) htmltools::tagList(
      htmltools::tags$h4("Candidates rejected"),
      report_table(rej[, intersect(c("step", "effect", "params", "reason"), names(rej)),
                       drop = FALSE])),
    if (NROW(fails)) htmltools::tagList(
      htmltools::tags$h4("Refits that failed"),
      report_table(fails[, intersect(c("step", "effect", "stage", "message"), names(fails)),
                         drop = FALSE])),
    htmltools::tags$h3("What stayed unexplained"),
    if (NROW(un)) {
      report_table(data.frame(tau = tau_range_text(un$tau_from, un$tau_to),
                              description = un$description,
                              strength = sprintf("%.1f sigma", un$strength),
                              `ADEV error` = sprintf("up to %.1f%%", un$size),
                              check.names = FALSE, stringsAsFactors = FALSE))
    } else {
      htmltools::tags$p(class = "ok", "Nothing: no residual structure is left.")
    },
    if (!is.null(r$tau_range)) htmltools::tags$p(class = "note", sprintf(
      "The model is fitted from tau = %s s on: no catalogue effect describes the first points.",
      format_num(r$tau_range[1L]))))
}

report_step <- function(s, k, fit, ch, x, psd, unit) {
  ev <- strsplit(s$evidence, "; raw data: ", fixed = TRUE)[[1L]]
  seen <- ev[1L]
  raw_txt <- if (length(ev) > 1L) paste(ev[-1L], collapse = "; ") else NULL
  par <- fit$layout[fit$layout$label == s$label, , drop = FALSE]
  figs <- list(report_svg(
    plot_step(fit, s$label, s$tau_from, s$tau_to, unit,
              main = sprintf("Step %d: + %s", k, s$effect)),
    width = 5.2, height = 3.9, alt = "the step's effect on the curve"))
  if (!is.null(x) && nrow(par)) {
    figs <- c(figs, list(report_evidence(par, x, ch$freq, psd, unit)))
  }
  ratio <- function(b, a) sprintf("%.3g &rarr; %.3g", b, a)
  htmltools::tags$div(
    class = "step", `data-axis` = ch$channel, `data-step` = k, `data-effect` = s$effect,
    htmltools::tags$h4(sprintf("Step %d: added %s", k, s$effect),
                       htmltools::tags$span(class = "sub", paste0(" (", s$params, ")"))),
    htmltools::tags$dl(
      htmltools::tags$dt("Residual seen"), htmltools::tags$dd(seen),
      htmltools::tags$dt("Raw-data evidence"),
      htmltools::tags$dd(raw_txt %||% "not given (no raw series)",
                         if (!is.na(s$confirmed)) {
                           verdict_badge(if (s$confirmed) "confirmed" else "contradicted")
                         }),
      htmltools::tags$dt("chi2/dof"),
      htmltools::tags$dd(htmltools::HTML(ratio(s$chi2_before, s$chi2_after))),
      htmltools::tags$dt("RMS error"),
      htmltools::tags$dd(htmltools::HTML(paste0(ratio(s$rms_before, s$rms_after), " %"))),
      htmltools::tags$dt("Criterion"),
      htmltools::tags$dd(htmltools::HTML(ratio(s$crit_before, s$crit_after)))),
    htmltools::tags$div(class = "figs", figs))
}

# The raw-data evidence of an added effect, chosen by what its parameters
# measure (the catalogue's units): a frequency is looked for in the
# periodogram, a time constant in the ACF of block means, a length in
# samples in the short-lag ACF of the samples.
report_evidence <- function(par, x, freq, psd, unit) {
  v <- stats::setNames(par$value, par$param)
  u <- stats::setNames(par$unit, par$param)
  hz <- v[u == "Hz"]
  secs <- v[u == "s"]
  if (length(hz) && !is.null(psd <- psd())) {
    band <- if (length(hz) >= 2L) range(hz)
            else if (length(secs)) hz[[1L]] + c(-1, 1) / (2 * pi * secs[[1L]])
    mark <- if (length(hz) == 1L) hz[[1L]] else numeric()
    return(report_svg(plot_periodogram(psd, mark = mark, band = band, unit = unit),
                      width = 5.2, height = 3.9, alt = "periodogram of the raw series"))
  }
  if (length(secs)) {
    return(report_svg(plot_block_acf(x, freq, secs[[1L]]), width = 5.2, height = 3.9,
                      alt = "autocorrelation of block means"))
  }
  if (any(u == "samples")) {
    return(report_svg(plot_lag_acf(x), width = 5.2, height = 3.9,
                      alt = "short-lag autocorrelation of the samples"))
  }
  NULL
}

# ---- series effects, guidance, exports ---------------------------------------

report_series <- function(ch, x, a) {
  se <- ch$fit$series %||% ch$series
  if (is.null(se)) return(NULL)
  tab <- se$table
  rd <- report_readings(ch)
  # what the effects found change in the ADEV at each reading's tau
  eff <- if (NROW(tab) && NROW(se$adev) && nrow(rd)) {
    ch_at <- function(t) {
      if (!is.finite(t)) return(NA_real_)
      se$adev$change[which.min(abs(log(se$adev$tau / t)))]
    }
    data.frame(reading = rd$term, tau = sprintf("%s s", format_num(rd$tau)),
               `ADEV change if left in` = sprintf("%+.2f%%", 100 * vapply(rd$tau, ch_at, 0)),
               check.names = FALSE, stringsAsFactors = FALSE)
  }
  duration <- ch$n / ch$freq
  fig <- if (!is.null(x)) {
    report_svg(plot_series_time(x, ch$freq, tab, ch$unit,
                                main = sprintf("%s: rate and series effects", ch$channel)),
               width = 7.5, height = 3.2, alt = "rate on a time axis with the series effects")
  } else if (NROW(tab)) {
    report_svg(plot_series_marks(tab, duration, main = "series effects on the time axis"),
               width = 7.5, height = 2, alt = "series effects on a time axis")
  }
  htmltools::tagList(
    htmltools::tags$h3("Series effects (steps, warm-up, spikes, transients)"),
    fig,
    if (NROW(tab)) {
      report_table(data.frame(kind = tab$kind, `time [s]` = format_sig(tab$time),
                              size = format_sig(tab$size), z = format_sig(tab$z, 3),
                              removed = ifelse(tab$removed, "removed", "left in"),
                              evidence = tab$evidence,
                              check.names = FALSE, stringsAsFactors = FALSE))
    } else {
      htmltools::tags$p(class = "ok", "None found.")
    },
    if (!is.null(eff)) report_table(eff))
}

report_guidance <- function(ch) {
  g <- ch$guidance
  htmltools::tagList(
    htmltools::tags$h3("Guidance on the record"),
    if (length(g)) htmltools::tags$ul(class = "guidance", lapply(g, htmltools::tags$li))
    else htmltools::tags$p(class = "ok", "The record is long enough for every reading."))
}

report_exports <- function(a) {
  tools <- c("kalibr", "openvins", "imu_utils", "vins", "matlab")
  parts <- lapply(tools, function(tl) {
    d <- tryCatch(tool_params(a, tl), error = function(e) e)
    if (inherits(d, "error")) {
      return(htmltools::tagList(htmltools::tags$h3(tl), htmltools::tags$p(
        class = "note", "Not available: ", conditionMessage(d))))
    }
    d$value <- format_sig(d$value, 6)
    d$bound <- ifelse(d$bound, "upper bound", "")
    htmltools::tagList(htmltools::tags$h3(tl),
                       report_table(d[, c("sensor", "axis", "key", "value", "unit",
                                          "formula", "bound")]))
  })
  htmltools::tags$section(
    id = "exports", class = "card",
    htmltools::tags$h2("Parameters in other tools' conventions"),
    htmltools::tags$p(class = "note", "From tool_params(); see ?conventions for each formula."),
    parts)
}

# ---- a curve alone -----------------------------------------------------------

report_curve <- function(cv) {
  d <- as.data.frame(unclass(cv))
  keep <- intersect(c("channel", "tau", "m", "adev", "lower", "upper", "edf"), names(d))
  d <- d[, keep, drop = FALSE]
  for (k in setdiff(keep, c("channel", "m"))) d[[k]] <- format_sig(d[[k]])
  htmltools::tags$section(
    class = "card axis", `data-axis` = "curve",
    htmltools::tags$h2("Allan deviation"),
    htmltools::tags$p(sprintf("%s estimator, %s samples at %s Hz.",
                              attr(cv, "type") %||% "?",
                              format(attr(cv, "N") %||% NA, big.mark = ","),
                              format(attr(cv, "freq") %||% NA))),
    report_svg(plot(cv), alt = "Allan deviation"),
    report_table(d))
}

# ---- tables ------------------------------------------------------------------

# A data frame as an HTML table (every cell escaped by htmltools); the
# column `badge` is shown as verdict badges.
report_table <- function(d, badge = NULL) {
  d <- as.data.frame(d, stringsAsFactors = FALSE)
  htmltools::tags$table(
    htmltools::tags$thead(htmltools::tags$tr(lapply(names(d), htmltools::tags$th))),
    htmltools::tags$tbody(lapply(seq_len(nrow(d)), function(i) {
      htmltools::tags$tr(lapply(names(d), function(k) {
        v <- d[[k]][i]
        if (identical(k, badge)) return(htmltools::tags$td(verdict_badge(as.character(v))))
        txt <- if (is.numeric(v)) format_sig(v) else as.character(v)
        htmltools::tags$td(class = if (is.numeric(v)) "num", if (is.na(txt)) "" else txt)
      }))
    })))
}
