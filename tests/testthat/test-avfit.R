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

test_that("the log-domain solve ends at its optimum whatever its start (KKT)", {
  # Each Gauss-Newton step's NNLS starts from the previous step's passive
  # set; a term that enters or leaves between steps must not stop it short.
  # The optimum of sum(w^2 (y - log(B c))^2), c >= 0: the gradient vanishes
  # for c_k > 0 and is >= 0 for c_k = 0.
  set.seed(3)
  tau <- 10^seq(-2, 3, length.out = 40)
  B <- cbind(Q = 3 / tau^2, N = 1 / tau, B = rep(1, 40), K = tau / 3, Rr = tau^2 / 2)
  for (i in 1:20) {
    ctrue <- c(rexp(1) * 1e-6 * (i %% 3 == 0), rexp(1) * 1e-4, rexp(1) * 1e-6,
               rexp(1) * 1e-8, rexp(1) * 1e-12 * (i %% 2 == 0))
    s <- runif(40, 0.02, 0.3)
    y <- log(drop(B %*% ctrue)) + rnorm(40, sd = s)
    w <- 1 / s
    for (start in list(numeric(5), ctrue, rev(ctrue) + 1e-9)) {
      r <- avfit_log_nnls(B, numeric(40), y, matrix(w, ncol = 1), start, 200L, 1e-14)
      av <- drop(B %*% r$c)
      grad <- -2 * colSums(w^2 * (y - log(av)) * B / av)
      scale <- sqrt(colSums((w * B / av)^2)) * sqrt(r$objective)
      on <- r$c > 0
      expect_true(all(abs(grad[on] * r$c[on]) <= 1e-5 * scale[on] * r$c[on]))
      expect_true(all(grad[!on] >= -1e-5 * scale[!on]))
    }
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
  skip_on_cran()
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
  expect_equal(allan_edf_cpp(allan_type_code("standard"), 64, 63, nn + 1, 0L, FALSE),
               2 * 63^2 / (3 * 63 - 1), tolerance = 0.1)
  # SP 1065 flicker FM at m = 1 keeps the square (no EDF < 1)
  expect_gt(edf_power_law(1, 1000, "overlapping", -1), 100)
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
  # the real allan(): single and multi-channel, standard (non-overlapping)
  a <- allan(x, f)
  fit_a <- avfit(a, c("N", "B"))
  expect_equal(fit_a$n, n)
  expect_equal(unname(coef(fit_a)["N"]), 0.01, tolerance = 0.02)
  expect_equal(unname(coef(fit_a)["B"]), 0.002, tolerance = 0.3)
  a2 <- allan(cbind(u = x, v = 2 * x), f, type = "standard")
  expect_error(avfit(a2, c("N", "B")), "channel",
    class = "allanvar_error_argument")
  fit_v <- avfit(a2, c("N", "B"), channel = "v")
  expect_equal(fit_v$type, "non-overlapping")
  expect_equal(unname(coef(fit_v)["N"]), 0.02, tolerance = 0.03)
  expect_error(avfit(allan(x, f, type = "modified"), "N"), "`type`",
    class = "allanvar_error_argument")
  # multi-channel allan-like object built to the contract
  al2 <- rbind(fake_allan(tab, n, f, "x"), fake_allan(tab, n, f, "y"))
  attributes(al2)[c("freq", "N", "type")] <- list(f, n, "overlapping")
  expect_error(avfit(al2, c("N", "B")), "channel",
    class = "allanvar_error_argument")
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
  expect_equal(fit$rms, 100 * sqrt(mean((sqrt(tab$avar / fitted(fit)) - 1)^2)))
  expect_equal(residuals(fit, "relative"), sqrt(tab$avar / fitted(fit)) - 1)
  s <- sqrt(trigamma(fit$data$edf / 2))
  expect_equal(as.numeric(logLik(fit)),
               sum(-0.5 * log(2 * pi * s^2) - 0.5 * z^2))
  expect_equal(AIC(fit), -2 * as.numeric(logLik(fit)) + 6)
  expect_equal(BIC(fit), -2 * as.numeric(logLik(fit)) + 3 * log(nrow(tab)))
  expect_equal(nrow(fit$steps), 0)
  expect_named(fit$steps, c("effect", "label", "tau_from", "tau_to", "params",
                            "evidence", "confirmed", "chi2_before",
                            "chi2_after", "rms_before", "rms_after",
                            "crit_before", "crit_after"))
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
  expect_error(avfit(1:3), "`av`", class = "allanvar_error_curve")
  expect_error(avfit(tab, "Z", n = n, freq = f), "`terms`",
    class = "allanvar_error_argument")
  expect_error(avfit(tab, c("N", "N"), n = n, freq = f), "`terms`",
    class = "allanvar_error_argument")
  expect_error(avfit(tab, "N"), "`n` and `freq`",
    class = "allanvar_error_argument")
  expect_error(avfit(tab, "N", n = n, freq = -1), "`freq`",
    class = "allanvar_error_argument")
  expect_error(avfit(tab, "N", n = n, freq = f, type = "modified"), "`type`",
    class = "allanvar_error_argument")
  expect_error(avfit(data.frame(time = 1, av = 1, error = 0.1), "N"), "`freq`",
    class = "allanvar_error_argument")
  expect_error(avfit(tab, "N", n = n, freq = f, start = c(X = 1)), "`start`",
    class = "allanvar_error_argument")
  expect_error(avfit(tab, "N", n = n, freq = f, tau_range = 1), "`tau_range`",
    class = "allanvar_error_argument")
  expect_error(avfit(tab[1:2, ], c("N", "B", "K"), n = n, freq = f), "free parameters",
    class = "allanvar_error_curve")
})

test_that("white-noise covariance kernel: exact values, strided sums, Monte Carlo", {
  skip_on_cran()
  nn <- 4096
  m <- c(1, 2, 4, 16, 64, 256, 1000)
  C <- avar_white_cov(m, nn, FALSE, 2L)
  M <- floor(nn / m) - 1
  expect_equal(2 / m^2 / diag(C), 2 * M^2 / (3 * M - 1))
  Co <- avar_white_cov(m, nn, TRUE, 2L)
  expect_equal(2 / m^2 / diag(Co), edf_power_law(m, nn, "overlapping", 0), tolerance = 0.02)
  # brute-force R sum for a long pair (the C++ sum is strided there)
  brute <- function(mi, mj, n) {
    w <- function(t, mm) ifelse(t >= 0 & t < mm, -1 / mm,
                                ifelse(t >= mm & t < 2 * mm, 1 / mm, 0))
    Mi <- n - 2 * mi + 1; Mj <- n - 2 * mj + 1
    t <- 0:(2 * mi - 1)
    tot <- 0
    for (h in (-2 * mj + 1):(2 * mi - 1)) {
      cnt <- min(Mi, Mj - h) - max(0, -h)
      if (cnt > 0) tot <- tot + cnt * sum(w(t, mi) * w(t - h, mj))^2
    }
    tot / (2 * Mi * Mj)
  }
  expect_equal(avar_white_cov(c(1500, 1100), 12000, TRUE, 1L)[1, 2],
               brute(1500, 1100, 12000), tolerance = 2e-3)
  expect_equal(avar_white_cov(c(3, 5), 500, TRUE, 1L)[1, 2], brute(3, 5, 500),
               tolerance = 1e-12)
  # explicit weight matrices, both estimators, pairs that take every branch
  wmat <- function(m, n, stride) {
    M <- if (stride == 1) n - 2 * m + 1 else floor(n / m) - 1
    t <- 0:(n - 1)
    vapply(0:(M - 1), function(a) {
      k <- a * stride
      ifelse(t >= k & t < k + m, -1 / m, ifelse(t >= k + m & t < k + 2 * m, 1 / m, 0))
    }, numeric(n))
  }
  ref <- function(mi, mj, n, ov) {
    Wi <- wmat(mi, n, if (ov) 1 else mi)
    Wj <- wmat(mj, n, if (ov) 1 else mj)
    sum(crossprod(Wi, Wj)^2) / (2 * ncol(Wi) * ncol(Wj))
  }
  for (p in list(c(1, 1, 300), c(2, 3, 400), c(1, 40, 700), c(6, 10, 900),
                 c(2, 300, 1200))) {
    for (ov in c(TRUE, FALSE)) {
      expect_equal(avar_white_cov(p[1:2], p[3], ov, 1L)[1, 2],
                   ref(p[1], p[2], p[3], ov), tolerance = 1e-12)
    }
  }
  # correlation between neighbouring octaves matches Monte Carlo
  set.seed(7)
  sims <- replicate(400, {
    y <- rnorm(nn)
    vapply(c(2, 4, 8), function(mm) oav_ref(y, mm, 1), 0)
  })
  Rth <- cov2cor(avar_white_cov(c(2, 4, 8), nn, TRUE, 2L))
  expect_equal(cor(t(sims))[1, 2], Rth[1, 2], tolerance = 0.2)
  expect_equal(cor(t(sims))[2, 3], Rth[2, 3], tolerance = 0.2)
})

test_that("correlation = TRUE: exact curves, calibrated chi2 and honest SE", {
  nn <- 2^15
  ms <- unique(round(10^seq(0, log10(nn / 4), by = 0.1)))
  tab <- data.frame(tau = ms / f,
                    avar = av_model(ms / f, c(N = 0.01, gm1.sigma = 0.01,
                                              gm1.tc = 3), f))
  fit <- avfit(tab, c("N", "gm"), n = nn, freq = f, correlation = TRUE,
               bias_correct = FALSE)
  expect_equal(coef(fit), c(N = 0.01, gm1.sigma = 0.01, gm1.tc = 3),
               tolerance = 1e-5)
  expect_true(fit$correlation)
  # on a dense tau grid the correlated fit's SE matches the spread over
  # seeds; so does the independent-points fit's (its sandwich SE)
  res <- t(vapply(1:8, function(s) {
    x <- avsim(nn, f, N = 0.01, B = 0.003, seed = 300 + s)
    tb <- oav_table(x, f, ms)
    a <- avfit(tb, c("N", "B"), n = nn, freq = f)
    b <- avfit(tb, c("N", "B"), n = nn, freq = f, correlation = TRUE)
    c(b$chi2, coef(b)["B"], b$se["B"], a$se["B"], coef(a)["B"])
  }, numeric(5)))
  expect_gt(mean(res[, 1]), 0.4)
  expect_lt(mean(res[, 1]), 2)
  sd_b <- sd(res[, 2])
  expect_gt(mean(res[, 3]) / sd_b, 0.5)
  expect_lt(mean(res[, 3]) / sd_b, 2)
  expect_gt(mean(res[, 4]) / sd(res[, 5]), 0.5)
  expect_lt(mean(res[, 4]) / sd(res[, 5]), 2)
  expect_equal(as.numeric(logLik(b <- avfit(tab, c("N", "gm"), n = nn, freq = f,
                                              correlation = TRUE))),
               {
                 s <- sqrt(trigamma(b$data$edf / 2))
                 r <- log(tab$avar) - log_bias(b$data$edf) - log(fitted(b))
                 S <- b$corr * outer(s, s)
                 as.numeric(-0.5 * (length(r) * log(2 * pi) +
                   determinant(S)$modulus + t(r) %*% solve(S, r)))
               }, tolerance = 1e-6)
})

test_that("refitting an avfit keeps its EDF (comparable AIC) and its estimates", {
  x <- avsim(n, f, N = 0.01, gm = list(sigma = 0.01, tc = 2), seed = 41)
  tab <- oav_table(x, f)
  fit0 <- avfit(tab, "N", n = n, freq = f)
  fit1 <- avfit(fit0, c("N", "gm"))
  expect_equal(fit1$data$edf, fit0$data$edf)
  expect_equal(fit1$edf_source, "previous")
  expect_lt(AIC(fit1), AIC(fit0) - 10)
  # a second refit starts from gm1's estimate and finds a second GM
  fit2 <- avfit(fit1, c("N", "gm", "gm"), start = c(gm2.tc = 100))
  expect_named(coef(fit2), c("N", "gm1.sigma", "gm1.tc", "gm2.sigma", "gm2.tc"))
  expect_lte(fit2$objective, fit1$objective + 1e-6)
  # start and fixed together; unknown names rejected
  fit3 <- avfit(tab, c("N", "gm"), n = n, freq = f, start = c(gm1.tc = 1),
                fixed = c(N = 0.01))
  expect_equal(unname(coef(fit3)["gm1.tc"]), 2, tolerance = 0.15)
  expect_error(avfit(tab, "N", n = n, freq = f, fixed = c(B = 1)), "`fixed`",
    class = "allanvar_error_argument")
  # avari() output is overlapping
  fit_i <- avfit(avari(cumsum(x) / f, f), c("N", "gm"), freq = f,
                 type = "overlapping")
  expect_equal(fit_i$type, "overlapping")
  expect_equal(unname(coef(fit_i)["N"]), 0.01, tolerance = 0.05)
})

test_that("several nonlinear terms: the search finds the global optimum", {
  skip_on_cran()
  nn <- 2^17
  x <- avsim(nn, f, N = 0.01, B = 0.002, gm = list(sigma = 0.006, tc = 3),
             sinusoid = list(amp = 0.01, f0 = 1.3), seed = 51)
  ms <- unique(round(10^seq(0, log10(nn / 4), by = 0.05)))
  tb <- oav_table(x, f, ms)
  for (corr in c(FALSE, TRUE)) {
    fit <- avfit(tb, c("N", "B", "gm", "sinusoid"), n = nn, freq = f,
                 correlation = corr)
    cf <- coef(fit)
    expect_equal(unname(cf["sinusoid1.f0"]), 1.3, tolerance = 0.05)
    expect_equal(unname(cf["sinusoid1.amp"]), 0.01, tolerance = 0.2)
    # diagonal weights: tc = 4.1 +- 0.4 here (adjacent taus are correlated,
    # the SE is too small); with correlation = TRUE: 3.3 +- 1.0
    expect_equal(unname(cf["gm1.tc"]), 3, tolerance = 0.4)
    if (corr) expect_lt(abs(cf[["gm1.tc"]] - 3), 2 * fit$se[["gm1.tc"]])
    # started at the truth, the fit ends no better than the search did
    st <- avfit(tb, c("N", "B", "gm", "sinusoid"), n = nn, freq = f,
                correlation = corr, start = c(gm1.tc = 3, sinusoid1.f0 = 1.3))
    expect_gte(st$objective, fit$objective - 1e-6 * fit$objective)
  }
  # a term fitted to nothing: its tc is not identified
  x <- avsim(2^16, f, N = 0.01, seed = 52)
  fit <- avfit(oav_table(x, f), c("N", "gm"), n = 2^16, freq = f,
               fixed = c(gm1.sigma = 0))
  expect_true(is.na(fit$se["gm1.tc"]))
})

test_that("avfit() and its methods raise classed errors with stable wording", {
  tab <- data.frame(tau = m_oct / f, avar = av_model(m_oct / f, c(N = 1), f))
  fit <- avfit(tab, "N", n = n, freq = f)
  expect_snapshot(error = TRUE, {
    avfit()
    avfit(tab, "Z", n = n, freq = f)
    avfit(tab, c("N", "N"), n = n, freq = f)
    avfit(tab, "N", n = n, freq = f, start = c(X = 1))
    avfit(tab, "N", n = n, freq = f, tau_range = 1)
    avfit(tab[1:2, ], c("N", "B", "K"), n = n, freq = f)
    avfit(tab, "N", n = n, freq = f, bias_correct = NA)
    avfit(tab, "N", n = n, freq = f, taus = 3)
    avfit(fit, "N", freq = 10)
    residuals(fit, type = "raw")
    predict(fit, -1)
    confint(fit, "B")
  })
  expect_error(avfit(tab, "Z", n = n, freq = f), class = "allanvar_error_argument")
  expect_error(avfit(1:3), class = "allanvar_error_curve")
  expect_error(avfit(tab[1:2, ], c("N", "B", "K"), n = n, freq = f),
               class = "allanvar_error_curve")
  expect_error(av_model(1, c(X = 1)), class = "allanvar_error_argument")
})

test_that("a fit with every coefficient fixed evaluates the model (no free parameter)", {
  set.seed(12)
  a <- allan(rnorm(1e4, sd = 1), 100)
  f <- avfit(a, terms = c("N", "K"), fixed = c(N = 0.1, K = 1e-4))
  expect_identical(unname(coef(f)), c(0.1, 1e-4))
  expect_identical(unname(diag(vcov(f))), c(0, 0))
  # every point is a degree of freedom; chi2 is the model's own misfit
  # (N = 0.1 is the truth)
  expect_equal(f$df.residual, f$nobs)
  expect_lt(f$chi2, 3)
  expect_true(is.finite(stats::BIC(f)))
})

test_that("model EDF is exact for a sum of noises (cross terms, Monte Carlo)", {
  # N + K + AR(1) at tau0 = 1 s, levels chosen so that all three are
  # comparable near m = 64; own generator, plain-R estimator (helper-oav.R)
  nn <- 4096
  par <- c(N = 1, K = sqrt(3) / 64, sigma = 0.19, tc = 20)
  lay <- coef_layout(c("N", "K", "gm"))
  lay$value <- unname(par[c("N", "K", "sigma", "tc")])
  m <- c(8, 64, 512)
  ex <- edf_fit_model(m, nn, "overlapping", m, 1, lay)
  mix <- edf_model(m, nn, "overlapping", model_components(m, 1, lay),
                   model_alpha(m, 1, lay))
  set.seed(11)
  phi <- exp(-1 / par[["tc"]])
  sims <- replicate(600, {
    w <- rnorm(nn, sd = par[["sigma"]] * sqrt(1 - phi^2))
    w[1] <- rnorm(1, sd = par[["sigma"]])
    y <- rnorm(nn, sd = par[["N"]]) + cumsum(rnorm(nn, sd = par[["K"]])) +
      as.numeric(stats::filter(w, phi, method = "recursive"))
    vapply(m, function(mm) oav_ref(y, mm, 1), 0)
  })
  av <- rowSums(model_components(m, 1, lay))
  # the model's AV is the mean of the estimates (unbiased estimator)
  expect_equal(rowMeans(sims), av, tolerance = 0.06)
  mc <- 2 * av^2 / apply(sims, 1, var)
  # sampling error of a variance from 600 draws: 6-8 % at these EDFs
  expect_equal(ex, mc, tolerance = 0.2)
  # where the three are level (m = 64) the per-term combination, which
  # leaves out the cross terms, is far too high (226 against 94)
  expect_gt(mix[2], 1.5 * mc[2])
})

test_that("the exact EDF kernel reduces to the exact single-noise values", {
  nn <- 1000
  m <- c(1, 2, 5, 16, 64)
  M <- nn + 1 - 2 * m
  kern <- function(w, q, p = 0, overlapping = TRUE, mm = m, MM = M) {
    # the three power-law parts of the structure function (shapes 0-2)
    avfit_exact_edf(mm, MM, overlapping, 0:2, c(w, q, p), numeric(3))
  }
  # Isserlis moments for white and random-walk rate noise (src/edf.cpp)
  expect_equal(kern(0.09, 0), allan_edf_direct("overlapping", m, M, nn + 1, rep(0L, 5)),
               tolerance = 1e-8)
  expect_equal(kern(0, 4), allan_edf_direct("overlapping", m, M, nn + 1, rep(-2L, 5)),
               tolerance = 1e-8)
  # white phase: d_i = e_{i+2m} - 2 e_{i+m} + e_i, R(0) = 6, R(m) = -4,
  # R(2m) = 1 (m > 0), so EDF = M^2 36 / (36 M + 2 (16 (M - m) + (M - 2m)))
  Mq <- M[4]
  expect_equal(kern(0, 0, 1, mm = 16, MM = Mq),
               Mq^2 * 36 / (36 * Mq + 2 * (16 * (Mq - 16) + (Mq - 32))))
  # non-overlapping white noise: 2 M^2 / (3 M - 1), M second differences
  Mn <- floor(4096 / 16) - 1
  expect_equal(kern(1, 0, overlapping = FALSE, mm = 16, MM = Mn),
               2 * Mn^2 / (3 * Mn - 1))
  # a 9,999-tau table costs little (long sums on 64 nodes per stretch)
  lay <- coef_layout(c("N", "K", "gm"))
  lay$value <- c(0.01, 2e-4, 0.02, 2)
  mm <- round(10^seq(0, 6, length.out = 9999))
  e <- edf_fit_model(mm, 1e8, "overlapping", mm / 100, 0.01, lay)
  expect_true(all(is.finite(e) & e >= 1))
})

test_that("model_error = TRUE: a discrepancy estimated where the model departs, none where it fits", {
  # an exact N + K curve with a Gauss-Markov bump the N + K model lacks
  tau <- 10^seq(-2, 3.3, by = 0.1)
  q <- tau / 300
  gm <- 2 * (2e-3)^2 * 300 / tau * (1 - (3 - 4 * exp(-q) + exp(-2 * q)) / (2 * q))
  n <- 20 * 3600 * 400
  edf <- pmax(1, 1.5 * n / (tau * 400))
  exact <- data.frame(tau = tau, avar = 1e-6 / tau + 1e-10 * tau / 3, edf = edf)
  f0 <- avfit(exact, c("N", "K"), control = avfit_control(model_error = TRUE))
  expect_identical(f0$model_error, 0)
  bumped <- exact
  bumped$avar <- bumped$avar + gm
  plain <- avfit(bumped, c("N", "K"))
  f1 <- avfit(bumped, c("N", "K"), control = avfit_control(model_error = TRUE))
  expect_identical(plain$model_error, 0)
  expect_gt(plain$chi2, 5)
  expect_gt(f1$model_error, 0.05)
  # the discrepancy brings the chi-square per dof to about 1
  expect_equal(f1$chi2, 1, tolerance = 0.1)
  expect_output(print(f1), "model error of")
  # the loop judges candidates on the points' own scatter
  expect_false(refit_settings(f1, list())$control$model_error)
})

test_that("confint(): log-scale Wald, one-sided at a zero amplitude, (0, Inf) for a dead tc", {
  # white noise alone (generated here): K and the GM amplitude go to 0
  set.seed(5)
  x <- rnorm(2^15, sd = 0.1)
  fit <- avfit(allan(x, 100), c("N", "K"))
  expect_identical(coef(fit)[["K"]], 0)
  ci <- confint(fit)
  expect_equal(unname(ci["K", ]), c(0, sqrt(qnorm(0.95)) * fit$se[["K"]]))
  expect_gt(ci["K", 2], 0)
  # the 90% bound: c <= qnorm(0.90) SE(c), SE(c) = se^2
  expect_equal(unname(confint(fit, "K", level = 0.9)[, 2]), sqrt(qnorm(0.9)) * fit$se[["K"]])
  cf <- coef(fit)[["N"]]
  expect_equal(unname(ci["N", ]), cf * exp(c(-1, 1) * qnorm(0.975) * fit$se[["N"]] / cf))
  g <- avfit(allan(x, 100), c("N", "gm"), fixed = c(gm1.sigma = 0))
  expect_equal(unname(confint(g)["gm1.tc", ]), c(0, Inf))
})

test_that("a weakly determined amplitude's interval is the Neyman one of its shifted chi-square law", {
  # own generator: white noise, a weak rate random walk beside a
  # Gauss-Markov term (K's AV shows only in the last octaves)
  set.seed(23)
  n <- 2^15
  phi <- exp(-1 / (100 * 2))
  w <- rnorm(n, sd = 0.02 * sqrt(1 - phi^2))
  x <- rnorm(n, sd = 0.1) + cumsum(rnorm(n, sd = 1e-4)) +
    as.numeric(stats::filter(w, phi, method = "recursive"))
  fit <- avfit(allan(x, 100), c("N", "K", "gm"))
  expect_gt(coef(fit)[["K"]], 0)
  weak <- allanvar:::amp_interval_weak(fit, c("N", "K", "gm1.sigma"))
  expect_identical(unname(weak), c(FALSE, TRUE, FALSE))
  ci <- confint(fit)
  k <- coef(fit)[["K"]]
  expect_lt(ci["K", 1], k)
  expect_gt(ci["K", 2], k)
  # N keeps its log-scale Wald interval
  expect_equal(unname(ci["N", ]), coef(fit)[["N"]] *
                 exp(c(-1, 1) * qnorm(0.975) * fit$se[["N"]] / coef(fit)[["N"]]))
  # at each end the law under that value puts the estimate at its 97.5% /
  # 2.5% quantile: c + s ~ (c0 + s) chi2_m / m with the fit's SE under c0
  se0 <- allanvar:::amp_se_c(fit, "K", 1e-4 * k^2)
  quant <- function(c0, p) {
    se <- allanvar:::amp_se_c(fit, "K", c0)
    s <- c0 * se0 / (se - se0)
    m <- 2 * (c0 + s)^2 / se^2
    (c0 + s) * qchisq(p, m) / m - s
  }
  if (ci["K", 1] > 0) expect_equal(quant(ci["K", 1]^2, 0.975), k^2, tolerance = 1e-3)
  expect_equal(quant(ci["K", 2]^2, 0.025), k^2, tolerance = 1e-3)
})

test_that("independent-points fits: 95% intervals cover (sandwich with the points' correlation)", {
  skip_on_cran()
  # own generator: white rate noise N and a rate random walk K at 100 Hz;
  # 300 seeds give the coverage to +-1.3 points. Treating the octave points
  # as independent (the default weighting) without the sandwich covered
  # N 85% and K 73% here, with it 95% and 96%.
  f <- 100
  n <- 2^14
  N <- 1e-3
  K <- 1e-3
  hit <- t(vapply(1:300, function(s) {
    set.seed(5000 + s)
    x <- N * sqrt(f) * rnorm(n) + cumsum(K / sqrt(f) * rnorm(n))
    fit <- avfit(allan(x, f), c("N", "K"))
    ci <- confint(fit)
    c(ci["N", 1] <= N && N <= ci["N", 2], ci["K", 1] <= K && K <= ci["K", 2])
  }, logical(2)))
  expect_gt(mean(hit[, 1]), 0.91)
  expect_lt(mean(hit[, 1]), 0.99)
  # K's too: the correlation is the fitted model's (a random walk's points
  # are far more correlated than white noise's; with the white-noise
  # correlation K covered 90%)
  expect_gt(mean(hit[, 2]), 0.91)
  expect_lt(mean(hit[, 2]), 0.99)
})
