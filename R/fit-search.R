# The search of the noise-model fit: for fixed nonlinear parameters the
# squared amplitudes come from a non-negative Gauss-Newton solve (C++,
# src/avfit.cpp); the nonlinear parameters (catalogue `nl_range`) are
# profiled on log grids, refined by one-dimensional optimisation and, with
# several, jointly by Levenberg-Marquardt (R/fit-polish.R; Nelder-Mead
# where it does not converge). Every knob is in avfit_control().

#' Settings of the noise-model search
#'
#' Every tuning constant of the search [avfit()] runs, in one object.
#'
#' The nonlinear parameters (Gauss-Markov correlation times, sinusoid
#' frequencies) are profiled: with the amplitudes solved for at each value,
#' each parameter is first searched on a log grid over its range (the
#' catalogue's `nl_range`: `grid_smooth` points for parameters the Allan
#' variance varies smoothly with, such as `tc`; `grid_oscillatory` for
#' those it oscillates with, such as `f0`), or, when it has a start value,
#' on `grid_start` points within a factor `start_span` of it; the best grid
#' point is refined by [stats::optimize()] to `tol` (in log units). No
#' step of the search leaves a parameter's bounds (the catalogue's
#' `nl_bounds`: what the curve and the record can see, e.g. a filter
#' between the sampling interval and the longest tau, a frequency below
#' Nyquist); a start value outside them starts at the nearest bound. Terms
#' enter greedily (the first of `cycles` passes); with several nonlinear
#' parameters, each further pass refines each within a factor `local_span`
#' of its value, and a joint refinement follows (`polish`):
#' Levenberg-Marquardt on the profiled problem (at most `polish_maxit`
#' steps, each one amplitude solve and one finite difference of the basis
#' per parameter; it stops when a step gains less than `reltol` relatively
#' or none lowers the objective), then, only if it did not stop so,
#' Nelder-Mead ([stats::optim()], `maxit` iterations, relative tolerance
#' `reltol`) from where it left off. `polish = "nelder-mead"` (with
#' `cycles = 2`, the search before this version) skips the first. The
#' greedy order matters, so up to `max_orders`
#' orders (rotations and their reverses) are tried. For each set of
#' nonlinear values the squared amplitudes are found by at most
#' `inner_maxit` Gauss-Newton steps, stopping when the objective falls by
#' less than `inner_tol` relatively. When the EDF comes from the model, the
#' fit is repeated `edf_passes` times (the first with white-noise EDF).
#'
#' @param grid_smooth,grid_oscillatory,grid_start Grid sizes (whole
#'   numbers, at least 3).
#' @param start_span Factor (> 1) either side of a start value covered by
#'   its grid.
#' @param local_span Factor (> 1) either side of the current value searched
#'   when refining.
#' @param tol Tolerance of the one-dimensional refinement (log units).
#' @param maxit Maximum Nelder-Mead iterations.
#' @param reltol Relative convergence tolerance of the joint refinement.
#' @param cycles Passes over the nonlinear parameters (the first enters
#'   them greedily).
#' @param max_orders Greedy entry orders tried.
#' @param inner_maxit Maximum Gauss-Newton steps of the amplitude solve.
#' @param inner_tol Relative tolerance of the amplitude solve.
#' @param edf_passes Fits when the EDF is derived from the model (at least
#'   1).
#' @param model_error `FALSE` (default) or `TRUE` to give the weights a
#'   model-error term when the model departs from the curve beyond the
#'   points' scatter (chi-square above its 99.9% point): a relative
#'   discrepancy sigma_m, estimated from the residuals so that the
#'   chi-square per degree of freedom becomes 1, is added to every point's
#'   log-variance (`trigamma(edf / 2) + sigma_m^2`), and the fit repeated;
#'   sigma_m is reported as the fit's `model_error`. Off by default, for a
#'   measured reason: where the model lacks a term (a Gauss-Markov bump at
#'   long tau), the common floor lets the long-tau run pull the short-tau
#'   terms too (N off by 6%, out of its points' limits, in a curve where
#'   the exact weights give N to 0.03%), so that no reading stays measured.
#'   With the exact weights a departure is never ignored either: each
#'   reading's verdict checks the final model against the curve over the
#'   taus it rests on (see [analyze_imu()]), and [avrefine()] names what
#'   stays unexplained. [avrefine()] judges its candidates without it.
#' @param polish The joint refinement of several nonlinear parameters:
#'   `"lm"` (default; Levenberg-Marquardt, Nelder-Mead only where it does
#'   not converge) or `"nelder-mead"`.
#' @param polish_maxit Maximum Levenberg-Marquardt steps.
#' @return An object of class `"avfit_control"`: a list of the settings.
#' @seealso [avfit()]
#' @export
#' @examples
#' avfit_control()
#' x <- avsim(2^15, 100, N = 0.01, gm = list(sigma = 0.01, tc = 2), seed = 1)
#' fit <- avfit(allan(x, 100), c("N", "gm"),
#'              control = avfit_control(grid_smooth = 20))
#' fit$convergence
avfit_control <- function(grid_smooth = 40L, grid_oscillatory = 120L,
                          grid_start = 13L, start_span = 4, local_span = 1.5,
                          tol = 1e-7, maxit = 400L, reltol = 1e-10,
                          cycles = 1L, max_orders = 6L, inner_maxit = 100L,
                          inner_tol = 1e-12, edf_passes = 2L, model_error = FALSE,
                          polish = "lm", polish_maxit = 50L) {
  out <- list(
    grid_smooth = check_number(grid_smooth, "grid_smooth", 3, 1e5, integer = TRUE),
    grid_oscillatory = check_number(grid_oscillatory, "grid_oscillatory", 3, 1e5,
                                    integer = TRUE),
    grid_start = check_number(grid_start, "grid_start", 3, 1e5, integer = TRUE),
    start_span = check_number(start_span, "start_span", 1, Inf, open = TRUE),
    local_span = check_number(local_span, "local_span", 1, Inf, open = TRUE),
    tol = check_number(tol, "tol", 0, 1, open = TRUE),
    maxit = check_number(maxit, "maxit", 1, 1e7, integer = TRUE),
    reltol = check_number(reltol, "reltol", 0, 1, open = TRUE),
    cycles = check_number(cycles, "cycles", 1, 100, integer = TRUE),
    max_orders = check_number(max_orders, "max_orders", 1, 1000, integer = TRUE),
    inner_maxit = check_number(inner_maxit, "inner_maxit", 1, 1e7, integer = TRUE),
    inner_tol = check_number(inner_tol, "inner_tol", 0, 1, open = TRUE),
    edf_passes = check_number(edf_passes, "edf_passes", 1, 10, integer = TRUE),
    model_error = check_flag(model_error, "model_error"),
    polish = check_choice(polish, c("lm", "nelder-mead"), "polish"),
    polish_maxit = check_number(polish_maxit, "polish_maxit", 1, 1e5, integer = TRUE))
  structure(out, class = "avfit_control")
}

