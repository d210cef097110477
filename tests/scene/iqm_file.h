// A small Inter-Quake Model (IQM version 2) for the scene tests: two meshes, "stand" and
// "cannon", of one triangle each over the same three vertices (float position and texture
// coordinate arrays), both with the material "mat". Offsets of its parts for tests that break
// them.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace vt::test {

struct IqmFile {
  static constexpr uint32_t kText = 124, kMeshes = kText + 18, kArrays = kMeshes + 48,
                            kTriangles = kArrays + 40, kPositions = kTriangles + 24,
                            kUvs = kPositions + 36, kSize = kUvs + 24;
  std::string bytes;

  IqmFile() {
    auto put = [this](uint32_t v) {
      for (int k = 0; k < 4; ++k) bytes += char(v >> (8 * k));
    };
    bytes.assign("INTERQUAKEMODEL\0", 16);
    // version, filesize, flags, text, meshes, vertex arrays and vertices, triangles; the
    // joints, poses, animations, frames, comments and extensions none.
    std::vector<uint32_t> header = {2,       kSize, 0, 18,      kText, 2,
                                    kMeshes, 2,     3, kArrays, 2,     kTriangles};
    header.resize(27, 0);
    for (uint32_t v : header) put(v);
    bytes.append("\0stand\0cannon\0mat\0", 18);
    for (uint32_t v : {1u, 14u, 0u, 3u, 0u, 1u, 7u, 14u, 0u, 3u, 1u, 1u}) put(v);  // meshes
    for (uint32_t v : {0u, 0u, 7u, 3u, kPositions, 1u, 0u, 7u, 2u, kUvs}) put(v);  // arrays
    for (uint32_t v : {0u, 1u, 2u, 0u, 2u, 1u}) put(v);                            // triangles
    for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 1.f}) {
      uint32_t bits;
      std::memcpy(&bits, &f, 4);
      put(bits);
    }
  }

  // Overwrites the 32-bit little-endian value at byte `at`.
  void set(uint32_t at, uint32_t v) {
    for (int k = 0; k < 4; ++k) bytes[at + k] = char(v >> (8 * k));
  }
};

}  // namespace vt::test
