// libFuzzer target: the OBJ importer with its MTL library (fuzz_obj.h: one input holds both).
// Without a marker the input is an OBJ alone and no MTL file is beside it. Dictionary: obj.dict.
#include <cstdint>
#include <filesystem>

#include "fuzz/fuzz_obj.h"
#include "fuzz/fuzz_scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vt::fuzz;
  const std::string_view input = as_text(data, size);
  const size_t marker = input.find(kMtlMarker);
  std::error_code ec;
  std::filesystem::remove(scratch_dir() + kMtlName, ec);
  if (marker != std::string_view::npos)
    write_input(kMtlName, input.substr(marker + kMtlMarker.size()));
  load_and_walk(write_input("input.obj", input.substr(0, marker)));
  return 0;
}
