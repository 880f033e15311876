#' Simulate a rate signal with a known noise model
#'
#' Generates `n` rate samples (angular rate, acceleration, fractional
#' frequency) at `freq` Hz as the sum of independent noise terms whose
#' expected Allan variance is the catalogue's exact discrete form
#' ([av_model()] with the same `freq`), so that a simulation and its
#' theory can be compared directly.
#'
#' Each effect of the catalogue ([av_terms()]) is given by name in `...`:
#' a single-parameter term by its coefficient (`N = 0.01`), a term with
#' several parameters by a list or data frame of them, one row per instance
#' for the repeatable ones (`gm = data.frame(sigma = , tc = )`). Each
#' entry's simulator is used, in the catalogue's order. The built-in
#' recipes (\eqn{\tau_0 = 1/f}, \eqn{w} standard normal):
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
#' @param ... The effects, named by their term: non-negative coefficients
#'   in IEEE 952 units ("u" the rate unit) for quantization `Q` \[u s\],
#'   white noise `N` \[u sqrt(s)\], bias instability (flicker) `B` \[u\],
#'   rate random walk `K` \[u/sqrt(s)\], rate ramp `R` \[u/s\]; Gauss-Markov
#'   terms `gm` as a list `list(sigma = , tc = )` or a data frame with
#'   columns `sigma` \[u\] and `tc` \[s\], one row per term; sinusoidal
#'   terms `sinusoid` as a list `list(amp = , f0 = )` or a data frame with
#'   columns `amp` \[u\] and `f0` \[Hz\] (below `freq / 2`). Any other effect
#'   registered in the catalogue likewise, by its parameters.
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
avsim <- function(n, freq, ..., seed = NULL) {
  check_present(missing(n), "n", "the number of samples")
  check_present(missing(freq), "freq", "the sampling frequency in Hz")
  n <- check_number(n, "n", lo = 2, hi = 2^31 - 1, integer = TRUE)
  freq <- check_freq(freq)
  effects <- list(...)
  nm <- names(effects)
  if (length(effects) && (is.null(nm) || any(!nzchar(nm)))) {
    abort("The effects in `...` must be named by their term, e.g. ",
          "avsim(n, freq, N = 0.01); see av_terms().", class = "argument")
  }
  kinds <- effect_kinds(c("av", "series"))
  unknown <- setdiff(nm, kinds)
  if (length(unknown)) {
    abort("`", unknown[1], "` is not an effect of the catalogue; known ",
          "effects are ", paste(kinds, collapse = ", "), ".", class = "argument")
  }
  if (anyDuplicated(nm)) {
    abort("`", nm[duplicated(nm)][1], "` is given twice.", class = "argument")
  }
  # Check everything before drawing anything.
  specs <- list()
  for (k in intersect(kinds, nm)) {
    e <- effect_entry(k)
    if (isTRUE(e$bare)) {
      specs[[k]] <- check_number(effects[[k]], k, lo = 0)
    } else {
      tab <- check_term_table(effects[[k]], k, e$params)
      if (!e$repeatable && nrow(tab) > 1L) {
        abort("`", k, "` may appear once; give one row.", class = "argument")
      }
      if (!is.null(e$sim_check)) e$sim_check(tab, freq, k)
      specs[[k]] <- tab
    }
  }
  if (!is.null(seed)) {
    seed <- check_number(seed, "seed", integer = TRUE,
                         lo = -.Machine$integer.max, hi = .Machine$integer.max)
    restore <- save_rng()
    on.exit(restore(), add = TRUE)
    set.seed(seed)
  }
  tau0 <- 1 / freq
  y <- numeric(n)
  coef <- numeric(0)
  for (k in names(specs)) {
    e <- effect_entry(k)
    v <- specs[[k]]
    if (isTRUE(e$bare)) {
      if (v > 0) {
        y <- y + e$sim(n, tau0, stats::setNames(v, k), NULL)
        coef[k] <- v
      }
      next
    }
    p <- e$params
    amp <- p$name[p$role == "amp"]
    nl <- p$name[p$role == "nonlinear"]
    if (!nrow(v)) next
    labels <- instance_labels(e, nrow(v))
    for (i in seq_len(nrow(v))) {
      row <- unlist(v[i, p$name, drop = FALSE])
      y <- y + e$sim(n, tau0, row[amp], if (length(nl)) row[nl] else NULL)
      coef[coef_names(e, labels[i])] <- unname(row)
    }
  }
  out <- stats::ts(y, start = 0, frequency = freq)
  attr(out, "coef") <- coef
  out
}

# The argument of an effect with several parameters: NULL, a list or a data
# frame with the parameters as columns -> a data frame (zero rows for NULL).
# Amplitudes must be non-negative, nonlinear parameters positive.
check_term_table <- function(x, arg, params) {
  cols <- params$name
  empty <- as.data.frame(stats::setNames(rep(list(numeric(0)), length(cols)), cols))
  if (is.null(x)) return(empty)
  if (is.list(x) && !is.data.frame(x)) {
    if (!all(cols %in% names(x))) {
      abort("`", arg, "` must be a list or data frame with elements ",
            paste(cols, collapse = " and "), "; got ",
            if (length(names(x))) paste(names(x), collapse = ", ") else "no names",
            ".", class = "argument")
    }
    lens <- lengths(x[cols])
    if (length(unique(lens)) != 1L) {
      abort("`", arg, "`: elements ", paste(cols, collapse = " and "),
            " must have the same length.", class = "argument")
    }
    x <- as.data.frame(x[cols])
  }
  if (!is.data.frame(x) || !all(cols %in% names(x))) {
    abort("`", arg, "` must be NULL, a list or a data frame with columns ",
          paste(cols, collapse = " and "), ", not ", describe_type(x), ".",
          class = "argument")
  }
  x <- x[cols]
  for (j in seq_along(cols)) {
    v <- x[[cols[j]]]
    amp <- params$role[j] == "amp"
    if (!is.numeric(v) || anyNA(v) || any(!is.finite(v)) ||
        any(v < 0) || (!amp && any(v <= 0))) {
      abort("`", arg, "$", cols[j], "` must be ",
            if (amp) "non-negative" else "positive",
            " finite numbers.", class = "argument")
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
