# Other tools' parameter files: each value against the tool's convention
# computed by hand from the readings, then written and read back.

# One analysis shared by the tests: white noise of known sigma per axis at
# 100 Hz (N = sigma / sqrt(100)).
tools_cache <- new.env()
tools_analysis <- function() {
  if (is.null(tools_cache$a)) {
    set.seed(21)
    n <- 2e4
    sig <- c(1e-3, 2e-3, 1e-3, 1e-2, 1e-2, 3e-2)
    m <- sapply(sig, function(s) rnorm(n) * s)
    colnames(m) <- c("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")
    r <- imu_record(m, freq = 100, units = c(rep("rad/s", 3), rep("m/s^2", 3)))
    tools_cache$a <- suppressWarnings(analyze_imu(r, refine = FALSE, progress = FALSE))
  }
  tools_cache$a
}

# The readings by hand: value of term `t` on channel `ch`.
reading <- function(a, ch, t) {
  rd <- a$channels[[ch]]$readings
  rd$value[rd$term == t]
}

test_that("tool_params() applies each tool's convention to the readings", {
  a <- tools_analysis()
  f <- 100
  N <- sapply(c("gyro_x", "gyro_y", "gyro_z"), function(ch) reading(a, ch, "N"))
  B <- sapply(c("gyro_x", "gyro_y", "gyro_z"), function(ch) reading(a, ch, "B"))
  K <- sapply(c("gyro_x", "gyro_y", "gyro_z"), function(ch) reading(a, ch, "K"))
  # the white noise is the one simulated: N = sigma / sqrt(f)
  expect_equal(unname(N), c(1e-3, 2e-3, 1e-3) / 10, tolerance = 0.05)

  k <- tool_params(a, "kalibr")
  g <- k[k$sensor == "gyro", ]
  expect_equal(g$value[g$key == "gyroscope_noise_density"], max(N))
  expect_equal(g$value[g$key == "gyroscope_random_walk"], max(K))
  expect_identical(unique(g$axis), "max")
  km <- tool_params(a, "kalibr", axis = "mean")
  expect_equal(km$value[km$key == "gyroscope_noise_density"], mean(N))

  iu <- tool_params(a, "imu_utils")
  gi <- iu[iu$sensor == "gyro", ]
  expect_equal(gi$value[gi$key == "gyr_n" & gi$axis != "avg"], unname(N) * sqrt(f))
  expect_equal(gi$value[gi$key == "gyr_n" & gi$axis == "avg"], mean(N) * sqrt(f))
  # the floor: B * sqrt(2 ln 2 / pi) = 0.6643 B, the minimum ADEV
  expect_equal(gi$value[gi$key == "gyr_w" & gi$axis != "avg"], unname(B) * 0.66428,
               tolerance = 1e-4)
  expect_identical(unique(gi$unit), "rad/s")

  v <- tool_params(a, "vins")
  expect_equal(v$value[v$key == "gyr_n"], max(N) * 10)
  expect_equal(v$value[v$key == "gyr_w"], max(K) * 10)
  expect_setequal(v$key, c("gyr_n", "gyr_w", "acc_n", "acc_w"))

  ml <- tool_params(a, "matlab")
  gm <- ml[ml$sensor == "gyro", ]
  expect_equal(gm$value[gm$key == "NoiseDensity"], unname(N))
  expect_equal(gm$value[gm$key == "BiasInstability"], unname(B))
  expect_equal(gm$value[gm$key == "RandomWalk"], unname(K))
  expect_identical(gm$unit[gm$key == "RandomWalk"][1], "(rad/s)*sqrt(Hz)")
  ms <- tool_params(a, "matlab", noise_type = "single-sided")
  expect_equal(ms$value[ms$sensor == "gyro" & ms$key == "NoiseDensity"],
               unname(N) * sqrt(2))
  expect_equal(ms$value[ms$sensor == "gyro" & ms$key == "BiasInstability"],
               unname(B))
  # a hand check of one number: N = 1e-4 at 100 Hz is gyr_n = 1e-3
  d1 <- data.frame(sensor = "gyro", axis = "x", N = 1e-4, B = 1e-5, K = 1e-6,
                   N_verdict = "measured", B_verdict = "measured",
                   K_verdict = "upper_bound", N_note = "MEASURED",
                   B_note = "MEASURED", K_note = "UPPER BOUND: why")
  one <- tool_rows("vins", "gyro", d1, 100, "double-sided")
  expect_equal(one$value, c(1e-3, 1e-5))
  # each value carries the verdict of the reading it comes from
  expect_identical(one$verdict, c("measured", "upper_bound"))
  expect_identical(one$bound, c(FALSE, TRUE))
})

