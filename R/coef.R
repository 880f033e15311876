# Terms and coefficient vectors of a model, and the model's expected AV,
# built from the catalogue: which instances a `terms` vector asks for, how
# their coefficients are named, and the basis matrix the fit solves with.
#
# A term is "kind" or "kind:variant"; an instance's label is the kind
# ("N"), numbered for repeatable kinds ("gm1"), with "_variant" appended
# for a variant. Coefficients are named "label.param", or bare ("N") for a
# single-parameter entry named as its parameter.

# Split "kind:variant" -> list(kind, variant ("" for none)).
split_term <- function(terms) {
  kind <- sub(":.*$", "", terms)
  has <- grepl(":", terms, fixed = TRUE)
  # (no variant anywhere, the common case: what ifelse() gives, without it)
  variant <- if (length(has) && !any(has)) rep("", length(has)) else
    ifelse(has, sub("^[^:]*:", "", terms), "")
  list(kind = kind, variant = variant)
}

# Validate a `terms` vector (repeatable kinds may repeat) and return it in
# canonical (catalogue) order.
check_terms <- function(terms, arg = "terms") {
  # every refit of the loop checks its terms again: a set that passed is
  # kept with the layouts (coef_layout(); emptied with them when the
  # catalogue changes), so the checks run once per set
  key <- if (is.character(terms) && length(terms) && !anyNA(terms))
    paste0("\001", paste(terms, collapse = "\r"))
  if (!is.null(key)) {
    hit <- .catalogue$layouts[[key]]
    if (!is.null(hit)) return(hit)
  }
  out <- check_terms_now(terms, arg)
  if (is.null(.catalogue$layouts)) .catalogue$layouts <- new.env(parent = emptyenv())
  assign(key, out, envir = .catalogue$layouts)
  out
}
check_terms_now <- function(terms, arg) {
  kinds <- effect_kinds()
  if (!is.character(terms) || length(terms) == 0L || anyNA(terms)) {
    abort("`", arg, "` must be a character vector of term names (",
          paste(kinds, collapse = ", "), "), not ", describe_type(terms), ".",
          class = "argument")
  }
  sp <- split_term(terms)
  bad <- setdiff(sp$kind, kinds)
  if (length(bad)) {
    abort("`", arg, "` contains unknown term ", encodeString(bad[1], quote = '"'),
          "; known terms are ", paste(kinds, collapse = ", "), ".",
          class = "argument")
  }
  for (i in which(nzchar(sp$variant))) effect_entry(sp$kind[i], sp$variant[i])
  rep_ok <- vapply(sp$kind, function(k) effect_entry(k)$repeatable, logical(1))
  single <- terms[!rep_ok]
  if (anyDuplicated(sp$kind[!rep_ok])) {
    rep_kinds <- kinds[vapply(kinds, function(k) effect_entry(k)$repeatable, logical(1))]
    abort("`", arg, "` repeats \"", single[duplicated(sp$kind[!rep_ok])][1],
          "\"; only ", and_list(rep_kinds),
          " may appear more than once.", class = "argument")
  }
  terms[order(match(sp$kind, kinds))]
}

# Labels of the term instances: c("N", "gm", "gm") -> c("N", "gm1", "gm2").
term_labels <- function(terms) {
  # the loop asks for the labels of the same few sets hundreds of times:
  # kept with the layouts (a pure function of the terms and the catalogue)
  key <- if (is.character(terms) && length(terms) && !anyNA(terms) &&
             is.null(attributes(terms)))
    paste0("\003", paste(terms, collapse = "\r"))
  catalogue_memo(key, function() term_labels_now(terms))
}

# `make()`'s value kept under `key` in the catalogue's store (emptied by
# register_effect() and unregister_effect()); NULL `key`: not kept.
catalogue_memo <- function(key, make) {
  if (is.null(key)) return(make())
  hit <- .catalogue$layouts[[key]]
  if (!is.null(hit)) return(hit)
  out <- make()
  if (is.null(.catalogue$layouts)) .catalogue$layouts <- new.env(parent = emptyenv())
  assign(key, out, envir = .catalogue$layouts)
  out
}
term_labels_now <- function(terms) {
  terms <- check_terms(terms)
  sp <- split_term(terms)
  lab <- sp$kind
  for (k in unique(sp$kind)) {
    i <- which(sp$kind == k)
    lab[i] <- instance_labels(effect_entry(k), length(i))
  }
  ifelse(nzchar(sp$variant), paste0(lab, "_", sp$variant), lab)
}

