/* The vendored LZ4 frame library (src/lz4/lz4frame.c). Its xxHash (the
   frame's checksums) gets a namespace of its own: PKG_CFLAGS name the
   vendored zstd's xxHash ZSTD_, a different version of the same symbols. */
#undef XXH_NAMESPACE
#define XXH_NAMESPACE LZ4_
#include "lz4/lz4frame.c"
