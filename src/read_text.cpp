// Helpers of the CSV reader (R/read-csv.R): the slow path that finds rows
// with the wrong number of fields, and exact integer timestamps.
#include <Rcpp.h>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <algorithm>
#include <vector>

// Lines of a delimited text whose number of fields differs from `expected`
// (blank lines count as 0 fields). `sep` is one byte, or 0 for runs of white
// space. Double quotes protect separators. Returns 1-based line numbers and
// their field counts, and the number of lines.
// [[Rcpp::export(rng = false)]]
Rcpp::List csv_field_faults(const Rcpp::RawVector& bytes, int sep, int expected) {
  const unsigned char* p = RAW(bytes);
  const R_xlen_t n = bytes.size();
  std::vector<int> bad_line, bad_count;
  R_xlen_t i = 0;
  int line = 0;
  while (i < n) {
    ++line;
    int fields = 0;
    bool in_quote = false, in_field = false, any = false;
    for (; i < n; ++i) {
      unsigned char c = p[i];
      if (c == '\n' && !in_quote) { ++i; break; }
      if (c == '\r' && !in_quote) continue;
      if (c == '"') in_quote = !in_quote;
      if (sep == 0) {
        bool ws = !in_quote && (c == ' ' || c == '\t');
        if (!ws && !in_field) { ++fields; in_field = true; }
        if (ws) in_field = false;
      } else {
        any = true;
        if (!in_quote && c == sep) ++fields;
      }
    }
    if (sep != 0) fields = any ? fields + 1 : 0;
    if (fields != expected) {
      bad_line.push_back(line);
      bad_count.push_back(fields);
    }
    if ((line & 0xFFFF) == 0) Rcpp::checkUserInterrupt();
  }
  return Rcpp::List::create(Rcpp::Named("line") = Rcpp::wrap(bad_line),
                            Rcpp::Named("fields") = Rcpp::wrap(bad_count),
                            Rcpp::Named("n_lines") = line);
}

// Integer stamps held as bit64::integer64 (int64 bits in a double vector):
// seconds since the stamp `origin` (1-based), computed exactly as
// (x - x0) / per_second with one rounding; NA for integer64's NA.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector int64_rel_seconds(const Rcpp::NumericVector& x, double origin,
                                      double per_second) {
  const R_xlen_t n = x.size();
  Rcpp::NumericVector out(n);
  const std::int64_t na = INT64_MIN;
  std::int64_t x0;
  std::memcpy(&x0, &x[static_cast<R_xlen_t>(origin) - 1], sizeof x0);
  for (R_xlen_t i = 0; i < n; ++i) {
    std::int64_t v;
    std::memcpy(&v, &x[i], sizeof v);
    out[i] = (v == na) ? NA_REAL : static_cast<double>(v - x0) / per_second;
  }
  return out;
}

// integer64 stamps as (rounded) doubles, for guessing their unit.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector int64_to_double(const Rcpp::NumericVector& x) {
  const R_xlen_t n = x.size();
  Rcpp::NumericVector out(n);
  for (R_xlen_t i = 0; i < n; ++i) {
    std::int64_t v;
    std::memcpy(&v, &x[i], sizeof v);
    out[i] = (v == INT64_MIN) ? NA_REAL : static_cast<double>(v);
  }
  return out;
}

// 1-based row of the first NA, NaN or infinite value of each column of a
// matrix (0 when a column is all finite), without copying the columns.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector col_first_nonfinite(const Rcpp::NumericMatrix& x) {
  const R_xlen_t n = x.nrow();
  const int p = x.ncol();
  Rcpp::NumericVector out(p);
  for (int j = 0; j < p; ++j) {
    const double* v = &x[static_cast<R_xlen_t>(j) * n];
    out[j] = 0;
    for (R_xlen_t i = 0; i < n; ++i) {
      if (!std::isfinite(v[i])) {
        out[j] = static_cast<double>(i + 1);
        break;
      }
    }
  }
  return out;
}

