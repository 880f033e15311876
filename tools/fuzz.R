# Fuzz battery: bad and extreme inputs to every exported function,
# the S3 methods, the CLI (in process and through inst/bin/allanvar) and
# malformed files. Each call is classified:
#   OK       a finite, sane result (or a clean return from a plot/print);
#   CLEAN    an error of class allanvar_error whose message names an argument
#            in backticks or a --flag;
#   UNCLEAR  any other error (R's own wording, or ours naming nothing);
#   GARBAGE  a result holding NaN, or Inf / negative values where a variance,
#            deviation or tau is expected;
#   CRASH    the R process running the call died or hung (the battery runs in
#            a callr::r_session child, restarted after a crash).
# Usage:
#   Rscript tools/fuzz.R [--quick] [--load-all] [--verbose] [--only FUN,FUN]
# prints a table of counts per function and exits 1 on any UNCLEAR, GARBAGE
# or CRASH. --load-all runs the working tree (pkgload::load_all) instead of
# the installed package. tests/testthat/test-fuzz.R sources this file and
# runs the quick subset. Nothing is written outside tempdir().

fuzz_bad_values <- function() {
  list(
    "NULL" = NULL, "NA" = NA, "NA_real_" = NA_real_, "\"a\"" = "a",
    "c(\"a\",\"b\")" = c("a", "b"), "numeric(0)" = numeric(0), "-1" = -1,
    "0" = 0, "Inf" = Inf, "NaN" = NaN, "1e300" = 1e300, "1e-300" = 1e-300,
    "list(1)" = list(1), "data.frame" = data.frame(a = 1:3), "sum" = sum,
    "factor" = factor("a"), "TRUE" = TRUE, "c(1,2)" = c(1, 2), "1i" = 1i,
    "Sys.Date()" = as.Date("2024-01-01")
  )
}

# Bad or extreme samples (for `x`, `values`).
fuzz_bad_series <- function() {
  set.seed(7)
  w <- rnorm(512)
  list(
    "huge 1e300" = 1e300 + w * 1e290, "scaled 1e300" = w * 1e300,
    "tiny 1e-300" = w * 1e-300, "constant" = rep(3, 512), "zeros" = rep(0, 512),
    "length 1" = 1, "length 2" = c(1, 2), "length 3" = c(1, 3, 2),
    "with NA" = replace(w, 5, NA), "with Inf" = replace(w, 5, Inf),
    "integer" = sample.int(10L, 512, TRUE), "Date" = as.Date("2024-01-01") + 0:511,
    "3-d array" = array(w, c(8, 8, 8)), "0-col matrix" = matrix(numeric(0), 512, 0),
    "character" = as.character(w), "logical" = w > 0, "complex" = complex(real = w),
    "dup names" = cbind(a = w, a = rev(w)), "list" = as.list(w[1:5]),
    "factor" = factor(round(w)), "NULL" = NULL, "step" = c(rep(0, 256), rep(1e6, 256))
  )
}

