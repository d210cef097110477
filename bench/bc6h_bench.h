// `vtbake-bench bc6h`: the BC6H encoder levels on HDR content (EXR/HDR images read with
// OpenImageIO, cut into pages, or a synthetic HDR set when none is given): Mtexel/s per core
// (thread CPU time, median of the passes), the log-space error and the PSNR after a tone map
// (codec/hdr_metrics.h), and the modes the blocks use.
#pragma once

#include "bench/registry.h"

namespace vt::bench {

BenchKind bc6h_bench_kind();

}  // namespace vt::bench
