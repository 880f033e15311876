# The noise-term catalogue. One entry per kind of effect: its parameters and
# units, its expected Allan variance, its simulator and its signature. The
# fit (avfit), the simulator (avsim), residual tracing (avrefine/diagnose) and
# the exporters all read this list, so adding an effect touches one place.
#
# Every term has exactly one amplitude parameter `a` and the expected AV is
# a^2 * basis(tau, tau0, nl), where `nl` holds the term's nonlinear parameters
# (gm: tc; sinusoid: f0). The AV is therefore linear in the squared
# amplitudes, which is what the fit's NNLS step relies on.
#
# Discrete vs continuous: with tau0 known, `basis` uses the exact discrete
# expectation for a sampled record (noise-models.md section 1) evaluated at
# m = tau / tau0; these expressions are smooth in m, so non-integer m gives a
# smooth curve through the exact integer-m values (flicker: interpolated
# table, see flicker_ratio()). With tau0 = NULL, or m < 1, the continuous
# IEEE 952 forms are used.

# ---- flicker (B): exact discrete Kasdin form ---------------------------------
# AV(m) / (2 ln2 B^2 / pi) = 1 + c(m) / m^2, where
# AV(m) = (2 B^2 / pi) * int_0^{pi/2} sin^4(m u) / (m^2 sin^3 u) du.
# c(m) tabulated by composite Simpson integration (>= 40000 panels, >= 800 per
# period of sin^4(m u)); c(1) = 1/ln 2 - 1 exactly. For large m, c(m) grows by
# 3/16 per doubling of m (checked to 4096), which gives the extrapolation.
flicker_table <- list(
  m = c(1:16, 20, 24, 32, 48, 64, 96, 128, 192, 256, 512, 1024, 2048, 4096),
  c = c(0.4426950409, 0.6166241308, 0.7233065772, 0.8000228111, 0.8598628084,
        0.9088954024, 0.95042024, 0.9864279848, 1.018211104, 1.046655918,
        1.072396513, 1.095902098, 1.117529577, 1.137556726, 1.156203965,
        1.173649124, 1.233977033, 1.283277714, 1.36107907, 1.470746552,
        1.548561537, 1.65823876, 1.736057158, 1.845736824, 1.923556085,
        2.111055904, 2.298556211, 2.486057692, 2.673563682)
)
flicker_c <- local({
  spline <- stats::splinefun(log(flicker_table$m), flicker_table$c,
                             method = "monoH.FC")
  function(m) {
    big <- m > 4096
    out <- numeric(length(m))
    out[!big] <- spline(log(m[!big]))
    out[big] <- 2.673563682 + 3 / (16 * log(2)) * log(m[big] / 4096)
    out
  }
})

# Ratio of the exact discrete flicker AV to the IEEE plateau 2 ln2 B^2 / pi.
flicker_ratio <- function(m) 1 + flicker_c(m) / m^2

# Kasdin & Walter (1992) 1/f generator: y = h * w, h_k = h_{k-1} (k - 1/2)/k,
# w ~ N(0, q_d), q_d = B^2. Linear convolution by zero-padded FFT. A warm-up
# of `warm` samples is generated and dropped so that early samples have a
# (nearly) full filter history.
sim_flicker <- function(n, B, warm = n) {
  len <- n + warm
  k <- seq_len(len - 1L)
  h <- cumprod(c(1, (k - 0.5) / k))
  w <- stats::rnorm(len, sd = B)
  nfft <- stats::nextn(2L * len)
  hz <- c(h, numeric(nfft - len))
  wz <- c(w, numeric(nfft - len))
  y <- Re(stats::fft(stats::fft(hz) * stats::fft(wz), inverse = TRUE)) / nfft
  y[(warm + 1L):len]
}