# Labels of `count` instances of entry `e` (any component): the kind, or the
# kind numbered for a repeatable entry.
instance_labels <- function(e, count) {
  if (e$repeatable) paste0(e$name, seq_len(count)) else rep(e$name, count)
}

# Kind and variant of labels: "gm2" -> ("gm", ""), "fwn1_ma" -> ("fwn", "ma").
parse_labels <- function(labels) {
  base <- sub("_.*$", "", labels)
  list(kind = sub("[0-9]+$", "", base),
       variant = ifelse(grepl("_", labels, fixed = TRUE), sub("^[^_]*_", "", labels), ""))
}

# Coefficient names of one instance.
coef_names <- function(e, label) {
  if (isTRUE(e$bare)) e$params$name else paste0(label, ".", e$params$name)
}

#' Layout of the coefficient vector for a set of terms (internal).
#'
#' One row per coefficient: `name` (e.g. "gm1.tc"), `label` (term instance,
#' "gm1"), `kind` ("gm"), `variant` ("" for none), `param` ("tc"), `role`
#' ("amp" or "nonlinear"), `unit`.
#' @noRd
coef_layout <- function(terms) {
  # the loop's refits ask for the same few layouts thousands of times:
  # each set of terms is built once per catalogue (register_effect() and
  # unregister_effect() empty the store)
  key <- if (is.character(terms) && !anyNA(terms)) paste(terms, collapse = "\r")
  catalogue_memo(key, function() build_coef_layout(terms))
}

build_coef_layout <- function(terms) {
  terms <- check_terms(terms)
  labs <- term_labels(terms)
  sp <- split_term(terms)
  # the columns concatenated over the terms, one data frame (a data frame
  # per term bound by rbind() cost more than the loop's refits using it)
  ents <- lapply(seq_along(terms), function(i) effect_entry(sp$kind[i], sp$variant[i]))
  np <- vapply(ents, function(e) nrow(e$params), 0L)
  col <- function(f) unlist(lapply(ents, function(e) e$params[[f]]), use.names = FALSE)
  data.frame(name = unlist(lapply(seq_along(ents), function(i) coef_names(ents[[i]], labs[i])),
                           use.names = FALSE),
             label = rep(labs, np), kind = rep(sp$kind, np), variant = rep(sp$variant, np),
             param = col("name"), role = col("role"), unit = col("unit"),
             hidden = col("hidden"), stringsAsFactors = FALSE)
}

# The terms a layout was built from, e.g. c("N", "gm", "gm").
layout_terms <- function(lay) {
  u <- lay[!duplicated(lay$label), , drop = FALSE]
  ifelse(nzchar(u$variant), paste0(u$kind, ":", u$variant), u$kind)
}

# Term strings from coefficient names: c("N", "gm1.sigma", "gm1.tc") ->
# c("N", "gm").
terms_from_coef <- function(names) {
  lab <- unique(sub("\\..*$", "", names))
  pl <- parse_labels(lab)
  ifelse(nzchar(pl$variant), paste0(pl$kind, ":", pl$variant), pl$kind)
}

# Check a named coefficient vector against the catalogue; returns its
# layout with a `value` column.
check_coef <- function(coef, arg = "coef") {
  if (is.list(coef) && !is.data.frame(coef)) coef <- unlist(coef)
  if (!is.numeric(coef) || is.null(names(coef)) || any(!nzchar(names(coef))) ||
      anyNA(coef)) {
    abort("`", arg, "` must be a named numeric vector of coefficients such as ",
          "c(N = 1e-3, B = 1e-4, gm1.sigma = 0.01, gm1.tc = 10), not ",
          describe_type(coef), ".", class = "argument")
  }
  terms <- terms_from_coef(names(coef))
  kinds <- split_term(terms)$kind
  bad <- setdiff(kinds, effect_kinds())
  if (length(bad)) {
    abort("`", arg, "` has a coefficient for the unknown term \"", bad[1],
          "\"; see av_terms().", class = "argument")
  }
  lay <- coef_layout(terms)
  # Labels as given by the user (gm1, gm3) may not be 1..k: map by label in
  # order of appearance within each kind.
  ulab <- unique(sub("\\..*$", "", names(coef)))
  ulab <- ulab[order(match(parse_labels(ulab)$kind, effect_kinds()))]
  lay$label <- ulab[match(lay$label, unique(lay$label))]
  bare <- vapply(seq_len(nrow(lay)), function(i) {
    isTRUE(effect_entry(lay$kind[i], lay$variant[i])$bare)
  }, logical(1))
  lay$name <- ifelse(bare, lay$param, paste0(lay$label, ".", lay$param))
  miss <- setdiff(lay$name, names(coef))
  if (length(miss)) {
    abort("`", arg, "` lacks the coefficient ", miss[1], ".", class = "argument")
  }
  extra <- setdiff(names(coef), lay$name)
  if (length(extra)) {
    abort("`", arg, "` has an unknown coefficient ", extra[1], ".",
          class = "argument")
  }
  val <- coef[lay$name]
  if (any(val[lay$role == "amp"] < 0)) {
    abort("`", arg, "`: amplitudes must be non-negative.", class = "argument")
  }
  if (any(val[lay$role == "nonlinear"] <= 0)) {
    nl <- unique(lay[lay$role == "nonlinear", c("kind", "param")])
    abort("`", arg, "`: ", paste0(nl$kind, " ", nl$param, collapse = ", "),
          " must be positive.", class = "argument")
  }
  lay$value <- unname(val)
  lay
}

