# Files out: validated output paths, all-or-nothing writes (a temporary
# file in the target directory, renamed into place) and the quoting of
# user text copied into YAML, so that no writer leaves a half file or lets a
# name open a new key.

# `file`: a single, non-empty path whose parent directory exists and which
# is not itself a directory. Returns the path.
check_output_path <- function(file, arg = "file") {
  if (!is.character(file) || length(file) != 1L || is.na(file)) {
    abort("`", arg, "` must be a single file path, not ", describe_type(file),
          ".", class = "output_path")
  }
  if (!nzchar(trimws(file))) {
    abort("`", arg, "` must name a file, not an empty string.",
          class = "output_path")
  }
  if (dir.exists(file)) {
    abort("`", arg, "` = \"", file, "\" is a directory; give a file path.",
          class = "output_path")
  }
  parent <- dirname(file)
  if (!dir.exists(parent)) {
    abort("`", arg, "` = \"", file, "\": its directory \"", parent,
          "\" does not exist; create it first.", class = "output_path")
  }
  file
}

# Writes through `writer(path)` into a temporary file beside `file`, then
# renames it over `file`: a failure (in the writer or the rename) leaves
# `file` as it was and no temporary behind.
write_atomic <- function(file, writer, arg = "file") {
  file <- check_output_path(file, arg)
  tmp <- tempfile(paste0(".", basename(file), "-"), tmpdir = dirname(file))
  ok <- FALSE
  on.exit(if (!ok) unlink(tmp), add = TRUE)
  writer(tmp)
  if (!suppressWarnings(file.rename(tmp, file))) {
    abort("cannot write \"", file, "\" (`", arg, "`): the file could not be ",
          "replaced.", class = "output_path")
  }
  ok <- TRUE
  invisible(file)
}

# A YAML double-quoted scalar (YAML 1.2, section 7.3.1): backslash, quote and
# every control character escaped, so that the text stays one value.
yaml_quote <- function(x) {
  x <- enc2utf8(as.character(x))
  x <- gsub("\\", "\\\\", x, fixed = TRUE)
  x <- gsub("\"", "\\\"", x, fixed = TRUE)
  x <- gsub("\n", "\\n", x, fixed = TRUE)
  x <- gsub("\r", "\\r", x, fixed = TRUE)
  x <- gsub("\t", "\\t", x, fixed = TRUE)
  ctl <- gregexpr("[\x01-\x1f\x7f]", x)
  regmatches(x, ctl) <- lapply(regmatches(x, ctl), function(m)
    sprintf("\\x%02x", vapply(m, function(ch) as.integer(charToRaw(ch)), 0L)))
  paste0("\"", x, "\"")
}

# Text for a comment line: line breaks and other control characters would
# end the comment, so they are shown escaped.
comment_text <- function(x) {
  x <- as.character(x)
  x <- gsub("\n", "\\n", x, fixed = TRUE)
  x <- gsub("\r", "\\r", x, fixed = TRUE)
  gsub("[\x01-\x1f\x7f]", "?", enc2utf8(x))
}