# Fixtures, created once in the child (and after a restart). Self-contained:
# callr sends the function without its environment.
fuzz_setup <- function(pkg_path) {
  if (nzchar(pkg_path)) {
    suppressMessages(pkgload::load_all(pkg_path, quiet = TRUE, export_all = FALSE))
  } else {
    suppressPackageStartupMessages(library(allanvar))
  }
  options(allanvar.threads = 1L, allanvar.progress = FALSE, warn = 1)
  grDevices::pdf(NULL)
  e <- new.env(parent = globalenv())
  set.seed(1)
  d <- file.path(tempdir(), "fuzz")
  dir.create(d, showWarnings = FALSE)
  e$dir <- d
  e$x <- rnorm(4096, sd = 0.01)
  e$m3 <- cbind("A-B" = rnorm(2048), "B-C" = rnorm(2048), "C-A" = rnorm(2048))
  e$av <- allan(e$x, 100)
  e$avdf <- avar(e$x, 100)
  e$fit <- suppressWarnings(avfit(e$av, terms = c("N", "K")))
  m <- cbind(gyro_x = rnorm(4000, sd = 0.01), gyro_y = rnorm(4000, sd = 0.01),
             accel_x = rnorm(4000, sd = 0.002))
  e$rec <- imu_record(m, freq = 100)
  e$ana <- suppressWarnings(analyze_imu(e$rec, refine = FALSE, progress = FALSE))
  e$dyn <- dynamic_allan(rnorm(4000), freq = 100, window = 10, step = 5)
  e$hat <- three_cornered_hat(e$m3, freq = 1)
  e$ds <- datasheet(e$ana)
  rec2 <- e$rec
  rec2$name <- "second"
  e$ana2 <- suppressWarnings(analyze_imu(list(e$rec, rec2), refine = FALSE, progress = FALSE))
  e$ref <- suppressWarnings(avrefine(e$fit, candidates = "gm", max_steps = 1))
  # files
  n <- 1000
  ts <- 1.6e18 + round(seq_len(n) * 1e7)
  g <- matrix(rnorm(n * 6, sd = 0.01), n, 6)
  hdr <- "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]"
  body <- apply(cbind(sprintf("%.0f", ts), matrix(sprintf("%.6f", g), n, 6)), 1,
                paste, collapse = ",")
  w <- function(name, lines, useBytes = FALSE) {
    f <- file.path(d, name)
    writeLines(lines, f, useBytes = useBytes)
    f
  }
  e$f_good <- w("good.csv", c(hdr, body))
  e$f_comma <- w("comma.csv", c(hdr, gsub("\\.", ",", body)))
  e$f_extra <- w("extra.csv", c(hdr, replace(body, 10, paste0(body[10], ",1,2"))))
  e$f_short <- w("short.csv", c(hdr, replace(body, 10, sub(",[^,]*$", "", body[10]))))
  e$f_inf <- w("inf.csv", c(hdr, replace(body, 10, sub(",[^,]*$", ",Inf", body[10]))))
  e$f_nan <- w("nan.csv", c(hdr, replace(body, 10, sub(",[^,]*$", ",NaN", body[10]))))
  e$f_abc <- w("abc.csv", c(hdr, replace(body, 10, sub(",[^,]*$", ",abc", body[10]))))
  e$f_empty_cell <- w("emptycell.csv", c(hdr, replace(body, 10, sub(",[^,]*$", ",", body[10]))))
  e$f_latin1 <- w("latin1.csv", c(paste0(hdr, ",temp \xb0C"),
                                  paste0(body, ",20")), useBytes = TRUE)
  e$f_two <- w("two.csv", c(hdr, body[1:2]))
  e$f_hdr <- w("header.csv", hdr)
  e$f_empty <- w("empty.csv", character())
  e$f_secs <- w("secs.csv", c(hdr, apply(cbind(sprintf("%.2f", seq_len(n) / 100),
                                                 matrix(sprintf("%.6f", g), n, 6)), 1,
                                           paste, collapse = ",")))
  e$f_dup_ts <- w("dupts.csv", c(hdr, body[c(1:10, 10, 11:n)]))
  e$f_back_ts <- w("backts.csv", c(hdr, body[c(1:10, 5, 11:n)]))
  e$f_const <- w("const.csv", c(hdr, paste0(sprintf("%.0f", ts), ",0,0,0,0,0,0")))
  e$f_noheader <- w("noheader.csv", body)
  e$f_semicolon <- w("semi.csv", gsub(",", ";", c(hdr, body)))
  # axes under names the reader cannot place (ax1, ...)
  e$f_unplaced <- w("unplaced.csv", c("t,wx,wy,wz,ax1,ay1,az1",
                                      apply(cbind(sprintf("%.2f", seq_len(n) / 100),
                                                  matrix(sprintf("%.6f", g), n, 6)), 1,
                                            paste, collapse = ",")))
  e$f_binary <- file.path(d, "binary.bag")
  writeBin(as.raw(c(0:255, 255:0)), e$f_binary)
  e$f_fakebag <- w("fake.bag", "#ROSBAG V2.0\nnot really")
  e$f_fakemcap <- w("fake.mcap", "not mcap")
  e$f_fakedb3 <- w("fake.db3", "not sqlite")
  e$f_yaml_bad <- w("bad.yaml", c("accelerometer_noise_density: [1, 2", "x: :"))
  e$f_yaml_neg <- w("neg.yaml", c("accelerometer_noise_density: -1",
                                  "accelerometer_random_walk: abc",
                                  "gyroscope_noise_density: .inf",
                                  "gyroscope_random_walk: 1", "update_rate: 0"))
  e$f_curve_bad <- w("curve.txt", c("tau avar", "1 -1", "2 NaN", "x y"))
  tau <- 0.01 * 2^(0:8)
  e$f_avr <- w("avr.csv", apply(cbind(tau, matrix(rep(1e-3 / sqrt(tau), 6), ncol = 6)), 1,
                                paste, collapse = " "))
  e$f_missing <- file.path(d, "does-not-exist.csv")
  e$reported <- function(r, pattern) {
    if (any(grepl(pattern, r$problems$detail))) return(r)
    list(unreported_fault = NaN)
  }
  e$outdir <- file.path(d, "out")
  e$outfile <- file.path(d, "out.txt")
  e$f_dir <- d
  assign(".fz", e, envir = globalenv())
  invisible(TRUE)
}

