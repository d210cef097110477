// libFuzzer target: the glTF 2.0 importer. An input starting with the GLB magic is written as a
// .glb, anything else as a .gltf (buffers as data: URIs in the seeds). Dictionary: gltf.dict.
#include <cstdint>
#include <cstring>

#include "fuzz/fuzz_scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  vt::fuzz::load_and_walk(
      vt::fuzz::write_input(glb ? "input.glb" : "input.gltf", vt::fuzz::as_text(data, size)));
  return 0;
}
