# Octave (or given) overlapping AV table from a simulated series, computed by
# the independent plain-R reference in helper-oav.R.
oav_table <- function(x, freq, ms = 2^(0:floor(log2(length(x) / 3)))) {
  data.frame(tau = ms / freq,
             avar = vapply(ms, function(m) oav_ref(x, m, 1 / freq), 0))
}

# A stand-in for allan()'s result, built to the interface contract.
fake_allan <- function(tab, n, freq, channel = NULL) {
  out <- data.frame(tau = tab$tau, m = round(tab$tau * freq), n = NA,
                    avar = tab$avar, adev = sqrt(tab$avar), lower = NA,
                    upper = NA,
                    edf = edf_model(round(tab$tau * freq), n, "overlapping",
                                    matrix(1, nrow(tab), 1), 0))
  if (!is.null(channel)) out$channel <- channel
  structure(out, class = c("allan", "data.frame"), freq = freq, N = n,
            type = "overlapping", input = "rate", conf = 0.683)
}

f <- 100
n <- 2^18
m_oct <- 2^(0:16)

test_that("NNLS kernel matches an exhaustive active-set reference", {
  set.seed(1)
  ref <- function(A, b) {
    p <- ncol(A); best <- rep(0, p); bestv <- sum(b^2)
    for (k in 1:(2^p - 1)) {
      S <- which(bitwAnd(k, 2^(0:(p - 1))) > 0)
      x <- qr.coef(qr(A[, S, drop = FALSE]), b)
      if (all(x > 0)) {
        v <- sum((b - A[, S, drop = FALSE] %*% x)^2)
        if (v < bestv) { bestv <- v; best <- rep(0, p); best[S] <- x }
      }
    }
    best
  }
  for (i in 1:20) {
    A <- matrix(rnorm(30 * 4), 30) * rep(10^(0:3), each = 30)
    b <- rnorm(30)
    expect_equal(avfit_nnls(A, b), ref(A, b), tolerance = 1e-8)
  }
})

test_that("an exact theoretical curve gives back its parameters, chi2 ~ 0", {
  cases <- list(
    list(terms = c("N", "B", "K"), coef = c(N = 0.01, B = 0.002, K = 1e-4)),
    list(terms = c("Q", "N", "R"), coef = c(Q = 1e-4, N = 0.01, R = 1e-5)),
    list(terms = c("N", "gm"), coef = c(N = 0.01, gm1.sigma = 0.01, gm1.tc = 20)),
    list(terms = c("N", "gm", "gm"),
         coef = c(N = 0.01, gm1.sigma = 0.02, gm1.tc = 0.5,
                  gm2.sigma = 0.005, gm2.tc = 100)),
    list(terms = c("N", "sinusoid"),
         coef = c(N = 0.01, sinusoid1.amp = 0.01, sinusoid1.f0 = 0.37)))
  m <- unique(round(10^seq(0, log10(n / 4), by = 0.1)))
  for (cs in cases) {
    tab <- data.frame(tau = m / f, avar = av_model(m / f, cs$coef, f))
    fit <- avfit(tab, cs$terms, n = n, freq = f, bias_correct = FALSE)
    expect_equal(coef(fit), cs$coef, tolerance = 1e-5,
                 label = paste(cs$terms, collapse = "+"))
    expect_lt(fit$chi2, 1e-8)
    expect_lt(fit$rms, 1e-3)
  }
})

