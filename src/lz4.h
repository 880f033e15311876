// LZ4 frame decoder (ROS1 bag lz4 chunks, MCAP lz4 chunks).
#ifndef ALLANVAR_LZ4_H
#define ALLANVAR_LZ4_H

#include <cstddef>
#include <vector>

namespace allanvar {

// Decodes every LZ4 frame in src[0, n) and appends the output to `out`.
// `expected` (0 when unknown) reserves the output. Throws format_error.
void lz4_frame_decode(const unsigned char* src, std::size_t n,
                      std::vector<unsigned char>& out, std::size_t expected);

}  // namespace allanvar

#endif
