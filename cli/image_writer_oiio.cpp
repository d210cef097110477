// The commands module's image writer for `vtbake extract` (every format OpenImageIO writes:
// EXR, TIFF, 16-bit and float images); the light executable writes 8-bit PNG itself.
#include <OpenImageIO/imageio.h>

#include <string>
#include <vector>

#include "cli/command.h"
#include "common/srgb.h"
#include "format/atomic_output.h"
#include "scene/image_load.h"

namespace {

OIIO::TypeDesc oiio_type(vt::TexelType type) {
  switch (type) {
    case vt::TexelType::kU8:
      return OIIO::TypeDesc::UINT8;
    case vt::TexelType::kF16:
      return OIIO::TypeDesc::HALF;
    case vt::TexelType::kF32:
      return OIIO::TypeDesc::FLOAT;
  }
  return OIIO::TypeDesc::UINT8;
}

// The image spec that makes OpenImageIO write the layer's texels unchanged.
OIIO::ImageSpec output_spec(const vt::LevelImage& image, const vt::LayerSpec& layer) {
  OIIO::ImageSpec spec(int(image.width), int(image.height), int(image.channels),
                       oiio_type(image.texel_type));
  const bool alpha = vt::is_colour(layer.semantic) && (image.channels == 2 || image.channels == 4);
  spec.alpha_channel = alpha ? int(image.channels) - 1 : -1;
  if (!alpha && image.channels == 4) spec.channelnames[3] = "W";  // data, not an alpha
  // The page file never premultiplies: without this, the PNG writer divides colour by the last
  // channel of every 2- and 4-channel image, taking it for associated alpha.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  return spec;
}

vt::Status write_image_oiio(const std::string& path, const vt::LevelImage& image,
                            const vt::LayerSpec& layer) {
  // The writer is chosen by the final name; the texels go to a staging file beside it (never
  // through a FIFO or onto a device, never truncated under the final name).
  auto out = OIIO::ImageOutput::create(path);
  if (!out)
    return vt::Error(vt::ErrorCode::kInvalidArgument,
                     path + ": cannot write this kind of image: " + OIIO::geterror());
  OIIO::TypeDesc type = oiio_type(image.texel_type);
  OIIO::ImageSpec spec = output_spec(image, layer);
  const void* texels = image.texels.data();
  // OpenEXR and Radiance HDR hold linear light (readers, vtbake's included, take them so): an
  // sRGB layer's colour goes in decoded. OpenEXR's colour is also premultiplied by its alpha:
  // the layer's straight colour goes in multiplied. Both as floats, so that they read back as
  // stored. Other formats get the stored values, tagged with the layer's encoding.
  const std::string format = out->format_name();
  const bool srgb = layer.color_space == vt::ColorSpace::kSrgb;
  const bool decode = srgb && (format == "openexr" || format == "hdr");
  const bool premultiply = spec.alpha_channel >= 0 && format == "openexr";
  spec.attribute("oiio:ColorSpace", srgb && !decode ? "sRGB" : "Linear");
  std::vector<float> converted;
  if (decode || premultiply) {
    const size_t count = size_t(image.width) * image.height;
    converted.resize(count * image.channels);
    OIIO::convert_pixel_values(type, image.texels.data(), OIIO::TypeDesc::FLOAT, converted.data(),
                               int(converted.size()));
    if (decode) {
      for (size_t i = 0; i < converted.size(); ++i)
        if (int(i % image.channels) != spec.alpha_channel)
          converted[i] = vt::srgb_to_linear(converted[i]);
    }
    if (premultiply)
      vt::scene::associate_alpha(converted.data(), count, int(image.channels), spec.alpha_channel);
    texels = converted.data();
    type = OIIO::TypeDesc::FLOAT;
  }
  return vt::write_output(path, [&](const std::string& temp) -> vt::Status {
    if (!out->open(temp, spec) || !out->write_image(type, texels) || !out->close())
      return vt::Error(vt::ErrorCode::kIo, path + ": " + out->geterror());
    return vt::Status::Ok();
  });
}

const bool kRegistered = (vt::cli::module_image_writer() = &write_image_oiio, true);

}  // namespace
