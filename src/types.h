// The estimator types of allan(): one definition shared by every kernel
// (allan.cpp, edf.cpp) and, through allan_type_table_cpp(), by R. A type is
// described by what the sums and the EDF need: the order of the difference,
// whether terms are taken at stride 1 (overlapping) or stride m, and whether
// the phase is averaged over m before differencing (modified).
#ifndef ALLANVAR_TYPES_H
#define ALLANVAR_TYPES_H

namespace allanvar {

enum Estimator {
  STANDARD = 0,
  OVERLAPPING = 1,
  MODIFIED = 2,
  HADAMARD = 3,
  OHADAMARD = 4,
  TOTAL = 5,
  N_ESTIMATORS = 6,  // the Allan-family types of the sums kernel (allan.cpp)
  // The further statistics, with kernels of their own
  // (src/tie.cpp, src/pdev.cpp, src/totals.cpp, src/theo.cpp; R side in
  // R/allan-types.R).
  TDEV = 6,
  MTOTAL = 7,
  TTOTAL = 8,
  HTOTAL = 9,
  THEO1 = 10,
  THEOBR = 11,
  THEOH = 12,
  MTIE = 13,
  TIERMS = 14,
  PDEV = 15,
  N_TYPES = 16
};

// What a type's deviation measures: fractional frequency (dimensionless for
// clock data, the rate unit for sensors) or a time (the phase unit).
enum DevUnit { UNIT_RATE = 0, UNIT_TIME = 1 };

struct EstimatorInfo {
  const char* name;   // the R name, as allan(type = ) takes it
  int d;              // order of the phase difference (2: Allan, 3: Hadamard)
  bool overlapping;   // terms at stride 1 (else stride m)
  bool modified;      // phase averaged over m before differencing
  int unit;           // DevUnit of the deviation column
  double tau_factor;  // reported tau = tau_factor * m * tau0 (Theo1: 0.75)
  bool debias;        // has a noise-dependent bias correction (SP 1065)
};

// Indexed by Estimator.
inline const EstimatorInfo& estimator_info(int type) {
  static const EstimatorInfo table[N_TYPES] = {
      {"standard", 2, false, false, UNIT_RATE, 1.0, false},
      {"overlapping", 2, true, false, UNIT_RATE, 1.0, false},
      {"modified", 2, true, true, UNIT_RATE, 1.0, false},
      {"hadamard", 3, false, false, UNIT_RATE, 1.0, false},
      {"ohadamard", 3, true, false, UNIT_RATE, 1.0, false},
      {"total", 2, true, false, UNIT_RATE, 1.0, false},
      {"tdev", 2, true, true, UNIT_TIME, 1.0, false},
      {"mtotdev", 2, true, true, UNIT_RATE, 1.0, true},
      {"ttotdev", 2, true, true, UNIT_TIME, 1.0, true},
      {"htotdev", 3, true, false, UNIT_RATE, 1.0, true},
      {"theo1", 2, true, false, UNIT_RATE, 0.75, true},
      {"theobr", 2, true, false, UNIT_RATE, 0.75, false},
      {"theoh", 2, true, false, UNIT_RATE, 1.0, false},
      {"mtie", 1, true, false, UNIT_TIME, 1.0, false},
      {"tierms", 1, true, false, UNIT_TIME, 1.0, false},
      {"pdev", 2, true, false, UNIT_RATE, 1.0, false}};
  return table[type];
}

inline bool valid_estimator(int type) {
  return type >= 0 && type < N_ESTIMATORS;
}

}  // namespace allanvar

#endif
