# allanvar demo: the workflow of allanvar 1.1 on its example gyro series.
# The green lines have slopes -1/2 (angle random walk) and +1/2 (rate random
# walk) on the log-log Allan deviation plot.
data(gyroz)
rate <- as.numeric(gyroz[1:1000])
freq <- frequency(gyroz)

guide_lines <- function(av) {
  abline(1.0 + log(av$time[1]), -1/2, col = "green", lwd = 4, lty = 10)
  abline(1.0 + log(av$time[1]), 1/2, col = "green", lwd = 4, lty = 10)
  # plotav() keeps the original's axis title; the unit goes beneath it
  mtext("(rad/s)", side = 2, line = 4)
  # the legend in the right margin, clear of the data (the original placed
  # its labels at fixed coordinates, past the right edge of short records)
  legend("topleft", inset = c(1.02, 0), xpd = NA, bty = "n", cex = 0.85,
         legend = c("slope -1/2:", "angle random walk", "slope +1/2:",
                    "rate random walk"),
         col = "green", lwd = c(4, NA, 4, NA), lty = c(10, NA, 10, NA))
}

# Room for the unit of the y axis and the legend beside the plot.
op <- par(mar = c(5, 5.5, 4, 9))

# Non-overlapping Allan variance at octave cluster sizes.
av_octave <- avar(rate, freq)
plotav(av_octave)
guide_lines(av_octave)

# The same estimator at every cluster size.
av_all <- avarn(rate, freq)
plotav(av_all)
guide_lines(av_all)

# Overlapping Allan variance from the integrated rate (the angle).
angle <- cumsum(rate * (1 / freq))
av_angle <- avari(angle, freq)
plotav(av_angle)
guide_lines(av_angle)

# All three on one plot.
par(op)
plot(av_octave$time, sqrt(av_octave$av), log = "xy", xaxt = "n", yaxt = "n",
     type = "l", col = "blue", xlab = "", ylab = "")
lines(av_all$time, sqrt(av_all$av), col = "green", lwd = 1)
lines(av_angle$time, sqrt(av_angle$av), col = "red")
axis(1, c(0.001, 0.01, 0.1, 0, 1, 10, 100, 1000, 10000, 100000))
axis(2, c(0.00001, 0.0001, 0.001, 0.01, 0.1, 0, 1, 10, 100, 1000, 10000))
grid(equilogs = TRUE, lwd = 1, col = "orange")
title(main = "Allan variance Analysis Comparison", xlab = "Cluster Times (Sec)",
      ylab = "Allan Standard Deviation (rad/s)")
legend("topright", c("GyroZ (avar)", "GyroZ (avarn)", "GyroZ (avari)"),
       fill = c("blue", "green", "red"), inset = 0.02, cex = 0.9)
