// `vtbake-bench hard`: the page codec on content that is not a photograph, made here (no outside
// assets): a saturated checker, a text/UI atlas, hard-alpha decals, pixel art, saturated
// gradients and a normal map with sharp creases. Per case and DCT quality: bytes, the stored
// error and the error after the runtime BC format (the DCT decoded, BC encoded as the runtime
// does, BC decoded), for the tables' own mode and for the per-page mode decision, beside
// lossless-then-BC; the largest page against its lossless form; encode time per page.
#pragma once

#include "bench/registry.h"

namespace vt::bench {

BenchKind hard_content_bench_kind();

}  // namespace vt::bench
