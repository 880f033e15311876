// Options of the allan() sums kernel, turned once from the R list built by
// allan_opts() (R/allan.R) into a typed struct the kernel reads. Checks here
// guard the kernel against a malformed internal call; users' arguments were
// already checked by allan().
#ifndef ALLANVAR_OPTS_ALLAN_H
#define ALLANVAR_OPTS_ALLAN_H

#include <Rcpp.h>
#include "types.h"

namespace allanvar {

struct AllanOptions {
  int type;      // an Estimator
  bool rate;     // rate samples (else integrated: phase, angle, velocity)
  bool octave;   // standard or Hadamard at m = 2^j: the one-pass kernel
  int threads;   // threads the kernel may use (>= 1)
  // noise identification (src/noise_id.h, R/taus.R noise_id_rules()):
  R_xlen_t acf_min = 64;     // fewest points the lag-1 ACF is read from
  bool b1_rw_own = false;    // random walk vs flicker FM by B1 with its own count
  bool rn_stable32 = false;  // R(n) as Stable32 (modified family: PM only)
  bool rn_check_wfm = false; // R(n) may turn B1's white FM into PM
  bool sums = true;          // false: noise identification only (no sums)
};

inline bool opt_flag(const Rcpp::List& o, const char* name) {
  SEXP v = o[name];
  if (TYPEOF(v) != LGLSXP || Rf_length(v) != 1 || LOGICAL(v)[0] == NA_LOGICAL)
    Rcpp::stop("internal: allan option `%s` must be TRUE or FALSE", name);
  return LOGICAL(v)[0] != 0;
}

inline int opt_int(const Rcpp::List& o, const char* name) {
  SEXP v = o[name];
  if (TYPEOF(v) != INTSXP || Rf_length(v) != 1 || INTEGER(v)[0] == NA_INTEGER)
    Rcpp::stop("internal: allan option `%s` must be a single integer", name);
  return INTEGER(v)[0];
}

inline AllanOptions allan_options(const Rcpp::List& o) {
  AllanOptions opts;
  opts.type = opt_int(o, "type");
  if (!valid_estimator(opts.type))
    Rcpp::stop("internal: unknown estimator code %d", opts.type);
  opts.rate = opt_flag(o, "rate");
  opts.octave = opt_flag(o, "octave");
  opts.threads = opt_int(o, "threads");
  if (opts.threads < 1) opts.threads = 1;
  if (o.containsElementNamed("b1_rw_own"))
    opts.b1_rw_own = opt_flag(o, "b1_rw_own");
  if (o.containsElementNamed("rn_stable32"))
    opts.rn_stable32 = opt_flag(o, "rn_stable32");
  if (o.containsElementNamed("rn_check_wfm"))
    opts.rn_check_wfm = opt_flag(o, "rn_check_wfm");
  if (o.containsElementNamed("acf_min")) {
    opts.acf_min = opt_int(o, "acf_min");
    if (opts.acf_min < 4) Rcpp::stop("internal: allan option `acf_min` < 4");
  }
  if (o.containsElementNamed("sums")) opts.sums = opt_flag(o, "sums");
  if (opts.octave && ((opts.type != STANDARD && opts.type != HADAMARD) ||
                      !opts.rate))
    Rcpp::stop("internal: the octave kernel is for standard or Hadamard rate "
               "input only");
  return opts;
}

}  // namespace allanvar

#endif
