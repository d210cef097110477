// `vtbake-bench decode`: decode speed of whole page files, every stored page of every level and
// layer, as a reader decodes them (format/layer_codec.h, lossless DCT pages included). The pages'
// bytes are read into memory first; each pass decodes all of them on one thread (thread CPU
// time), and the median pass is reported. For comparing two builds of the same images (with and
// without the DCT page modes), run the two sets one after the other.
#pragma once

#include "bench/registry.h"

namespace vt::bench {

BenchKind file_decode_bench_kind();

}  // namespace vt::bench
