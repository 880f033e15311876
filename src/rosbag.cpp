// ROS1 bag format 2.0 (wiki.ros.org/Bags/Format/2.0): after the version
// line, records of <header_len u32><header><data_len u32><data>, the header
// being fields <len u32><name>=<value>. Chunks (op 0x05) hold connection
// (0x07) and message data (0x02) records, compressed as the chunk's
// `compression` field says (none, lz4: src/lz4.cpp, bz2: src/bz2.cpp).
#include "bytes.h"
#include "bz2.h"
#include "lz4.h"
#include "parallel.h"
#include "ros_msgs.h"

#include <Rcpp.h>
#include <algorithm>
#include <string>
#include <vector>

namespace {

using allanvar::format_error;
using allanvar::rd_u32;

// The value of header field `name`, or nullptr.
const unsigned char* find_field(const unsigned char* h, std::size_t n,
                                const char* name, std::size_t* len) {
  const std::size_t nl = std::strlen(name);
  std::size_t i = 0;
  while (i + 4 <= n) {
    const std::size_t fl = rd_u32(h + i);
    i += 4;
    if (fl > n - i) throw format_error("bag: a header field runs past its header");
    const unsigned char* f = h + i;
    if (fl > nl && std::memcmp(f, name, nl) == 0 && f[nl] == '=') {
      *len = fl - nl - 1;
      return f + nl + 1;
    }
    i += fl;
  }
  return nullptr;
}

struct record {
  std::size_t hdr, hdr_len, data, data_len;
  int op;
};

// The records in buf[start, end).
std::vector<record> walk(const unsigned char* p, std::size_t start, std::size_t end) {
  std::vector<record> out;
  std::size_t i = start;
  while (i < end) {
    if (end - i < 4) throw format_error("bag: truncated record header length");
    record r;
    r.hdr_len = rd_u32(p + i);
    r.hdr = i + 4;
    if (r.hdr_len > end - r.hdr || end - r.hdr - r.hdr_len < 4) {
      throw format_error("bag: truncated record header at byte " + std::to_string(i));
    }
    r.data_len = rd_u32(p + r.hdr + r.hdr_len);
    r.data = r.hdr + r.hdr_len + 4;
    if (r.data_len > end - r.data) {
      throw format_error("bag: truncated record data at byte " + std::to_string(i));
    }
    std::size_t len = 0;
    const unsigned char* op = find_field(p + r.hdr, r.hdr_len, "op", &len);
    r.op = (op && len == 1) ? op[0] : -1;
    out.push_back(r);
    i = r.data + r.data_len;
  }
  return out;
}

void chunk_messages(const unsigned char* p, std::size_t n,
                    const std::vector<int>& conns, std::vector<double>& out,
                    R_xlen_t* bad) {
  const std::vector<record> recs = walk(p, 0, n);
  std::vector<double> row;
  for (const record& r : recs) {
    if (r.op != 2) continue;
    std::size_t len = 0;
    const unsigned char* c = find_field(p + r.hdr, r.hdr_len, "conn", &len);
    if (!c || len != 4) throw format_error("bag: message record without its connection");
    const int conn = static_cast<int>(rd_u32(c));
    if (std::find(conns.begin(), conns.end(), conn) == conns.end()) continue;
    const unsigned char* t = find_field(p + r.hdr, r.hdr_len, "time", &len);
    std::int64_t recv = 0;
    if (t && len == 8) {
      recv = static_cast<std::int64_t>(rd_u32(t)) * 1000000000LL + rd_u32(t + 4);
    }
    if (!allanvar::decode_imu(p + r.data, r.data_len, allanvar::ENC_ROS1, recv, out)) {
      ++*bad;
    }
  }
}

Rcpp::NumericMatrix as_matrix(const std::vector<double>& v) {
  const R_xlen_t n = v.size() / allanvar::kImuCols;
  Rcpp::NumericMatrix m(n, allanvar::kImuCols);
  for (R_xlen_t i = 0; i < n; ++i) {
    for (int j = 0; j < allanvar::kImuCols; ++j) m(i, j) = v[i * allanvar::kImuCols + j];
  }
  return m;
}

}  // namespace

