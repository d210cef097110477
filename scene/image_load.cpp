#include "scene/image_load.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <filesystem>
#include <memory>

namespace vt::scene {

std::string oiio_first_line(std::string message) {
  message = message.substr(0, message.find('\n'));
  return message.empty() ? "OpenImageIO cannot read it" : message;
}

std::unique_ptr<OIIO::ImageInput> open_image_input(const std::string& path, std::string& error,
                                                   OIIO::Filesystem::IOProxy* proxy) {
  std::error_code ec;
  if (!proxy && !std::filesystem::is_regular_file(path, ec)) {
    error = "Could not open file \"" + path + "\"";
    return nullptr;
  }
  static const OIIO::ImageSpec straight_colour = [] {
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    return config;
  }();
  // OpenImageIO 2.4 drops the proxy argument when a config is given: it goes in the config.
  OIIO::ImageSpec with_proxy;
  if (proxy) {
    with_proxy = straight_colour;
    with_proxy.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  }
  auto in = OIIO::ImageInput::open(path, proxy ? &with_proxy : &straight_colour, proxy);
  if (!in) {
    error = oiio_first_line(OIIO::geterror());
  } else if (std::string(in->format_name()) == "null") {
    error = "not an image file";
    return nullptr;
  }
  return in;
}

Expected<int> data_channels(OIIO::ImageInput& in) {
  const OIIO::ImageSpec& spec = in.spec();
  const int alpha = spec.alpha_channel;
  const std::string format = in.format_name();
  if ((format != "bmp" && format != "targa") || alpha < 0 || alpha != spec.nchannels - 1 ||
      spec.width <= 0 || spec.height <= 0)
    return spec.nchannels;
  const int band = std::max(1, (1 << 20) / spec.width);
  std::vector<uint8_t> a(size_t(spec.width) * size_t(std::min(band, spec.height)));
  for (int y = 0; y < spec.height; y += band) {
    const int y1 = std::min(spec.height, y + band);
    if (!in.read_scanlines(0, 0, spec.y + y, spec.y + y1, 0, alpha, alpha + 1,
                           OIIO::TypeDesc::UINT8, a.data()))
      return Error(ErrorCode::kCorrupt, oiio_first_line(in.geterror()));
    const size_t n = size_t(spec.width) * size_t(y1 - y);
    if (std::any_of(a.begin(), a.begin() + std::ptrdiff_t(n), [](uint8_t v) { return v != 0; }))
      return spec.nchannels;
  }
  return alpha;
}

int associated_alpha_channel(const OIIO::ImageInput& in, int channels) {
  // A TIFF says which it stores (OpenImageIO marks the unassociated kind, which open_image_input
  // asks to keep as stored); OpenEXR is premultiplied by definition. Formats that know no such
  // thing (SGI, BMP, DDS, ...) store straight colour.
  const OIIO::ImageSpec& spec = in.spec();
  const std::string format = in.format_name();
  const bool associated =
      format == "openexr" ||
      (format == "tiff" && spec.get_int_attribute("oiio:UnassociatedAlpha", 0) == 0);
  return associated && spec.alpha_channel >= 0 && spec.alpha_channel < channels ? spec.alpha_channel
                                                                                : -1;
}

void unassociate_alpha(float* texels, size_t count, int channels, int alpha) {
  for (size_t i = 0; i < count; ++i) {
    float* t = texels + i * size_t(channels);
    if (!(t[alpha] > 0)) continue;
    for (int c = 0; c < channels; ++c)
      if (c != alpha) t[c] /= t[alpha];
  }
}

void associate_alpha(float* texels, size_t count, int channels, int alpha) {
  for (size_t i = 0; i < count; ++i) {
    float* t = texels + i * size_t(channels);
    for (int c = 0; c < channels; ++c)
      if (c != alpha) t[c] *= t[alpha];
  }
}

Expected<FloatImage> load_float_image(const scene::Image& image) {
  OIIO::Filesystem::IOMemReader mem(image.bytes.data(), image.bytes.size());
  const std::string name =
      image.embedded() ? std::string("embedded") + image.embedded_extension() : image.path;
  std::string error;
  std::unique_ptr<OIIO::ImageInput> in =
      open_image_input(name, error, image.embedded() ? &mem : nullptr);
  if (!in) return Error(ErrorCode::kNotFound, "cannot open image '" + name + "': " + error);
  const OIIO::ImageSpec& spec = in->spec();
  const Expected<int> data = data_channels(*in);
  if (!data.ok())
    return Error(ErrorCode::kCorrupt,
                 "cannot read image '" + name + "': " + data.status().message());
  const int ch = *data;
  if (spec.width <= 0 || spec.height <= 0 || ch <= 0 || spec.width > 65536 || spec.height > 65536) {
    return Error(ErrorCode::kCorrupt, "image '" + name + "' has a bad size");
  }
  std::vector<float> px(size_t(spec.width) * spec.height * ch);
  if (!in->read_image(0, 0, 0, ch, OIIO::TypeDesc::FLOAT, px.data())) {
    return Error(ErrorCode::kCorrupt, "cannot read image '" + name + "': " + in->geterror());
  }
  if (const int a = associated_alpha_channel(*in, ch); a >= 0)
    unassociate_alpha(px.data(), px.size() / size_t(ch), ch, a);
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

Expected<Image> embedded_png(const std::string& name, const OIIO::ImageSpec& spec,
                             OIIO::TypeDesc pixel_type, const void* pixels) {
  Image out;
  out.name = name;
  out.mime_type = "image/png";
  OIIO::Filesystem::IOVecOutput proxy(out.bytes);
  auto writer = OIIO::ImageOutput::create("embedded.png", &proxy);
  OIIO::ImageSpec stored = spec;
  // Stored as given, like an artist's RGBA PNG: OpenImageIO would otherwise un-premultiply.
  stored.attribute("oiio:UnassociatedAlpha", 1);
  if (!writer || !writer->open("embedded.png", stored) ||
      !writer->write_image(pixel_type, pixels) || !writer->close())
    return Error(ErrorCode::kIo, name + ": cannot encode the texels as PNG (" +
                                     (writer ? writer->geterror() : OIIO::geterror()) + ")");
  return out;
}

}  // namespace vt::scene
