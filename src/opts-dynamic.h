// Options of the windowed-sums kernel (src/dynamic.cpp), turned once from
// the R list built by dyn_opts() (R/dynamic.R) into a typed struct. Checks
// here guard the kernel against a malformed internal call; users' arguments
// were already checked by dynamic_allan() or groslambert().
#ifndef ALLANVAR_OPTS_DYNAMIC_H
#define ALLANVAR_OPTS_DYNAMIC_H

#include <Rcpp.h>
#include "types.h"

namespace allanvar {

struct DynamicOptions {
  int type;       // an Estimator other than TOTAL
  bool rate;      // rate samples (else integrated: phase, angle, velocity)
  R_xlen_t step;  // samples between the starts of consecutive windows (>= 1)
  R_xlen_t nwin;  // number of windows (>= 1)
  int threads;    // threads the kernel may use (>= 1)
};

inline double dyn_opt_number(const Rcpp::List& o, const char* name) {
  SEXP v = o[name];
  if (!Rf_isNumeric(v) || Rf_isLogical(v) || Rf_length(v) != 1 ||
      !std::isfinite(Rf_asReal(v)))
    Rcpp::stop("internal: dynamic option `%s` must be a single number", name);
  return Rf_asReal(v);
}

inline DynamicOptions dynamic_options(const Rcpp::List& o) {
  DynamicOptions opts;
  opts.type = static_cast<int>(dyn_opt_number(o, "type"));
  if (!valid_estimator(opts.type) || opts.type == TOTAL)
    Rcpp::stop("internal: no windowed kernel for estimator code %d",
               opts.type);
  SEXP rate = o["rate"];
  if (TYPEOF(rate) != LGLSXP || Rf_length(rate) != 1 ||
      LOGICAL(rate)[0] == NA_LOGICAL)
    Rcpp::stop("internal: dynamic option `rate` must be TRUE or FALSE");
  opts.rate = LOGICAL(rate)[0] != 0;
  opts.step = static_cast<R_xlen_t>(dyn_opt_number(o, "step"));
  opts.nwin = static_cast<R_xlen_t>(dyn_opt_number(o, "nwin"));
  opts.threads = static_cast<int>(dyn_opt_number(o, "threads"));
  if (opts.step < 1 || opts.nwin < 1)
    Rcpp::stop("internal: dynamic options need step >= 1 and nwin >= 1");
  if (opts.threads < 1) opts.threads = 1;
  return opts;
}

}  // namespace allanvar

#endif