# ---- Gauss-Markov: AR(1) exact discrete form, numerically stable ------------
# AV(m) / sigma^2 = [m - 3 phi - m phi^2 + 4 phi^(m+1) - phi^(2m+1)] /
#                   [m^2 (1 - phi)^2],  phi = exp(-tau0 / tc).
# Written with E_j = 1 - phi^j = -expm1(-j eps) to limit cancellation; for
# m * eps < 1e-5 the first-order form eps (2 m^2 + 1) / (3 m) is used
# (the RRW-like short-tau limit, relative error ~ m * eps).
gm_basis_discrete <- function(m, eps) {
  E <- function(j) -expm1(-j * eps)
  num <- 3 * E(1) + m * E(2) - 4 * E(m + 1) + E(2 * m + 1)
  out <- num / (m^2 * E(1)^2)
  small <- m * eps < 1e-5
  out[small] <- (eps * (2 * m^2 + 1) / (3 * m))[small]
  out
}

# Continuous form: (tc/tau)^2 [2x - 3 + 4 e^-x - e^-2x], x = tau / tc; series
# for small x (the bracket is (2/3) x^3 - x^4/2 + ...).
gm_basis_continuous <- function(tau, tc) {
  x <- tau / tc
  br <- 2 * x - 3 + 4 * exp(-x) - exp(-2 * x)
  small <- x < 0.05
  if (any(small)) {
    xs <- x[small]
    s <- 0
    for (k in 3:14) s <- s + (-1)^k * xs^k * (4 - 2^k) / factorial(k)
    br[small] <- s
  }
  br / x^2
}

sim_gm <- function(n, tau0, sigma, tc) {
  phi <- exp(-tau0 / tc)
  w <- stats::rnorm(n, sd = sigma * sqrt(1 - phi^2))
  w[1L] <- stats::rnorm(1L, sd = sigma)            # stationary start
  as.numeric(stats::filter(w, phi, method = "recursive"))
}

