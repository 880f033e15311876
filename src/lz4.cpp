// LZ4 frame decoder written from the LZ4 Frame Format Description 1.6.x
// and the LZ4 Block Format Description (github.com/lz4/lz4, doc/). Blocks
// are decoded into one contiguous buffer, so linked blocks (matches that
// reach into the previous block) need nothing extra. The frame's checksums
// (xxHash32 of the header, of each block if flagged, of the content if
// flagged) are verified: a damaged chunk is an error, not silent garbage.
#include "lz4.h"
#include "bytes.h"

#include <Rcpp.h>
#include <algorithm>
#include <cstring>
#include <string>

namespace allanvar {

namespace {

const std::uint32_t kFrameMagic = 0x184D2204u;

// xxHash32 (github.com/Cyan4973/xxHash, doc/xxhash_spec.md), seed 0.
inline std::uint32_t rotl(std::uint32_t x, int r) { return (x << r) | (x >> (32 - r)); }

std::uint32_t xxh32(const unsigned char* p, std::size_t n) {
  const std::uint32_t P1 = 2654435761u, P2 = 2246822519u, P3 = 3266489917u,
                      P4 = 668265263u, P5 = 374761393u;
  std::size_t i = 0;
  std::uint32_t h;
  if (n >= 16) {
    std::uint32_t v1 = P1 + P2, v2 = P2, v3 = 0, v4 = 0u - P1;
    for (; i + 16 <= n; i += 16) {
      v1 = rotl(v1 + rd_u32(p + i) * P2, 13) * P1;
      v2 = rotl(v2 + rd_u32(p + i + 4) * P2, 13) * P1;
      v3 = rotl(v3 + rd_u32(p + i + 8) * P2, 13) * P1;
      v4 = rotl(v4 + rd_u32(p + i + 12) * P2, 13) * P1;
    }
    h = rotl(v1, 1) + rotl(v2, 7) + rotl(v3, 12) + rotl(v4, 18);
  } else {
    h = P5;
  }
  h += static_cast<std::uint32_t>(n);
  for (; i + 4 <= n; i += 4) h = rotl(h + rd_u32(p + i) * P3, 17) * P4;
  for (; i < n; ++i) h = rotl(h + p[i] * P5, 11) * P1;
  h ^= h >> 15;
  h *= P2;
  h ^= h >> 13;
  h *= P3;
  h ^= h >> 16;
  return h;
}

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
    if (((xxh32(src + i, hdr - 1) >> 8) & 0xFFu) != src[i + hdr - 1]) {
      throw format_error("lz4: frame header checksum mismatch");
    }
    i += hdr;
    const std::size_t frame_start = out.pos;
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
      if (block_checksum) {
        if (n - i - size < 4) throw format_error("lz4: truncated block checksum");
        if (xxh32(src + i, size) != rd_u32(src + i + size)) {
          throw format_error("lz4: block checksum mismatch");
        }
      }
      i += size + (block_checksum ? 4 : 0);
    }
    if (content_checksum) {
      if (n - i < 4) throw format_error("lz4: truncated content checksum");
      if (xxh32(dst.data() + frame_start, out.pos - frame_start) != rd_u32(src + i)) {
        throw format_error("lz4: content checksum mismatch");
      }
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
