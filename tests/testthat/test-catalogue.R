# The catalogue is extensible from one place: an effect defined here, in the
# test, runs through avsim(), avfit(), avrefine() and datasheet(). The toy
# is a random telegraph signal (+-amp, flipping at `rate` per second): its
# sampled autocovariance is amp^2 phi^h with phi = exp(-2 rate tau0), so
# its AV is the AR(1) form written out below (Zhang 2008), independent of
# the package's Gauss-Markov entry; its simulator flips a sign.

telegraph_av <- function(tau, tau0, rate) {
  if (is.null(tau0)) {
    tc <- 1 / (2 * rate)
    x <- tau / tc
    return((2 * x - 3 + 4 * exp(-x) - exp(-2 * x)) / x^2)
  }
  phi <- exp(-2 * rate * tau0)
  m <- tau / tau0
  (m - 3 * phi - m * phi^2 + 4 * phi^(m + 1) - phi^(2 * m + 1)) /
    (m^2 * (1 - phi)^2)
}

telegraph_entry <- function() {
  allanvar:::new_effect(
    name = "telegraph", title = "random telegraph noise",
    params = rbind(
      allanvar:::effect_param("amp", "amp", "u", "rate unit (level)"),
      allanvar:::effect_param("rate", "nonlinear", "Hz", "hertz (switching rate)",
                              profile = "smooth", print_unit = TRUE)),
    repeatable = TRUE,
    formula = "AR(1) form with phi = exp(-2 rate tau0)",
    signature = "a bump like a Gauss-Markov process",
    basis = function(tau, tau0, nl) telegraph_av(tau, tau0, nl[["rate"]]),
    sim = function(n, tau0, amp, nl) {
      p <- (1 - exp(-2 * nl[["rate"]] * tau0)) / 2
      s0 <- if (stats::runif(1) < 0.5) -1 else 1
      amp[[1]] * s0 * (-1)^cumsum(stats::runif(n) < p)
    },
    edf_alpha = function(tau, tau0, nl) rep(0, length(tau)),
    nl_range = function(tau, freq) list(rate = c(0.1 / max(tau), 1 / min(tau))),
    trace = function(ctx) {
      if (ctx$sign <= 0 || !is.finite(ctx$emax)) return(NULL)
      list(init = list(rate = 1.893 / (2 * ctx$tau_max)), score = 2)
    },
    describe = function(values) {
      sprintf("telegraph (rate = %s Hz)", paste(signif(values$rate, 3), collapse = ", "))
    })
}

with_effect <- function(entry, code) {
  allanvar:::register_effect(entry)
  on.exit(allanvar:::unregister_effect(entry$name))
  code
}

test_that("a toy effect defined in a test runs through avsim, avfit, avrefine and datasheet", {
  with_effect(telegraph_entry(), {
    expect_true("telegraph" %in% av_terms()$term)
    # the simulator and the expected AV agree (Monte Carlo, 2 records)
    ms <- c(1, 8, 64)
    mc <- rowMeans(vapply(1:2, function(s) {
      x <- avsim(1e5, 100, telegraph = list(amp = 1, rate = 0.5), seed = s)
      vapply(ms, function(m) oav_ref(x, m, 0.01), 0)
    }, numeric(length(ms))))
    th <- av_model(ms / 100, c(telegraph1.amp = 1, telegraph1.rate = 0.5), 100)
    expect_equal(mc, th, tolerance = 0.1)

    x <- avsim(1e5, 100, N = 0.01, telegraph = list(amp = 0.01, rate = 0.25),
               seed = 7)
    expect_named(attr(x, "coef"), c("N", "telegraph1.amp", "telegraph1.rate"))
    curve <- allan(x, 100, taus = 5)
    fit <- avfit(curve, c("N", "telegraph"))
    expect_equal(unname(coef(fit)["telegraph1.rate"]), 0.25, tolerance = 0.2)
    expect_equal(unname(coef(fit)["telegraph1.amp"]), 0.01, tolerance = 0.2)
    expect_true(fit$convergence$converged)

    ref <- avrefine(avfit(curve, "N"), candidates = "telegraph", max_steps = 1)
    expect_identical(ref$steps$effect, "telegraph")
    expect_match(ref$steps$params, "rate=0.2[0-9]* Hz")
    expect_equal(unname(coef(ref)["telegraph1.rate"]), 0.25, tolerance = 0.2)

    a <- suppressWarnings(analyze_imu(
      imu_record(cbind(gyro_x = as.numeric(x)), freq = 100), progress = FALSE,
      terms = c("N", "K"), refine_args = list(candidates = "telegraph",
                                               max_steps = 1)))
    expect_match(datasheet(a)$gyro$effects, "^telegraph \\(rate = 0.2")
  })
  expect_false("telegraph" %in% av_terms()$term)
})

