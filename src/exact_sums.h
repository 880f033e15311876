// Arithmetic that reproduces allanvar 1.1 (R code) bit for bit.
#ifndef ALLANVAR_EXACT_SUMS_H
#define ALLANVAR_EXACT_SUMS_H

#include <Rcpp.h>
#include <algorithm>
#include <cfloat>
#include <vector>

namespace allanvar {

// R's sum() of doubles: long double, left to right from 0, rounded once, with
// R's own overflow rule (a sum beyond DBL_MAX is Inf even if it would round
// down to DBL_MAX).
inline double r_sum_result(long double s) {
  if (s > DBL_MAX) return R_PosInf;
  if (s < -DBL_MAX) return R_NegInf;
  return static_cast<double>(s);
}

// A cluster to be summed as R's sum() sums it; the sum goes to *dest.
struct Chain {
  const double* p;
  R_xlen_t len;
  double* dest;
};

// Sums chains four at a time. One long-double chain is bound by the latency
// of the x87 add; four independent chains overlap in the pipeline while each
// keeps its own left-to-right order, so the bits do not change. A lane whose
// chain ends takes the next one, so chains of unequal length (the last
// clusters of several cluster sizes) still overlap.
inline void sum_chains(std::vector<Chain>& chains) {
  std::sort(chains.begin(), chains.end(),
            [](const Chain& a, const Chain& b) { return a.len > b.len; });
  std::size_t next = 0;
  const double* p[4];
  R_xlen_t left[4];
  long double s[4];
  double* dest[4];
  bool live[4];
  auto load = [&](int i) {
    live[i] = next < chains.size();
    if (live[i]) {
      p[i] = chains[next].p;
      left[i] = chains[next].len;
      dest[i] = chains[next].dest;
      s[i] = 0;
      ++next;
    }
  };
  for (int i = 0; i < 4; ++i) load(i);
  for (;;) {
    int first = -1;
    R_xlen_t step = 0;
    for (int i = 0; i < 4; ++i) {
      if (!live[i]) continue;
      if (first < 0 || left[i] < step) step = left[i];
      if (first < 0) first = i;
    }
    if (first < 0) return;
    // An idle lane re-reads a live lane's data; its sum is discarded.
    const double* q0 = live[0] ? p[0] : p[first];
    const double* q1 = live[1] ? p[1] : p[first];
    const double* q2 = live[2] ? p[2] : p[first];
    const double* q3 = live[3] ? p[3] : p[first];
    long double s0 = s[0], s1 = s[1], s2 = s[2], s3 = s[3];
    for (R_xlen_t j = 0; j < step; ++j) {
      s0 += q0[j];
      s1 += q1[j];
      s2 += q2[j];
      s3 += q3[j];
    }
    s[0] = s0;
    s[1] = s1;
    s[2] = s2;
    s[3] = s3;
    for (int i = 0; i < 4; ++i) {
      if (!live[i]) continue;
      p[i] += step;
      left[i] -= step;
      if (left[i] == 0) {
        *dest[i] = r_sum_result(s[i]);
        load(i);
      }
    }
  }
}

// allanvar 1.1's non-overlapping Allan variance of one cluster size c,
// assembled from its cluster sums in order: S = S + (w[k+1] - w[k])^2 in
// double, left to right, then S / (2 (M - 1)), with w = sum / c.
class ClusterLevel {
 public:
  ClusterLevel(R_xlen_t c, R_xlen_t M)
      : c_(static_cast<double>(c)), M_(M), S_(0.0), prev_(0.0),
        has_prev_(false), tail_count_(0) {}

  // Cluster sums in order; the last clusters may come later via tail().
  void add_sums(const double* sums, R_xlen_t count) {
    for (R_xlen_t k = 0; k < count; ++k) add_mean(sums[k] / c_);
  }
  // Room for a cluster sum that is computed later (by sum_chains).
  double* tail() { return &tail_[tail_count_++]; }
  void finish_tail() {
    for (int k = 0; k < tail_count_; ++k) add_mean(tail_[k] / c_);
    tail_count_ = 0;
  }
  double av() const { return S_ / (2.0 * (static_cast<double>(M_) - 1.0)); }

 private:
  void add_mean(double w) {
    if (has_prev_) {
      const double d = w - prev_;
      const double d2 = d * d;
      S_ = S_ + d2;
    }
    prev_ = w;
    has_prev_ = true;
  }
  double c_;
  R_xlen_t M_;
  double S_, prev_;
  bool has_prev_;
  int tail_count_;
  double tail_[4];
};

// Sums of the M consecutive clusters of size c at x, four clusters at a time,
// into sums[0 .. 4 floor(M/4)); the last M mod 4 clusters are queued on
// `later` (into level.tail()) so that they overlap with other levels' last
// clusters. Returns the number of sums written.
inline R_xlen_t cluster_sums(const double* x, R_xlen_t c, R_xlen_t M,
                             double* sums, ClusterLevel& level,
                             std::vector<Chain>& later) {
  R_xlen_t k = 0;
  for (; k + 4 <= M; k += 4) {
    const double* p0 = x + k * c;
    const double* p1 = p0 + c;
    const double* p2 = p1 + c;
    const double* p3 = p2 + c;
    long double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    for (R_xlen_t j = 0; j < c; ++j) {
      s0 += p0[j];
      s1 += p1[j];
      s2 += p2[j];
      s3 += p3[j];
    }
    sums[k] = r_sum_result(s0);
    sums[k + 1] = r_sum_result(s1);
    sums[k + 2] = r_sum_result(s2);
    sums[k + 3] = r_sum_result(s3);
  }
  for (R_xlen_t j = k; j < M; ++j) later.push_back({x + j * c, c, level.tail()});
  return k;
}

// The `error` column of allanvar 1.1: 1/sqrt(2 (N/c - 1)).
inline double cluster_error(R_xlen_t N, double c) {
  return 1.0 / std::sqrt(2.0 * ((static_cast<double>(N) / c) - 1.0));
}

// The largest octave exponent p = floor(log10(n)/log10(2)), n = ceiling((N-1)/2),
// computed with the same double expressions as allanvar 1.1.
inline int octave_count(R_xlen_t N) {
  const double n = std::ceil((static_cast<double>(N) - 1.0) / 2.0);
  return static_cast<int>(std::floor(std::log10(n) / std::log10(2.0)));
}

// Non-overlapping Allan variances, allanvar 1.1's way, for the cluster sizes
// sizes[0 .. count): av[i] for sizes[i]. `sums` is scratch of length N.
template <class Check>
inline void cluster_avars(const double* x, R_xlen_t N, const R_xlen_t* sizes,
                          R_xlen_t count, double* av, double* sums,
                          Check check) {
  std::vector<ClusterLevel> levels;
  levels.reserve(count);
  std::vector<Chain> later;
  for (R_xlen_t i = 0; i < count; ++i) {
    const R_xlen_t c = sizes[i];
    const R_xlen_t M = N / c;
    levels.emplace_back(c, M);
    const R_xlen_t done = cluster_sums(x, c, M, sums, levels.back(), later);
    levels.back().add_sums(sums, done);
    check();
  }
  sum_chains(later);
  for (R_xlen_t i = 0; i < count; ++i) {
    levels[i].finish_tail();
    av[i] = levels[i].av();
  }
}

}  // namespace allanvar

#endif
