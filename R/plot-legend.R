# Legends beside the plot region, never over it: the right margin is
# widened to the legend's width before the plot is drawn (reserve_legend()),
# and the legend is drawn in that margin (legend_beside()). Every plot
# method with a legend uses this pair.

# Widens the right margin for legend `args` (a list of graphics::legend()
# arguments) at `cex`; returns the old par() values for on.exit().
reserve_legend <- function(args, cex = 0.8) {
  text_in <- max(graphics::strwidth(args$legend, units = "inches", cex = cex))
  # symbol and line sample (about 3 character widths) plus gaps
  char_in <- graphics::par("cin")[1L] * cex
  need_in <- text_in + 4 * char_in + 0.1
  inch_per_line <- graphics::par("csi")
  mar <- graphics::par("mar")
  mar[4L] <- max(mar[4L], need_in / inch_per_line + 0.5)
  graphics::par(mar = mar)
}

# Draws legend `args` in the right margin, top-aligned with the plot region;
# returns graphics::legend()'s value (its rectangle in user coordinates).
legend_beside <- function(args, cex = 0.8) {
  invisible(do.call(graphics::legend, c(list("topleft", inset = c(1.01, 0), xpd = NA,
                                             bty = "n", cex = cex), args)))
}