# ---- evaluating a model -----------------------------------------------------

# A model plan: per instance its resolved entry and the names of its
# amplitude and nonlinear coefficients, built once per layout so that the
# fit's many evaluations do not re-read the layout.
model_plan <- function(lay) {
  labs <- unique(lay$label)
  # the layout's columns as vectors (every fit of the loop plans its
  # layout; data frame row subsets per label cost more than the rest)
  label <- lay$label
  name <- lay$name
  role <- lay$role
  param <- lay$param
  lapply(labs, function(l) {
    i <- which(label == l)
    r <- role[i]
    e <- effect_entry(lay$kind[i[1L]], lay$variant[i[1L]])
    list(label = l, entry = e,
         amp = name[i][r == "amp"],
         nl = name[i][r == "nonlinear"],
         nl_param = param[i][r == "nonlinear"])
  })
}

# Basis matrix: AV per squared amplitude, one column per amplitude
# coefficient, rows are tau. `values` is a named vector holding (at least)
# the nonlinear coefficients.
# `memo`: an environment keeping each term's last columns and the values
# they were made at, for a search that calls this for one `tau` many times
# and moves one term at a time (the others' columns are reused as made).
plan_basis <- function(plan, tau, tau0, values, memo = NULL) {
  amps <- unlist(lapply(plan, `[[`, "amp"))
  out <- matrix(0, length(tau), length(amps), dimnames = list(NULL, amps))
  for (p in plan) {
    nl <- if (length(p$nl)) stats::setNames(values[p$nl], p$nl_param) else NULL
    if (is.null(memo)) {
      out[, p$amp] <- stored_basis(p$entry, tau, tau0, nl)
      next
    }
    hit <- memo[[p$label]]
    if (is.null(hit) || !identical(hit$nl, nl)) {
      hit <- list(nl = nl, b = stored_basis(p$entry, tau, tau0, nl))
      assign(p$label, hit, envir = memo)
    }
    out[, p$amp] <- hit$b
  }
  out
}

# The basis columns of one term, through the store avrefine() opens for
# its call: the loop's many refits rebuild the same terms at the same
# values (each candidate's grid, the model's terms at their current
# values), so each (term, values, tau grid) is built once per call. The
# columns are a pure function of those, so the store changes no result.
# Outside a loop, and on long tau grids, the columns are built directly.
basis_store <- new.env(parent = emptyenv())
basis_store$depth <- 0L
basis_store$slots <- list()

# A store that lives for one call of the outermost function that opens it
# (the basis store above, the refit memo of R/refine-refits.R): `depth`
# counts the opens, and the store's `field` is emptied when the last one
# closes.
call_store_open <- function(store) {
  store$depth <- store$depth + 1L
  invisible(NULL)
}

call_store_close <- function(store, field) {
  store$depth <- max(store$depth - 1L, 0L)
  if (store$depth == 0L) store[[field]] <- list()
  invisible(NULL)
}

stored_basis <- function(entry, tau, tau0, nl) {
  stored_basis_in(basis_store_env(tau, tau0), entry, basis_key(entry), tau, tau0, nl)
}

