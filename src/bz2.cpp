// bzip2 chunks of ROS1 bags through the system's libbz2, loaded at first use
// with dlopen() as src/zstd.cpp loads libzstd: R itself links libbz2, so it
// is present wherever R runs, and no -dev package is needed to build. Unlike
// base R's memDecompress(), which does not know the output size and
// decompresses again into a doubled buffer when its guess is short, the bag's
// chunk header gives the size, so each chunk is decoded once. The function
// used, BZ2_bzBuffToBuffDecompress, is bzlib's stable API (bzlib.h, 1.0).
#include "bz2.h"
#include "bytes.h"

#include <Rcpp.h>
#include <cstdlib>
#include <string>

#ifndef _WIN32
#include <dlfcn.h>
#endif

namespace allanvar {

namespace {

typedef int (*buff_decompress_fn)(char*, unsigned int*, char*, unsigned int, int, int);

buff_decompress_fn bz2_fn() {
  static bool tried = false;
  static buff_decompress_fn fn = nullptr;
  if (tried) return fn;
  tried = true;
  // For tests of the fallback (memDecompress in R/read-bag.R).
  const char* off = std::getenv("ALLANVAR_DISABLE_BZ2");
  if (off && *off) return fn;
#ifndef _WIN32
  const char* names[] = {"libbz2.so.1.0", "libbz2.so.1", "libbz2.so", "libbz2.1.0.dylib",
                         "libbz2.dylib"};
  for (const char* name : names) {
    void* h = dlopen(name, RTLD_NOW | RTLD_LOCAL);
    if (!h) continue;
    fn = reinterpret_cast<buff_decompress_fn>(dlsym(h, "BZ2_bzBuffToBuffDecompress"));
    if (fn) break;
    dlclose(h);
  }
#endif
  return fn;
}

}  // namespace

bool bz2_available() { return bz2_fn() != nullptr; }

void bz2_decode(const unsigned char* p, std::size_t n, std::size_t size,
                std::vector<unsigned char>& out) {
  buff_decompress_fn fn = bz2_fn();
  if (!fn) throw format_error("bz2: libbz2 is not available");
  if (n > 0xFFFFFFFFu || size > 0xFFFFFFFFu) {
    throw format_error("bag: a bz2 chunk larger than 4 GB");
  }
  out.resize(size);
  unsigned int got = static_cast<unsigned int>(size);
  // bzlib takes char* for its input although it only reads it.
  const int rc = fn(reinterpret_cast<char*>(out.data()), &got,
                    const_cast<char*>(reinterpret_cast<const char*>(p)),
                    static_cast<unsigned int>(n), 0, 0);
  if (rc != 0 || got != size) {
    throw format_error("bag: a bz2 chunk does not decompress to its stated size (bzlib code " +
                       std::to_string(rc) + ")");
  }
}

}  // namespace allanvar

// [[Rcpp::export(rng = false)]]
bool bz2_available_cpp() { return allanvar::bz2_available(); }
