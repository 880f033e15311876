// The estimator table of src/types.h, for R (R/taus.R reads it once).
#include <Rcpp.h>
#include "types.h"

// all = FALSE: the Allan-family types of the sums kernel; TRUE: every type
// allan() computes.
// [[Rcpp::export(rng = false)]]
Rcpp::DataFrame allan_type_table_cpp(bool all = false) {
  const int n = all ? allanvar::N_TYPES : allanvar::N_ESTIMATORS;
  Rcpp::CharacterVector name(n);
  Rcpp::IntegerVector code(n), d(n);
  Rcpp::LogicalVector overlapping(n), modified(n), debias(n);
  Rcpp::CharacterVector unit(n);
  Rcpp::NumericVector tau_factor(n);
  for (int i = 0; i < n; ++i) {
    const allanvar::EstimatorInfo& e = allanvar::estimator_info(i);
    name[i] = e.name;
    code[i] = i;
    d[i] = e.d;
    overlapping[i] = e.overlapping;
    modified[i] = e.modified;
    unit[i] = e.unit == allanvar::UNIT_TIME ? "time" : "rate";
    tau_factor[i] = e.tau_factor;
    debias[i] = e.debias;
  }
  return Rcpp::DataFrame::create(
      Rcpp::Named("name") = name, Rcpp::Named("code") = code,
      Rcpp::Named("d") = d, Rcpp::Named("overlapping") = overlapping,
      Rcpp::Named("modified") = modified, Rcpp::Named("unit") = unit,
      Rcpp::Named("tau_factor") = tau_factor, Rcpp::Named("debias") = debias,
      Rcpp::Named("stringsAsFactors") = false);
}
