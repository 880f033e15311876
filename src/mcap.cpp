// MCAP (mcap.dev/spec), streamed from the file: magic "\x89MCAP0\r\n", then
// records of <opcode u8><length u64><content>, a summary section (Schema
// 0x03, Channel 0x04, Statistics 0x0B, Chunk Index 0x08) found through the
// Footer (0x02) before the closing magic. Chunks (0x06) hold Schema, Channel
// and Message (0x05) records, compressed with "" (none), "lz4" (LZ4 frame)
// or "zstd". Messages are sensor_msgs/Imu in "cdr" (ROS2) or "ros1"
// encoding. One chunk in memory at a time.
#include "bytes.h"
#include "file_reader.h"
#include "lz4.h"
#include "ros_msgs.h"
#include "zstd.h"

#include <Rcpp.h>
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

namespace {

using allanvar::FileReader;
using allanvar::format_error;
using allanvar::rd_u16;
using allanvar::rd_u32;
using allanvar::rd_u64;

const std::uint64_t kMagic = 8;

struct tables {
  std::vector<double> sch_id, ch_id, ch_schema, count_id, count_n;
  std::vector<std::string> sch_name, ch_topic, ch_enc;
  void schema(const unsigned char* p, std::size_t n) {
    if (n < 6) throw format_error("a truncated schema record");
    const std::uint32_t nl = rd_u32(p + 2);
    if (nl > n - 6) throw format_error("a schema name runs past its record");
    const double id = rd_u16(p);
    if (std::find(sch_id.begin(), sch_id.end(), id) != sch_id.end()) return;
    sch_id.push_back(id);
    sch_name.push_back(std::string(reinterpret_cast<const char*>(p + 6), nl));
  }
  void channel(const unsigned char* p, std::size_t n) {
    if (n < 8) throw format_error("a truncated channel record");
    const std::uint32_t tl = rd_u32(p + 4);
    if (tl > n - 8 || n - 8 - tl < 4) throw format_error("a channel topic runs past its record");
    const std::uint32_t el = rd_u32(p + 8 + tl);
    if (el > n - 12 - tl) throw format_error("a channel encoding runs past its record");
    const double id = rd_u16(p);
    if (std::find(ch_id.begin(), ch_id.end(), id) != ch_id.end()) return;
    ch_id.push_back(id);
    ch_schema.push_back(rd_u16(p + 2));
    ch_topic.push_back(std::string(reinterpret_cast<const char*>(p + 8), tl));
    ch_enc.push_back(std::string(reinterpret_cast<const char*>(p + 12 + tl), el));
  }
  void statistics(const unsigned char* p, std::size_t n) {
    if (n < 46) throw format_error("a truncated statistics record");
    const std::uint32_t len = rd_u32(p + 42);
    if (len > n - 46) throw format_error("statistics counts run past their record");
    for (std::uint32_t e = 0; e + 10 <= len; e += 10) {
      count_id.push_back(rd_u16(p + 46 + e));
      count_n.push_back(static_cast<double>(rd_u64(p + 46 + e + 2)));
    }
  }
};

struct sink {
  std::vector<int> id, enc;
  double from = R_NegInf, to = R_PosInf;
  std::vector<double> rows;
  R_xlen_t bad = 0;
  tables* tabs = nullptr;  // when set, schema and channel records are collected
  void message(const unsigned char* p, std::size_t n) {
    if (n < 22) throw format_error("a truncated message record");
    const int c = rd_u16(p);
    int e = -1;
    for (std::size_t k = 0; k < id.size(); ++k) if (id[k] == c) e = enc[k];
    if (e < 0) return;
    const std::int64_t log_time = static_cast<std::int64_t>(rd_u64(p + 6));
    const double t = static_cast<double>(log_time);
    if (t < from || t > to) return;
    if (!allanvar::decode_imu(p + 22, n - 22, e, log_time, rows)) ++bad;
  }
  void records(const unsigned char* p, std::size_t n) {
    std::size_t i = 0;
    while (i < n) {
      if (n - i < 9) throw format_error("a record cut off inside a chunk");
      const std::uint64_t len = rd_u64(p + i + 1);
      if (len > n - i - 9) throw format_error("a record runs past its chunk");
      const unsigned char* c = p + i + 9;
      const std::size_t cl = static_cast<std::size_t>(len);
      switch (p[i]) {
        case 0x05: message(c, cl); break;
        case 0x03: if (tabs) tabs->schema(c, cl); break;
        case 0x04: if (tabs) tabs->channel(c, cl); break;
        default: break;
      }
      i += 9 + cl;
    }
  }
};

// A chunk's content: decompress and walk its records.
void chunk(const unsigned char* p, std::size_t n, std::vector<unsigned char>& raw, sink& s) {
  if (n < 32) throw format_error("a truncated chunk");
  const std::uint64_t usize = rd_u64(p + 16);
  const std::size_t clen = rd_u32(p + 28);
  if (clen > n - 32) throw format_error("a chunk compression name runs past its chunk");
  const std::string comp(reinterpret_cast<const char*>(p + 32), clen);
  std::size_t i = 32 + clen;
  if (n - i < 8) throw format_error("a chunk cut off before its records");
  const std::uint64_t rlen = rd_u64(p + i);
  i += 8;
  if (rlen > n - i) throw format_error("chunk records run past the chunk");
  if (comp.empty()) {
    s.records(p + i, static_cast<std::size_t>(rlen));
    return;
  }
  raw.clear();
  if (comp == "lz4") {
    allanvar::lz4_frame_decode(p + i, static_cast<std::size_t>(rlen), raw, static_cast<std::size_t>(usize));
  } else if (comp == "zstd") {
    allanvar::zstd_decode(p + i, static_cast<std::size_t>(rlen), raw, static_cast<std::size_t>(usize));
  } else {
    throw format_error("chunk compression \"" + comp + "\" is not supported (none, lz4, zstd are)");
  }
  if (raw.size() != usize) throw format_error("a chunk does not decompress to its stated size");
  s.records(raw.data(), raw.size());
}

// An uncompressed chunk walked in the file, the messages of other channels
// (camera images) skipped, never read; false for compressed chunks. Throws
// format_error.
bool uncompressed_chunk_walk(FileReader& f, std::uint64_t at, std::uint64_t n, sink& s) {
  unsigned char b[40];
  if (n < 40 || !f.read(at, 32, b)) throw format_error("a truncated chunk");
  const std::uint32_t clen = rd_u32(b + 28);
  if (clen != 0) return false;
  if (!f.read(at + 32, 8, b)) throw format_error("a truncated chunk");
  const std::uint64_t rlen = rd_u64(b);
  if (rlen > n - 40) throw format_error("chunk records run past the chunk");
  std::uint64_t i = at + 40;
  const std::uint64_t end = i + rlen;
  std::vector<unsigned char> c;
  while (i < end) {
    if (end - i < 9 || !f.read(i, 9, b)) throw format_error("a record cut off inside a chunk");
    const std::uint64_t len = rd_u64(b + 1);
    if (len > end - i - 9) throw format_error("a record runs past its chunk");
    if (b[0] == 0x05) {
      if (len < 22 || !f.read(i + 9, 2, b + 9)) throw format_error("a truncated message record");
      const int ch = rd_u16(b + 9);
      if (std::find(s.id.begin(), s.id.end(), ch) != s.id.end()) {
        if (!f.read(i + 9, static_cast<std::size_t>(len), c)) throw format_error("a message cut off");
        s.message(c.data(), c.size());
      }
    }
    i += 9 + len;
  }
  return true;
}

Rcpp::List fault_list(double off, const std::string& why) {
  return Rcpp::List::create(Rcpp::Named("off") = off, Rcpp::Named("what") = why);
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

// What an MCAP file says of itself without its messages: schemas, channels,
// message counts (Statistics) and the chunks (record position, time span in
// ns). From the summary section when the footer points to one; else (or
// when the summary has no chunk indexes) the chunks from one pass over the
// record headers (seeks, a few bytes per chunk), and the schemas and
// channels of the data section (chunks decompressed only when the summary
// does not list channels). `fault`: where a pass stopped (byte offset, what).
// [[Rcpp::export(rng = false)]]
Rcpp::List mcap_index_cpp(std::string path) {
  tables t;
  std::vector<double> pos, start, end;
  bool summary = false;
  Rcpp::List fault;
  double bytes = 0, size = 0;
  try {
    FileReader f(path);
    size = static_cast<double>(f.size());
    std::vector<unsigned char> b;
    // Footer: op, length 20, summary_start, summary_offset_start, crc; magic.
    const std::uint64_t tail = 1 + 8 + 20 + kMagic;
    std::uint64_t summary_start = 0;
    if (f.size() >= kMagic + tail && f.read(f.size() - tail, static_cast<std::size_t>(tail), b) &&
        b[0] == 0x02 && rd_u64(b.data() + 1) == 20 &&
        std::memcmp(b.data() + 29, "\x89MCAP0\r\n", 8) == 0) {
      summary_start = rd_u64(b.data() + 9);
    }
    const std::uint64_t footer = f.size() - tail;
    if (summary_start >= kMagic && summary_start < footer) {
      summary = true;
      std::uint64_t off = summary_start;
      while (off < footer) {
        if (!f.read(off, 9, b)) throw format_error("the summary section cut off");
        const int op = b[0];
        const std::uint64_t len = rd_u64(b.data() + 1);
        if (len > footer - off - 9) throw format_error("a summary record runs past the footer at byte " + std::to_string(off));
        if (op == 0x03 || op == 0x04 || op == 0x0B || op == 0x08) {
          if (!f.read(off + 9, static_cast<std::size_t>(len), b)) throw format_error("the summary section cut off");
          const unsigned char* c = b.data();
          const std::size_t n = static_cast<std::size_t>(len);
          if (op == 0x03) t.schema(c, n);
          if (op == 0x04) t.channel(c, n);
          if (op == 0x0B) t.statistics(c, n);
          if (op == 0x08) {
            if (n < 32) throw format_error("a truncated chunk index record");
            start.push_back(static_cast<double>(rd_u64(c)));
            end.push_back(static_cast<double>(rd_u64(c + 8)));
            pos.push_back(static_cast<double>(rd_u64(c + 16)));
          }
        }
        off += 9 + len;
      }
    }
    if (pos.empty()) {
      // One pass over the data section's record headers.
      const std::uint64_t stop = summary ? summary_start : f.size();
      const bool need_channels = t.ch_id.empty();
      sink s;
      s.tabs = &t;
      std::vector<unsigned char> raw;
      std::uint64_t off = kMagic;
      while (off < stop) {
        if (off % 64 == 0) Rcpp::checkUserInterrupt();
        if (stop - off < 9 || !f.read(off, 9, b)) {
          if (!summary && stop - off == kMagic) break;  // the closing magic
          fault = fault_list(static_cast<double>(off), "a record header cut off");
          break;
        }
        const int op = b[0];
        const std::uint64_t len = rd_u64(b.data() + 1);
        if (len > stop - off - 9) {
          fault = fault_list(static_cast<double>(off), "a record runs past the end of the file");
          break;
        }
        if (op == 0x02) break;  // footer: the end of the data
        if (op == 0x06 || op == 0x05) {
          if (op == 0x06) {
            if (!f.read(off + 9, 16, b)) throw format_error("a chunk cut off");
            start.push_back(static_cast<double>(rd_u64(b.data())));
            end.push_back(static_cast<double>(rd_u64(b.data() + 8)));
          } else {
            if (len < 22 || !f.read(off + 9, 22, b)) throw format_error("a message cut off");
            start.push_back(static_cast<double>(rd_u64(b.data() + 6)));
            end.push_back(start.back());
          }
          pos.push_back(static_cast<double>(off));
          if (op == 0x06 && need_channels) {
            std::vector<unsigned char> c;
            if (!f.read(off + 9, static_cast<std::size_t>(len), c)) throw format_error("a chunk cut off");
            try {
              chunk(c.data(), c.size(), raw, s);
            } catch (const format_error& e) {
              fault = fault_list(static_cast<double>(off), e.what());
              pos.pop_back(); start.pop_back(); end.pop_back();
              break;
            }
          }
        } else if (op == 0x03 || op == 0x04) {
          std::vector<unsigned char> c;
          if (!f.read(off + 9, static_cast<std::size_t>(len), c)) throw format_error("a record cut off");
          if (op == 0x03) t.schema(c.data(), c.size()); else t.channel(c.data(), c.size());
        }
        off += 9 + len;
      }
    }
    bytes = f.bytes_read();
  } catch (const format_error& e) {
    Rcpp::stop(e.what());
  }
  Rcpp::CharacterVector sname(t.sch_name.size()), topic(t.ch_topic.size()), enc(t.ch_enc.size());
  for (std::size_t k = 0; k < t.sch_name.size(); ++k) sname[k] = t.sch_name[k];
  for (std::size_t k = 0; k < t.ch_topic.size(); ++k) {
    topic[k] = t.ch_topic[k];
    enc[k] = t.ch_enc[k];
  }
  return Rcpp::List::create(
      Rcpp::Named("summary") = summary, Rcpp::Named("size") = size, Rcpp::Named("bytes") = bytes,
      Rcpp::Named("schemas") = Rcpp::DataFrame::create(
          Rcpp::Named("id") = Rcpp::wrap(t.sch_id), Rcpp::Named("name") = sname,
          Rcpp::Named("stringsAsFactors") = false),
      Rcpp::Named("channels") = Rcpp::DataFrame::create(
          Rcpp::Named("id") = Rcpp::wrap(t.ch_id), Rcpp::Named("schema") = Rcpp::wrap(t.ch_schema),
          Rcpp::Named("topic") = topic, Rcpp::Named("encoding") = enc,
          Rcpp::Named("stringsAsFactors") = false),
      Rcpp::Named("counts") = Rcpp::DataFrame::create(
          Rcpp::Named("id") = Rcpp::wrap(t.count_id), Rcpp::Named("n") = Rcpp::wrap(t.count_n)),
      Rcpp::Named("chunks") = Rcpp::DataFrame::create(
          Rcpp::Named("pos") = Rcpp::wrap(pos), Rcpp::Named("start") = Rcpp::wrap(start),
          Rcpp::Named("end") = Rcpp::wrap(end)),
      Rcpp::Named("fault") = fault);
}

// The sensor_msgs/Imu messages of channels `ids` (encodings `enc`: 0 ros1,
// 1 cdr) logged in [from, to] (ns), from the Chunk or Message records at
// file positions `pos`, one at a time. Stops at a fault (`fault`: byte
// offset and what); `done`: the number of records read.
// [[Rcpp::export(rng = false)]]
Rcpp::List mcap_read_cpp(std::string path, const Rcpp::NumericVector& pos,
                         const Rcpp::IntegerVector& ids, const Rcpp::IntegerVector& enc,
                         double from, double to) {
  sink s;
  s.id.assign(ids.begin(), ids.end());
  s.enc.assign(enc.begin(), enc.end());
  s.from = from;
  s.to = to;
  Rcpp::List fault;
  R_xlen_t k = 0;
  double bytes = 0;
  try {
    FileReader f(path);
    std::vector<unsigned char> b, c, raw;
    for (; k < pos.size(); ++k) {
      if (k % 16 == 0) Rcpp::checkUserInterrupt();
      const std::uint64_t off = static_cast<std::uint64_t>(pos[k]);
      if (!f.read(off, 9, b)) { fault = fault_list(pos[k], "a record header cut off"); break; }
      const std::uint64_t len = rd_u64(b.data() + 1);
      if (b[0] != 0x06 && b[0] != 0x05) { fault = fault_list(pos[k], "no chunk where the index says"); break; }
      if (len > f.size() - off - 9) {
        fault = fault_list(pos[k], "a record runs past the end of the file");
        break;
      }
      if (b[0] == 0x06) {
        try {
          if (uncompressed_chunk_walk(f, off + 9, len, s)) continue;
        } catch (const format_error& e) {
          fault = fault_list(pos[k], e.what());
          break;
        }
      }
      if (!f.read(off + 9, static_cast<std::size_t>(len), c)) {
        fault = fault_list(pos[k], "a record runs past the end of the file");
        break;
      }
      try {
        if (b[0] == 0x06) chunk(c.data(), c.size(), raw, s); else s.message(c.data(), c.size());
      } catch (const format_error& e) {
        fault = fault_list(pos[k], e.what());
        break;
      }
    }
    bytes = f.bytes_read();
  } catch (const format_error& e) {
    Rcpp::stop(e.what());
  }
  return Rcpp::List::create(Rcpp::Named("imu") = as_matrix(s.rows),
                            Rcpp::Named("bad") = static_cast<double>(s.bad),
                            Rcpp::Named("done") = static_cast<double>(k),
                            Rcpp::Named("fault") = fault, Rcpp::Named("bytes") = bytes);
}