#' @export
print.avfit_control <- function(x, ...) {
  cat("<avfit_control>\n")
  v <- vapply(x, function(v) format(v), "")
  cat(paste0("  ", format(names(v)), " = ", v, "\n"), sep = "")
  invisible(x)
}

check_control <- function(control) {
  if (is.null(control)) return(avfit_control())
  if (is.list(control) && !inherits(control, "avfit_control")) {
    bad <- setdiff(names(control), names(formals(avfit_control)))
    if (is.null(names(control)) || length(bad) || is.data.frame(control)) {
      abort("`control` must be avfit_control() or a named list of its arguments",
            if (length(bad)) paste0("; unknown: ", paste(bad, collapse = ", ")), ".",
            class = "argument")
    }
    return(do.call(avfit_control, control))
  }
  if (!inherits(control, "avfit_control")) {
    abort("`control` must be avfit_control() or a list of its arguments, not ",
          describe_type(control), ".", class = "argument")
  }
  # a fit saved by an earlier version lacks the knobs added since: their
  # defaults
  if (!all(names(formals(avfit_control)) %in% names(control))) {
    control <- do.call(avfit_control, unclass(control))
  }
  control
}

# The fitting problem at fixed EDF: log data, weights, the model plan.
# What every amplitude solve of the search needs and that does not change
# between them is worked out here once: the amplitude coefficients, which
# are fixed, their labels, and the basis columns of the terms without
# free nonlinear parameters (N, B, K..., and the terms whose nonlinear
# values are held, as the loop's screening holds the model's), which do not
# depend on the values being searched.
fit_problem <- function(data, tau0, lay, bias_correct, corr, model_var = 0) {
  y <- log(data$avar) - if (bias_correct) log_bias(data$edf) else 0
  s <- sqrt(log_sd(data$edf)^2 + model_var)
  plan <- model_plan(lay)
  is_amp <- lay$role == "amp"
  amp <- list(name = lay$name[is_amp], fixed = lay$fixed[is_amp],
              label = lay$label[is_amp], value = lay$value[is_amp])
  held <- stats::setNames(lay$fixed, lay$name)
  const <- vapply(plan, function(p) !length(p$nl) || all(held[p$nl]), NA)
  basis0 <- plan_basis(plan[const], data$tau, tau0, stats::setNames(lay$value, lay$name))
  plan_nl <- plan[!const]
  # the full basis with the constant columns in place (the searched terms'
  # columns after them), and each amplitude's column in it, so that a
  # solve only fills the searched terms' columns
  cols <- c(colnames(basis0), unlist(lapply(plan_nl, `[[`, "amp")))
  B0 <- matrix(0, nrow(data), length(cols), dimnames = list(NULL, cols))
  B0[, seq_len(ncol(basis0))] <- basis0
  amp$col <- match(amp$name, cols)
  # what every solve reads, worked out once: the fixed amplitudes, the
  # free ones' template, the store's grid and each searched term's key
  amp$fixed_idx <- which(amp$fixed)
  amp$cc0 <- stats::setNames(numeric(sum(!amp$fixed)), amp$name[!amp$fixed])
  for (k in seq_along(plan_nl)) {
    plan_nl[[k]]$key <- basis_key(plan_nl[[k]]$entry)
    # its nonlinear values' positions in `values` (no name matching per solve)
    plan_nl[[k]]$nl_idx <- match(plan_nl[[k]]$nl, lay$name)
  }
  list(data = data, tau0 = tau0, lay = lay, plan = plan, y = y,
       s = s, W = whitening(s, corr), corr = corr, bias_correct = bias_correct,
       amp = amp, plan_nl = plan_nl, basis0 = basis0, B0 = B0,
       nl_cols = lapply(plan_nl, function(p) match(p$amp, cols)),
       values = stats::setNames(lay$value, lay$name),
       memo = new.env(parent = emptyenv()), tau = data$tau,
       store = basis_store_env(data$tau, tau0), zero = numeric(nrow(data)))
}

