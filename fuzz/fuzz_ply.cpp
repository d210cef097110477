// libFuzzer target: the PLY importer (ASCII and both binary encodings). Dictionary: ply.dict.
#include <cstdint>

#include "fuzz/fuzz_scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  vt::fuzz::load_and_walk(vt::fuzz::write_input("input.ply", vt::fuzz::as_text(data, size)));
  return 0;
}
