#' Simulate a rate signal with a known noise model
#'
#' Generates `n` rate samples (angular rate, acceleration, fractional
#' frequency) at `freq` Hz as the sum of independent noise terms whose
#' expected Allan variance is the catalogue's exact discrete form
#' ([av_model()] with the same `freq`), so that a simulation and its
#' theory can be compared directly.
#'
#' Recipes (\eqn{\tau_0 = 1/f}, \eqn{w} standard normal):
#' * `Q`: \eqn{y_k = (e_{k+1} - e_k)/\tau_0}, \eqn{e} i.i.d. uniform with
#'   variance \eqn{Q^2} (angle quantum \eqn{\sqrt{12}Q}).
#' * `N`: \eqn{y_k = (N/\sqrt{\tau_0}) w_k}.
#' * `B`: flicker (1/f) noise by the Kasdin-Walter fractional-difference
#'   filter \eqn{h_0 = 1}, \eqn{h_k = h_{k-1}(k - 1/2)/k} applied by FFT
#'   convolution to white noise of variance \eqn{B^2}; `n` warm-up samples
#'   are generated and discarded. Its expected Allan variance equals the
#'   exact form for \eqn{\tau} well below the record length.
#' * `K`: \eqn{b_k = b_{k-1} + K\sqrt{\tau_0} w_k}.
#' * `R`: \eqn{y_k = R\tau_0 k}.
#' * `gm`: AR(1) \eqn{x_k = \phi x_{k-1} + \sigma\sqrt{1-\phi^2} w_k},
#'   \eqn{\phi = e^{-\tau_0/t_c}}, started from its stationary law.
#' * `sinusoid`: \eqn{A\sin(2\pi f_0 k\tau_0 + \varphi)} with a uniform random
#'   phase.
#'
#' @param n Number of samples (a whole number >= 2).
#' @param freq Sampling frequency in Hz.
#' @param Q,N,B,K,R Non-negative coefficients in IEEE 952 units ("u" the rate
#'   unit): quantization `Q` \[u s\], white noise `N` \[u sqrt(s)\], bias
#'   instability (flicker) `B` \[u\], rate random walk `K` \[u/sqrt(s)\],
#'   rate ramp `R` \[u/s\].
#' @param gm Gauss-Markov terms: `NULL`, a list `list(sigma = , tc = )` or a
#'   data frame with columns `sigma` \[u\] and `tc` \[s\], one row per term.
#' @param sinusoid Sinusoidal terms: `NULL`, a list `list(amp = , f0 = )` or
#'   a data frame with columns `amp` \[u\] and `f0` \[Hz\] (below `freq / 2`),
#'   one row per term.
#' @param seed Optional integer seed. When given, the result is reproducible
#'   and the caller's random-number state is left as it was.
#' @return A `ts` of `n` samples with frequency `freq`, and attribute
#'   `coef`: the named coefficient vector (as in [av_model()]) of the
#'   simulated model.
#' @seealso [av_model()] for the expected Allan variance, [avfit()].
#' @export
#' @examples
#' x <- avsim(1e5, freq = 100, N = 0.01, B = 0.002,
#'            gm = list(sigma = 0.005, tc = 5), seed = 1)
#' attr(x, "coef")
#' av <- avar(x, 100)
#' cbind(av$time, sqrt(av$av), sqrt(av_model(av$time, attr(x, "coef"), 100)))
avsim <- function(n, freq, Q = 0, N = 0, B = 0, K = 0, R = 0, gm = NULL,
                  sinusoid = NULL, seed = NULL) {
  check_present(missing(n), "n", "the number of samples")
  check_present(missing(freq), "freq", "the sampling frequency in Hz")
  n <- check_number(n, "n", lo = 2, hi = 2^31 - 1, integer = TRUE)
  freq <- check_freq(freq)
  amps <- c(Q = check_number(Q, "Q", lo = 0), N = check_number(N, "N", lo = 0),
            B = check_number(B, "B", lo = 0), K = check_number(K, "K", lo = 0),
            R = check_number(R, "R", lo = 0))
  gm <- check_term_table(gm, "gm", c("sigma", "tc"))
  sinusoid <- check_term_table(sinusoid, "sinusoid", c("amp", "f0"))
  if (nrow(sinusoid) && any(sinusoid$f0 >= freq / 2)) {
    abort("`sinusoid` frequencies `f0` must be below the Nyquist frequency ",
          "freq / 2 = ", format(freq / 2), " Hz.")
  }
  if (!is.null(seed)) {
    seed <- check_number(seed, "seed", integer = TRUE,
                         lo = -.Machine$integer.max, hi = .Machine$integer.max)
    restore <- save_rng()
    on.exit(restore(), add = TRUE)
    set.seed(seed)
  }
  tau0 <- 1 / freq
  cat <- term_catalogue()
  y <- numeric(n)
  coef <- numeric(0)
  for (k in names(amps)) {
    if (amps[[k]] > 0) y <- y + cat[[k]]$sim(n, tau0, amps[[k]], NULL)
    coef[k] <- amps[[k]]
  }
  coef <- coef[coef > 0]
  for (i in seq_len(nrow(gm))) {
    y <- y + cat$gm$sim(n, tau0, gm$sigma[i], c(tc = gm$tc[i]))
    coef[paste0("gm", i, c(".sigma", ".tc"))] <- c(gm$sigma[i], gm$tc[i])
  }
  for (i in seq_len(nrow(sinusoid))) {
    y <- y + cat$sinusoid$sim(n, tau0, sinusoid$amp[i], c(f0 = sinusoid$f0[i]))
    coef[paste0("sinusoid", i, c(".amp", ".f0"))] <-
      c(sinusoid$amp[i], sinusoid$f0[i])
  }
  out <- stats::ts(y, start = 0, frequency = freq)
  attr(out, "coef") <- coef
  out
}

