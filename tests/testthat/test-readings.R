# Typed readings of an axis (readings.R).

test_that("white-like Gauss-Markov terms are folded into N, once", {
  curve <- data.frame(tau = 2^(0:8) / 100, adev = 1e-3 / sqrt(2^(0:8) / 100),
                      upper = 1.1e-3 / sqrt(2^(0:8) / 100))
  cf <- c(N = 3e-4, B = 0, K = 0, gm1.sigma = 5e-3, gm1.tc = 0.005,
          gm2.sigma = 1e-3, gm2.tc = 20)
  rd <- allanvar:::channel_readings(curve, cf, "gyro")
  # N^2 + 2 sigma^2 Tc (gm1 only; gm2 has Tc = 20 s)
  expect_equal(rd$value[rd$term == "N"], sqrt(3e-4^2 + 2 * 5e-3^2 * 0.005))
  expect_match(rd$method[rd$term == "N"], "white-like GM")
  # B = 0 in the fit: min ADEV / 0.664 at the minimum's tau
  expect_equal(rd$value[rd$term == "B"], min(curve$adev) / sqrt(2 * log(2) / pi))
  expect_equal(rd$tau[rd$term == "B"], 2.56)
  # with a fitted curve, B is read at its minimum; without, only reliable
  # taus (edf >= 10) count
  rd2 <- allanvar:::channel_readings(curve, cf, "gyro",
                                     fitted = data.frame(tau = curve$tau,
                                                         fitted = (curve$tau - 0.3)^2 + 1))
  expect_equal(rd2$tau[rd2$term == "B"], 0.32)
  curve$edf <- c(rep(50, 6), 5, 2, 1)
  rd3 <- allanvar:::channel_readings(curve, c(N = 1e-3), "gyro")
  expect_equal(rd3$tau[rd3$term == "B"], 0.32)
  expect_equal(rd3$value[rd3$term == "B"], curve$adev[6] / sqrt(2 * log(2) / pi))
  expect_match(rd$method[rd$term == "K"], "upper bound")
  g <- allanvar:::unfolded_coef(cf, kinds = "gm")
  expect_identical(names(g), c("gm1.sigma", "gm1.tc"))
  expect_equal(unname(g), c(1e-3, 20))
})