# The basis of a solve: the problem's constant columns and the searched
# terms' columns at `values`, each term's kept in the problem's memo while
# its values do not move (what plan_basis() does with a memo, without
# rebuilding the constant part per solve). `store`: the call's store of
# columns (pr$store), or NULL for values no later search meets again.
solve_basis <- function(pr, values, store = pr$store) {
  Bm <- pr$B0
  memo <- pr$memo
  for (k in seq_along(pr$plan_nl)) {
    p <- pr$plan_nl[[k]]
    nl <- NULL
    if (length(p$nl)) {
      nl <- values[p$nl_idx]
      names(nl) <- p$nl_param
    }
    hit <- memo[[p$label]]
    if (is.null(hit) || !identical(hit$nl, nl)) {
      hit <- list(nl = nl, b = stored_basis_in(store, p$entry, p$key, pr$tau,
                                               pr$tau0, nl))
      assign(p$label, hit, envir = memo)
    }
    Bm[, pr$nl_cols[[k]]] <- hit$b
  }
  Bm
}

# The Allan variance of the fixed amplitudes' terms in basis `Bm`: a
# solve's offset.
fixed_av <- function(pr, Bm) {
  amp <- pr$amp
  av <- pr$zero
  for (i in amp$fixed_idx) av <- av + amp$value[i]^2 * Bm[, amp$col[i]]
  av
}