# gm / sinusoid arguments: NULL, a list or a data frame with the given
# columns -> a data frame (zero rows for NULL).
check_term_table <- function(x, arg, cols) {
  empty <- as.data.frame(stats::setNames(rep(list(numeric(0)), length(cols)), cols))
  if (is.null(x)) return(empty)
  if (is.list(x) && !is.data.frame(x)) {
    if (!all(cols %in% names(x))) {
      abort("`", arg, "` must be a list or data frame with elements ",
            paste(cols, collapse = " and "), "; got ",
            if (length(names(x))) paste(names(x), collapse = ", ") else "no names",
            ".")
    }
    x <- tryCatch(as.data.frame(x[cols]), error = function(e) {
      abort("`", arg, "`: elements ", paste(cols, collapse = " and "),
            " must have the same length.")
    })
  }
  if (!is.data.frame(x) || !all(cols %in% names(x))) {
    abort("`", arg, "` must be NULL, a list or a data frame with columns ",
          paste(cols, collapse = " and "), ", not ", describe_type(x), ".")
  }
  x <- x[cols]
  for (cl in cols) {
    v <- x[[cl]]
    if (!is.numeric(v) || anyNA(v) || any(!is.finite(v)) ||
        any(v < 0) || (cl != cols[1] && any(v <= 0))) {
      abort("`", arg, "$", cl, "` must be ",
            if (cl == cols[1]) "non-negative" else "positive",
            " finite numbers.")
    }
  }
  rownames(x) <- NULL
  x
}

# Save the global RNG state; the returned function restores it (removing
# .Random.seed if there was none), like withr::with_seed without the import.
save_rng <- function() {
  env <- globalenv()
  had <- exists(".Random.seed", envir = env, inherits = FALSE)
  old <- if (had) get(".Random.seed", envir = env, inherits = FALSE) else NULL
  kind <- RNGkind()
  function() {
    do.call(RNGkind, as.list(kind))
    if (had) assign(".Random.seed", old, envir = env)
    else if (exists(".Random.seed", envir = env, inherits = FALSE))
      rm(".Random.seed", envir = env)
  }
}
