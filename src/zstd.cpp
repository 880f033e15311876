// zstd chunks of MCAP files. The format (RFC 8878) is decoded by the
// system's libzstd; configure defines ALLANVAR_HAVE_ZSTD when it is found,
// and without it only zstd chunks are unreadable (with a clear error).
#include "zstd.h"
#include "bytes.h"

#include <Rcpp.h>
#include <string>

#ifdef ALLANVAR_HAVE_ZSTD
#include <zstd.h>
#endif

namespace allanvar {

bool zstd_available() {
#ifdef ALLANVAR_HAVE_ZSTD
  return true;
#else
  return false;
#endif
}

void zstd_decode(const unsigned char* src, std::size_t n,
                 std::vector<unsigned char>& out, std::size_t expected) {
#ifdef ALLANVAR_HAVE_ZSTD
  const std::size_t base = out.size();
  out.resize(base + expected);
  const std::size_t got = ZSTD_decompress(out.data() + base, expected, src, n);
  if (ZSTD_isError(got)) {
    throw format_error(std::string("zstd: ") + ZSTD_getErrorName(got));
  }
  if (got != expected) throw format_error("zstd: the chunk's size does not match its record");
#else
  (void)src; (void)n; (void)out; (void)expected;
  throw format_error("zstd: this build of allanvar has no zstd support; "
                     "install libzstd-dev (Debian/Ubuntu) or libzstd-devel "
                     "(Fedora) and reinstall allanvar");
#endif
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
