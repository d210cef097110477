// A small Inter-Quake Model (IQM version 2) for the scene tests: two meshes, "stand" and
// "cannon", of one triangle each over the same three vertices (float position and texture
// coordinate arrays), both with the material "mat". Offsets of its parts for tests that break
// them.
#pragma once

#include <cstdint>
#include <string>

#include "tests/scene/le_bytes.h"

namespace vt::test {

struct IqmFile {
  static constexpr uint32_t kText = 124, kMeshes = kText + 18, kArrays = kMeshes + 48,
                            kTriangles = kArrays + 40, kPositions = kTriangles + 24,
                            kUvs = kPositions + 36, kSize = kUvs + 24;
  std::string bytes;

  IqmFile() {
    bytes.assign("INTERQUAKEMODEL\0", 16);
    // version, filesize, flags, text, meshes, vertex arrays and vertices, triangles; then 15
    // zero words: no adjacency, joints, poses, animations, frames, bounds, comments, extensions.
    bytes += le32({2, kSize, 0, 18, kText, 2, kMeshes, 2, 3, kArrays, 2, kTriangles}) +
             std::string(15 * 4, '\0');
    bytes.append("\0stand\0cannon\0mat\0", 18);
    bytes += le32({1, 14, 0, 3, 0, 1, 7, 14, 0, 3, 1, 1});        // meshes
    bytes += le32({0, 0, 7, 3, kPositions, 1, 0, 7, 2, kUvs});    // arrays
    bytes += le32({0, 1, 2, 0, 2, 1});                            // triangles
    bytes += lef({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1});  // positions, uvs
  }

  // Overwrites the 32-bit little-endian value at byte `at`.
  void set(uint32_t at, uint32_t v) {
    for (int k = 0; k < 4; ++k) bytes[at + k] = char(v >> (8 * k));
  }
};

}  // namespace vt::test