# ---- the catalogue ----------------------------------------------------------
# basis(tau, tau0, nl): AV per squared amplitude; tau0 = NULL -> continuous.
# sim(n, tau0, amp, nl): n rate samples.
# alpha: power-law exponent of the rate PSD where it has one (for EDF).
term_catalogue <- function() {
  disc <- function(tau, tau0) !is.null(tau0) & tau >= tau0 * (1 - 1e-9)
  list(
    Q = list(
      kind = "Q", params = "Q", nonlinear = character(0),
      units = c(Q = "u*s"),
      words = c(Q = "rate unit x second (angle quantum / sqrt(12))"),
      repeatable = FALSE, slope = -1, alpha = 2,
      formula = "3 Q^2 / tau^2 (exact for differenced uniform noise)",
      signature = paste("ADEV slope -1, largest at the smallest tau;",
                        "lag-1 ACF of the rate near -1/2; LSB grid"),
      basis = function(tau, tau0, nl) 3 / tau^2,
      sim = function(n, tau0, amp, nl) {
        e <- stats::runif(n + 1L, -sqrt(3) * amp, sqrt(3) * amp)
        diff(e) / tau0
      }
    ),
    N = list(
      kind = "N", params = "N", nonlinear = character(0),
      units = c(N = "u*sqrt(s)"),
      words = c(N = "rate unit x sqrt(second) (angle/velocity random walk)"),
      repeatable = FALSE, slope = -0.5, alpha = 0,
      formula = "N^2 / tau",
      signature = "ADEV slope -1/2; flat PSD, ACF near 0",
      basis = function(tau, tau0, nl) 1 / tau,
      sim = function(n, tau0, amp, nl) stats::rnorm(n, sd = amp / sqrt(tau0))
    ),
    B = list(
      kind = "B", params = "B", nonlinear = character(0),
      units = c(B = "u"),
      words = c(B = "rate unit (bias instability)"),
      repeatable = FALSE, slope = 0, alpha = -1,
      formula = paste("(2 ln2 / pi) B^2 x exact Kasdin ratio",
                      "(1.443 at m = 1, 1.050 at m = 4)"),
      signature = "ADEV slope 0: a flat minimum; PSD ~ 1/f",
      basis = function(tau, tau0, nl) {
        out <- rep(2 * log(2) / pi, length(tau))
        d <- disc(tau, tau0)
        if (any(d)) out[d] <- out[d] * flicker_ratio(tau[d] / tau0)
        out
      },
      sim = function(n, tau0, amp, nl) sim_flicker(n, amp)
    ),
    K = list(
      kind = "K", params = "K", nonlinear = character(0),
      units = c(K = "u/sqrt(s)"),
      words = c(K = "rate unit / sqrt(second) (rate random walk)"),
      repeatable = FALSE, slope = 0.5, alpha = -2,
      formula = "K^2 tau / 3 + K^2 tau0^2 / (6 tau)",
      signature = "ADEV slope +1/2 at long tau; PSD ~ 1/f^2",
      basis = function(tau, tau0, nl) {
        out <- tau / 3
        d <- disc(tau, tau0)
        if (any(d)) out[d] <- out[d] + tau0^2 / (6 * tau[d])
        out
      },
      sim = function(n, tau0, amp, nl) cumsum(stats::rnorm(n, sd = amp * sqrt(tau0)))
    ),
    R = list(
      kind = "R", params = "R", nonlinear = character(0),
      units = c(R = "u/s"),
      words = c(R = "rate unit / second (rate ramp)"),
      repeatable = FALSE, slope = 1, alpha = -2,
      formula = "R^2 tau^2 / 2 (exact for y_k = R tau0 k)",
      signature = "ADEV slope +1 at the longest tau; a trend in the data",
      basis = function(tau, tau0, nl) tau^2 / 2,
      sim = function(n, tau0, amp, nl) amp * tau0 * seq_len(n)
    ),
    gm = list(
      kind = "gm", params = c("sigma", "tc"), nonlinear = "tc",
      units = c(sigma = "u", tc = "s"),
      words = c(sigma = "rate unit (stationary standard deviation)",
                tc = "second (correlation time)"),
      repeatable = TRUE, slope = NA_real_, alpha = NA_real_,
      formula = paste("AR(1) exact: sigma^2 [m - 3phi - m phi^2 + 4 phi^(m+1)",
                      "- phi^(2m+1)] / [m^2 (1-phi)^2], phi = exp(-tau0/tc)"),
      signature = paste("a bump: slope +1/2 for tau << tc, -1/2 for tau >> tc;",
                        "peak ADEV 0.6174 sigma at tau = 1.893 tc;",
                        "exponential ACF"),
      basis = function(tau, tau0, nl) {
        tc <- nl[["tc"]]
        out <- gm_basis_continuous(tau, tc)
        d <- disc(tau, tau0)
        if (any(d)) out[d] <- gm_basis_discrete(tau[d] / tau0, tau0 / tc)
        out
      },
      sim = function(n, tau0, amp, nl) sim_gm(n, tau0, amp, nl[["tc"]])
    ),
    sinusoid = list(
      kind = "sinusoid", params = c("amp", "f0"), nonlinear = "f0",
      units = c(amp = "u", f0 = "Hz"),
      words = c(amp = "rate unit (amplitude)", f0 = "hertz (frequency)"),
      repeatable = TRUE, slope = -1, alpha = NA_real_,
      formula = paste("amp^2 sin^4(pi f0 m tau0) / (m^2 sin^2(pi f0 tau0)),",
                      "phase-averaged"),
      signature = paste("nulls at tau = k / f0; first peak 0.7246 amp at",
                        "tau = 0.371 / f0; envelope slope -1;",
                        "periodogram line at f0"),
      basis = function(tau, tau0, nl) {
        f0 <- nl[["f0"]]
        x <- pi * f0 * tau
        out <- sin(x)^4 / x^2
        d <- disc(tau, tau0)
        if (any(d)) {
          s1 <- sin(pi * f0 * tau0)^2
          out[d] <- if (s1 < 1e-300) 0 else
            sin(x[d])^4 / ((tau[d] / tau0)^2 * s1)
        }
        out
      },
      sim = function(n, tau0, amp, nl) {
        amp * sin(2 * pi * nl[["f0"]] * tau0 * seq_len(n) +
                    stats::runif(1L, 0, 2 * pi))
      }
    )
  )
}