# Runs one case in the child and returns its classification. Self-contained.
fuzz_one <- function(expr) {
  e <- get(".fz", envir = globalenv())
  setwd(e$dir)
  vnames <- "(^|[._ ])(avar|adev|av|sigma|sd|var|variance|deviation|dev|tau|time|se|q_d|sigma_d|coef|value|estimate|N|B|K|Q|R|tc)($|[._ ])"
  garbage <- function(x, path = "value", depth = 0L) {
    if (depth > 6L || is.null(x) || is.function(x) || is.environment(x) ||
        inherits(x, c("ggplot", "recordedplot"))) return(NULL)
    if (is.list(x)) {
      nm <- names(x)
      for (i in seq_along(x)) {
        p <- paste0(path, "$", if (!is.null(nm) && nzchar(nm[i])) nm[i] else i)
        r <- garbage(x[[i]], p, depth + 1L)
        if (!is.null(r)) return(r)
      }
      return(NULL)
    }
    if (!is.double(x)) return(NULL)
    if (any(is.nan(x))) return(paste("NaN in", path))
    # a named coefficient vector: amplitudes, taus and time constants
    if (!is.null(names(x)) && is.null(dim(x))) {
      pn <- grepl("^(Q|N|B|K|R)$|\\.(sigma|tc|tau|A|f0|N)$|^tau", names(x))
      if (any(pn & (is.infinite(x) | x < 0), na.rm = TRUE)) {
        return(paste0("negative or infinite ", names(x)[which(pn & (is.infinite(x) | x < 0))[1L]],
                      " in ", path))
      }
    }
    if (is.matrix(x) && !is.null(colnames(x))) {
      if (grepl("vcov|cov|cor", path)) return(NULL)  # covariances may be negative
      for (j in seq_len(ncol(x))) {
        r <- garbage(unname(x[, j]), paste0(path, "[, \"", colnames(x)[j], "\"]"), depth + 1L)
        if (!is.null(r)) return(r)
      }
      return(NULL)
    }
    leaf <- sub("^.*\\$", "", path)
    if (grepl(vnames, leaf, ignore.case = FALSE) && !grepl("lower|upper|ci|conf|log", leaf)) {
      if (any(is.infinite(x))) return(paste("Inf in", path))
      if (any(x < 0, na.rm = TRUE) && !grepl("time|coef|value|estimate", leaf))
        return(paste("negative value in", path))
    }
    NULL
  }
  # names an argument (`arg`), a CLI flag (--flag) or, for a file's
  # content, the file ("name.csv")
  named <- function(msg) grepl("`[^`]+`|--[a-z]|\"[^\"]+\"", msg)
  t0 <- Sys.time()
  out <- tryCatch({
    v <- withCallingHandlers(
      utils::capture.output(val <- eval(expr, e), type = "output"),
      warning = function(w) invokeRestart("muffleWarning"),
      message = function(m) invokeRestart("muffleMessage"))
    g <- garbage(val)
    if (is.null(g)) {
      # printing must work too
      utils::capture.output(try(print(val), silent = TRUE))
      list(class = "OK", detail = "")
    } else list(class = "GARBAGE", detail = g)
  }, error = function(err) {
    msg <- conditionMessage(err)
    if (inherits(err, "allanvar_error") && named(msg)) {
      list(class = "CLEAN", detail = msg)
    } else {
      list(class = "UNCLEAR", detail = paste0("[", class(err)[1L], "] ", msg))
    }
  })
  while (grDevices::dev.cur() > 1L) grDevices::dev.off()
  grDevices::pdf(NULL)
  out$secs <- as.numeric(difftime(Sys.time(), t0, units = "secs"))
  out
}