# Solve for the squared amplitudes at nonlinear values `nlv` (named by
# coefficient). `off`: instance labels left out (amplitude 0) for this
# solve. Returns c (named by free amplitude coefficient), objective,
# iterations, converged and (unless `layout = FALSE`, as in the search's
# objective) the layout with the nonlinear values set. `store`: see
# solve_basis().
solve_amps <- function(pr, nlv, control, off = NULL, layout = TRUE, store = pr$store) {
  values <- pr$values
  if (length(nlv)) values[names(nlv)] <- nlv
  amp <- pr$amp
  Bm <- solve_basis(pr, values, store)
  # the free set, its columns and its warm-start key: kept in the memo for
  # the solves without `off` (most of them)
  fs <- if (is.null(off)) pr$memo[["\001free"]]
  if (is.null(fs)) {
    on <- if (is.null(off)) !amp$fixed else !amp$fixed & !amp$label %in% off
    fs <- list(free = amp$name[on], cols = amp$col[on],
               key = paste(amp$name[on], collapse = "\r"),
               pos = match(amp$name[on], names(amp$cc0)))
    fs$all <- identical(fs$cols, seq_len(ncol(Bm)))
    if (is.null(off)) assign("\001free", fs, envir = pr$memo)
  }
  free <- fs$free
  offset <- fixed_av(pr, Bm)
  cc <- amp$cc0
  lay <- NULL
  if (layout) {
    lay <- pr$lay
    if (length(nlv)) lay$value[match(names(nlv), lay$name)] <- nlv
  }
  if (!length(free)) {
    obj <- if (all(offset > 0)) sum(wmul(pr$W, pr$y - log(offset))^2) else Inf
    return(list(c = cc, objective = obj, iterations = 0L, converged = TRUE,
                layout = lay))
  }
  # warm start: the last solve of this problem with the same free set (the
  # search's next value is near its last one)
  key <- fs$key
  prev <- pr$memo[["\001warm"]]
  c0 <- if (!is.null(prev) && identical(prev$key, key)) prev$c else numeric(length(free))
  r <- avfit_log_nnls(if (fs$all) Bm else Bm[, fs$cols, drop = FALSE], offset, pr$y,
                      pr$W, c0, control$inner_maxit, control$inner_tol)
  if (all(is.finite(r$c)) && sum(r$c) > 0) {
    assign("\001warm", list(key = key, c = r$c), envir = pr$memo)
  }
  cc[fs$pos] <- r$c
  list(c = cc, objective = r$objective, iterations = r$iterations,
       converged = r$converged, layout = lay)
}

