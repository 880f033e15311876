# Plain-R overlapping Allan variance, an independent reference for the model
# tests (phase theta_0 = 0, theta_k = tau0 * cumsum(y)).
oav_ref <- function(y, m, tau0) {
  th <- c(0, cumsum(as.numeric(y))) * tau0
  k <- seq_len(length(th) - 2 * m)
  d <- th[k + 2 * m] - 2 * th[k + m] + th[k]
  mean(d^2) / (2 * (m * tau0)^2)
}