test_that("registration validates entries and protects the built-ins", {
  e <- telegraph_entry()
  e$basis <- NULL
  expect_error(allanvar:::register_effect(e), "`basis`",
               class = "allanvar_error_catalogue")
  e <- telegraph_entry()
  e$name <- "tele2"
  expect_error(allanvar:::register_effect(e), "letters only",
               class = "allanvar_error_catalogue")
  e <- telegraph_entry()
  e$params$profile <- NA
  expect_error(allanvar:::register_effect(e), "profile",
    class = "allanvar_error_catalogue")
  expect_error(allanvar:::register_effect(allanvar:::effect_white()),
               "already has an effect \"N\"",
               class = "allanvar_error_catalogue")
  expect_error(allanvar:::unregister_effect("N"), "built-in",
    class = "allanvar_error_catalogue")
  expect_error(allanvar:::unregister_effect("nothing"), "no effect",
    class = "allanvar_error_catalogue")
})

test_that("a non-stationary effect corrected in the series fits the schema", {
  # a bias step: detected and removed in the series, never added to the AV
  step <- allanvar:::new_effect(
    name = "step", title = "bias step", component = "series",
    params = rbind(allanvar:::effect_param("size", "amp", "u", "rate unit (size)"),
                   allanvar:::effect_param("time", "nonlinear", "s", "second (when)",
                                           profile = "smooth")),
    sim = function(n, tau0, amp, nl) amp[[1]] * (seq_len(n) * tau0 > nl[["time"]]),
    detect = function(x, freq) {
      d <- abs(diff(x))
      k <- which.max(d)
      data.frame(size = x[k + 1] - x[k], time = k / freq)
    },
    remove = function(x, freq, par) {
      x - par$size * (seq_along(x) / freq > par$time)
    })
  with_effect(step, {
    tt <- av_terms()
    expect_identical(tt$component[tt$term == "step"], c("series", "series"))
    expect_false("step" %in% allanvar:::effect_kinds())
    expect_error(avfit(data.frame(tau = 1:3, avar = 1:3), "step", n = 100, freq = 1),
                 "unknown term", class = "allanvar_error_argument")
    y <- avsim(1000, 10, step = list(size = 5, time = 30))
    expect_equal(sum(diff(y) != 0), 1)
    e <- allanvar:::effect_entry("step")
    par <- e$detect(as.numeric(y), 10)
    expect_equal(par$size, 5)
    expect_equal(max(abs(e$remove(as.numeric(y), 10, par))), 0)
  })
})

