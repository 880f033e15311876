// ROS1 bag format 2.0 (wiki.ros.org/Bags/Format/2.0), streamed from the
// file: after the version line, records of <header_len u32><header>
// <data_len u32><data>, the header being fields <len u32><name>=<value>.
// The bag header record gives the index position; the index (connection
// records 0x07 and chunk-info records 0x06 at the end) says which chunks
// hold which connections and their time span. Chunks (0x05) hold
// connection and message data (0x02) records, compressed as the chunk's
// `compression` field says (none; lz4: src/lz4.cpp; bz2: decompressed by R,
// R/read-bag.R). One chunk in memory at a time.
#include "bytes.h"
#include "file_reader.h"
#include "lz4.h"
#include "ros_msgs.h"

#include <Rcpp.h>
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

namespace {

using allanvar::FileReader;
using allanvar::format_error;
using allanvar::rd_u32;
using allanvar::rd_u64;

const std::uint64_t kVersionLen = 13;  // "#ROSBAG V2.0\n"

// The value of header field `name`, or nullptr.
const unsigned char* find_field(const unsigned char* h, std::size_t n,
                                const char* name, std::size_t* len) {
  const std::size_t nl = std::strlen(name);
  std::size_t i = 0;
  while (i + 4 <= n) {
    const std::size_t fl = rd_u32(h + i);
    i += 4;
    if (fl > n - i) throw format_error("a header field runs past its header");
    const unsigned char* f = h + i;
    if (fl > nl && std::memcmp(f, name, nl) == 0 && f[nl] == '=') {
      *len = fl - nl - 1;
      return f + nl + 1;
    }
    i += fl;
  }
  return nullptr;
}

std::string field_str(const unsigned char* h, std::size_t n, const char* name) {
  std::size_t len = 0;
  const unsigned char* v = find_field(h, n, name, &len);
  return v ? std::string(reinterpret_cast<const char*>(v), len) : std::string();
}

bool field_u32(const unsigned char* h, std::size_t n, const char* name, std::uint32_t* out) {
  std::size_t len = 0;
  const unsigned char* v = find_field(h, n, name, &len);
  if (!v || len != 4) return false;
  *out = rd_u32(v);
  return true;
}

bool field_u64(const unsigned char* h, std::size_t n, const char* name, std::uint64_t* out) {
  std::size_t len = 0;
  const unsigned char* v = find_field(h, n, name, &len);
  if (!v || len != 8) return false;
  *out = rd_u64(v);
  return true;
}

double field_time(const unsigned char* h, std::size_t n, const char* name) {
  std::uint64_t t = 0;
  if (!field_u64(h, n, name, &t)) return NA_REAL;
  return static_cast<double>(t & 0xffffffffu) * 1e9 + static_cast<double>(t >> 32);
}

int field_op(const unsigned char* h, std::size_t n) {
  std::size_t len = 0;
  const unsigned char* op = find_field(h, n, "op", &len);
  return (op && len == 1) ? op[0] : -1;
}

// A record read from the file: header bytes, data position and length.
struct file_record {
  std::vector<unsigned char> hdr;
  std::uint64_t data = 0, data_len = 0, end = 0;
  int op = -1;
};

// The record at `off`; false (with `why`) when the file ends inside it.
bool read_record_header(FileReader& f, std::uint64_t off, file_record& r, std::string* why) {
  unsigned char b[4];
  if (!f.read(off, 4, b)) { *why = "a record header length cut off"; return false; }
  const std::uint64_t hl = rd_u32(b);
  if (hl > f.size() - off - 4) { *why = "a record header runs past the end of the file"; return false; }
  if (!f.read(off + 4, static_cast<std::size_t>(hl), r.hdr)) { *why = "a record header cut off"; return false; }
  if (!f.read(off + 4 + hl, 4, b)) { *why = "a record data length cut off"; return false; }
  r.data_len = rd_u32(b);
  r.data = off + 8 + hl;
  if (r.data_len > f.size() - r.data) { *why = "a record runs past the end of the file"; return false; }
  r.end = r.data + r.data_len;
  r.op = field_op(r.hdr.data(), r.hdr.size());
  return true;
}

// The decoded messages of the wanted connections, and what else a pass
// over chunks learns (connections, message counts per connection).
struct sink {
  std::vector<int> conns;
  double from = R_NegInf, to = R_PosInf;
  std::vector<double> rows;
  R_xlen_t bad = 0;
  bool want_conns = false;  // collect connection records and counts
  std::vector<double> conn_id, conn_n;
  std::vector<std::string> conn_topic, conn_type;
};

void note_conn(sink& s, const unsigned char* h, std::size_t hn, const unsigned char* d, std::size_t dn) {
  std::uint32_t id = 0;
  if (!field_u32(h, hn, "conn", &id)) throw format_error("a connection record without its id");
  for (double c : s.conn_id) if (c == id) return;
  s.conn_id.push_back(id);
  s.conn_n.push_back(0);
  s.conn_topic.push_back(field_str(h, hn, "topic"));
  s.conn_type.push_back(field_str(d, dn, "type"));
}

// The records of a decompressed chunk.
void chunk_messages(const unsigned char* p, std::size_t n, sink& s) {
  std::size_t i = 0;
  while (i < n) {
    if (n - i < 4) throw format_error("a record header length cut off inside a chunk");
    const std::size_t hl = rd_u32(p + i);
    const std::size_t h = i + 4;
    if (hl > n - h || n - h - hl < 4) throw format_error("a record header cut off inside a chunk");
    const std::size_t dl = rd_u32(p + h + hl);
    const std::size_t d = h + hl + 4;
    if (dl > n - d) throw format_error("a record runs past its chunk");
    const int op = field_op(p + h, hl);
    if (op == 7 && s.want_conns) note_conn(s, p + h, hl, p + d, dl);
    if (op == 2) {
      std::uint32_t conn = 0;
      if (!field_u32(p + h, hl, "conn", &conn)) throw format_error("a message record without its connection");
      if (s.want_conns) {
        for (std::size_t k = 0; k < s.conn_id.size(); ++k) {
          if (s.conn_id[k] == conn) s.conn_n[k] += 1;
        }
      }
      if (std::find(s.conns.begin(), s.conns.end(), static_cast<int>(conn)) != s.conns.end()) {
        std::uint64_t t = 0;
        std::int64_t recv = 0;
        if (field_u64(p + h, hl, "time", &t)) {
          recv = static_cast<std::int64_t>(t & 0xffffffffu) * 1000000000LL +
                 static_cast<std::int64_t>(t >> 32);
        }
        const double tr = static_cast<double>(recv);
        if (tr >= s.from && tr <= s.to) {
          if (!allanvar::decode_imu(p + d, dl, allanvar::ENC_ROS1, recv, s.rows)) ++s.bad;
        }
      }
    }
    i = d + dl;
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

// Reads and decodes the chunk record `r` (already read up to its data).
// Returns 0, or 2 for a bz2 chunk (left to R), and throws format_error.
int read_chunk(FileReader& f, const file_record& r, std::vector<unsigned char>& comp,
               std::vector<unsigned char>& raw, sink& s) {
  const std::string c = field_str(r.hdr.data(), r.hdr.size(), "compression");
  std::uint32_t size = 0;
  field_u32(r.hdr.data(), r.hdr.size(), "size", &size);
  if (c == "bz2") return 2;
  if (c != "none" && c != "lz4") throw format_error("chunks compressed with \"" + c + "\" (none, bz2 and lz4 are read)");
  if (c == "none") {
    // Uncompressed: the records walked in the file, the data of other
    // topics (camera images) skipped, never read.
    std::uint64_t i = r.data;
    unsigned char b[4];
    std::vector<unsigned char> h, d;
    while (i < r.end) {
      if (r.end - i < 8 || !f.read(i, 4, b)) throw format_error("a record cut off inside a chunk");
      const std::uint64_t hl = rd_u32(b);
      if (hl > r.end - i - 8) throw format_error("a record header cut off inside a chunk");
      if (!f.read(i + 4, static_cast<std::size_t>(hl), h) || !f.read(i + 4 + hl, 4, b)) {
        throw format_error("a record cut off inside a chunk");
      }
      const std::uint64_t dl = rd_u32(b);
      const std::uint64_t at = i + 8 + hl;
      if (dl > r.end - at) throw format_error("a record runs past its chunk");
      const int op = field_op(h.data(), h.size());
      bool want = op == 7 && s.want_conns;
      std::uint32_t conn = 0;
      if (op == 2) {
        if (!field_u32(h.data(), h.size(), "conn", &conn)) throw format_error("a message record without its connection");
        want = std::find(s.conns.begin(), s.conns.end(), static_cast<int>(conn)) != s.conns.end();
        if (!want && s.want_conns) {
          for (std::size_t k = 0; k < s.conn_id.size(); ++k) {
            if (s.conn_id[k] == conn) s.conn_n[k] += 1;
          }
        }
      }
      if (want) {
        // The record re-assembled as chunk_messages() reads it.
        d.resize(static_cast<std::size_t>(8 + hl + dl));
        std::memcpy(d.data() + 4, h.data(), h.size());
        for (int k = 0; k < 4; ++k) {
          d[k] = static_cast<unsigned char>(hl >> (8 * k));
          d[4 + hl + k] = static_cast<unsigned char>(dl >> (8 * k));
        }
        if (!f.read(at, static_cast<std::size_t>(dl), d.data() + 8 + hl)) throw format_error("a record cut off inside a chunk");
        chunk_messages(d.data(), d.size(), s);
      }
      i = at + dl;
    }
  } else {
    if (!f.read(r.data, static_cast<std::size_t>(r.data_len), comp)) throw format_error("a chunk cut off");
    raw.clear();
    allanvar::lz4_frame_decode(comp.data(), comp.size(), raw, size);
    if (raw.size() != size) throw format_error("an lz4 chunk does not decompress to its stated size");
    chunk_messages(raw.data(), raw.size(), s);
  }
  return 0;
}

Rcpp::DataFrame conn_frame(const sink& s) {
  Rcpp::CharacterVector topic(s.conn_topic.size()), type(s.conn_type.size());
  for (std::size_t k = 0; k < s.conn_topic.size(); ++k) {
    topic[k] = s.conn_topic[k];
    type[k] = s.conn_type[k].empty() ? Rcpp::String(NA_STRING) : Rcpp::String(s.conn_type[k]);
  }
  return Rcpp::DataFrame::create(
      Rcpp::Named("conn") = Rcpp::wrap(s.conn_id), Rcpp::Named("topic") = topic,
      Rcpp::Named("type") = type, Rcpp::Named("n") = Rcpp::wrap(s.conn_n),
      Rcpp::Named("stringsAsFactors") = false);
}

Rcpp::List fault_list(double off, const std::string& why) {
  return Rcpp::List::create(Rcpp::Named("off") = off, Rcpp::Named("what") = why);
}

}  // namespace

// The bag's index without reading its chunks: the bag header's fields and,
// when the index is there, every connection (id, topic, type) and chunk
// (position, time span in ns, message count per connection). Without an
// index (`indexed` FALSE): one pass over the chunks, each decompressed in
// turn (bz2 ones only listed, `bz2` TRUE), for the connections and counts;
// the pass stops at the first fault (`fault`: byte offset and what).
// [[Rcpp::export(rng = false)]]
Rcpp::List rosbag_index_cpp(std::string path) {
  std::vector<double> ch_pos, ch_start, ch_end, cc_chunk, cc_conn, cc_n;
  sink s;
  s.want_conns = true;
  bool indexed = false, has_bz2 = false;
  Rcpp::List fault;
  double bytes = 0, size = 0;
  try {
    FileReader f(path);
    size = static_cast<double>(f.size());
    file_record h;
    std::string why;
    if (!read_record_header(f, kVersionLen, h, &why) || h.op != 3) {
      throw format_error("no bag header record after the version line");
    }
    std::uint64_t index_pos = 0;
    std::uint32_t n_conn = 0, n_chunk = 0;
    field_u64(h.hdr.data(), h.hdr.size(), "index_pos", &index_pos);
    field_u32(h.hdr.data(), h.hdr.size(), "conn_count", &n_conn);
    field_u32(h.hdr.data(), h.hdr.size(), "chunk_count", &n_chunk);
    if (index_pos >= h.end && index_pos < f.size() && n_chunk > 0) {
      // The index: connection and chunk-info records to the end.
      indexed = true;
      std::uint64_t off = index_pos;
      std::vector<unsigned char> d;
      while (off < f.size()) {
        file_record r;
        if (!read_record_header(f, off, r, &why)) { indexed = false; break; }
        if (r.op == 7 || r.op == 6) {
          if (!f.read(r.data, static_cast<std::size_t>(r.data_len), d)) { indexed = false; break; }
        }
        if (r.op == 7) {
          note_conn(s, r.hdr.data(), r.hdr.size(), d.data(), d.size());
        } else if (r.op == 6) {
          std::uint64_t pos = 0;
          if (!field_u64(r.hdr.data(), r.hdr.size(), "chunk_pos", &pos)) { indexed = false; break; }
          const double k = static_cast<double>(ch_pos.size());
          ch_pos.push_back(static_cast<double>(pos));
          ch_start.push_back(field_time(r.hdr.data(), r.hdr.size(), "start_time"));
          ch_end.push_back(field_time(r.hdr.data(), r.hdr.size(), "end_time"));
          for (std::size_t e = 0; e + 8 <= d.size(); e += 8) {
            cc_chunk.push_back(k);
            cc_conn.push_back(rd_u32(d.data() + e));
            cc_n.push_back(rd_u32(d.data() + e + 4));
          }
        }
        off = r.end;
      }
      if (indexed && (ch_pos.size() != n_chunk || s.conn_id.size() != n_conn)) indexed = false;
      if (!indexed) {
        ch_pos.clear(); ch_start.clear(); ch_end.clear();
        cc_chunk.clear(); cc_conn.clear(); cc_n.clear();
        s = sink();
        s.want_conns = true;
      }
    }
    if (!indexed) {
      // One pass over the records after the bag header.
      std::vector<unsigned char> comp, raw;
      std::uint64_t off = h.end;
      const std::uint64_t stop = (index_pos >= h.end && index_pos <= f.size()) ? index_pos : f.size();
      while (off < stop) {
        Rcpp::checkUserInterrupt();
        file_record r;
        if (!read_record_header(f, off, r, &why)) { fault = fault_list(static_cast<double>(off), why); break; }
        if (r.op == 5) {
          try {
            if (read_chunk(f, r, comp, raw, s) == 2) has_bz2 = true;
          } catch (const format_error& e) {
            fault = fault_list(static_cast<double>(off), e.what());
            break;
          }
          ch_pos.push_back(static_cast<double>(off));
          ch_start.push_back(NA_REAL);
          ch_end.push_back(NA_REAL);
        } else if (r.op == 7) {
          std::vector<unsigned char> d;
          if (!f.read(r.data, static_cast<std::size_t>(r.data_len), d)) { fault = fault_list(static_cast<double>(off), "a connection record cut off"); break; }
          note_conn(s, r.hdr.data(), r.hdr.size(), d.data(), d.size());
        }
        off = r.end;
      }
    }
    bytes = f.bytes_read();
  } catch (const format_error& e) {
    Rcpp::stop(e.what());
  }
  if (indexed) {
    std::fill(s.conn_n.begin(), s.conn_n.end(), 0.0);
    for (std::size_t e = 0; e < cc_conn.size(); ++e) {
      for (std::size_t k = 0; k < s.conn_id.size(); ++k) {
        if (s.conn_id[k] == cc_conn[e]) s.conn_n[k] += cc_n[e];
      }
    }
  } else if (has_bz2) {
    std::fill(s.conn_n.begin(), s.conn_n.end(), NA_REAL);
  }
  return Rcpp::List::create(
      Rcpp::Named("indexed") = indexed, Rcpp::Named("bz2") = has_bz2,
      Rcpp::Named("size") = size, Rcpp::Named("bytes") = bytes,
      Rcpp::Named("conns") = conn_frame(s),
      Rcpp::Named("chunks") = Rcpp::DataFrame::create(
          Rcpp::Named("pos") = Rcpp::wrap(ch_pos), Rcpp::Named("start") = Rcpp::wrap(ch_start),
          Rcpp::Named("end") = Rcpp::wrap(ch_end)),
      Rcpp::Named("chunk_conns") = Rcpp::DataFrame::create(
          Rcpp::Named("chunk") = Rcpp::wrap(cc_chunk), Rcpp::Named("conn") = Rcpp::wrap(cc_conn),
          Rcpp::Named("n") = Rcpp::wrap(cc_n)),
      Rcpp::Named("fault") = fault);
}

// The sensor_msgs/Imu messages of connections `conns` received in
// [from, to] (ns) in the chunks at file positions `pos`, read one at a time
// in order. Stops before a bz2 chunk (`next`: its index, 1-based, for R to
// decompress) or at a fault (`fault`: byte offset and what); `done`: the
// number of chunks read.
// [[Rcpp::export(rng = false)]]
Rcpp::List rosbag_read_cpp(std::string path, const Rcpp::NumericVector& pos,
                           const Rcpp::IntegerVector& conns, double from, double to) {
  sink s;
  s.conns.assign(conns.begin(), conns.end());
  s.from = from;
  s.to = to;
  Rcpp::List fault;
  R_xlen_t k = 0;
  bool bz2 = false;
  double bytes = 0;
  try {
    FileReader f(path);
    std::vector<unsigned char> comp, raw;
    for (; k < pos.size(); ++k) {
      if (k % 16 == 0) Rcpp::checkUserInterrupt();
      const std::uint64_t off = static_cast<std::uint64_t>(pos[k]);
      file_record r;
      std::string why;
      if (!read_record_header(f, off, r, &why)) { fault = fault_list(pos[k], why); break; }
      if (r.op != 5) { fault = fault_list(pos[k], "no chunk record where the index says"); break; }
      try {
        if (read_chunk(f, r, comp, raw, s) == 2) { bz2 = true; break; }
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
                            Rcpp::Named("bz2") = bz2, Rcpp::Named("fault") = fault,
                            Rcpp::Named("bytes") = bytes);
}

// The compressed data of the chunk at `pos` and its stated size (bz2
// chunks, which R decompresses).
// [[Rcpp::export(rng = false)]]
Rcpp::List rosbag_chunk_cpp(std::string path, double pos) {
  std::vector<unsigned char> d;
  std::uint32_t size = 0;
  std::string comp;
  try {
    FileReader f(path);
    file_record r;
    std::string why;
    if (!read_record_header(f, static_cast<std::uint64_t>(pos), r, &why)) throw format_error(why);
    if (!f.read(r.data, static_cast<std::size_t>(r.data_len), d)) throw format_error("a chunk cut off");
    field_u32(r.hdr.data(), r.hdr.size(), "size", &size);
    comp = field_str(r.hdr.data(), r.hdr.size(), "compression");
  } catch (const format_error& e) {
    Rcpp::stop(e.what());
  }
  Rcpp::RawVector out(d.size());
  if (!d.empty()) std::memcpy(RAW(out), d.data(), d.size());
  return Rcpp::List::create(Rcpp::Named("data") = out, Rcpp::Named("size") = static_cast<double>(size),
                            Rcpp::Named("compression") = comp);
}

// The messages of a decompressed chunk (as rosbag_read_cpp()), and its
// connection records.
// [[Rcpp::export(rng = false)]]
Rcpp::List rosbag_decode_cpp(const Rcpp::RawVector& raw, const Rcpp::IntegerVector& conns,
                             double from, double to) {
  sink s;
  s.conns.assign(conns.begin(), conns.end());
  s.from = from;
  s.to = to;
  s.want_conns = true;
  try {
    chunk_messages(RAW(raw), raw.size(), s);
  } catch (const format_error& e) {
    Rcpp::stop(e.what());
  }
  return Rcpp::List::create(Rcpp::Named("imu") = as_matrix(s.rows),
                            Rcpp::Named("bad") = static_cast<double>(s.bad),
                            Rcpp::Named("conns") = conn_frame(s));
}
