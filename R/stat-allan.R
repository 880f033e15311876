# Catalogue entries of the Allan family: the six statistics of the sums
# kernel (src/allan.cpp), whose EDF is the one engine's (src/edf.cpp).

# The Allan-family statistics in the order allan()'s documentation lists
# them (overlapping, the default, first); registered in this order.
allan_types <- c("overlapping", "standard", "modified", "hadamard",
                 "ohadamard", "total")

# allantools' names for them.
allan_type_aliases <- c(adev = "standard", oadev = "overlapping",
                        mdev = "modified", hdev = "hadamard",
                        ohdev = "ohadamard", totdev = "total")

stats_allan_family <- function() {
  alias <- function(name) names(allan_type_aliases)[allan_type_aliases == name]
  # the identification switches every type but "total" shares (R/taus.R)
  id_common <- function(rule) {
    list(b1_rw_own = rule == "coverage", rn_check_wfm = rule == "default")
  }
  allan_dev <- function(name, title, ylab, max_m, nterms, divisor,
                        alpha_range = c(-2L, 2L), noise_id = id_common,
                        gaps = "sums", exact_ci = TRUE, ...) {
    new_stat(name, title = title, ylab = ylab, max_m = max_m,
             nterms = function(m, L, theo_row = NULL) nterms(m, L),
             kernel = "sums", divisor = divisor, edf = "engine",
             alpha_range = alpha_range, noise_id = noise_id, gaps = gaps,
             aliases = alias(name), exact_ci = exact_ci, ...)
  }
  allan_div <- function(m) 2 * m^2
  list(
    allan_dev("overlapping", "overlapping variance", "Allan deviation",
              max_m = function(L) floor((L - 1) / 2),
              nterms = function(m, L) L - 2 * m, divisor = allan_div),
    allan_dev("standard", "standard variance", "Allan deviation",
              max_m = function(L) floor((L - 1) / 2),
              nterms = function(m, L) floor((L - 1) / m) - 1,
              divisor = allan_div, octave_pass = TRUE),
    allan_dev("modified", "modified variance", "modified Allan deviation",
              max_m = function(L) floor(L / 3),
              nterms = function(m, L) L - 3 * m + 1,
              divisor = function(m) 2 * m^4, min_points = 4L),
    allan_dev("hadamard", "hadamard variance", "Hadamard deviation",
              max_m = function(L) floor((L - 1) / 3),
              nterms = function(m, L) floor((L - 1) / m) - 2,
              divisor = function(m) 6 * m^2, alpha_range = c(-4L, 2L),
              min_points = 4L, octave_pass = TRUE),
    allan_dev("ohadamard", "ohadamard variance", "Hadamard deviation",
              max_m = function(L) floor((L - 1) / 3),
              nterms = function(m, L) L - 3 * m,
              divisor = function(m) 6 * m^2, alpha_range = c(-4L, 2L),
              min_points = 4L),
    allan_dev("total", "total variance", "total deviation",
              max_m = function(L) if (L >= 3) L - 1 else 0,
              nterms = function(m, L) rep(L - 2, length(m)),
              divisor = allan_div, exact_ci = TRUE,
              exact_form = "exact_form_total",
              # its own reading leans to white FM at long tau (below), which
              # the exact law no longer needs: white PM was read as white
              # FM in 40% of records at N/m = 8 (N = 256), widening the
              # interval to 0.80 coverage; the overlapping reading, with
              # R(n), tells them apart
              exact_id = "overlapping",
              edf_fallback = function(m, n, L) 1.5 * (L - 1) / m,
              # random walk told from flicker FM by B1 with its own count;
              # R(n) never overrides white FM (its white-PM EDF is itself
              # too high at long tau): R/taus.R
              noise_id = function(rule) {
                list(b1_rw_own = rule %in% c("coverage", "default"),
                     rn_check_wfm = FALSE)
              },
              gaps = paste0("`gaps = \"skip\"` is not defined for type ",
                            "\"total\" (its reflected extension would ",
                            "carry a gap to the far end); use ",
                            "\"overlapping\" or fill the gaps."))
  )
}