test_that("families (variants) and harmonic sets with a variable number of components", {
  # One entry, "harm:k", holds the first k harmonics of one periodic source:
  # k amplitudes and one f0; its AV is the sum of the sinusoid AVs at
  # f0, 2 f0, ..., k f0 (the package's sinusoid entry, checked elsewhere).
  harm_variant <- function(v) {
    k <- suppressWarnings(as.integer(v))
    if (is.na(k) || k < 1L) return(NULL)
    list(params = rbind(
      do.call(rbind, lapply(seq_len(k), function(j) allanvar:::effect_param(
        paste0("amp", j), "amp", "u", "rate unit (amplitude)"))),
      allanvar:::effect_param("f0", "nonlinear", "Hz", "hertz", profile = "oscillatory")),
      basis = function(tau, tau0, nl) {
        sin_b <- allanvar:::effect_entry("sinusoid")$basis
        vapply(seq_len(k), function(j) sin_b(tau, tau0, c(f0 = j * nl[["f0"]])),
               numeric(length(tau)))
      })
  }
  harm <- allanvar:::new_effect(
    name = "harm", title = "harmonic set",
    params = rbind(allanvar:::effect_param("amp1", "amp", "u", "rate unit"),
                   allanvar:::effect_param("f0", "nonlinear", "Hz", "hertz",
                                           profile = "oscillatory")),
    repeatable = TRUE, variants = harm_variant,
    basis = function(tau, tau0, nl) {
      allanvar:::effect_entry("sinusoid")$basis(tau, tau0, nl)
    },
    sim = function(n, tau0, amp, nl) numeric(n),
    edf_alpha = function(tau, tau0, nl) rep(NA_real_, length(tau)),
    nl_range = function(tau, freq) list(f0 = c(0.2 / max(tau), 0.2 * freq)))
  with_effect(harm, {
    lay <- allanvar:::coef_layout(c("N", "harm:3"))
    expect_identical(lay$name, c("N", "harm1_3.amp1", "harm1_3.amp2",
                                 "harm1_3.amp3", "harm1_3.f0"))
    cf <- c(N = 0.01, harm1_3.amp1 = 0.02, harm1_3.amp2 = 0.01,
            harm1_3.amp3 = 0.005, harm1_3.f0 = 0.3)
    tau <- unique(round(10^seq(0, 4.5, by = 0.05))) / 100
    ref <- av_model(tau, c(N = 0.01, sinusoid1.amp = 0.02, sinusoid1.f0 = 0.3,
                           sinusoid2.amp = 0.01, sinusoid2.f0 = 0.6,
                           sinusoid3.amp = 0.005, sinusoid3.f0 = 0.9), freq = 100)
    expect_equal(av_model(tau, cf, freq = 100), ref)
    expect_equal(colnames(av_model(tau, cf, 100, by_term = TRUE)), c("N", "harm1_3"))
    fit <- avfit(data.frame(tau = tau, avar = ref), c("N", "harm:3"), n = 1e6,
                 freq = 100, bias_correct = FALSE, start = c(harm1_3.f0 = 0.28))
    expect_equal(coef(fit), cf, tolerance = 1e-4)
    expect_error(allanvar:::coef_layout("harm:x"), "no variant \"x\"",
      class = "allanvar_error_model")
    expect_error(allanvar:::coef_layout("N:2"), "has no variants",
      class = "allanvar_error_model")
  })
})

test_that("coef_layout()'s store of layouts follows the catalogue", {
  expect_error(coef_layout(c("N", "telegraph")), class = "allanvar_error_argument")
  with_effect(telegraph_entry(), {
    lay <- coef_layout(c("N", "telegraph", "telegraph"))
    expect_identical(lay$name, c("N", "telegraph1.amp", "telegraph1.rate",
                                 "telegraph2.amp", "telegraph2.rate"))
    expect_identical(coef_layout(c("N", "telegraph", "telegraph")),
                     build_coef_layout(c("N", "telegraph", "telegraph")))
  })
  # unregistered: the stored layout goes with the entry
  expect_error(coef_layout(c("N", "telegraph", "telegraph")),
               class = "allanvar_error_argument")
  expect_identical(coef_layout(c("N", "K")), build_coef_layout(c("N", "K")))
})

test_that("the coefficient layout is the per-term data frames bound together", {
  # the layout as one data frame per term, bound by rbind()
  by_rows <- function(terms) {
    labs <- term_labels(terms)
    sp <- split_term(terms)
    do.call(rbind, lapply(seq_along(terms), function(i) {
      e <- effect_entry(sp$kind[i], sp$variant[i])
      p <- e$params
      data.frame(name = coef_names(e, labs[i]), label = labs[i], kind = sp$kind[i],
                 variant = sp$variant[i], param = p$name, role = p$role,
                 unit = p$unit, hidden = p$hidden, stringsAsFactors = FALSE)
    }))
  }
  sets <- list(c("N", "B", "K"), c("Q", "N", "gm", "gm", "R"),
               c("filter:lp2", "B", "K", "sinusoid", "sinusoid", "resonance"),
               c("filter", "band", "K"), c("filter:lp1", "gm", "resonance", "resonance"),
               effect_kinds())
  for (t in sets) {
    t <- check_terms(t)
    expect_identical(build_coef_layout(t), by_rows(t))
  }
})
