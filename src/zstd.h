// zstd decompression by the vendored reference library (src/zstd/).
#ifndef ALLANVAR_ZSTD_H
#define ALLANVAR_ZSTD_H

#include <cstddef>
#include <vector>

namespace allanvar {

bool zstd_available();
// Decodes zstd frames of known total output size. Throws format_error.
void zstd_decode(const unsigned char* src, std::size_t n,
                 std::vector<unsigned char>& out, std::size_t expected);

}  // namespace allanvar

#endif
