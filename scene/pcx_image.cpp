// ZSoft PCX images (Quake and Quake 2 skins, 3D Studio-era textures), which OpenImageIO cannot
// read: decoded here and handed on as embedded PNGs (image_load.h).
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstring>

#include "scene/image_load.h"
#include "scene/scene_io_util.h"

namespace vt::scene {
namespace {

uint32_t u16_at(const std::vector<uint8_t>& b, size_t at) {
  return uint32_t(b[at]) | uint32_t(b[at + 1]) << 8;
}

}  // namespace

Expected<Image> pcx_as_png(const std::string& path) {
  VT_ASSIGN_OR_RETURN(const std::vector<uint8_t> bytes, detail::read_file(path));
  const auto bad = [&](const std::string& what) {
    return Error(ErrorCode::kCorrupt, path + ": not a readable PCX image (" + what + ")");
  };
  constexpr size_t kHeader = 128;
  if (bytes.size() < kHeader || bytes[0] != 0x0a) return bad("no PCX header");
  const uint32_t encoding = bytes[2], bits = bytes[3], planes = bytes[65];
  const uint32_t xmin = u16_at(bytes, 4), ymin = u16_at(bytes, 6), xmax = u16_at(bytes, 8),
                 ymax = u16_at(bytes, 10), line_bytes = u16_at(bytes, 66);
  if (xmax < xmin || ymax < ymin) return bad("an empty window");
  const uint32_t width = xmax - xmin + 1, height = ymax - ymin + 1;
  // 256 colours (one plane and a palette at the end), RGB or RGBA (a plane a channel): what
  // texture tools wrote. The 2-, 4- and 16-colour kinds are EGA screen images.
  if (bits != 8 || (planes != 1 && planes != 3 && planes != 4))
    return bad(std::to_string(bits) + " bits x " + std::to_string(planes) +
               " planes: only 8-bit images with 1, 3 or 4 planes are read");
  if (encoding > 1 || line_bytes < width) return bad("a bad encoding or line length");
  const bool paletted = planes == 1;
  const size_t end = paletted ? bytes.size() - std::min<size_t>(bytes.size(), 769) : bytes.size();
  if (paletted && (end < kHeader || bytes[end] != 0x0c)) return bad("no 256-colour palette");
  // Each scan line holds every plane's line_bytes in turn; run-length runs may cross lines.
  const size_t line = size_t(planes) * line_bytes;
  // A run is two bytes for at most 63: a crafted header cannot ask for more than that.
  if (line * height / (encoding == 1 ? 63 : 1) > end - kHeader)
    return bad(std::to_string(width) + " x " + std::to_string(height) +
               " texels need more data than the file holds");
  std::vector<uint8_t> raw(line * height);
  size_t at = kHeader, out = 0;
  while (out < raw.size()) {
    if (at >= end) return bad("the pixel data ends early");
    uint8_t value = bytes[at++];
    size_t count = 1;
    if (encoding == 1 && (value & 0xc0) == 0xc0) {
      if (at >= end) return bad("the pixel data ends early");
      count = value & 0x3f;
      value = bytes[at++];
    }
    count = std::min(count, raw.size() - out);
    std::memset(&raw[out], value, count);
    out += count;
  }
  const int channels = paletted ? 3 : int(planes);
  std::vector<uint8_t> texels(size_t(width) * height * channels);
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) {
      uint8_t* t = &texels[(size_t(y) * width + x) * channels];
      const uint8_t* src = &raw[y * line + x];
      if (paletted) {
        std::memcpy(t, &bytes[end + 1 + 3 * size_t(*src)], 3);
      } else {
        for (int c = 0; c < channels; ++c) t[c] = src[size_t(c) * line_bytes];
      }
    }
  const OIIO::ImageSpec spec(int(width), int(height), channels, OIIO::TypeDesc::UINT8);
  return embedded_png(path, spec, OIIO::TypeDesc::UINT8, texels.data());
}

}  // namespace vt::scene
