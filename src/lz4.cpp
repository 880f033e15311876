// LZ4 frame decoder written from the LZ4 Frame Format Description 1.6.x
// and the LZ4 Block Format Description (github.com/lz4/lz4, doc/). Blocks
// are decoded into one contiguous buffer, so linked blocks (matches that
// reach into the previous block) need nothing extra. Checksums (xxHash32)
// are skipped: the bag and MCAP layers check the record structure.
#include "lz4.h"
#include "bytes.h"

#include <Rcpp.h>
#include <algorithm>
#include <cstring>
#include <string>

namespace allanvar {

namespace {

const std::uint32_t kFrameMagic = 0x184D2204u;

// Output buffer written through a raw pointer; grows geometrically.
struct sink {
  std::vector<unsigned char>& v;
  std::size_t pos;
  void need(std::size_t extra) {
    if (v.size() - pos < extra) v.resize(std::max(v.size() * 2, pos + extra));
  }
};

void block_decode(const unsigned char* p, std::size_t n, sink& out) {
  std::size_t i = 0;
  while (i < n) {
    const unsigned token = p[i++];
    std::size_t lit = token >> 4;
    if (lit == 15) {
      unsigned char b;
      do {
        if (i >= n) throw format_error("lz4: literal length runs past the block");
        b = p[i++];
        lit += b;
      } while (b == 255);
    }
    if (lit > n - i) throw format_error("lz4: literals run past the block");
    out.need(lit);
    std::memcpy(out.v.data() + out.pos, p + i, lit);
    out.pos += lit;
    i += lit;
    if (i == n) break;  // the last sequence has literals only
    if (n - i < 2) throw format_error("lz4: truncated match offset");
    const std::size_t offset = rd_u16(p + i);
    i += 2;
    if (offset == 0 || offset > out.pos) {
      throw format_error("lz4: match offset outside the decoded data");
    }
    std::size_t len = (token & 15u) + 4;
    if ((token & 15u) == 15) {
      unsigned char b;
      do {
        if (i >= n) throw format_error("lz4: match length runs past the block");
        b = p[i++];
        len += b;
      } while (b == 255);
    }
    out.need(len);
    unsigned char* d = out.v.data() + out.pos;
    const unsigned char* s = d - offset;
    if (offset >= len) {
      std::memcpy(d, s, len);
    } else {
      // Overlapping match: the bytes repeat with period `offset`; copy
      // from a whole number of periods back, the span doubling each time.
      std::size_t done = 0;
      while (done < len) {
        const std::size_t back = (done / offset + 1) * offset;
        const std::size_t c = std::min(len - done, back);
        std::memcpy(d + done, d + done - back, c);
        done += c;
      }
      (void)s;
    }
    out.pos += len;
  }
}

}  // namespace

void lz4_frame_decode(const unsigned char* src, std::size_t n,
                      std::vector<unsigned char>& dst, std::size_t expected) {
  sink out{dst, dst.size()};
  dst.resize(dst.size() + (expected ? expected : 4 * n + 64));
  std::size_t i = 0;
  while (i < n) {
    if (n - i < 4) throw format_error("lz4: truncated frame");
    const std::uint32_t magic = rd_u32(src + i);
    if ((magic & 0xFFFFFFF0u) == 0x184D2A50u) {  // skippable frame
      if (n - i < 8) throw format_error("lz4: truncated skippable frame");
      const std::size_t len = rd_u32(src + i + 4);
      if (len > n - i - 8) throw format_error("lz4: truncated skippable frame");
      i += 8 + len;
      continue;
    }
    if (magic != kFrameMagic) throw format_error("lz4: not an LZ4 frame (bad magic number)");
    i += 4;
    if (n - i < 3) throw format_error("lz4: truncated frame header");
    const unsigned flg = src[i];
    if ((flg >> 6) != 1) throw format_error("lz4: unsupported frame version");
    const bool block_checksum = flg & 0x10u;
    const bool content_size = flg & 0x08u;
    const bool content_checksum = flg & 0x04u;
    const bool dict_id = flg & 0x01u;
    if (dict_id) throw format_error("lz4: frames with a dictionary are not supported");
    std::size_t hdr = 2 + (content_size ? 8 : 0) + 1;  // FLG BD [size] HC
    if (n - i < hdr) throw format_error("lz4: truncated frame header");
    i += hdr;
    for (;;) {
      if (n - i < 4) throw format_error("lz4: truncated block");
      const std::uint32_t word = rd_u32(src + i);
      i += 4;
      if (word == 0) break;  // EndMark
      const std::size_t size = word & 0x7FFFFFFFu;
      if (size > n - i) throw format_error("lz4: block runs past the data");
      if (word & 0x80000000u) {
        out.need(size);
        std::memcpy(dst.data() + out.pos, src + i, size);
        out.pos += size;
      } else {
        block_decode(src + i, size, out);
      }
      i += size + (block_checksum ? 4 : 0);
      if (i > n) throw format_error("lz4: truncated block checksum");
    }
    if (content_checksum) {
      if (n - i < 4) throw format_error("lz4: truncated content checksum");
      i += 4;
    }
  }
  dst.resize(out.pos);
}

}  // namespace allanvar

// R entry point (tests, and R-level callers): decode an LZ4 frame.
// [[Rcpp::export(rng = false)]]
Rcpp::RawVector lz4_decompress_cpp(const Rcpp::RawVector& x, double expected) {
  std::vector<unsigned char> out;
  try {
    allanvar::lz4_frame_decode(RAW(x), x.size(), out,
                               expected > 0 ? static_cast<std::size_t>(expected) : 0);
  } catch (const allanvar::format_error& e) {
    Rcpp::stop(e.what());
  }
  Rcpp::RawVector r(out.size());
  if (!out.empty()) std::memcpy(RAW(r), out.data(), out.size());
  return r;
}
