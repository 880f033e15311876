/* The vendored LZ4 block codec (src/lz4/lz4.c) and its HC compressor
   (lz4/lz4hc.c, which the frame library links to) in one unit: lz4hc.c
   then takes its shared definitions from the full lz4.c, so no static
   helper is left unused. */
#include "lz4/lz4.c"
#include "lz4/lz4hc.c"
