// libFuzzer target: the PCX decoder (scene images OpenImageIO cannot read). A decoded image must
// read back as a PNG of the header's size; a refusal must name the file.
#include <cstdint>

#include "fuzz/fuzz_input.h"
#include "scene/image_load.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vt;
  const std::string path = fuzz::write_input("input.pcx", fuzz::as_text(data, size));
  auto png = scene::pcx_as_png(path);
  if (!png.ok()) {
    fuzz::check_refusal(png.status(), path);
    return 0;
  }
  auto texels = scene::load_float_image(*png);
  if (!texels.ok()) fuzz::finding("the decoded PCX does not read back", texels.status().message());
  const uint32_t width = uint32_t(data[8] | data[9] << 8) - uint32_t(data[4] | data[5] << 8) + 1;
  if (texels->width != width) fuzz::finding("decoded width differs from the header's", path);
  return 0;
}
