// libFuzzer target: Inter-Quake Models (IQM), read by assimp behind the layout check that keeps
// its unchecked reader inside the file (scene/assimp_import.cpp, iqm_mesh_names).
#include <cstdint>

#include "fuzz/fuzz_scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  vt::fuzz::load_and_walk(vt::fuzz::write_input("input.iqm", vt::fuzz::as_text(data, size)));
  return 0;
}
