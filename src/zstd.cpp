// zstd chunks of MCAP files. The format (RFC 8878) is decoded by the
// system's libzstd, loaded at first use with dlopen(): no headers or -dev
// package are needed to build, and libzstd.so.1 is part of every Debian and
// Ubuntu base system (dpkg depends on it). Without it only zstd chunks are
// unreadable, with a clear error. The three functions used are libzstd's
// stable ABI (zstd.h, "ZSTDLIB_API", unchanged since v1.0).
#include "zstd.h"
#include "bytes.h"

#include <Rcpp.h>
#include <cstdlib>
#include <string>

#ifndef _WIN32
#include <dlfcn.h>
#endif

namespace allanvar {

namespace {

typedef std::size_t (*decompress_fn)(void*, std::size_t, const void*, std::size_t);
typedef unsigned (*is_error_fn)(std::size_t);
typedef const char* (*error_name_fn)(std::size_t);

struct zstd_lib {
  decompress_fn decompress = nullptr;
  is_error_fn is_error = nullptr;
  error_name_fn error_name = nullptr;
  bool tried = false;
};

zstd_lib& lib() {
  static zstd_lib z;
  if (z.tried) return z;
  z.tried = true;
  // For tests of the error path: behave as if libzstd were absent.
  const char* off = std::getenv("ALLANVAR_DISABLE_ZSTD");
  if (off && *off) return z;
#ifndef _WIN32
  const char* names[] = {"libzstd.so.1", "libzstd.so", "libzstd.1.dylib",
                         "/opt/homebrew/lib/libzstd.1.dylib",
                         "/usr/local/lib/libzstd.1.dylib"};
  for (const char* name : names) {
    void* h = dlopen(name, RTLD_NOW | RTLD_LOCAL);
    if (!h) continue;
    z.decompress = reinterpret_cast<decompress_fn>(dlsym(h, "ZSTD_decompress"));
    z.is_error = reinterpret_cast<is_error_fn>(dlsym(h, "ZSTD_isError"));
    z.error_name = reinterpret_cast<error_name_fn>(dlsym(h, "ZSTD_getErrorName"));
    if (z.decompress && z.is_error && z.error_name) break;
    z.decompress = nullptr;
    dlclose(h);
  }
#endif
  return z;
}

}  // namespace

bool zstd_available() { return lib().decompress != nullptr; }

void zstd_decode(const unsigned char* src, std::size_t n,
                 std::vector<unsigned char>& out, std::size_t expected) {
  zstd_lib& z = lib();
  if (!z.decompress) {
    throw format_error("zstd: no zstd support: the system library libzstd "
                       "(libzstd.so.1) was not found; install it (Debian/Ubuntu: "
                       "libzstd1, Fedora: libzstd, macOS: brew install zstd)");
  }
  const std::size_t base = out.size();
  out.resize(base + expected);
  const std::size_t got = z.decompress(out.data() + base, expected, src, n);
  if (z.is_error(got)) throw format_error(std::string("zstd: ") + z.error_name(got));
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
