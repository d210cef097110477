// The resource budget for untrusted scene files. Every count an importer reads from a file (an
// accessor's count, a sparse count, a PLY element's count, a decoded Draco mesh's size) is
// checked against the bytes that back it and against these ceilings before anything is
// allocated for it, so a small hostile file gets a clear error instead of a huge allocation.
// Internal to vt_scene.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "common/status.h"

namespace vt::scene::detail {

// Ceilings per primitive: 2^28 vertices (3 GiB of float positions alone) and 2^30 triangle-list
// indices (2^30 / 3 triangles, 4 GiB of indices). Larger meshes are refused with
// ErrorCode::kResourceLimit; the bake of anything this size would not fit in memory anyway.
inline constexpr uint64_t kMaxVertices = uint64_t{1} << 28;
inline constexpr uint64_t kMaxIndices = uint64_t{1} << 30;

// A size for messages: exact with thousands separators below 1 MiB ("1,300 bytes"), else one
// decimal in binary units ("1.5 GiB").
std::string format_bytes(double bytes);

// "count N x U bytes needs SIZE but HOLDER holds SIZE" (count * unit in doubles: no overflow).
std::string needs_but_holds(uint64_t count, uint64_t unit, const std::string& holder,
                            uint64_t held);

// Checks that `count` entries of `unit` bytes fit in the `held` bytes of `holder`; otherwise a
// kCorrupt error "WHAT: count N x U bytes needs SIZE but HOLDER holds SIZE". Overflow-safe.
Status check_backed(const std::string& what, uint64_t count, uint64_t unit,
                    const std::string& holder, uint64_t held);

// Checks count <= ceiling; otherwise a kResourceLimit error "WHAT: count N exceeds the ceiling
// of C NOUN per primitive".
Status check_ceiling(const std::string& what, uint64_t count, uint64_t ceiling,
                     const std::string& noun);

}  // namespace vt::scene::detail
