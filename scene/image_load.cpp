#include "scene/image_load.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <filesystem>
#include <memory>

namespace vt::scene {

std::unique_ptr<OIIO::ImageInput> open_image_input(const std::string& path, std::string& error) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    error = "Could not open file \"" + path + "\"";
    return nullptr;
  }
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    error = OIIO::geterror();
    error = error.substr(0, error.find('\n'));  // further lines repeat it
    if (error.empty()) error = "OpenImageIO cannot read it";
  } else if (std::string(in->format_name()) == "null") {
    error = "not an image file";
    return nullptr;
  }
  return in;
}

Expected<FloatImage> load_float_image(const scene::Image& image) {
  OIIO::Filesystem::IOMemReader mem(image.bytes.data(), image.bytes.size());
  const std::string name =
      image.embedded() ? std::string("embedded") + image.embedded_extension() : image.path;
  std::string error;
  std::unique_ptr<OIIO::ImageInput> in = image.embedded()
                                             ? OIIO::ImageInput::open(name, nullptr, &mem)
                                             : open_image_input(name, error);
  if (!in) {
    return Error(ErrorCode::kNotFound, "cannot open image '" + name +
                                           "': " + (image.embedded() ? OIIO::geterror() : error));
  }
  const OIIO::ImageSpec& spec = in->spec();
  const int ch = spec.nchannels;
  if (spec.width <= 0 || spec.height <= 0 || ch <= 0 || spec.width > 65536 || spec.height > 65536) {
    return Error(ErrorCode::kCorrupt, "image '" + name + "' has a bad size");
  }
  std::vector<float> px(size_t(spec.width) * spec.height * ch);
  if (!in->read_image(0, 0, 0, ch, OIIO::TypeDesc::FLOAT, px.data())) {
    return Error(ErrorCode::kCorrupt, "cannot read image '" + name + "': " + in->geterror());
  }
  FloatImage out;
  out.width = uint32_t(spec.width);
  out.height = uint32_t(spec.height);
  out.channels = uint32_t(ch);
  out.is_float = spec.format.is_floating_point();
  out.rgba.resize(size_t(out.width) * out.height * 4);
  for (size_t i = 0, n = size_t(out.width) * out.height; i < n; ++i) {
    const float* s = &px[i * ch];
    float* d = &out.rgba[i * 4];
    d[0] = s[0];
    d[1] = ch >= 3 ? s[1] : s[0];
    d[2] = ch >= 3 ? s[2] : s[0];
    d[3] = ch == 2 ? s[1] : ch >= 4 ? s[3] : 1.0f;
  }
  return out;
}

}  // namespace vt::scene
