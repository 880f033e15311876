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
  N_ESTIMATORS = 6
};

struct EstimatorInfo {
  const char* name;   // the R name, as allan(type = ) takes it
  int d;              // order of the phase difference (2: Allan, 3: Hadamard)
  bool overlapping;   // terms at stride 1 (else stride m)
  bool modified;      // phase averaged over m before differencing
};

// Indexed by Estimator.
inline const EstimatorInfo& estimator_info(int type) {
  static const EstimatorInfo table[N_ESTIMATORS] = {
      {"standard", 2, false, false},  {"overlapping", 2, true, false},
      {"modified", 2, true, true},    {"hadamard", 3, false, false},
      {"ohadamard", 3, true, false},  {"total", 2, true, false}};
  return table[type];
}

inline bool valid_estimator(int type) {
  return type >= 0 && type < N_ESTIMATORS;
}

}  // namespace allanvar

#endif
