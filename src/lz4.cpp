// LZ4 chunks of ROS1 bags and MCAP files, decoded by the reference LZ4
// frame library vendored in src/lz4/ (v1.10.0, BSD-2; see inst/COPYRIGHTS).
// It verifies the frame header's checksum and, when the frame carries them,
// every block's and the content's: a damaged chunk is an error, never
// silent garbage.
#include "lz4.h"
#include "bytes.h"

#define LZ4F_STATIC_LINKING_ONLY  // LZ4F_getErrorCode()
#include "lz4/lz4frame.h"

#include <Rcpp.h>
#include <algorithm>
#include <cstring>
#include <string>

namespace allanvar {

namespace {

// The library's error in the words the readers' messages use.
std::string lz4_error(std::size_t code) {
  switch (LZ4F_getErrorCode(code)) {
    case LZ4F_ERROR_blockChecksum_invalid: return "lz4: block checksum mismatch";
    case LZ4F_ERROR_contentChecksum_invalid: return "lz4: content checksum mismatch";
    case LZ4F_ERROR_headerChecksum_invalid: return "lz4: frame header checksum mismatch";
    case LZ4F_ERROR_frameType_unknown: return "lz4: not an LZ4 frame (bad magic number)";
    case LZ4F_ERROR_decompressionFailed: return "lz4: a block does not decode (damaged data)";
    case LZ4F_ERROR_allocation_failed: return "lz4: out of memory";
    default: return std::string("lz4: ") + LZ4F_getErrorName(code);
  }
}

// A decompression context per thread, kept between chunks so that its
// block buffers (up to 4 MB) are allocated once, not once a chunk.
struct dctx_holder {
  LZ4F_dctx* d = nullptr;
  dctx_holder() = default;
  ~dctx_holder() { LZ4F_freeDecompressionContext(d); }
  dctx_holder(const dctx_holder&) = delete;
  dctx_holder& operator=(const dctx_holder&) = delete;
  LZ4F_dctx* get() {
    if (!d && LZ4F_isError(LZ4F_createDecompressionContext(&d, LZ4F_VERSION))) {
      d = nullptr;
      throw format_error("lz4: out of memory");
    }
    LZ4F_resetDecompressionContext(d);  // a previous chunk may have failed midway
    return d;
  }
};

}  // namespace

void lz4_frame_decode(const unsigned char* src, std::size_t n,
                      std::vector<unsigned char>& dst, std::size_t expected) {
  thread_local dctx_holder holder;
  LZ4F_dctx* const d = holder.get();
  std::size_t pos = dst.size();
  dst.resize(pos + (expected ? expected : 4 * n + 64));
  std::size_t i = 0;
  std::size_t hint = 0;  // 0 once the last frame has ended
  // Frames follow one another; the context starts a new one by itself.
  while (i < n) {
    if (dst.size() == pos) dst.resize(std::max(dst.size() * 2, pos + (std::size_t{1} << 16)));
    std::size_t in = n - i, out = dst.size() - pos;
    hint = LZ4F_decompress(d, dst.data() + pos, &out, src + i, &in, nullptr);
    if (LZ4F_isError(hint)) throw format_error(lz4_error(hint));
    i += in;
    pos += out;
    if (in == 0 && out == 0) break;  // no progress: cannot happen on valid input
  }
  if (hint != 0) throw format_error("lz4: truncated frame");
  dst.resize(pos);
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