term_kinds <- function() c("Q", "N", "B", "K", "R", "gm", "sinusoid")

term_entry <- function(kind) {
  cat <- term_catalogue()
  if (!kind %in% names(cat)) abort("Unknown noise term \"", kind, "\".")
  cat[[kind]]
}

# Validate a `terms` vector (kinds, repeatable ones may repeat) and return the
# canonical order Q, N, B, K, R, gm..., sinusoid....
check_terms <- function(terms, arg = "terms") {
  if (!is.character(terms) || length(terms) == 0L || anyNA(terms)) {
    abort("`", arg, "` must be a character vector of term names (",
          paste(term_kinds(), collapse = ", "), "), not ",
          describe_type(terms), ".")
  }
  bad <- setdiff(terms, term_kinds())
  if (length(bad)) {
    abort("`", arg, "` contains unknown term ", encodeString(bad[1], quote = '"'),
          "; known terms are ", paste(term_kinds(), collapse = ", "), ".")
  }
  single <- terms[terms %in% c("Q", "N", "B", "K", "R")]
  if (anyDuplicated(single)) {
    abort("`", arg, "` repeats \"", single[duplicated(single)][1],
          "\"; only gm and sinusoid may appear more than once.")
  }
  terms[order(match(terms, term_kinds()))]
}

# Labels of the term instances: c("N", "gm", "gm") -> c("N", "gm1", "gm2").
term_labels <- function(terms) {
  terms <- check_terms(terms)
  lab <- terms
  for (k in c("gm", "sinusoid")) {
    i <- which(terms == k)
    lab[i] <- paste0(k, seq_along(i))
  }
  lab
}

#' Layout of the coefficient vector for a set of terms (internal).
#'
#' One row per coefficient: `name` (e.g. "gm1.tc"), `label` (term instance,
#' "gm1"), `kind` ("gm"), `param` ("tc"), `role` ("amp" or "nonlinear"),
#' `unit`.
#' @noRd
coef_layout <- function(terms) {
  terms <- check_terms(terms)
  labs <- term_labels(terms)
  rows <- lapply(seq_along(terms), function(i) {
    e <- term_entry(terms[i])
    nm <- if (e$repeatable) paste0(labs[i], ".", e$params) else e$params
    data.frame(name = nm, label = labs[i], kind = terms[i], param = e$params,
               role = ifelse(e$params %in% e$nonlinear, "nonlinear", "amp"),
               unit = unname(e$units[e$params]), stringsAsFactors = FALSE)
  })
  do.call(rbind, rows)
}

# Term kinds from coefficient names: c("N", "gm1.sigma", "gm1.tc") -> c("N", "gm").
terms_from_coef <- function(names) {
  lab <- unique(sub("\\..*$", "", names))
  kind <- sub("[0-9]+$", "", lab)
  kind
}

# Check a named coefficient vector against the catalogue; returns it with the
# layout attached.
check_coef <- function(coef, arg = "coef") {
  if (is.list(coef) && !is.data.frame(coef)) coef <- unlist(coef)
  if (!is.numeric(coef) || is.null(names(coef)) || any(!nzchar(names(coef))) ||
      anyNA(coef)) {
    abort("`", arg, "` must be a named numeric vector of coefficients such as ",
          "c(N = 1e-3, B = 1e-4, gm1.sigma = 0.01, gm1.tc = 10), not ",
          describe_type(coef), ".")
  }
  kinds <- terms_from_coef(names(coef))
  bad <- setdiff(kinds, term_kinds())
  if (length(bad)) {
    abort("`", arg, "` has a coefficient for the unknown term \"", bad[1],
          "\"; see av_terms().")
  }
  lay <- coef_layout(kinds)
  # Repeatable labels as given by the user (gm1, gm3) may not be 1..k: map by
  # label in order of appearance.
  ulab <- unique(sub("\\..*$", "", names(coef)))
  ulab <- ulab[order(match(sub("[0-9]+$", "", ulab), term_kinds()))]
  lay$label <- ulab[match(lay$label, unique(lay$label))]
  lay$name <- ifelse(lay$kind %in% c("gm", "sinusoid"),
                     paste0(lay$label, ".", lay$param), lay$param)
  miss <- setdiff(lay$name, names(coef))
  if (length(miss)) {
    abort("`", arg, "` lacks the coefficient ", miss[1], ".")
  }
  extra <- setdiff(names(coef), lay$name)
  if (length(extra)) abort("`", arg, "` has an unknown coefficient ", extra[1], ".")
  val <- coef[lay$name]
  if (any(val[lay$role == "amp"] < 0)) {
    abort("`", arg, "`: amplitudes must be non-negative.")
  }
  if (any(val[lay$role == "nonlinear"] <= 0)) {
    abort("`", arg, "`: gm time constants and sinusoid frequencies must be ",
          "positive.")
  }
  lay$value <- unname(val)
  lay
}

