# Argument checks shared by the exported functions. Each returns the clean
# value (or stops with a message that names the argument) so that C++ never
# sees unchecked input.

# A short description of what `x` is, for error messages.
describe_type <- function(x) {
  if (is.null(x)) return("NULL")
  if (is.factor(x)) return("a factor")
  if (is_time_like(x)) return(paste("a", class(x)[1L], "object"))
  if (is.data.frame(x)) return("a data frame")
  if (is.matrix(x)) return(paste("a", typeof(x), "matrix"))
  if (is.list(x)) return("a list")
  switch(typeof(x),
    logical = "a logical vector",
    character = "a character vector",
    complex = "a complex vector",
    integer = "an integer vector",
    double = "a double vector",
    paste("an object of type", typeof(x))
  )
}

# `a`, or `b` when `a` is NULL (the package's one definition).
`%||%` <- function(a, b) if (is.null(a)) b else a

format_value <- function(x) {
  if (is.null(x)) return("NULL")
  if (length(x) != 1L) return(paste0("of length ", length(x)))
  if (is.character(x)) return(encodeString(x, quote = '"'))
  format(x)
}

# Conditions. Every error the package raises has class
# c("allanvar_error_<class>", "allanvar_error", "error", "condition") and, as
# its call, the user's call (the outermost call into the package), so that
# callers can catch errors by kind and messages say where they came from.
# The message is the pasted `...`, unchanged.
abort <- function(..., class = NULL, call = user_call(), data = list()) {
  cls <- c(if (length(class)) paste0("allanvar_error_", class), "allanvar_error",
           "error", "condition")
  stop(structure(c(list(message = paste0(...), call = call), data), class = cls))
}

# Warnings likewise: c("allanvar_warning_<class>", "allanvar_warning",
# "warning", "condition").
warn <- function(..., class = NULL, call = user_call(), data = list()) {
  cls <- c(if (length(class)) paste0("allanvar_warning_", class),
           "allanvar_warning", "warning", "condition")
  warning(structure(c(list(message = paste0(...), call = call), data),
                    class = cls))
}

# The user's call: the outermost frame running a function of this package
# (the exported function or S3 method the user called), or NULL.
user_call <- function() {
  ns <- topenv(environment(user_call))
  n <- sys.nframe() - 1L
  for (i in seq_len(max(n, 0L))) {
    e <- environment(sys.function(i))
    if (!is.null(e) && identical(topenv(e), ns)) {
      return(sys.call(i))
    }
  }
  NULL
}

# `values`: a numeric vector (or ts, or a one-column matrix/data frame) of
# finite numbers with at least `min_n` samples; returned as a plain double.
check_values <- function(values, min_n = 2L, arg = "values") {
  if (is.data.frame(values) || is.matrix(values)) {
    if (NCOL(values) != 1L) {
      abort("`", arg, "` must be a single series; got ", describe_type(values),
            " with ", NCOL(values), " columns. Pass one column at a time, ",
            "or use allan() for several channels.",
          class = "argument")
    }
    values <- if (is.data.frame(values)) values[[1L]] else values[, 1L]
  }
  if (is.null(values) || is.factor(values) || is.list(values) || is_time_like(values) ||
      !(is.double(values) || is.integer(values))) {
    abort("`", arg, "` must be a numeric vector, not ", describe_type(values), ".",
          class = "argument")
  }
  n <- length(values)
  if (n < min_n) {
    abort("`", arg, "` must have at least ", min_n, " samples, not ", n, ".",
          class = "argument")
  }
  values <- as.double(values)
  first <- first_nonfinite(values)
  if (first > 0) {
    more <- sum(!is.finite(values)) - 1L
    abort("`", arg, "` must contain only finite numbers; found ",
          format(values[first]), " at position ", first,
          if (more > 0L) paste0(" (and ", more, " more)"), ".",
          class = "argument")
  }
  values
}

# Dates and times are stored as doubles but are not samples or settings.
is_time_like <- function(x) inherits(x, c("Date", "POSIXt", "difftime"))

