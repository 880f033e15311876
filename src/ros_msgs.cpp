// sensor_msgs/Imu as serialized by ROS1 (wiki.ros.org/msg, "Serialization":
// little-endian, packed, strings as uint32 length + bytes) and by ROS2 over
// DDS (OMG CDR: a 4-byte encapsulation header, then fields aligned to their
// size relative to the end of that header; XCDR2 aligns 8-byte values to 4).
// Message layout (sensor_msgs/msg/Imu): Header header {stamp {sec, nsec},
// frame_id} [ROS1: uint32 seq first], Quaternion orientation (4 float64),
// float64[9] orientation_covariance, Vector3 angular_velocity, float64[9],
// Vector3 linear_acceleration, float64[9].
#include "ros_msgs.h"
#include "bytes.h"

#include <Rcpp.h>
#include <cstring>

namespace allanvar {

namespace {

double rd_f64(const unsigned char* p, bool swap) {
  unsigned char b[8];
  if (swap) {
    for (int k = 0; k < 8; ++k) b[k] = p[7 - k];
  } else {
    std::memcpy(b, p, 8);
  }
  double v;
  std::memcpy(&v, b, 8);
  return v;
}

std::uint32_t rd_u32e(const unsigned char* p, bool big) {
  return big ? (static_cast<std::uint32_t>(p[3]) | (static_cast<std::uint32_t>(p[2]) << 8) |
                (static_cast<std::uint32_t>(p[1]) << 16) | (static_cast<std::uint32_t>(p[0]) << 24))
             : rd_u32(p);
}

}  // namespace

bool decode_imu(const unsigned char* p, std::size_t n, int encoding,
                std::int64_t recv_ns, std::vector<double>& out) {
  double sec, nsec;
  std::size_t pos;       // position of the first float64 (orientation.x)
  bool swap = false;     // big-endian payload
  if (encoding == ENC_ROS1) {
    if (n < 16) return false;
    sec = rd_u32(p + 4);
    nsec = rd_u32(p + 8);
    const std::size_t len = rd_u32(p + 12);
    if (len > n - 16) return false;
    pos = 16 + len;
  } else {
    if (n < 4 + 12) return false;
    const unsigned kind = p[1];  // 0/1: CDR BE/LE; 6/7: PLAIN_CDR2 BE/LE
    if (p[0] != 0 || !(kind == 0 || kind == 1 || kind == 6 || kind == 7)) return false;
    const bool big = (kind == 0 || kind == 6);
    swap = big;
    const std::size_t align8 = (kind >= 6) ? 4 : 8;
    const unsigned char* b = p + 4;
    const std::size_t m = n - 4;
    sec = static_cast<double>(static_cast<std::int32_t>(rd_u32e(b, big)));
    nsec = rd_u32e(b + 4, big);
    const std::size_t len = rd_u32e(b + 8, big);  // includes the NUL
    if (len > m - 12) return false;
    std::size_t q = 12 + len;
    q = (q + align8 - 1) / align8 * align8;
    pos = 4 + q;
  }
  if (pos > n || n - pos < 37 * 8) return false;
  const unsigned char* d = p + pos;
  out.push_back(sec);
  out.push_back(nsec);
  for (int k = 0; k < 3; ++k) out.push_back(rd_f64(d + (13 + k) * 8, swap));
  for (int k = 0; k < 3; ++k) out.push_back(rd_f64(d + (25 + k) * 8, swap));
  out.push_back(static_cast<double>(recv_ns / 1000000000));
  out.push_back(static_cast<double>(recv_ns % 1000000000));
  return true;
}

}  // namespace allanvar

// Decodes a list of serialized messages (ROS2 db3 rows): one row per
// message, columns as in ros_msgs.h; `recv_ns` are the storage stamps as
// integer64 bits. Rows that do not decode are NA (the R side reports them).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericMatrix decode_imu_blobs(const Rcpp::List& blobs, int encoding,
                                     const Rcpp::NumericVector& recv_ns) {
  const R_xlen_t n = blobs.size();
  std::vector<double> row;
  row.reserve(allanvar::kImuCols);
  Rcpp::NumericMatrix out(n, allanvar::kImuCols);
  for (R_xlen_t i = 0; i < n; ++i) {
    if ((i & 0xFFFF) == 0) Rcpp::checkUserInterrupt();
    SEXP b = blobs[i];
    std::int64_t recv = 0;
    if (i < recv_ns.size()) std::memcpy(&recv, &recv_ns[i], sizeof recv);
    row.clear();
    const bool ok = TYPEOF(b) == RAWSXP &&
      allanvar::decode_imu(RAW(b), XLENGTH(b), encoding, recv, row);
    for (int j = 0; j < allanvar::kImuCols; ++j) out(i, j) = ok ? row[j] : NA_REAL;
  }
  return out;
}

// Seconds since the stamp `origin` (1-based) of (sec, nsec) pairs, exactly as
// for integer nanosecond stamps: ((sec - sec0) * 1e9 + nsec - nsec0) / 1e9.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector stamp_rel_seconds(const Rcpp::NumericVector& sec,
                                      const Rcpp::NumericVector& nsec, double origin) {
  const R_xlen_t n = sec.size();
  Rcpp::NumericVector out(n);
  const R_xlen_t o = static_cast<R_xlen_t>(origin) - 1;
  const std::int64_t s0 = static_cast<std::int64_t>(sec[o]);
  const std::int64_t n0 = static_cast<std::int64_t>(nsec[o]);
  for (R_xlen_t i = 0; i < n; ++i) {
    if (ISNAN(sec[i]) || ISNAN(nsec[i])) {
      out[i] = NA_REAL;
      continue;
    }
    const std::int64_t d = (static_cast<std::int64_t>(sec[i]) - s0) * 1000000000LL +
      (static_cast<std::int64_t>(nsec[i]) - n0);
    out[i] = static_cast<double>(d) / 1e9;
  }
  return out;
}