# The cases: list(fun, label, expr). `quick` keeps a subset CI runs.
fuzz_cases <- function(quick = FALSE) {
  cases <- list()
  add <- function(fun, label, expr) {
    cases[[length(cases) + 1L]] <<- list(fun = fun, label = label, expr = expr)
  }
  bad <- fuzz_bad_values()
  if (quick) bad <- bad[c("NULL", "NA", "\"a\"", "numeric(0)", "-1", "Inf",
                          "list(1)", "factor", "c(1,2)", "Sys.Date()")]
  series <- fuzz_bad_series()
  if (quick) series <- series[c("huge 1e300", "tiny 1e-300", "constant",
                                "length 2", "with NA", "Date", "3-d array",
                                "dup names", "character")]
  # Substitute each bad value into one argument of a valid base call.
  sub_arg <- function(fun, base, args, values = bad) {
    for (a in args) for (k in names(values)) {
      cl <- base
      if (is.null(values[[k]])) cl[a] <- list(NULL) else cl[[a]] <- values[[k]]
      add(fun, paste0(a, " = ", k), cl)
    }
  }
  S <- function(...) as.call(c(list(as.name(..1)), list(...)[-1]))
  q <- quote

  # estimators
  sub_arg("allan", q(allan(x = x, freq = 100)), c("x"), series)
  sub_arg("allan", q(allan(x = x, freq = 100)), c("freq", "taus", "type", "input", "conf", "gaps", "debias"))
  add("allan", "integrated input, freq 1e300", q(allan(cumsum(x), 1e300, input = "integrated")))
  add("allan", "taus all, 3 samples", q(allan(c(1, 2, 4), 1, taus = "all")))
  add("allan", "taus beyond length", q(allan(x, 100, taus = c(1e6))))
  for (f in c("avar", "avari", "avarn")) {
    sub_arg(f, S(f, values = q(x), freq = 100), "values", series)
    sub_arg(f, S(f, values = q(x), freq = 100), "freq")
  }
  sub_arg("avarn", q(avarn(values = x, freq = 100)), "exact")
  sub_arg("dynamic_allan", q(dynamic_allan(x = x, freq = 100, window = 1, step = 0.5)), "x", series)
  sub_arg("dynamic_allan", q(dynamic_allan(x = x, freq = 100, window = 10, step = 5)),
          c("freq", "window", "step", "taus", "type", "conf", "alpha"))
  for (f in c("three_cornered_hat", "groslambert")) {
    sub_arg(f, S(f, x = q(m3), freq = 1), "x", series)
    sub_arg(f, S(f, x = q(m3), freq = 1), c("freq", "pairs", "taus", "type", "input", "conf"))
  }
  # models, simulation
  sub_arg("av_model", q(av_model(tau = c(0.1, 1), coef = c(N = 0.01, B = 0.001), freq = 100)),
          c("tau", "coef", "freq", "by_term"))
  add("av_model", "huge coef", q(av_model(1, c(N = 1e300, K = 1e300))))
  add("av_model", "Inf coef", q(av_model(1, c(N = Inf))))
  add("av_model", "tau 1e-300", q(av_model(1e-300, c(N = 0.01, K = 1e-3))))
  add("av_model", "unknown coef", q(av_model(1, c(Z = 1))))
  add("av_model", "negative coef", q(av_model(1, c(N = -1))))
  sub_arg("avsim", q(avsim(n = 100, freq = 100, N = 0.01, seed = 1)), c("n", "freq", "seed"))
  add("avsim", "N = -1", q(avsim(100, 100, N = -1)))
  add("avsim", "N = Inf", q(avsim(100, 100, N = Inf)))
  add("avsim", "unknown term", q(avsim(100, 100, Z = 1)))
  add("avsim", "gm tc = 0", q(avsim(100, 100, gm = list(sigma = 1, tc = 0))))
  add("avsim", "no terms", q(avsim(100, 100)))
  add("av_terms", "no args", q(av_terms()))
  sub_arg("av_units", q(av_units()), c("sensor", "kind"))
  sub_arg("convert_units", q(convert_units(x = 1, from = "deg/s", to = "rad/s")), c("x", "from", "to"))
  add("convert_units", "gyro to accel", q(convert_units(1, "deg/s", "m/s^2")))
  # fitting
  sub_arg("avfit", q(avfit(av = av, terms = c("N", "K"))),
          c("av", "terms", "n", "freq", "type", "channel", "start", "fixed",
            "tau_range", "bias_correct", "correlation", "control"))
  add("avfit", "fixed gm1.tc = -1", q(avfit(av, terms = c("N", "gm"), fixed = c(gm1.tc = -1))))
  add("avfit", "fixed N = -1", q(avfit(av, terms = c("N", "K"), fixed = c(N = -1))))
  add("avfit", "constant series", q(avfit(allan(rep(1, 1000), 100))))
  add("avfit", "dup channel names", q(avfit(allan(cbind(a = x, a = rev(x)), 100))))
  add("avfit", "unknown term", q(avfit(av, terms = "Z")))
  sub_arg("avmle", q(avmle(x = x, freq = 100, terms = c("N", "K"))),
          c("x", "freq", "terms", "start"))
  add("avmle", "term without a state-space form", q(avmle(x, 100, terms = c("N", "B"))))
  add("avmle", "constant series", q(avmle(rep(1, 1000), 100, terms = c("N", "K"))))
  sub_arg("av_information", q(av_information(model = c(N = 0.01, K = 1e-3), n = 1000, freq = 100)),
          c("model", "n", "freq"))
  add("av_information", "zero amplitude", q(av_information(c(N = 0.01, K = 0), 1000, 100)))
  sub_arg("av_plan", q(av_plan(model = c(N = 0.01, K = 1e-3), freq = 100, target = 0.2, n = 1000)),
          c("model", "freq", "target", "n", "max_n"))
  sub_arg("avfit_control", q(avfit_control()), c("tol", "maxit", "cycles"))
  sub_arg("as_av_curve", q(as_av_curve(av = av)), c("av", "n", "freq", "type", "channel"))
  add("as_av_curve", "df negative avar", q(as_av_curve(data.frame(tau = 1:3, avar = c(1, -1, 1)), n = 100, freq = 1)))
  sub_arg("avrefine", q(avrefine(fit = fit, candidates = "gm", max_steps = 1)),
          c("fit", "data", "candidates", "max_steps", "criterion", "min_gain", "level"))
  add("avrefine", "constant data", q(avrefine(fit, data = rep(1, 4096), candidates = "gm", max_steps = 1)))
  add("avrefine", "data near 1e300", q(avrefine(fit, data = x * 1e302, candidates = "gm", max_steps = 1)))
  add("avrefine", "fit without data", q(avrefine({f <- fit; f$data <- NULL; f}, candidates = "gm", max_steps = 1)))
  add("avrefine", "not a fit", q(avrefine(unclass(fit), candidates = "gm", max_steps = 1)))
  sub_arg("avdiagnose", q(avdiagnose(x = x, freq = 100)), "x", series)
  sub_arg("avdiagnose", q(avdiagnose(x = x, freq = 100)), c("freq", "alpha"))
  # fit methods
  sub_arg("predict.avfit", q(predict(fit, newdata = c(0.1, 1))), c("newdata", "type"))
  add("predict.avfit", "tau Inf", q(predict(fit, Inf)))
  add("predict.avfit", "tau 0", q(predict(fit, 0)))
  for (f in c("coef", "confint", "fitted", "residuals", "vcov", "logLik", "nobs",
              "summary", "print", "plot")) {
    add(paste0(f, ".avfit"), "valid", S(f, q(fit)))
  }
  sub_arg("confint.avfit", q(confint(fit)), c("level", "parm"))
  sub_arg("plot.avfit", q(plot(fit)), c("by_term"))
  # allan-family methods
  cls <- c(av = "allan", dyn = "allan_dynamic", hat = "allan_sources")
  for (o in names(cls)) for (f in c("print", "summary", "plot", "as.data.frame")) {
    add(paste0(f, ".", cls[[o]]), "valid", S(f, as.name(o)))
  }
  sub_arg("plot.allan", q(plot(av)), c("conf"))
  sub_arg("plot.allan_dynamic", q(plot(dyn)), c("what", "at"))
  sub_arg("plotav", q(plotav(avdf = avdf)), "avdf")
  add("plotav", "allan result", q(plotav(av)))
  # every registered S3 method, called once on a valid object
  methods <- list(
    "print.av_curve" = q(as_av_curve(av)), "print.avdiagnose" = q(avdiagnose(x, 100)),
    "print.avfit_control" = q(avfit_control()), "print.avrefine" = q(ref),
    "print.av_information" = q(print(av_information(c(N = 0.01, K = 1e-3), 1000, 100))),
    "print.imu_analysis_list" = q(ana2), "plot.imu_analysis_list" = q(plot(ana2)),
    "datasheet.imu_analysis_list" = q(datasheet(ana2)),
    "datasheet.imu_analysis" = q(datasheet(ana)),
    "print.imu_datasheet" = q(print(ds)), "print.imu_record" = q(print(rec)),
    "print.summary.allan" = q(print(summary(av))),
    "print.summary.allan_dynamic" = q(print(summary(dyn))),
    "print.summary.allan_sources" = q(print(summary(hat))),
    "print.summary.avfit" = q(print(summary(fit))),
    "print.tool_curve" = q(print(read_allan_variance_ros_curve(f_avr))),
    "predict.avfit" = q(predict(fit, c(0.1, 1))),
    "[.allan" = q(av[av$tau > 0.05, ]),
    "[.allan_sources" = q(hat[hat$source == hat$source[1], ]),
    "[.tool_curve" = q(read_allan_variance_ros_curve(f_avr)[1:2, ]))
  for (m in names(methods)) add(m, "valid", methods[[m]])
  add("[.allan", "columns", q(print(av[, c("tau", "adev")])))
  add("[.allan", "no rows", q(print(av[av$tau < 0, ])))
  # IMU workflow
  sub_arg("imu_record", q(imu_record(x = rec$data, freq = 100)), "x", series)
  sub_arg("imu_record", q(imu_record(x = cbind(gyro_x = x), freq = 100)),
          c("freq", "units", "sensors", "time", "time_unit", "gap", "name"))
  sub_arg("analyze_imu", q(analyze_imu(x = rec, refine = FALSE, progress = FALSE)),
          c("x", "taus", "type", "terms", "refine", "segment", "channels", "progress",
            "read_args", "refine_args"))
  add("analyze_imu", "one dead axis",
      q(analyze_imu(imu_record(cbind(gyro_x = x, gyro_y = 0), freq = 100), refine = FALSE, progress = FALSE)))
  add("analyze_imu", "constant file", q(analyze_imu(f_const, refine = FALSE, progress = FALSE)))
  sub_arg("datasheet", q(datasheet(x = ana)), c("x", "average"))
  for (f in c("print", "plot", "summary")) add(paste0(f, ".imu_analysis"), "valid", S(f, q(ana)))
  add("as.data.frame.imu_datasheet", "valid", q(as.data.frame(ds)))
  sub_arg("imu_guidance", q(imu_guidance(x = ana)), "x")
  sub_arg("kalman_params", q(kalman_params(x = c(N = 1e-3, K = 1e-5, B = 1e-4), dt = 0.01)),
          c("x", "dt", "bias_instability", "tau_B"))
  add("kalman_params", "tau_B = -1", q(kalman_params(c(N = 1, B = 1), dt = 0.01, tau_B = -1)))
  add("kalman_params", "negative N", q(kalman_params(c(N = -1, K = 1), dt = 0.01)))
  add("kalman_params", "gm tc = 0", q(kalman_params(c(N = 1, gm1.sigma = 1, gm1.tc = 0), dt = 0.01)))
  sub_arg("write_datasheet", q(write_datasheet(x = ana, file = file.path(dir, "ds.csv"))),
          c("x", "file", "format"))
  add("write_datasheet", "file is a directory", q(write_datasheet(ana, dir)))
  # other tools' conventions, curve-only readings, series effects
  sub_arg("tool_params", q(tool_params(x = ana, tool = "imu_utils")),
          c("x", "tool", "axis", "freq", "noise_type"))
  add("tool_params", "an avfit without freq", q(tool_params(fit, "matlab")))
  sub_arg("write_tool_params", q(write_tool_params(x = ana, tool = "openvins",
                                                   file = file.path(dir, "kalibr_imu_chain.yaml"))),
          c("x", "tool", "file", "axis", "noise_type", "rostopic"))
  add("write_tool_params", "file is a directory", q(write_tool_params(ana, "imu_utils", dir)))
  sub_arg("write_report", q(write_report(x = ana, file = file.path(dir, "report.html"))),
          c("x", "file", "record", "title"))
  add("write_report", "file is a directory", q(write_report(ana, dir)))
  sub_arg("datasheet.avfit", q(datasheet(x = fit)), c("average", "unit"))
  add("datasheet.default", "a number", q(datasheet(1)))
  sub_arg("detect_series_effects", q(detect_series_effects(x = x, freq = 100)), c("x"), series)
  sub_arg("detect_series_effects", q(detect_series_effects(x = x, freq = 100)), c("freq", "remove", "kinds"))
  add("series_reading_bias", "valid", q(series_reading_bias(detect_series_effects(x, 100))))
  sub_arg("series_reading_bias",
          q(series_reading_bias(pass = detect_series_effects(x, 100), readings = NULL)),
          c("pass", "readings"))
  # the deprecated names still answer, with their deprecation warning
  add("series_effects", "deprecated alias", q(suppressWarnings(series_effects(x, 100))))
  add("filter_params", "deprecated alias",
      q(suppressWarnings(filter_params(c(N = 1e-3, K = 1e-5), dt = 0.01))))
  add("read_avr_curve", "deprecated alias, missing file",
      q(suppressWarnings(read_avr_curve(file.path(dir, "none.csv")))))
  add("print.series_effects", "valid", q(print(detect_series_effects(x, 100))))
  sub_arg("write_kalibr_yaml", q(write_kalibr_yaml(x = ana, file = file.path(dir, "imu.yaml"))),
          c("x", "file", "axis", "rostopic", "inflate"))
  # what is copied from the user must come back as written
  add("write_kalibr_yaml", "rostopic with newline",
      q({
        f <- write_kalibr_yaml(ana, file.path(dir, "imu2.yaml"), rostopic = "a\nb: evil")
        y <- yaml::read_yaml(f)
        if (!identical(y$rostopic, "a\nb: evil") || "b" %in% names(y))
          list(yaml_injection = NaN) else y
      }))
  add("write_kalibr_yaml", "rostopic with quote and colon",
      q({
        f <- write_kalibr_yaml(ana, file.path(dir, "imu3.yaml"), rostopic = "'x': \"#y")
        y <- yaml::read_yaml(f)
        if (!identical(y$rostopic, "'x': \"#y")) list(yaml_injection = NaN) else y
      }))
  # readers
  files <- c("f_good", "f_comma", "f_extra", "f_short", "f_inf", "f_nan", "f_abc",
             "f_empty_cell", "f_latin1", "f_two", "f_hdr", "f_empty", "f_secs",
             "f_dup_ts", "f_back_ts", "f_const", "f_noheader", "f_semicolon",
             "f_binary", "f_fakebag", "f_fakemcap", "f_fakedb3", "f_missing", "f_dir")
  for (f in files) add("read_imu", paste("file =", f), S("read_imu", as.name(f)))
  # a malformed file that is read must report the fault with its line and
  # column; otherwise the case counts as GARBAGE
  faults <- c(f_extra = "line 11.*column 8", f_short = "line 11.*column 6",
              f_inf = "line 11, column accel_z", f_nan = "line 11, column accel_z",
              f_abc = "line 11, column 7", f_empty_cell = "line 11, column accel_z",
              f_latin1 = "line 1, column 8", f_dup_ts = "line 12", f_back_ts = "line 12")
  for (f in names(faults)) {
    add("read_imu", paste("report of", f),
        bquote(reported(read_imu(.(as.name(f))), .(faults[[f]]))))
  }
  sub_arg("read_imu", q(read_imu(file = f_good)),
          c("file", "time", "time_unit", "columns", "units", "sep", "gap", "freq",
            "sensors", "topic", "dec"))
  for (f in c("f_binary", "f_fakebag", "f_fakemcap", "f_fakedb3", "f_missing", "f_dir", "f_good"))
    add("imu_topics", paste("file =", f), S("imu_topics", as.name(f)))
  sub_arg("imu_topics", q(imu_topics(file = f_good)), "file")
  for (f in c("read_kalibr_yaml", "read_allan_variance_ros_curve")) {
    for (g in c("f_yaml_bad", "f_yaml_neg", "f_curve_bad", "f_binary", "f_missing", "f_dir", "f_empty"))
      add(f, paste("file =", g), S(f, as.name(g)))
    sub_arg(f, S(f, file = q(f_good)), "file")
  }
  for (g in c("f_yaml_bad", "f_yaml_neg", "f_binary", "f_missing", "f_dir", "f_empty"))
    add("read_imu_utils_yaml", paste("file =", g), S("read_imu_utils_yaml", as.name(g)))
  sub_arg("read_imu_utils_yaml", q(read_imu_utils_yaml(file = f_yaml_neg)), c("file", "freq", "curve", "scaled"))
  sub_arg("read_imu_utils_curve", q(read_imu_utils_curve(dir = dir, name = "x")), c("dir", "name", "fitted"))
  # CLI in process
  # inputs that cannot be right: a classed error naming the argument
  add("read_imu", "ns stamps read as s", q(read_imu(f_good, time_unit = "s")))
  add("read_imu", "freq disagrees with stamps", q(read_imu(f_good, freq = 1000)))
  add("read_imu", "unplaced columns", q(read_imu(f_unplaced)))
  add("imu_record", "x = function", q(imu_record(x = function(x) x, freq = 100)))
  add("imu_record", "freq = 0.01", q(imu_record(cbind(gyro_x = rnorm(1000)), freq = 0.01)))
  add("imu_record", "ms stamps read as s",
      q(imu_record(cbind(gyro_x = rnorm(1000)), time = (0:999) * 10, time_unit = "s")))
  add("avfit", "start gm1.tc = -1", q(avfit(av, c("N", "gm"), start = c(gm1.tc = -1))))
  add("avfit", "edf below 1", q(avfit(data.frame(tau = c(1, 2, 4, 8), avar = c(1, 0.5, 0.3, 0.2),
                                                 edf = 0.01), c("N", "K"))))
  add("datasheet", "malformed analysis",
      q(datasheet(structure(list(channels = list(1)), class = "imu_analysis"))))
  add("write_datasheet", "malformed analysis",
      q(write_datasheet(structure(list(channels = list(1)), class = "imu_analysis"),
                        file.path(dir, "ds.csv"))))
  add("avdiagnose", "integers near integer.max",
      q(avdiagnose(as.integer(.Machine$integer.max - rep(0:3, 1250)), 100)))
  cli <- function(label, ...) add("allanvar_cli", label, S("allanvar_cli", c(...)))
  add("allanvar_cli", "ns stamps as --time-unit s",
      q(allanvar_cli(c(f_good, "--time-unit", "s", "--quiet", "--no-refine",
                       "--out", file.path(dir, "cliout")))))
  add("allanvar_cli", "unplaced columns",
      q(allanvar_cli(c(f_unplaced, "--quiet", "--no-refine", "--out", file.path(dir, "cliout")))))
  for (f in files) add("allanvar_cli", paste("file =", f),
                       bquote(allanvar_cli(c(.(as.name(f)), "--out", file.path(dir, .(f)), "--quiet", "--no-refine"))))
  flags <- list(c("--out="), c("--out", ""), c("--out", "/"), c("--out", "OUTFILE"),
                c("--rate", "-1"), c("--rate", "abc"), c("--rate", "Inf"), c("--rate"),
                c("--time-unit", "hours"), c("--gyro-units", "furlongs"), c("--sep", "xx"),
                c("--dec", ";"), c("--gap", "maybe"), c("--terms", "X"), c("--terms", ""),
                c("--axis", "min"), c("--width", "-5"), c("--height", "abc"),
                c("--workers", "0"), c("--workers", "abc"), c("--bogus"),
                c("--time-col", "nope"), c("--gyro-cols", "a,b"), c("--no-time"),
                c("--topic", "/nope"), character())
  for (fl in flags) {
    add("allanvar_cli", paste(c("good", fl), collapse = " "),
        bquote(allanvar_cli(c(f_good, "--quiet", "--no-refine",
                              sub("OUTFILE", outfile, .(fl)),
                              if (!any(grepl("^--out", .(fl)))) c("--out", file.path(dir, "cliout"))))))
  }
  add("allanvar_cli", "no args", q(allanvar_cli(character())))
  add("allanvar_cli", "--help", q(allanvar_cli("--help")))
  sub_arg("allanvar_cli", q(allanvar_cli(args = "--help")), "args",
          bad[intersect(names(bad), c("NULL", "NA", "numeric(0)", "-1", "list(1)", "factor"))])
  # the installed launcher (exit status and stderr only)
  if (!quick) {
    for (fl in list(character(), c("--rate", "-1"), c("--out", ""), c("--terms", "X"))) {
      add("inst/bin/allanvar", paste(fl, collapse = " "),
          bquote({
            args <- shQuote(c(f_good, "--quiet", "--no-refine", "--out",
                              file.path(dir, "binout"), .(fl)))
            bin <- system.file("bin", "allanvar", package = "allanvar")
            if (requireNamespace("pkgload", quietly = TRUE) &&
                pkgload::is_dev_package("allanvar")) {
              # the working tree is not installed: load it, then run the launcher
              path <- getNamespaceInfo("allanvar", "path")
              bin <- file.path(path, "inst", "bin", "allanvar")
              expr <- sprintf("suppressMessages(pkgload::load_all(%s, quiet = TRUE)); source(%s)",
                              deparse(path), deparse(bin))
              out <- suppressWarnings(system2("Rscript", c("-e", shQuote(expr), "--args", args),
                                              stdout = TRUE, stderr = TRUE))
            } else {
              out <- suppressWarnings(system2("Rscript", c(bin, args), stdout = TRUE,
                                              stderr = TRUE))
            }
            st <- attr(out, "status")
            if (!is.null(st) && st != 0L) {
              txt <- paste(out, collapse = "\n")
              if (grepl("--[a-z]", txt)) abort_like(txt) else stop(txt)
            }
            invisible(NULL)
          }))
    }
  }
  if (quick) {
    # a deterministic subset: every function keeps at least its first cases
    # the faults the battery was built for, plus a deterministic subset spread over
    # each function's arguments
    keys <- c("integrated input, freq 1e300", "huge coef", "Inf coef", "tau 1e-300",
              "tau Inf", "fixed gm1.tc = -1", "tau_B = -1", "negative N",
              "dup channel names", "constant series", "fit without data",
              "constant data", "one dead axis", "allan result", "rostopic with newline",
              "file = f_comma", "file = f_two", "file = f_const", "file = f_dir",
              "file = f_secs", "file = f_latin1", "report of f_extra",
              "report of f_inf", "report of f_abc", "good --out=", "good --terms X",
              "x = huge 1e300", "x = constant", "ns stamps read as s",
              "freq disagrees with stamps", "unplaced columns", "x = function",
              "freq = 0.01", "ms stamps read as s", "start gm1.tc = -1", "edf below 1",
              "malformed analysis", "integers near integer.max",
              "ns stamps as --time-unit s")
    funs <- vapply(cases, `[[`, "", "fun")
    labels <- vapply(cases, `[[`, "", "label")
    keep <- unlist(lapply(split(seq_along(cases), factor(funs, unique(funs))), function(i)
      i[unique(round(seq(1, length(i), length.out = min(length(i), 6L))))]))
    cases <- cases[sort(unique(c(keep, which(labels %in% keys))))]
  }
  cases
}