test_that("written files read back to the same numbers under each convention", {
  a <- tools_analysis()
  d <- tempfile("tools")
  dir.create(d)
  on.exit(unlink(d, recursive = TRUE))
  # imu_utils: read_imu_utils_yaml() gives back gyr_n, gyr_w and N, B
  f <- file.path(d, "imu_param.yaml")
  tp <- attr(write_tool_params(a, "imu_utils", f), "values")
  y <- read_imu_utils_yaml(f, freq = 100, scaled = TRUE)
  for (s in c("gyro", "accel")) {
    for (ax in c("x", "y", "z", "avg")) {
      row <- y[y$sensor == s & y$axis == ax, ]
      key <- if (s == "gyro") "gyr" else "acc"
      lab <- ifelse(tp$axis == "avg", "avg", axis_letter(tp$axis))
      pick <- function(k) tp$value[tp$sensor == s & tp$key == k & lab == ax]
      expect_equal(row$white, pick(paste0(key, "_n")), tolerance = 1e-9)
      expect_equal(row$floor, pick(paste0(key, "_w")), tolerance = 1e-9)
    }
  }
  gx <- y[y$sensor == "gyro" & y$axis == "x", ]
  expect_equal(gx$N, reading(a, "gyro_x", "N"), tolerance = 1e-9)
  # the reader divides by the rounded 0.664
  expect_equal(gx$B, reading(a, "gyro_x", "B"), tolerance = 1e-3)
  # OpenVINS: read_kalibr_yaml() reads the imu0 block
  f <- file.path(d, "kalibr_imu_chain.yaml")
  write_tool_params(a, "openvins", f, rostopic = "/cam\nimu: 1")
  k <- read_kalibr_yaml(f)
  kv <- tool_params(a, "kalibr")
  expect_equal(k$value[match(kv$key, k$key)], kv$value, tolerance = 1e-9)
  expect_identical(attr(k, "rostopic"), "/cam\nimu: 1")
  expect_identical(attr(k, "update_rate"), 100)
  # VINS: the four keys, per-sample sigmas
  f <- file.path(d, "vins.yaml")
  write_tool_params(a, "vins", f)
  txt <- readLines(f)
  expect_identical(txt[1], "%YAML:1.0")
  v <- yaml::yaml.load(paste(txt[-1], collapse = "\n"))
  vv <- tool_params(a, "vins")
  expect_equal(unlist(v[vv$key]), stats::setNames(vv$value, vv$key), tolerance = 1e-9)
  # MATLAB: the [x y z] vectors of the script
  f <- file.path(d, "params.m")
  write_tool_params(a, "matlab", f)
  txt <- paste(readLines(f), collapse = "\n")
  vec <- function(fun, key) {
    blk <- regmatches(txt, regexpr(paste0(fun, "\\([^;]*\\);"), txt))
    inner <- regmatches(blk, regexpr(paste0("'", key, "', \\[[^]]*\\]"), blk))
    as.numeric(strsplit(sub(".*\\[(.*)\\]", "\\1", inner), " ")[[1]])
  }
  ml <- tool_params(a, "matlab")
  expect_equal(vec("gyroparams", "NoiseDensity"),
               ml$value[ml$sensor == "gyro" & ml$key == "NoiseDensity"], tolerance = 1e-9)
  expect_equal(vec("accelparams", "RandomWalk"),
               ml$value[ml$sensor == "accel" & ml$key == "RandomWalk"], tolerance = 1e-9)
  expect_false(grepl("NoiseType", txt))
  write_tool_params(a, "matlab", f, noise_type = "single-sided")
  expect_match(paste(readLines(f), collapse = "\n"), "'NoiseType', 'single-sided'",
               fixed = TRUE)
})

test_that("a gyro-only analysis and a curve-only fit are written; bad input refused", {
  set.seed(22)
  m <- cbind(gyro_x = rnorm(1e4) * 1e-3, gyro_y = rnorm(1e4) * 1e-3,
             gyro_z = rep(0.5, 1e4))
  a <- suppressWarnings(analyze_imu(imu_record(m, freq = 100, units = rep("rad/s", 3)),
                                    refine = FALSE, progress = FALSE))
  tp <- tool_params(a, "imu_utils")
  # the dead z axis is left out, the mean is of x and y
  expect_setequal(unique(tp$axis), c("gyro_x", "gyro_y", "avg"))
  expect_identical(unique(tp$sensor), "gyro")
  f <- tempfile(fileext = ".m")
  on.exit(unlink(f))
  write_tool_params(a, "matlab", f)
  txt <- readLines(f)
  expect_false(any(grepl("accelparams", txt)))
  # two live axes: gyroparams takes a scalar, the worst
  expect_match(txt, "'NoiseDensity', \\[[0-9.e-]+\\]", all = FALSE)
  # a fit of another tool's curve, in SI
  cv <- data.frame(tau = 10^seq(-1, 2, 0.1), avar = 1e-8 / 10^seq(-1, 2, 0.1),
                   unit = "rad/s")
  fit <- avfit(cv, "N", n = 1e5, freq = 100)
  kf <- tool_params(fit, "kalibr")
  expect_equal(kf$value[kf$key == "gyroscope_noise_density"], 1e-4, tolerance = 1e-3)
  expect_error(tool_params(a, "ros"), class = "allanvar_error_argument")
  expect_error(tool_params(a, "vins", freq = -1), class = "allanvar_error_argument")
  expect_error(tool_params(1, "vins"), class = "allanvar_error_argument")
  expect_error(write_tool_params(a, "vins", tempdir()),
               class = "allanvar_error_output_path")
  expect_error(write_tool_params(a, "kalibr", f), class = "allanvar_error_argument")
  un <- avfit(data.frame(tau = cv$tau, avar = cv$avar), "N", n = 1e5, freq = 100)
  expect_error(tool_params(un, "kalibr"), "unit", class = "allanvar_error_argument")
})
