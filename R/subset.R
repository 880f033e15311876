# `[` of the package's data-frame classes (allan(), three_cornered_hat() and
# groslambert(), the curve readers). Their print, plot and summary methods
# read attributes (type, freq, conf, ...) that `[.data.frame` drops when
# columns are selected. A subset that keeps every column (rows, or the
# columns reordered) stays of its class with its attributes; any other is a
# plain data frame, since it no longer holds what the methods read (a
# curve without `channel` would mix channels, one without `lower` has no
# interval to plot).
subset_keeping_class <- function(out, x) {
  if (!is.data.frame(out)) return(out)
  if (!all(names(x) %in% names(out))) {
    class(out) <- setdiff(class(out), class(x)[1L])
    return(out)
  }
  a <- attributes(x)
  for (nm in setdiff(names(a), c("names", "row.names", "class", "dim",
                                 "dimnames"))) {
    attr(out, nm) <- a[[nm]]
  }
  class(out) <- class(x)
  out
}

#' @export
`[.allan` <- function(x, ...) subset_keeping_class(NextMethod(), x)

#' @export
`[.allan_sources` <- function(x, ...) subset_keeping_class(NextMethod(), x)

#' @export
`[.tool_curve` <- function(x, ...) subset_keeping_class(NextMethod(), x)