# Runs `cases` in a callr r_session child; restarts it after a crash or hang.
fuzz_run <- function(cases, pkg_path = "", timeout = 120, verbose = FALSE) {
  start <- function() {
    rs <- callr::r_session$new(wait = TRUE)
    rs$run(fuzz_setup, list(pkg_path = pkg_path))
    rs$run(function() {
      # lets the launcher case raise a classed error naming a flag
      assign("abort_like", function(msg) stop(structure(class = c("allanvar_error", "error", "condition"),
                                                           list(message = msg, call = NULL))),
             envir = get(".fz", envir = globalenv()))
    })
    rs
  }
  rs <- start()
  on.exit(try(rs$close(), silent = TRUE), add = TRUE)
  res <- vector("list", length(cases))
  for (i in seq_along(cases)) {
    cs <- cases[[i]]
    rs$call(fuzz_one, list(expr = cs$expr))
    st <- rs$poll_process(timeout * 1000)
    r <- if (st == "ready") rs$read() else NULL
    if (is.null(r) || !is.null(r$error) || is.null(r$result)) {
      why <- if (st != "ready") paste("timeout after", timeout, "s") else
        if (!is.null(r$error)) conditionMessage(r$error) else "R session died"
      res[[i]] <- list(class = "CRASH", detail = why, secs = NA_real_)
      try(rs$kill(), silent = TRUE)
      rs <- start()
    } else {
      res[[i]] <- r$result
    }
    if (verbose) cat(sprintf("%-28s %-40s %-8s %s\n", cs$fun, substr(cs$label, 1, 40),
                             res[[i]]$class, substr(res[[i]]$detail, 1, 120)))
  }
  data.frame(fun = vapply(cases, `[[`, "", "fun"),
             label = vapply(cases, `[[`, "", "label"),
             class = vapply(res, `[[`, "", "class"),
             detail = vapply(res, function(r) as.character(r$detail)[1], ""),
             secs = vapply(res, function(r) as.numeric(r$secs)[1], 0),
             stringsAsFactors = FALSE)
}

