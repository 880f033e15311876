# The search and its settings: avfit_control(); a fit records whether it
# converged.

f <- 100
nn <- 2^16
ms <- unique(round(10^seq(0, log10(nn / 4), by = 0.1)))
exact <- function(coef) data.frame(tau = ms / f, avar = av_model(ms / f, coef, f))

test_that("avfit_control() holds every knob, with the documented defaults", {
  ctl <- avfit_control()
  expect_s3_class(ctl, "avfit_control")
  expect_identical(unlist(ctl[c("grid_smooth", "grid_oscillatory", "grid_start",
                                "maxit", "inner_maxit", "edf_passes")]),
                   c(grid_smooth = 40L, grid_oscillatory = 120L, grid_start = 13L,
                     maxit = 400L, inner_maxit = 100L, edf_passes = 2L))
  expect_output(print(ctl), "grid_smooth")
  # a list of arguments is accepted in avfit(control =)
  fit <- avfit(exact(c(N = 0.01, gm1.sigma = 0.01, gm1.tc = 3)), c("N", "gm"),
               n = nn, freq = f, bias_correct = FALSE,
               control = list(grid_smooth = 20))
  expect_identical(fit$control$grid_smooth, 20L)
  # a control saved by an earlier version (without the knobs added since)
  # takes their defaults
  old <- structure(unclass(avfit_control())[c("grid_smooth", "maxit", "reltol", "cycles")],
                   class = "avfit_control")
  fit_old <- avfit(exact(c(N = 0.01, gm1.sigma = 0.01, gm1.tc = 3)), c("N", "gm"),
                   n = nn, freq = f, bias_correct = FALSE, control = old)
  expect_identical(fit_old$control$polish, "lm")
  expect_identical(fit_old$control$grid_start, 13L)
  expect_equal(unname(coef(fit)["gm1.tc"]), 3, tolerance = 1e-4)
  expect_snapshot(error = TRUE, {
    avfit_control(grid_smooth = 2)
    avfit_control(maxit = 0)
    avfit_control(start_span = 1)
    avfit_control(polish = "bfgs")
    avfit(exact(c(N = 0.01)), "N", n = nn, freq = f, control = "fast")
  })
})

test_that("a fit that did not converge says so (maxit = 1)", {
  tab <- exact(c(N = 0.01, gm1.sigma = 0.02, gm1.tc = 0.5, gm2.sigma = 0.005,
                 gm2.tc = 100))
  ok <- avfit(tab, c("N", "gm", "gm"), n = nn, freq = f)
  expect_true(ok$convergence$converged)
  expect_identical(ok$convergence$message, "converged")
  expect_gt(ok$convergence$evaluations, 40)  # (a grid of grid_smooth points at least)
  expect_false(any(grepl("NOT converge", capture.output(print(ok)))))
  # Nelder-Mead stopped after one iteration
  bad <- avfit(tab, c("N", "gm", "gm"), n = nn, freq = f,
               control = avfit_control(maxit = 1, polish = "nelder-mead"))
  expect_false(bad$convergence$converged)
  expect_match(bad$convergence$message, "^Nelder-Mead stopped .* \\(maxit = 1\\)")
  expect_output(print(bad), "The fit did NOT converge: Nelder-Mead")
  # Levenberg-Marquardt stopped after one step, then Nelder-Mead after one
  bad_lm <- avfit(tab, c("N", "gm", "gm"), n = nn, freq = f,
                  control = avfit_control(maxit = 1, polish_maxit = 1))
  expect_false(bad_lm$convergence$converged)
  expect_match(bad_lm$convergence$message,
               "Levenberg-Marquardt did not converge in 1 steps .* Nelder-Mead stopped")
  # one step short of converging, Nelder-Mead takes over and converges
  late <- avfit(tab, c("N", "gm", "gm"), n = nn, freq = f,
                control = avfit_control(polish_maxit = 1))
  expect_true(late$convergence$converged)
  expect_equal(coef(late), coef(ok), tolerance = 1e-4)
  expect_output(print(summary(bad)), "did NOT converge")
  # the amplitude solve stopped after one Gauss-Newton step
  x <- avsim(nn, f, N = 0.01, B = 0.002, K = 1e-4, seed = 8)
  bad2 <- avfit(allan(x, f), control = avfit_control(inner_maxit = 1))
  expect_false(bad2$convergence$converged)
  expect_match(bad2$convergence$message, "amplitude solve stopped after 1 ")
  expect_output(print(bad2), "did NOT converge")
  expect_true(avfit(allan(x, f))$convergence$converged)
})

