// libFuzzer target: the AC3D / ACC reader (scene/ac3d_import.cpp). Dictionary: ac3d.dict.
#include <cstdint>

#include "fuzz/fuzz_scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  vt::fuzz::load_and_walk(vt::fuzz::write_input("input.acc", vt::fuzz::as_text(data, size)));
  return 0;
}