fuzz_table <- function(df) {
  lv <- c("OK", "CLEAN", "UNCLEAR", "GARBAGE", "CRASH")
  tab <- table(factor(df$fun), factor(df$class, levels = lv))
  tab <- rbind(tab, TOTAL = colSums(tab))
  tab
}

fuzz_findings <- function(df) df[df$class %in% c("UNCLEAR", "GARBAGE", "CRASH"), ]

fuzz_main <- function(args = commandArgs(trailingOnly = TRUE)) {
  quick <- "--quick" %in% args
  pkg_path <- if ("--load-all" %in% args) normalizePath(".") else ""
  cases <- fuzz_cases(quick = quick)
  only <- which(args == "--only")
  if (length(only)) {
    funs <- strsplit(args[only + 1L], ",")[[1]]
    cases <- Filter(function(c) c$fun %in% funs, cases)
  }
  t0 <- Sys.time()
  df <- fuzz_run(cases, pkg_path = pkg_path, verbose = "--verbose" %in% args)
  print(fuzz_table(df))
  cat(sprintf("\n%d cases in %.0f s (wall, including the child's start).\n", nrow(df),
              as.numeric(difftime(Sys.time(), t0, units = "secs"))))
  bad <- fuzz_findings(df)
  if (nrow(bad)) {
    cat("\nFindings:\n")
    for (i in seq_len(nrow(bad))) {
      cat(sprintf("%-8s %s(%s): %s\n", bad$class[i], bad$fun[i], bad$label[i],
                  gsub("\n", " ", substr(bad$detail[i], 1, 200))))
    }
  }
  invisible(df)
  quit(status = if (nrow(bad)) 1L else 0L, save = "no")
}

if (sys.nframe() == 0L) fuzz_main()
