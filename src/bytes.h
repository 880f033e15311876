// Little-endian reads from a byte buffer, bounds-checked by the callers'
// length tests; shared by the bag, MCAP and message decoders.
#ifndef ALLANVAR_BYTES_H
#define ALLANVAR_BYTES_H

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

namespace allanvar {

inline std::uint32_t rd_u32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

inline std::uint64_t rd_u64(const unsigned char* p) {
  return static_cast<std::uint64_t>(rd_u32(p)) |
         (static_cast<std::uint64_t>(rd_u32(p + 4)) << 32);
}

inline std::uint16_t rd_u16(const unsigned char* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}

// A malformed file: the message says where.
struct format_error : std::runtime_error {
  explicit format_error(const std::string& m) : std::runtime_error(m) {}
};

}  // namespace allanvar

#endif