test_that("parameters are recovered from simulated records", {
  x <- avsim(n, f, N = 0.01, B = 0.002, K = 2e-4, seed = 11)
  fit <- avfit(oav_table(x, f), c("N", "B", "K"), n = n, freq = f)
  cf <- coef(fit)
  expect_equal(unname(cf["N"]), 0.01, tolerance = 0.02)
  expect_equal(unname(cf["B"]), 0.002, tolerance = 0.25)
  expect_equal(unname(cf["K"]), 2e-4, tolerance = 0.5)
  expect_true(all(abs(cf - c(0.01, 0.002, 2e-4)) < 3 * fit$se))
  expect_lt(fit$chi2, 3)

  x <- avsim(n, f, N = 0.01, gm = list(sigma = 0.01, tc = 2), seed = 12)
  fit <- avfit(oav_table(x, f), c("N", "gm"), n = n, freq = f)
  expect_equal(unname(coef(fit)["gm1.tc"]), 2, tolerance = 0.15)
  expect_equal(unname(coef(fit)["gm1.sigma"]), 0.01, tolerance = 0.15)

  ms <- unique(round(10^seq(0, log10(n / 4), by = 0.05)))
  x <- avsim(n, f, N = 0.01, sinusoid = list(amp = 0.01, f0 = 0.5), seed = 13)
  fit <- avfit(oav_table(x, f, ms), c("N", "sinusoid"), n = n, freq = f)
  expect_equal(unname(coef(fit)["sinusoid1.f0"]), 0.5, tolerance = 0.05)
  expect_equal(unname(coef(fit)["sinusoid1.amp"]), 0.01, tolerance = 0.2)
})

test_that("standardized residuals are calibrated (chi2/dof near 1 on average)", {
  chi <- vapply(1:6, function(s) {
    x <- avsim(2^16, f, N = 0.01, B = 0.003, seed = 100 + s)
    avfit(oav_table(x, f), c("N", "B"), n = 2^16, freq = f)$chi2
  }, 0)
  expect_gt(mean(chi), 0.4)
  expect_lt(mean(chi), 2)
})

test_that("model EDF agrees with Monte Carlo (white noise, both estimators)", {
  set.seed(5)
  nn <- 4096; m <- 16
  sims <- replicate(300, {
    y <- rnorm(nn)
    cm <- colMeans(matrix(y[1:(floor(nn / m) * m)], m))
    c(oav_ref(y, m, 1), mean(diff(cm)^2) / 2)
  })
  mc_edf <- 2 * (1 / m)^2 / apply(sims, 1, var)
  th_o <- edf_model(m, nn, "overlapping", matrix(1), 0)
  th_n <- edf_model(m, nn, "non-overlapping", matrix(1), 0)
  # sampling error of a variance from 300 draws is ~ 8%
  expect_equal(mc_edf[1], th_o, tolerance = 0.25)
  expect_equal(mc_edf[2], th_n, tolerance = 0.25)
  expect_equal(th_n, 2 * 255^2 / (3 * 255 - 1))
  # Greenhall's white-FM value approaches the exact one at larger m
  expect_equal(edf_greenhall_noavar(64, nn + 1, 0),
               2 * 63^2 / (3 * 63 - 1), tolerance = 0.1)
  # SP 1065 flicker FM at m = 1 keeps the square (no EDF < 1)
  expect_gt(edf_simple_oavar(1, 1001, -1), 100)
})

test_that("avfit accepts allan(), avar() and plain tables", {
  x <- avsim(n, f, N = 0.01, B = 0.002, seed = 21)
  tab <- oav_table(x, f)
  fit_plain <- avfit(tab, c("N", "B"), n = n, freq = f)
  al <- fake_allan(tab, n, f)
  fit_al <- avfit(al, c("N", "B"))
  expect_equal(coef(fit_al), coef(fit_plain), tolerance = 0.05)
  expect_equal(fit_al$edf_source, "input")
  expect_equal(fit_al$freq, f)
  # multi-channel allan object
  al2 <- rbind(fake_allan(tab, n, f, "x"), fake_allan(tab, n, f, "y"))
  attributes(al2)[c("freq", "N", "type")] <- list(f, n, "overlapping")
  expect_error(avfit(al2, c("N", "B")), "channel")
  expect_equal(coef(avfit(al2, c("N", "B"), channel = "y")), coef(fit_al))
  # avar(): non-overlapping, n recovered from the error column
  av <- avar(x, f)
  fit_av <- avfit(av, c("N", "B"), freq = f)
  expect_equal(fit_av$n, n)
  expect_equal(fit_av$type, "non-overlapping")
  expect_equal(unname(coef(fit_av)["N"]), 0.01, tolerance = 0.03)
  # plain table with edf and no n / freq: continuous forms
  tab$edf <- al$edf
  fit_edf <- avfit(tab, c("N", "B"))
  expect_null(fit_edf$freq)
  expect_equal(unname(coef(fit_edf)["N"]), 0.01, tolerance = 0.05)
  # refit an avfit with more terms; tau_range; fixed
  fit3 <- avfit(fit_plain, c("N", "B", "K"))
  expect_named(coef(fit3), c("N", "B", "K"))
  fit_r <- avfit(tab, "N", tau_range = c(0, 1))
  expect_true(all(fit_r$data$tau <= 1))
  fit_fx <- avfit(tab, c("N", "B"), fixed = c(N = 0.01))
  expect_equal(unname(coef(fit_fx)["N"]), 0.01)
  expect_equal(unname(fit_fx$se["N"]), 0)
})

