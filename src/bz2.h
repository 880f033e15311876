// bzip2 chunks of ROS1 bags, decoded by the system's libbz2 (see bz2.cpp).
#ifndef ALLANVAR_BZ2_H
#define ALLANVAR_BZ2_H

#include <cstddef>
#include <vector>

namespace allanvar {

// True when libbz2 could be loaded (then bz2_decode works).
bool bz2_available();

// Decodes a bzip2 stream of known output size `size` into `out`. Throws
// format_error when the data are not bzip2 or do not give `size` bytes.
void bz2_decode(const unsigned char* p, std::size_t n, std::size_t size,
                std::vector<unsigned char>& out);

}  // namespace allanvar

#endif
