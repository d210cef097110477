// The one JSON form of a build's summary (docs/JSON.md): `vtbake build --json` prints it and
// the scene bake's report nests it under "build", so a build farm reads both with one schema.
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>

#include "bake/build.h"

namespace vt {

// Every level of every layer as uncompressed stored texels (no borders): what the file would
// hold without paging or compression.
uint64_t raw_texel_bytes(const BuildSummary& summary);
// raw_texel_bytes / file bytes; 0 when no file was written.
double compression_ratio(const BuildSummary& summary);

// {"width", "height", "payload", "border", "pages": {...}, "bytes": {...}, "levels": [...],
//  "layers": [...], "seconds": {...}}, documented key by key in docs/JSON.md.
nlohmann::json to_json(const BuildSummary& summary);

}  // namespace vt