# Basis matrix: one column per term instance (AV per squared amplitude), rows
# are tau. `lay` from coef_layout()/check_coef(); `nl` a named numeric vector
# of the nonlinear coefficients (names as in lay$name).
term_basis_matrix <- function(tau, tau0, lay, nl = NULL) {
  labs <- unique(lay$label)
  out <- matrix(0, length(tau), length(labs), dimnames = list(NULL, labs))
  for (j in seq_along(labs)) {
    rows <- lay[lay$label == labs[j], , drop = FALSE]
    e <- term_entry(rows$kind[1])
    nlv <- NULL
    if (length(e$nonlinear)) {
      nm <- rows$name[rows$role == "nonlinear"]
      nlv <- stats::setNames(if (!is.null(nl)) nl[nm] else rows$value[rows$role == "nonlinear"],
                             e$nonlinear)
    }
    out[, j] <- e$basis(tau, tau0, nlv)
  }
  out
}

#' The noise-term catalogue
#'
#' Lists the noise terms that [avsim()], [avfit()] and [av_model()] know:
#' one row per parameter, with its unit and the term's Allan-deviation slope
#' and signature. Units follow IEEE Std 952 with "u" standing for the
#' input's rate unit (deg/s, m/s^2, ...).
#'
#' | term | parameters | Allan variance (continuous form) |
#' |---|---|---|
#' | Q | Q \[u s\] | \eqn{3Q^2/\tau^2} |
#' | N | N \[u sqrt(s)\] | \eqn{N^2/\tau} |
#' | B | B \[u\] | \eqn{(2\ln 2/\pi) B^2} |
#' | K | K \[u/sqrt(s)\] | \eqn{K^2\tau/3} |
#' | R | R \[u/s\] | \eqn{R^2\tau^2/2} |
#' | gm | sigma \[u\], tc \[s\] | \eqn{\sigma^2 (t_c/\tau)^2 (2\tau/t_c - 3 + 4e^{-\tau/t_c} - e^{-2\tau/t_c})} |
#' | sinusoid | amp \[u\], f0 \[Hz\] | \eqn{A^2 \sin^4(\pi f_0 \tau)/(\pi f_0\tau)^2} |
#'
#' With the sampling frequency known, the exact expectations for a sampled
#' record are used instead (see [av_model()]).
#'
#' @return A data frame with columns `term`, `parameter`, `unit`, `meaning`,
#'   `repeatable` (gm and sinusoid may appear several times in a model),
#'   `slope` (log-log slope of the Allan deviation, NA for gm whose slope
#'   goes from +1/2 to -1/2), `formula` and `signature` (how the term shows
#'   in an Allan deviation plot and in the raw data).
#' @seealso [av_model()], [avsim()], [avfit()]
#' @export
#' @examples
#' av_terms()[, c("term", "parameter", "unit", "slope")]
av_terms <- function() {
  cat <- term_catalogue()
  rows <- lapply(cat, function(e) {
    data.frame(term = e$kind, parameter = e$params,
               unit = unname(e$units[e$params]),
               meaning = unname(e$words[e$params]),
               repeatable = e$repeatable, slope = e$slope,
               formula = e$formula, signature = e$signature,
               stringsAsFactors = FALSE)
  })
  out <- do.call(rbind, rows)
  rownames(out) <- NULL
  out
}

