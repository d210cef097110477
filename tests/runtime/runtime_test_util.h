// Helpers shared by the runtime tests that write real page files.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "format/page_file.h"
#include "tests/process_temp_dir.h"

namespace vt::runtime_test {

// A path in a fresh per-process, per-call folder (tests in one binary never share a file).
inline std::string temp_file(const std::string& name) {
  static int counter = 0;
  auto dir = vt::test::process_temp_dir("vtbake_runtime") / std::to_string(counter++);
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

// A layer of a test file, named by what the tests vary.
inline LayerSpec test_layer(const std::string& name, uint8_t channels, PageCodec codec,
                            RuntimeFormat runtime,
                            LayerSemantic semantic = LayerSemantic::kAlbedo) {
  return LayerSpec{.semantic = semantic,
                   .name = name,
                   .channels = channels,
                   .codec = codec,
                   .runtime_format = runtime,
                   .codec_tables = {}};
}

// 4 x 3 pages of 8 + 2 * 4 texels, raw RGBA8; every texel of a page is (level, x, y, 255).
inline std::string write_marked_file() {
  PageFileDesc desc;
  desc.geometry.width = 32;
  desc.geometry.height = 24;
  desc.geometry.payload = 8;
  desc.geometry.border = 4;
  LayerSpec layer;
  layer.name = "albedo";
  layer.codec = PageCodec::kRaw;
  desc.layers = {layer};
  const std::string path = temp_file("marked.vtpf");
  auto w = PageFileWriter::create(path, desc);
  EXPECT_TRUE(w.ok());
  const PageGeometry& g = desc.geometry;
  for (uint32_t l = 0; l < g.level_count(); ++l)
    for (uint32_t y = 0; y < g.pages_y(l); ++y)
      for (uint32_t x = 0; x < g.pages_x(l); ++x) {
        std::vector<uint8_t> page(16 * 16 * 4);
        for (size_t i = 0; i < page.size(); i += 4) {
          page[i] = uint8_t(l);
          page[i + 1] = uint8_t(x);
          page[i + 2] = uint8_t(y);
          page[i + 3] = 255;
        }
        EXPECT_TRUE((*w)->add_page({l, x, y}, 0, page).ok());
      }
  EXPECT_TRUE((*w)->finish().ok());
  return path;
}

}  // namespace vt::runtime_test
