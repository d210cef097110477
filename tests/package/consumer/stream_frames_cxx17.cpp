// The C consumer compiled as C++17: the C headers must be valid C++17 too, and vtbake::runtime_c
// must not raise the standard.
static_assert(__cplusplus == 201703L, "this consumer is built as C++17");
#include "stream_frames.c"
