# The catalogue as users see it: av_terms() lists the entries, av_model()
# evaluates a model's expected Allan variance. The entries themselves are in
# R/effect-*.R, the registry in R/catalogue.R, coefficient layouts in
# R/coef.R.

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
#' | filter | Nf \[u sqrt(s)\], L \[samples\] (`filter:ma`) or fc \[Hz\] (`filter:lp1`, `filter:lp2`) or fn \[Hz\] and zeta (`filter:ar2`, a two-pole recursive section) | \eqn{N_f^2} times the exact AV of the filter's autocovariance (unit DC gain: \eqn{N_f^2/\tau} beyond a few samples) |
#' | resonance | sigma \[u\], fr \[Hz\], tc \[s\] | white noise through a damped oscillator: the real AR(2) with poles \eqn{e^{-\tau_0/t_c \pm 2\pi i f_r\tau_0}} (sigma its sd, FWHM about \eqn{1/(\pi t_c)}) |
#'
#' With the sampling frequency known, the exact expectations for a sampled
#' record are used instead (see [av_model()]).
#'
#' @return A data frame with columns `term`, `parameter`, `unit`, `meaning`,
#'   `repeatable` (gm and sinusoid may appear several times in a model),
#'   `slope` (log-log slope of the Allan deviation, NA for gm whose slope
#'   goes from +1/2 to -1/2), `formula`, `signature` (how the term shows
#'   in an Allan deviation plot and in the raw data) and `component`
#'   (`"av"` for a term that adds to the Allan variance and can be fitted;
#'   `"series"` for a non-stationary effect corrected in the series).
#' @seealso [av_model()], [avsim()], [avfit()]
#' @export
#' @examples
#' av_terms()[, c("term", "parameter", "unit", "slope")]
av_terms <- function() {
  rows <- lapply(catalogue(), function(e) {
    p <- e$params
    data.frame(term = e$name, parameter = p$name, unit = p$unit,
               meaning = p$meaning, repeatable = e$repeatable, slope = e$slope,
               formula = e$formula, signature = e$signature,
               component = e$component, stringsAsFactors = FALSE)
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
          "seconds, not ", describe_type(tau), ".", class = "argument")
  }
  by_term <- check_true_false(by_term, "by_term")
  lay <- check_coef(coef)
  tau0 <- if (is.null(freq)) NULL else 1 / check_freq(freq)
  comp <- model_components(tau, tau0, lay)
  if (!all(is.finite(comp))) {
    abort("the model overflows: `coef` or `tau` too large or too small to give ",
          "a finite Allan variance.", class = "argument")
  }
  if (by_term) comp else rowSums(comp)
}