// Column j (1-based) of x: the mean of each of the k = n %/% m clusters of
// m samples, then the non-overlapping Allan variance of those means
// (IEEE Std 952, eq. C.2), for the unit plausibility checks (R/units.R).
// [[Rcpp::export(rng = false)]]
double col_block_avar(const Rcpp::NumericMatrix& x, int j, double m) {
  const R_xlen_t n = x.nrow();
  const R_xlen_t mm = static_cast<R_xlen_t>(m);
  const R_xlen_t k = n / mm;
  const double* v = &x[static_cast<R_xlen_t>(j - 1) * n];
  double prev = 0, s = 0;
  for (R_xlen_t c = 0; c < k; ++c) {
    double a = 0;
    for (R_xlen_t i = c * mm; i < (c + 1) * mm; ++i) a += v[i];
    a /= m;
    if (c > 0) s += (a - prev) * (a - prev);
    prev = a;
  }
  return k > 1 ? 0.5 * s / static_cast<double>(k - 1) : NA_REAL;
}

// The steps of sorted, distinct stamps t (seconds) in one pass after the
// median, for new_imu_record() (R/read.R): the median step (as R's
// median(): the mean of the two middle values for an even count), gaps
// (steps > 1.5 median: 1-based index of the step and its length), and the
// jitter of the other steps: mean((step - median)^2) with R's mean()
// arithmetic (long double sum, then its correction pass), and how many
// deviate by more than 1% of the median.
// [[Rcpp::export(rng = false)]]
Rcpp::List stamp_steps(const Rcpp::NumericVector& t) {
  const R_xlen_t n = t.size() - 1;
  if (n < 1) return Rcpp::List::create(Rcpp::Named("n") = 0);
  std::vector<double> s(static_cast<size_t>(n));
  for (R_xlen_t i = 0; i < n; ++i) s[i] = t[i + 1] - t[i];
  const R_xlen_t half = n / 2;
  std::nth_element(s.begin(), s.begin() + half, s.end());
  double med = s[half];
  if (n % 2 == 0) {
    const double lo = *std::max_element(s.begin(), s.begin() + half);
    med = static_cast<double>((static_cast<long double>(lo) + med) / 2.0L);
  }
  const double lim = 1.5 * med, tol = 0.01 * med;
  std::vector<double> gap_at, gap_len;
  long double sum = 0;
  R_xlen_t k = 0, over = 0;
  for (R_xlen_t i = 0; i < n; ++i) {
    const double st = t[i + 1] - t[i];
    if (st > lim) {
      gap_at.push_back(static_cast<double>(i + 1));
      gap_len.push_back(st);
      continue;
    }
    const double d = st - med;
    sum += d * d;
    if (std::fabs(d) > tol) ++over;
    ++k;
  }
  double ms = NA_REAL;
  if (k > 0) {
    long double m = sum / k;
    if (std::isfinite(static_cast<double>(m))) {
      long double c = 0;
      for (R_xlen_t i = 0; i < n; ++i) {
        const double st = t[i + 1] - t[i];
        if (st > lim) continue;
        const double d = st - med;
        c += d * d - m;
      }
      m += c / k;
    }
    ms = static_cast<double>(m);
  }
  return Rcpp::List::create(Rcpp::Named("n") = static_cast<double>(n),
                            Rcpp::Named("median") = med,
                            Rcpp::Named("mean_sq") = ms,
                            Rcpp::Named("over") = static_cast<double>(over),
                            Rcpp::Named("gap_at") = Rcpp::wrap(gap_at),
                            Rcpp::Named("gap_len") = Rcpp::wrap(gap_len));
}

// 1-based index of the first stamp equal to its predecessor (0: none), and
// how many there are, for sorted t.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector stamp_repeats(const Rcpp::NumericVector& t) {
  const R_xlen_t n = t.size();
  double first = 0, count = 0;
  for (R_xlen_t i = 1; i < n; ++i) {
    if (t[i] == t[i - 1]) {
      if (count == 0) first = static_cast<double>(i + 1);
      ++count;
    }
  }
  return Rcpp::NumericVector::create(first, count);
}