# `freq`: a single positive finite number (sampling frequency in Hz).
check_freq <- function(freq, arg = "freq") {
  if (is.null(freq) || !(is.double(freq) || is.integer(freq)) ||
      is.factor(freq) || is_time_like(freq) || length(freq) != 1L || is.na(freq) ||
      !is.finite(freq) || freq <= 0) {
    abort("`", arg, "` must be a single positive number (the sampling ",
          "frequency in Hz), not ", describe_freq(freq), ".",
          class = "argument")
  }
  as.double(freq)
}

describe_freq <- function(freq) {
  if (is.null(freq) || is.factor(freq) || !is.atomic(freq) ||
      !(is.numeric(freq))) {
    return(describe_type(freq))
  }
  format_value(freq)
}

# Stop with a clear message when a required argument is missing.
check_present <- function(missing, arg, what) {
  if (missing) {
    abort("`", arg, "` is missing; give ", what, ".", class = "missing_argument")
  }
  invisible(TRUE)
}

# A single number in [lo, hi] (or (lo, hi) when open).
check_number <- function(x, arg, lo = -Inf, hi = Inf, open = FALSE,
                         integer = FALSE) {
  ok <- (is.double(x) || is.integer(x)) && !is_time_like(x) && length(x) == 1L &&
    !is.na(x) && is.finite(x)
  if (ok) ok <- if (open) x > lo && x < hi else x >= lo && x <= hi
  if (ok && integer) ok <- x == round(x)
  if (!ok) {
    range <- if (open) sprintf("in (%s, %s)", lo, hi) else
      sprintf("in [%s, %s]", lo, hi)
    abort("`", arg, "` must be a single ", if (integer) "whole " else "",
          "number ", range, ", not ",
          if (is.numeric(x) && !is.factor(x)) format_value(x) else describe_type(x), ".",
          class = "argument")
  }
  if (integer) as.integer(x) else as.double(x)
}

# One of `choices`, with a message naming the argument.
check_choice <- function(x, choices, arg) {
  if (!is.character(x) || length(x) != 1L || is.na(x) || !x %in% choices) {
    abort("`", arg, "` must be one of ",
          paste0("\"", choices, "\"", collapse = ", "), "; not ",
          if (is.character(x) && length(x) == 1L) format_value(x) else describe_type(x),
          ".",
          class = "argument")
  }
  x
}

# Threads the C++ kernels may use: option `allanvar.threads` (default 2).
allanvar_threads <- function() {
  n <- getOption("allanvar.threads", 2L)
  if (!is.numeric(n) || length(n) != 1L || is.na(n) || n < 1) n <- 1L
  as.integer(min(n, 64L))
}

# A single non-missing string (optionally non-empty).
check_string <- function(x, arg, empty_ok = TRUE) {
  if (!is.character(x) || length(x) != 1L || is.na(x) || (!empty_ok && !nzchar(x))) {
    abort("`", arg, "` must be a single ", if (!empty_ok) "non-empty ", "string, not ",
          if (is.character(x) && length(x) == 1L) format_value(x) else describe_type(x),
          if (!is.null(x) && length(x) != 1L) paste0(" of length ", length(x)), ".",
          class = "argument")
  }
  x
}

# An IMU sampling rate: check_freq() and at most 1 GHz (beyond that the
# per-sample arithmetic of the readers loses its integers).
check_imu_freq <- function(freq, arg = "freq") {
  freq <- check_freq(freq, arg)
  if (freq > 1e9) {
    abort("`", arg, "` = ", format(freq), " Hz is not a plausible IMU sampling ",
          "rate (at most 1e9 Hz); give the rate in Hz.", class = "argument")
  }
  freq
}

# Samples the diagnostics (avdiagnose(), avrefine(data =)) can work on: not
# constant, and of a magnitude whose squares neither overflow nor underflow
# double precision (beyond 1e154 / below 1e-154).
check_diagnosable <- function(x, arg) {
  if (max(x) == min(x)) {
    abort("`", arg, "` is constant (every sample is ", format(x[1L]), "): there ",
          "is no noise to diagnose.", class = "argument")
  }
  big <- max(abs(x))
  if (big > 1e150 || big < 1e-150) {
    abort("`", arg, "` holds values up to ", format(big, digits = 3), "; their ",
          "squares ", if (big > 1) "overflow" else "underflow", " double ",
          "precision: rescale `", arg, "` (and its units) to numbers between ",
          "1e-150 and 1e150.", class = "argument")
  }
  invisible(x)
}