test_that("no nonlinear parameter leaves what the curve and record can see", {
  # white noise from our own generator; starts far outside every bound (an
  # unbounded search took the moving average to L = 2.5e9 samples and a
  # GM to Tc = 4e8 s from these starts)
  set.seed(11)
  fw <- 100
  av <- allan(rnorm(2^16, sd = 0.1 * sqrt(fw)), fw)
  tmax <- max(av$tau)
  ma <- avfit(av, "filter", start = c(filter.L = 7e8))
  expect_gte(coef(ma)[["filter.L"]], 1)
  expect_lte(coef(ma)[["filter.L"]], tmax * fw)
  gm <- avfit(av, c("N", "gm"), start = c(gm1.tc = 1e9))
  expect_lte(coef(gm)[["gm1.tc"]], 4 * tmax)
  expect_gte(coef(gm)[["gm1.tc"]], min(av$tau) / 4)
  # a band centre never above Nyquist, nor below what the curve sees
  rs <- avfit(av, c("N", "resonance"), start = c(resonance1.fr = 80))
  expect_lte(coef(rs)[["resonance1.fr"]], 0.499 * fw)
  expect_gte(coef(rs)[["resonance1.fr"]], 1 / tmax * (1 - 1e-9))
  sn <- avfit(av, c("N", "sinusoid"), start = c(sinusoid1.f0 = 400))
  expect_lte(coef(sn)[grep("f0$", names(coef(sn)))][[1]], fw / 2)
  # the bounds are the entries' own
  b <- effect_nl_bounds(effect_entry("filter", "lp1"), "fc", av$tau, fw)
  expect_equal(b[2], fw / 2)
  expect_equal(b[1], 1 / (2 * pi * tmax))
  expect_equal(effect_nl_bounds(effect_entry("filter"), "L", av$tau, fw),
               c(1, tmax * fw))
})

test_that("Levenberg-Marquardt reaches Nelder-Mead's optimum with a fraction of the solves", {
  # exact curves (the model's own formulas) with 2 and 3 nonlinear parameters
  cases <- list(
    list(coef = c(N = 0.01, gm1.sigma = 0.02, gm1.tc = 0.5, gm2.sigma = 0.005, gm2.tc = 100),
         terms = c("N", "gm", "gm")),
    list(coef = c(N = 0.01, gm1.sigma = 0.03, gm1.tc = 0.3, gm2.sigma = 0.01, gm2.tc = 5,
                  gm3.sigma = 0.005, gm3.tc = 60),
         terms = c("N", "gm", "gm", "gm")))
  for (cs in cases) {
    tab <- exact(cs$coef)
    lm <- avfit(tab, cs$terms, n = nn, freq = f, bias_correct = FALSE)
    nm <- avfit(tab, cs$terms, n = nn, freq = f, bias_correct = FALSE,
                control = avfit_control(polish = "nelder-mead", cycles = 2))
    expect_true(lm$convergence$converged)
    expect_lte(lm$objective, nm$objective + 1e-8)
    # (the labels may come in another order)
    tcs <- function(ft) sort(coef(ft)[grep("tc$", names(coef(ft)))])
    expect_equal(unname(tcs(lm)), unname(sort(cs$coef[grep("tc$", names(cs$coef))])),
                 tolerance = 1e-4)
    expect_lt(lm$convergence$evaluations, 0.6 * nm$convergence$evaluations)
  }
  # a line fitted as a resonance: its width sits at its bound (the step
  # keeps it there and moves the centre); white noise and a sinusoid of
  # our own
  set.seed(5)
  tt <- seq_len(2^16) / f
  x <- rnorm(2^16, sd = 0.02 * sqrt(f)) + 0.05 * sin(2 * pi * 1.3 * tt + 0.4)
  av <- allan(x, f)
  lm <- avfit(av, c("N", "resonance"), start = c(resonance1.fr = 1.2))
  nm <- avfit(av, c("N", "resonance"), start = c(resonance1.fr = 1.2),
              control = avfit_control(polish = "nelder-mead", cycles = 2))
  expect_true(lm$convergence$converged)
  expect_lte(lm$objective, nm$objective + 1e-6)
  expect_equal(coef(lm)[["resonance1.fr"]], coef(nm)[["resonance1.fr"]], tolerance = 1e-3)
})