# The store's environment for one tau grid (NULL: no store, outside a loop
# or on a long grid), made when first asked for.
basis_store_env <- function(tau, tau0) {
  if (basis_store$depth == 0L || length(tau) > 2048L) return(NULL)
  slots <- basis_store$slots
  for (s in slots) {
    if (identical(s$tau, tau) && identical(s$tau0, tau0)) return(s$env)
  }
  env <- new.env(hash = TRUE, parent = emptyenv())
  # a few tau grids per call (the curve, a trimmed range); oldest out
  if (length(slots) >= 8L) slots <- slots[-1L]
  basis_store$slots <- c(slots, list(list(tau = tau, tau0 = tau0, env = env)))
  env
}

# The entry's part of a store key.
# [[ ]]: `$variant` would partially match `variants` on a bare entry
basis_key <- function(entry) paste0(entry[["name"]], ":", entry[["variant"]], "|")

# stored_basis() with the grid's environment `env` (or NULL) and the
# entry's key part `key` found beforehand (a search asks for one term's
# columns at many values on one grid).
stored_basis_in <- function(env, entry, key, tau, tau0, nl) {
  if (is.null(env)) return(entry$basis(tau, tau0, nl))
  # (one value, the common case: its hex form is the collapsed string)
  key <- paste0(key, if (length(nl) == 1L) sprintf("%a", nl) else
    paste(sprintf("%a", nl), collapse = ","))
  b <- env[[key]]
  if (is.null(b)) {
    b <- entry$basis(tau, tau0, nl)
    assign(key, b, envir = env)
  }
  b
}

# Per-instance AV contributions (matrix, columns = term labels).
model_components <- function(tau, tau0, lay, plan = model_plan(lay)) {
  values <- stats::setNames(lay$value, lay$name)
  basis_components(plan_basis(plan, tau, tau0, values), plan, values)
}

# The same from the basis columns `Bm` (plan_basis()) at `values`.
basis_components <- function(Bm, plan, values) {
  out <- matrix(0, nrow(Bm), length(plan),
                dimnames = list(NULL, vapply(plan, `[[`, "", "label")))
  for (j in seq_along(plan)) {
    a <- plan[[j]]$amp
    out[, j] <- Bm[, a, drop = FALSE] %*% (values[a]^2)
  }
  out
}

# Power-law exponent per instance at each tau, for the EDF (matrix like
# model_components()); NA marks a deterministic term.
model_alpha <- function(tau, tau0, lay, plan = model_plan(lay)) {
  values <- stats::setNames(lay$value, lay$name)
  out <- matrix(NA_real_, length(tau), length(plan),
                dimnames = list(NULL, vapply(plan, `[[`, "", "label")))
  for (j in seq_along(plan)) {
    p <- plan[[j]]
    nl <- if (length(p$nl)) stats::setNames(values[p$nl], p$nl_param) else NULL
    out[, j] <- p$entry$edf_alpha(tau, tau0, nl)
  }
  out
}

# The autocovariance of the sampled rate at lags `h` (samples) that the
# model with coefficients `values` (layout `lay`) implies: each term's
# entry `acf` (per squared amplitude) times its amplitude squared. Terms
# without one (the random walk, flicker, a ramp: not stationary) are left
# out; over a few lags they are flat and cancel in differences.
model_acov <- function(lay, values, h, tau0) {
  out <- numeric(length(h))
  for (p in model_plan(lay)) {
    if (is.null(p$entry$acf) || length(p$amp) != 1L) next
    nl <- if (length(p$nl)) as.list(stats::setNames(unname(values[p$nl]), p$nl_param))
    out <- out + unname(values[[p$amp]])^2 * p$entry$acf(h, tau0, nl)
  }
  out
}

# The parameters of one instance as a named vector (names without the label
# prefix: sigma, tc, or the kind for a bare coefficient).
instance_params <- function(coef, lay, label) {
  rows <- lay[lay$label == label, , drop = FALSE]
  stats::setNames(unname(coef[rows$name]), rows$param)
}

# Label a new instance of `term` gets next to `terms`: "gm" -> "gm2" when one
# gm is already there.
new_label <- function(terms, term) {
  all <- c(terms, term)
  ord <- order(match(split_term(all)$kind, effect_kinds()))
  term_labels(all)[ord == length(all)]
}

# "a", "a and b", "a, b and c".
and_list <- function(x) {
  if (length(x) <= 1L) return(paste(x))
  paste(paste(x[-length(x)], collapse = ", "), "and", x[length(x)])
}
