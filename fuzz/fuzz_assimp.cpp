// libFuzzer target: the game model formats read through assimp that vtbake guards or repairs
// before assimp sees them (Quake 2 MD2, Quake 3 MD3, Doom 3 MD5); the first byte picks the
// format. Not in fuzz/run.sh (CI): it still finds faults inside assimp that no check here
// prevents yet (an MD5 whose sections are garbled runs assimp's parser out of memory; leaks on
// malformed input); run it by hand without leak detection:
//   ASAN_OPTIONS=detect_leaks=0 build/fuzz/fuzz/vt_fuzz_assimp -max_len=65536 CORPUS
// OFF (a face count its face lines do not reach), B3D, MS3D and 3DS crashed it too and are left
// out until they are guarded.
#include <cstdint>
#include <string>

#include "fuzz/fuzz_scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const char* const kExtensions[] = {".md2", ".md5mesh", ".md3"};
  if (size < 1) return 0;
  const std::string name = std::string("input") + kExtensions[data[0] % 3];
  vt::fuzz::load_and_walk(vt::fuzz::write_input(name, vt::fuzz::as_text(data + 1, size - 1)));
  return 0;
}
