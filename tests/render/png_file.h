// Test helper: 8-bit texels (rows top down, `channels` a texel) written as a PNG file.
#pragma once

#include <OpenImageIO/imageio.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vt::render {

// False when OpenImageIO cannot create, open, write or close the file.
inline bool write_png_file(const std::string& path, int width, int height, int channels,
                           const std::vector<uint8_t>& texels) {
  auto out = OIIO::ImageOutput::create(path);
  OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:UnassociatedAlpha", 1);  // texels as given: straight colour
  return out && out->open(path, spec) && out->write_image(OIIO::TypeDesc::UINT8, texels.data()) &&
         out->close();
}

}  // namespace vt::render