test_that("methods: coef, vcov, confint, predict, logLik, AIC, BIC, print, plot", {
  x <- avsim(n, f, N = 0.01, gm = list(sigma = 0.01, tc = 2), seed = 31)
  tab <- oav_table(x, f)
  fit <- avfit(tab, c("N", "gm"), n = n, freq = f)
  expect_s3_class(fit, "avfit")
  expect_named(coef(fit), c("N", "gm1.sigma", "gm1.tc"))
  expect_equal(dim(vcov(fit)), c(3, 3))
  expect_equal(sqrt(diag(vcov(fit))), fit$se)
  ci <- confint(fit)
  expect_true(all(ci[, 1] <= coef(fit) & coef(fit) <= ci[, 2]))
  expect_equal(fitted(fit), av_model(tab$tau, coef(fit), f))
  expect_equal(predict(fit, c(0.5, 5)), av_model(c(0.5, 5), coef(fit), f))
  expect_equal(predict(fit, data.frame(tau = 3), type = "adev"),
               sqrt(av_model(3, coef(fit), f)))
  expect_equal(ncol(predict(fit, 1, by_term = TRUE)), 2)
  z <- residuals(fit)
  expect_equal(fit$chi2, sum(z^2) / (nrow(tab) - 3))
  expect_equal(fit$rms, 100 * sqrt(mean((sqrt(fitted(fit) / tab$avar) - 1)^2)))
  s <- sqrt(trigamma(fit$data$edf / 2))
  expect_equal(as.numeric(logLik(fit)),
               sum(-0.5 * log(2 * pi * s^2) - 0.5 * z^2))
  expect_equal(AIC(fit), -2 * as.numeric(logLik(fit)) + 6)
  expect_equal(BIC(fit), -2 * as.numeric(logLik(fit)) + 3 * log(nrow(tab)))
  expect_equal(nrow(fit$steps), 0)
  expect_named(fit$steps, c("effect", "tau_from", "tau_to", "evidence",
                            "chi2_before", "chi2_after", "rms_before",
                            "rms_after"))
  expect_output(print(fit), "chi2/dof")
  expect_output(print(summary(fit)), "correlation time")
  pdf(NULL)
  op <- par("mar")
  expect_invisible(plot(fit))
  expect_equal(par("mar"), op)
  dev.off()
})

test_that("bad input errors name the argument", {
  tab <- data.frame(tau = m_oct / f, avar = av_model(m_oct / f, c(N = 1), f))
  expect_error(avfit(1:3), "`av`")
  expect_error(avfit(tab, "Z", n = n, freq = f), "`terms`")
  expect_error(avfit(tab, c("N", "N"), n = n, freq = f), "`terms`")
  expect_error(avfit(tab, "N"), "`n` and `freq`")
  expect_error(avfit(tab, "N", n = n, freq = -1), "`freq`")
  expect_error(avfit(tab, "N", n = n, freq = f, type = "modified"), "`type`")
  expect_error(avfit(data.frame(time = 1, av = 1, error = 0.1), "N"), "`freq`")
  expect_error(avfit(tab, "N", n = n, freq = f, start = c(X = 1)), "`start`")
  expect_error(avfit(tab, "N", n = n, freq = f, tau_range = 1), "`tau_range`")
  expect_error(avfit(tab[1:2, ], c("N", "B", "K"), n = n, freq = f), "free parameters")
})