#' Expected Allan variance of a noise model
#'
#' Evaluates the expected Allan variance of a sum of independent noise
#' terms with the named coefficients, as used by [avfit()] and simulated by
#' [avsim()].
#'
#' With `freq` given (sample period \eqn{\tau_0 = 1/f}), each term uses its
#' exact expectation for a sampled record at cluster size
#' \eqn{m = \tau/\tau_0}: quantization \eqn{3Q^2/\tau^2}; white noise
#' \eqn{N^2/\tau}; flicker the exact Kasdin discrete form
#' \eqn{(2B^2/\pi)\int_0^{\pi/2}\sin^4(mu)/(m^2\sin^3 u)\,du} (1.443 times the
#' plateau at \eqn{m = 1}, 1.05 at \eqn{m = 4}); random walk
#' \eqn{K^2\tau_0(2m^2+1)/(6m)}; ramp \eqn{R^2\tau^2/2}; Gauss-Markov the
#' exact AR(1) form with \eqn{\phi = e^{-\tau_0/t_c}}; sinusoid the
#' phase-averaged Dirichlet form
#' \eqn{A^2\sin^4(\pi f_0 m\tau_0)/(m^2\sin^2(\pi f_0\tau_0))}. These
#' expressions are smooth in \eqn{m}; at non-integer \eqn{m} they
#' interpolate the exact integer-\eqn{m} values. Without `freq`, or for
#' \eqn{\tau < \tau_0}, the continuous IEEE 952 forms of [av_terms()] are
#' used (flicker: the plateau \eqn{2\ln 2 B^2/\pi}).
#'
#' @param tau Numeric vector of averaging times in seconds (positive).
#' @param coef Named numeric vector of coefficients, e.g.
#'   `c(N = 0.01, B = 0.002, gm1.sigma = 0.01, gm1.tc = 20)`; names as in
#'   [av_terms()], repeatable terms numbered (`gm1`, `gm2`, `sinusoid1`).
#'   A fitted [avfit()] object is also accepted.
#' @param freq Sampling frequency in Hz, or `NULL` for the continuous forms.
#'   Taken from the fit when `coef` is an `avfit` object.
#' @param by_term If `TRUE`, return a matrix with one column per term
#'   instance instead of the total.
#' @return The expected Allan variance at each `tau` (square of the rate
#'   unit), or with `by_term = TRUE` a matrix of each term's contribution.
#' @seealso [av_terms()], [avfit()], [avsim()]
#' @export
#' @examples
#' tau <- 10^seq(-2, 3, by = 0.5)
#' sqrt(av_model(tau, c(N = 0.01, B = 0.003, K = 1e-4), freq = 100))
#' # flicker at tau0 is 1.443 times the IEEE plateau
#' av_model(0.01, c(B = 1), freq = 100) / (2 * log(2) / pi)
av_model <- function(tau, coef, freq = NULL, by_term = FALSE) {
  if (inherits(coef, "avfit")) {
    if (missing(freq)) freq <- coef$freq
    coef <- coef$coefficients
  }
  check_present(missing(tau), "tau", "the averaging times in seconds")
  if (!is.numeric(tau) || length(tau) == 0L || anyNA(tau) || any(tau <= 0) ||
      any(!is.finite(tau))) {
    abort("`tau` must be a numeric vector of positive averaging times in ",
          "seconds, not ", describe_type(tau), ".")
  }
  lay <- check_coef(coef)
  tau0 <- if (is.null(freq)) NULL else 1 / check_freq(freq)
  comp <- model_components(tau, tau0, lay)
  if (by_term) comp else rowSums(comp)
}

# Per-term AV contributions (matrix, columns = term labels).
model_components <- function(tau, tau0, lay) {
  Bm <- term_basis_matrix(tau, tau0, lay)
  amp <- lay$value[lay$role == "amp"]
  names(amp) <- lay$label[lay$role == "amp"]
  sweep(Bm, 2L, amp[colnames(Bm)]^2, `*`)
}
