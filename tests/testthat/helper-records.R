# Two simulated IMU records (gyro_x, accel_x), for test-analyze.R and
# test-plot-imu.R.
two_records <- function() {
  n <- 2e4
  r1 <- imu_record(cbind(gyro_x = avsim(n, 100, N = 1e-3, K = 1e-3, seed = 1),
                         accel_x = avsim(n, 100, N = 1e-2, K = 1e-2, seed = 2)),
                   freq = 100, name = "rec1")
  r2 <- imu_record(cbind(gyro_x = avsim(n, 100, N = 2e-3, K = 1e-3, seed = 3),
                         accel_x = avsim(n, 100, N = 3e-2, K = 1e-2, seed = 4)),
                   freq = 100, name = "rec2")
  list(r1, r2)
}