// Top-level (or chunk-level) records of a bag: op, header and data
// positions (0-based offsets into `buf`).
// [[Rcpp::export(rng = false)]]
Rcpp::List rosbag_records(const Rcpp::RawVector& buf, double start, double end) {
  std::vector<record> recs;
  try {
    recs = walk(RAW(buf), static_cast<std::size_t>(start), static_cast<std::size_t>(end));
  } catch (const format_error& e) {
    Rcpp::stop(e.what());
  }
  const R_xlen_t n = recs.size();
  Rcpp::IntegerVector op(n);
  Rcpp::NumericVector hdr(n), hdr_len(n), data(n), data_len(n), size(n, NA_REAL);
  Rcpp::CharacterVector compression(n, NA_STRING);
  const unsigned char* p = RAW(buf);
  for (R_xlen_t i = 0; i < n; ++i) {
    op[i] = recs[i].op;
    if (op[i] == 5) {
      // Chunk: its compression and uncompressed size, from its header.
      std::size_t len = 0;
      const unsigned char* c = find_field(p + recs[i].hdr, recs[i].hdr_len, "compression", &len);
      if (c) compression[i] = std::string(reinterpret_cast<const char*>(c), len);
      const unsigned char* z = find_field(p + recs[i].hdr, recs[i].hdr_len, "size", &len);
      if (z && len == 4) size[i] = rd_u32(z);
    }
    hdr[i] = recs[i].hdr;
    hdr_len[i] = recs[i].hdr_len;
    data[i] = recs[i].data;
    data_len[i] = recs[i].data_len;
  }
  return Rcpp::List::create(Rcpp::Named("op") = op, Rcpp::Named("hdr") = hdr,
                            Rcpp::Named("hdr_len") = hdr_len, Rcpp::Named("data") = data,
                            Rcpp::Named("data_len") = data_len,
                            Rcpp::Named("compression") = compression,
                            Rcpp::Named("size") = size);
}

// Every chunk of a bag at once: the sensor_msgs/Imu messages of connections
// `conns` in the chunks at buf[off[k], off[k] + len[k]), of compression
// `comp[k]` (0 none, read in place; 1 lz4; 2 bz2, through libbz2) and
// uncompressed size `size[k]`, decoded into one table (one copy at the end,
// no R call per chunk). Compressed chunks are decompressed on up to
// `threads` threads, a batch of a few chunks per thread at a time (bz2 costs
// about 20 ns a byte, the decoding after it little); messages are decoded
// in file order on the calling thread. Returns the table and the number of
// messages that did not decode.
// [[Rcpp::export(rng = false)]]
Rcpp::List rosbag_imu(const Rcpp::RawVector& buf, const Rcpp::NumericVector& off,
                      const Rcpp::NumericVector& len, const Rcpp::IntegerVector& comp,
                      const Rcpp::NumericVector& size, const Rcpp::IntegerVector& conns,
                      int threads = 1) {
  std::vector<int> cs(conns.begin(), conns.end());
  std::vector<double> out;
  R_xlen_t bad = 0;
  const R_xlen_t nk = off.size();
  const unsigned char* base = RAW(buf);
  const std::size_t total = buf.size();
  if (threads < 1) threads = 1;
  allanvar::InterruptScope scope;
  try {
    for (R_xlen_t k = 0; k < nk; ++k) {
      const std::size_t o = static_cast<std::size_t>(off[k]);
      const std::size_t n = static_cast<std::size_t>(len[k]);
      if (o > total || n > total - o) throw format_error("bag: a chunk runs past the end of the file");
      if (comp[k] < 0 || comp[k] > 2) throw format_error("bag: unknown chunk compression code");
    }
    for (R_xlen_t k = 0; k < nk; ++k) {
      if (comp[k] == 2 && !allanvar::bz2_available()) throw format_error("bz2: libbz2 is not available");
    }
    const R_xlen_t batch = 4 * static_cast<R_xlen_t>(threads);
    std::vector<std::vector<unsigned char>> raws(static_cast<std::size_t>(batch));
    for (R_xlen_t k0 = 0; k0 < nk; k0 += batch) {
      const R_xlen_t m = std::min(batch, nk - k0);
      allanvar::parallel_for(m, threads, [&](R_xlen_t i, int) {
        const R_xlen_t k = k0 + i;
        std::vector<unsigned char>& raw = raws[static_cast<std::size_t>(i)];
        raw.clear();
        if (comp[k] == 0) return;
        const unsigned char* p = base + static_cast<std::size_t>(off[k]);
        const std::size_t n = static_cast<std::size_t>(len[k]);
        const std::size_t sz = static_cast<std::size_t>(size[k]);
        if (comp[k] == 1) {
          allanvar::lz4_frame_decode(p, n, raw, sz);
          if (raw.size() != sz) {
            throw format_error("bag: an lz4 chunk does not decompress to its stated size");
          }
        } else {
          allanvar::bz2_decode(p, n, sz, raw);
        }
      });
      for (R_xlen_t i = 0; i < m; ++i) {
        const R_xlen_t k = k0 + i;
        if (comp[k] == 0) {
          chunk_messages(base + static_cast<std::size_t>(off[k]),
                         static_cast<std::size_t>(len[k]), cs, out, &bad);
        } else {
          const std::vector<unsigned char>& raw = raws[static_cast<std::size_t>(i)];
          chunk_messages(raw.data(), raw.size(), cs, out, &bad);
        }
      }
    }
  } catch (const format_error& e) {
    Rcpp::stop(e.what());
  }
  scope.finish();
  return Rcpp::List::create(Rcpp::Named("imu") = as_matrix(out),
                            Rcpp::Named("bad") = static_cast<double>(bad));
}
