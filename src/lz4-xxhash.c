/* LZ4's xxHash (src/lz4/xxhash.c), in the namespace lz4-frame.c uses. */
#undef XXH_NAMESPACE
#define XXH_NAMESPACE LZ4_
#include "lz4/xxhash.c"
