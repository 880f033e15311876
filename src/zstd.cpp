// zstd chunks of MCAP files (RFC 8878), decoded by the reference library's
// decompression side vendored in src/zstd/ (v1.5.6, BSD licence; see
// inst/COPYRIGHTS): no system libzstd is needed to build or to read.
#include "zstd.h"
#include "bytes.h"
#include "zstd/zstd.h"

#include <Rcpp.h>
#include <cstring>
#include <string>

namespace allanvar {

bool zstd_available() { return true; }

void zstd_decode(const unsigned char* src, std::size_t n,
                 std::vector<unsigned char>& out, std::size_t expected) {
  const std::size_t base = out.size();
  out.resize(base + expected);
  const std::size_t got = ZSTD_decompress(out.data() + base, expected, src, n);
  if (ZSTD_isError(got)) {
    out.resize(base);
    throw format_error(std::string("zstd: ") + ZSTD_getErrorName(got));
  }
  if (got != expected) throw format_error("zstd: the chunk's size does not match its record");
}

}  // namespace allanvar

// [[Rcpp::export(rng = false)]]
bool zstd_available_cpp() { return allanvar::zstd_available(); }

// [[Rcpp::export(rng = false)]]
Rcpp::RawVector zstd_decompress_cpp(const Rcpp::RawVector& x, double expected) {
  std::vector<unsigned char> out;
  try {
    allanvar::zstd_decode(RAW(x), x.size(), out, static_cast<std::size_t>(expected));
  } catch (const allanvar::format_error& e) {
    Rcpp::stop(e.what());
  }
  Rcpp::RawVector r(out.size());
  if (!out.empty()) std::memcpy(RAW(r), out.data(), out.size());
  return r;
}
