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

test_that("readings are typed columns; rewording the method text changes no export", {
  a <- suppressWarnings(analyze_imu(two_records()[[1]], refine = FALSE,
                                    progress = FALSE))
  # an axis whose fit has a white-like GM (folded into N), a slow GM and
  # K = 0 (so K is an upper bound)
  cf <- c(N = 1e-3, B = 1e-5, K = 0, gm1.sigma = 5e-3, gm1.tc = 0.005,
          gm2.sigma = 1e-3, gm2.tc = 20)
  ch <- a$channels$gyro_x
  a$channels$gyro_x$coef <- cf
  rd <- allanvar:::channel_readings(ch$curve, cf, "gyro")
  a$channels$gyro_x$readings <- rd
  expect_identical(rd$term, c("N", "B", "K"))
  expect_identical(rd$source, c("fit", "fit", "bound"))
  expect_identical(rd$is_bound, c(FALSE, FALSE, TRUE))
  expect_identical(rd$folded, c("gm1", "", ""))
  expect_equal(rd$adev, rd$value * c(1, sqrt(2 * log(2) / pi), 1))
  # the same analysis with every method string reworded
  b <- a
  for (i in seq_along(b$channels)) {
    b$channels[[i]]$readings$method <- paste("reworded", seq_len(3))
  }
  expect_identical(kalman_params(b), kalman_params(a))
  fp <- kalman_params(a)
  expect_identical(unique(fp$term[fp$channel == "gyro_x"]), c("N", "B", "K", "gm1"))
  expect_equal(fp$continuous[fp$channel == "gyro_x" & fp$term == "gm1"], c(20, 1e-3))
  expect_match(fp$convention[fp$channel == "gyro_x" & fp$term == "K"], "upper bound")
  fa <- tempfile(fileext = ".yaml")
  fb <- tempfile(fileext = ".yaml")
  pa <- tempfile(fileext = ".png")
  pb <- tempfile(fileext = ".png")
  on.exit(unlink(c(fa, fb, pa, pb)))
  write_kalibr_yaml(a, fa)
  write_kalibr_yaml(b, fb)
  expect_identical(readLines(fb), readLines(fa))
  expect_true(any(grepl("gyroscope_random_walk.*UPPER BOUND", readLines(fa))))
  for (ch in names(a$channels)) {
    expect_identical(allanvar:::channel_guidance(b$channels[[ch]]),
                     allanvar:::channel_guidance(a$channels[[ch]]))
  }
  for (p in list(c(pa, "a"), c(pb, "b"))) {
    grDevices::png(p[1], width = 600, height = 400)
    plot(if (p[2] == "a") a else b)
    grDevices::dev.off()
  }
  expect_identical(unname(tools::md5sum(pb)), unname(tools::md5sum(pa)))
  ds_a <- datasheet(a)$long
  ds_b <- datasheet(b)$long
  expect_identical(ds_b[names(ds_b) != "method"], ds_a[names(ds_a) != "method"])
})