# The profile search. `start`: named start values of nonlinear
# coefficients; `prev`: the result of a previous pass (its values start this
# one and only local refinement is done). Returns the layout with every
# value set, the objective and the convergence record.
fit_search <- function(pr, start, prev, control) {
  lay <- pr$lay
  freq <- if (is.null(pr$tau0)) NULL else 1 / pr$tau0
  nlrows <- which(lay$role == "nonlinear" & !lay$fixed)
  nlv <- stats::setNames(numeric(length(nlrows)), lay$name[nlrows])
  nl_names <- names(nlv)
  evals <- 0L
  # Every nonlinear parameter stays within its entry's hard bounds (what
  # the curve and the record can see): outside them the objective is
  # infinite, so neither a start, a grid nor Nelder-Mead can leave them
  # (polish_lm() clamps its steps to them).
  lb <- ub <- numeric(length(nlrows))
  # The grids' columns go to the call's store (the same candidate's grid
  # comes back at the next step); the values optimize() and the joint
  # refinement visit are met by no other search, so they are not stored.
  store <- NULL
  obj <- function(lognl, off = NULL) {
    if (any(lognl < lb | lognl > ub)) return(Inf)
    evals <<- evals + 1L
    v <- exp(lognl)
    names(v) <- nl_names
    solve_amps(pr, v, control, off, layout = FALSE, store = store)$objective
  }
  nm <- NULL
  if (length(nlrows)) {
    entries <- lapply(nlrows, function(i) effect_entry(lay$kind[i], lay$variant[i]))
    bounds <- lapply(seq_along(nlrows), function(k) {
      effect_nl_bounds(entries[[k]], lay$param[nlrows[k]], pr$data$tau, freq)
    })
    lb <- log(vapply(bounds, `[`, 0, 1L))
    ub <- log(vapply(bounds, `[`, 0, 2L))
    clamp <- function(v, k) min(max(v, lb[k]), ub[k])
    # the grid's range, within the bounds
    ranges <- lapply(seq_along(nlrows), function(k) {
      r <- entries[[k]]$nl_range(pr$data$tau, freq)[[lay$param[nlrows[k]]]]
      r <- exp(c(clamp(log(r[1]), k), clamp(log(r[2]), k)))
      if (r[1] < r[2]) r else bounds[[k]]
    })
    profile <- vapply(nlrows, function(i) {
      p <- effect_entry(lay$kind[i], lay$variant[i])$params
      p$profile[p$name == lay$param[i]]
    }, "")
    # initial values: previous pass, start, or grid centre
    for (k in seq_along(nlrows)) {
      nm_k <- names(nlv)[k]
      nlv[k] <- if (!is.null(prev)) prev$layout$value[prev$layout$name == nm_k] else
        if (!is.null(start) && nm_k %in% names(start)) start[[nm_k]] else
          sqrt(prod(ranges[[k]]))
      nlv[k] <- exp(clamp(log(nlv[[k]]), k))
    }
    # a parameter with a start (given, or from the previous pass) is refined
    # locally; the others are searched on the grid first
    has_start <- names(nlv) %in% names(start)
    search <- function(order) {
      lognl <- log(nlv)
      cycles <- if (length(nlrows) > 1L) control$cycles else 1L
      for (cy in seq_len(cycles)) {
        for (pos in seq_along(order)) {
          k <- order[pos]
          # first cycle: terms not searched yet stay out of the model (greedy)
          later <- if (cy == 1L) {
            j <- order[seq_along(order) > pos]
            lay$label[nlrows[j[!has_start[j]]]]
          } else NULL
          f1 <- function(v) { l <- lognl; l[k] <- v; obj(l, later) }
          if (lay$label[nlrows[k]] %in% later &&
              !any(lay$fixed[lay$label == lay$label[nlrows[k]] & lay$role == "amp"])) {
            # this parameter's own term is left out (its other parameter
            # enters later): the objective does not depend on v, so one
            # solve gives every value (each still counted as an evaluation)
            flat <- NULL
            f1 <- function(v) {
              l <- lognl
              l[k] <- v
              if (any(l < lb | l > ub)) return(Inf)
              if (is.null(flat)) return(flat <<- obj(l, later))
              evals <<- evals + 1L
              flat
            }
          }
          if (cy > 1L || !is.null(prev)) {
            lo <- clamp(lognl[k] - log(control$local_span), k)
            hi <- clamp(lognl[k] + log(control$local_span), k)
          } else {
            # a start value: a short grid around it; otherwise the whole range
            ng <- if (has_start[k]) control$grid_start else
              control[[paste0("grid_", profile[k])]]
            g <- if (has_start[k]) {
              vapply(lognl[k] + seq(-log(control$start_span), log(control$start_span),
                                    length.out = ng), clamp, 0, k = k)
            } else {
              seq(log(ranges[[k]][1]), log(ranges[[k]][2]), length.out = ng)
            }
            store <<- pr$store
            vals <- vapply(g, f1, 0)
            store <<- NULL
            i <- which.min(vals)
            lo <- g[max(i - 1L, 1L)]; hi <- g[min(i + 1L, ng)]
            lognl[k] <- g[i]
          }
          if (hi > lo) {
            o <- stats::optimize(f1, c(lo, hi), tol = control$tol)
            if (o$objective <= f1(lognl[k])) lognl[k] <- o$minimum
          }
        }
      }
      nm <- NULL
      if (length(nlrows) > 1L) {
        v0 <- obj(lognl)
        count <- 0L
        nm_count <- 0L
        conv <- 1L
        if (control$polish == "lm") {
          pol <- polish_lm(pr, lognl, lb, ub, control)
          evals <<- evals + pol$evals
          count <- pol$evals
          if (pol$value <= v0) {
            lognl <- pol$lognl
            v0 <- pol$value
          }
          if (pol$converged) conv <- 0L
        }
        # Nelder-Mead restarted from its own result (a fresh simplex) until
        # it stops on its tolerance or a restart no longer improves: a
        # simplex that collapsed along a curved valley otherwise spends
        # maxit crawling. A restart that gains less than reltol (relative)
        # means the search sits at the optimum.
        if (conv != 0L) {
          for (restart in seq_len(4L)) {
            o <- stats::optim(lognl, obj, method = "Nelder-Mead",
                              control = list(reltol = control$reltol,
                                             maxit = control$maxit))
            count <- count + o$counts[["function"]]
            nm_count <- nm_count + o$counts[["function"]]
            gain <- v0 - o$value
            if (o$value <= v0) lognl <- o$par
            # (a restart too short to move the simplex proves nothing)
            if (o$convergence == 0L ||
                (restart > 1L && o$counts[["function"]] >= 20L * length(lognl) &&
                 gain <= control$reltol * (abs(v0) + control$reltol))) {
              conv <- 0L
              break
            }
            v0 <- min(v0, o$value)
          }
        }
        nm <- list(convergence = conv, count = count, nm_count = nm_count)
      }
      list(lognl = lognl, value = obj(lognl), nm = nm)
    }
    # The greedy search depends on the order in which the terms enter; with
    # several unstarted nonlinear terms try each rotation of the order (and
    # its reverse) and keep the best objective.
    K <- length(nlrows)
    orders <- list(seq_len(K))
    if (is.null(prev) && sum(!has_start) > 1L) {
      rot <- lapply(seq_len(K) - 1L, function(r) (seq_len(K) + r - 1L) %% K + 1L)
      orders <- unique(c(rot, lapply(rot, rev)))
      if (length(orders) > control$max_orders) orders <- orders[seq_len(control$max_orders)]
    }
    # Orders that end in the same optimum (the same terms, labelled in
    # another order) tie to within rounding: the first order keeps it.
    best <- NULL
    for (ord in orders) {
      r <- search(ord)
      if (is.null(best) || r$value < best$value - 1e-9 * max(1, abs(best$value))) {
        best <- r
      }
    }
    nlv[] <- exp(best$lognl)
    nm <- best$nm
  }
  sol <- solve_amps(pr, nlv, control)
  lay2 <- sol$layout
  amprows <- which(lay2$role == "amp" & !lay2$fixed)
  lay2$value[amprows] <- sqrt(pmax(sol$c[lay2$name[amprows]], 0))
  list(layout = lay2, objective = sol$objective,
       convergence = search_convergence(sol, nm, evals, control))
}

