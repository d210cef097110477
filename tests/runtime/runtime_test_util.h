// Helpers shared by the runtime tests that write real page files.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

#include "format/page_file.h"

namespace vt::runtime_test {

// A path in a fresh per-process, per-call folder (tests in one binary never share a file).
inline std::string temp_file(const std::string& name) {
  static int counter = 0;
  auto dir = std::filesystem::temp_directory_path() /
             ("vtbake_runtime_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
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

}  // namespace vt::runtime_test
