// MCAP (mcap.dev/spec): magic "\x89MCAP0\r\n", then records of
// <opcode u8><length u64><content>. Chunks (0x06) hold Schema, Channel and
// Message (0x05) records, compressed with "" (none), "lz4" (LZ4 frame) or
// "zstd". Messages are sensor_msgs/Imu in "cdr" (ROS2) or "ros1" encoding.
#include "bytes.h"
#include "lz4.h"
#include "ros_msgs.h"
#include "zstd.h"

#include <Rcpp.h>
#include <algorithm>
#include <string>
#include <vector>

namespace {

using allanvar::format_error;
using allanvar::rd_u16;
using allanvar::rd_u32;
using allanvar::rd_u64;

struct rec {
  int op;
  std::size_t off, len;  // content
};

std::vector<rec> walk(const unsigned char* p, std::size_t start, std::size_t end) {
  std::vector<rec> out;
  std::size_t i = start;
  while (i < end) {
    if (end - i < 9) throw format_error("mcap: truncated record at byte " + std::to_string(i));
    rec r;
    r.op = p[i];
    const std::uint64_t len = rd_u64(p + i + 1);
    r.off = i + 9;
    if (len > end - r.off) throw format_error("mcap: record runs past the data at byte " + std::to_string(i));
    r.len = static_cast<std::size_t>(len);
    out.push_back(r);
    i = r.off + r.len;
  }
  return out;
}

struct channels {
  std::vector<int> id, enc;
  int encoding(int c) const {
    for (std::size_t k = 0; k < id.size(); ++k) if (id[k] == c) return enc[k];
    return -1;
  }
};

void message(const unsigned char* p, std::size_t n, const channels& ch,
             std::vector<double>& out, R_xlen_t* bad) {
  if (n < 22) throw format_error("mcap: truncated message record");
  const int c = rd_u16(p);
  const int enc = ch.encoding(c);
  if (enc < 0) return;
  const std::int64_t log_time = static_cast<std::int64_t>(rd_u64(p + 6));
  if (!allanvar::decode_imu(p + 22, n - 22, enc, log_time, out)) ++*bad;
}

// Decompressed records of a chunk's content.
void chunk_records(const unsigned char* p, std::size_t n, std::vector<unsigned char>& raw,
                   const unsigned char** rp, std::size_t* rn) {
  if (n < 32) throw format_error("mcap: truncated chunk");
  const std::uint64_t usize = rd_u64(p + 16);
  const std::size_t clen = rd_u32(p + 28);
  if (clen > n - 32) throw format_error("mcap: truncated chunk compression name");
  const std::string comp(reinterpret_cast<const char*>(p + 32), clen);
  std::size_t i = 32 + clen;
  if (n - i < 8) throw format_error("mcap: truncated chunk records");
  const std::uint64_t rlen = rd_u64(p + i);
  i += 8;
  if (rlen > n - i) throw format_error("mcap: chunk records run past the chunk");
  if (comp.empty()) {
    *rp = p + i;
    *rn = static_cast<std::size_t>(rlen);
    return;
  }
  raw.clear();
  if (comp == "lz4") {
    allanvar::lz4_frame_decode(p + i, static_cast<std::size_t>(rlen), raw,
                               static_cast<std::size_t>(usize));
  } else if (comp == "zstd") {
    allanvar::zstd_decode(p + i, static_cast<std::size_t>(rlen), raw,
                          static_cast<std::size_t>(usize));
  } else {
    throw format_error("mcap: chunk compression \"" + comp + "\" is not supported (none, lz4, zstd are)");
  }
  if (raw.size() != usize) throw format_error("mcap: a chunk does not decompress to its stated size");
  *rp = raw.data();
  *rn = raw.size();
}

}  // namespace

// Records of buf[start, end): opcode, content offset (0-based) and length.
// [[Rcpp::export(rng = false)]]
Rcpp::List mcap_records(const Rcpp::RawVector& buf, double start, double end) {
  std::vector<rec> r;
  try {
    r = walk(RAW(buf), static_cast<std::size_t>(start), static_cast<std::size_t>(end));
  } catch (const format_error& e) {
    Rcpp::stop(e.what());
  }
  const R_xlen_t n = r.size();
  Rcpp::IntegerVector op(n);
  Rcpp::NumericVector off(n), len(n);
  for (R_xlen_t i = 0; i < n; ++i) {
    op[i] = r[i].op;
    off[i] = r[i].off;
    len[i] = r[i].len;
  }
  return Rcpp::List::create(Rcpp::Named("op") = op, Rcpp::Named("off") = off,
                            Rcpp::Named("len") = len);
}

// The decompressed records of the chunk whose content is buf[off, off+len).
// [[Rcpp::export(rng = false)]]
Rcpp::RawVector mcap_chunk_raw(const Rcpp::RawVector& buf, double off, double len) {
  std::vector<unsigned char> raw;
  const unsigned char* rp = nullptr;
  std::size_t rn = 0;
  try {
    chunk_records(RAW(buf) + static_cast<std::size_t>(off), static_cast<std::size_t>(len),
                  raw, &rp, &rn);
  } catch (const format_error& e) {
    Rcpp::stop(e.what());
  }
  Rcpp::RawVector out(rn);
  if (rn) std::memcpy(RAW(out), rp, rn);
  return out;
}

// The sensor_msgs/Imu messages of channels `ids` (encodings `enc`: 0 ros1,
// 1 cdr) in the given top-level records (Message and Chunk records; others
// are skipped). Returns the table and the count of undecodable messages.
// [[Rcpp::export(rng = false)]]
Rcpp::List mcap_imu(const Rcpp::RawVector& buf, const Rcpp::IntegerVector& op,
                    const Rcpp::NumericVector& off, const Rcpp::NumericVector& len,
                    const Rcpp::IntegerVector& ids, const Rcpp::IntegerVector& enc) {
  channels ch;
  ch.id.assign(ids.begin(), ids.end());
  ch.enc.assign(enc.begin(), enc.end());
  std::vector<double> out;
  std::vector<unsigned char> raw;
  R_xlen_t bad = 0;
  const unsigned char* p = RAW(buf);
  try {
    for (R_xlen_t k = 0; k < op.size(); ++k) {
      Rcpp::checkUserInterrupt();
      const std::size_t o = static_cast<std::size_t>(off[k]);
      const std::size_t n = static_cast<std::size_t>(len[k]);
      if (op[k] == 0x05) {
        message(p + o, n, ch, out, &bad);
      } else if (op[k] == 0x06) {
        const unsigned char* rp = nullptr;
        std::size_t rn = 0;
        chunk_records(p + o, n, raw, &rp, &rn);
        for (const rec& r : walk(rp, 0, rn)) {
          if (r.op == 0x05) message(rp + r.off, r.len, ch, out, &bad);
        }
      }
    }
  } catch (const format_error& e) {
    Rcpp::stop(e.what());
  }
  const R_xlen_t n = out.size() / allanvar::kImuCols;
  Rcpp::NumericMatrix m(n, allanvar::kImuCols);
  for (R_xlen_t i = 0; i < n; ++i) {
    for (int j = 0; j < allanvar::kImuCols; ++j) m(i, j) = out[i * allanvar::kImuCols + j];
  }
  return Rcpp::List::create(Rcpp::Named("imu") = m, Rcpp::Named("bad") = static_cast<double>(bad));
}