# What the search says about its own convergence: the final amplitude solve
# and, with several nonlinear parameters, the joint refinement.
search_convergence <- function(sol, nm, evals, control) {
  msg <- character()
  if (!isTRUE(sol$converged)) {
    msg <- c(msg, sprintf(
      "the amplitude solve stopped after %d Gauss-Newton steps (inner_maxit = %d) before converging",
      sol$iterations, control$inner_maxit))
  }
  if (!is.null(nm) && nm$convergence != 0L) {
    msg <- c(msg, sprintf(
      "%sNelder-Mead stopped after %d evaluations (maxit = %d) before converging",
      if (control$polish == "lm") sprintf(
        "Levenberg-Marquardt did not converge in %d steps (polish_maxit) and ",
        control$polish_maxit) else "",
      nm$nm_count, control$maxit))
  }
  list(converged = !length(msg),
       iterations = if (is.null(nm)) as.integer(sol$iterations) else as.integer(nm$count),
       evaluations = as.integer(evals),
       message = if (length(msg)) paste(msg, collapse = "; ") else "converged")
}

# The model-error variance (log scale) the residuals of `res` on problem
# `pr` call for: 0 while the chi-square of the points' own scatter stays
# below its 99.9% point; else the v with sum r^2 / (s^2 + v) = dof.
model_error_var <- function(res, pr) {
  lay <- res$layout
  dof <- nrow(pr$data) - sum(!lay$fixed)
  if (dof < 1L) return(0)
  fitted <- rowSums(model_components(pr$data$tau, pr$tau0, lay, pr$plan))
  r2 <- (pr$y - log(fitted))^2
  s2 <- log_sd(pr$data$edf)^2
  if (!all(is.finite(r2)) || sum(r2 / s2) <= stats::qchisq(0.999, dof)) return(0)
  f <- function(v) sum(r2 / (s2 + v)) - dof
  hi <- max(r2) * length(r2)
  if (f(hi) > 0) return(hi)
  stats::uniroot(f, c(0, hi), tol = 1e-10 * hi)$root
}
