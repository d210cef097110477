// The one whole-image reader of a scene's images (OpenImageIO, files or embedded bytes), with the
// transfer's channel rules (bake/transfer.cpp sample_texture): grey -> (g, g, g, 1), grey + alpha
// -> (g, g, g, a), RGB -> alpha 1. The validator's reference and lit reference passes and the
// lighting baker's alpha-masked shadows (bake/lighting.cpp) build on it.
#pragma once

#include <OpenImageIO/imageio.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/status.h"
#include "scene/scene.h"

namespace vt::scene {

struct FloatImage {
  uint32_t width = 0, height = 0;
  uint32_t channels = 0;  // in the file
  bool is_float = false;  // a float file: linear values; otherwise the file's encoding (sRGB)
  std::vector<float> rgba;
  const float* at(uint32_t x, uint32_t y) const { return &rgba[(size_t(y) * width + x) * 4]; }
};

// OpenImageIO's reader of the image file at `path`, or null with `error` saying why (its first
// line). Only a file of a real format: OpenImageIO's "null" plugin makes up an image for any name
// ending in .nul, file or not, which would bake as if the texture were there. Colour comes as
// the file stores it: by default OpenImageIO premultiplies straight alpha (PNG, TGA, TIFF, ...)
// as it reads, and every reader here takes straight colour (the bake premultiplies it once, in
// linear light). With `proxy` (embedded bytes) `path` only names the format.
std::unique_ptr<OIIO::ImageInput> open_image_input(const std::string& path, std::string& error,
                                                   OIIO::Filesystem::IOProxy* proxy = nullptr);

// The first line of an OpenImageIO error message (further lines repeat it), or "OpenImageIO
// cannot read it" when there is none.
std::string oiio_first_line(std::string message);

// How many of the file's channels carry data: all, except in a BMP or TGA whose alpha is 0 in
// every texel, where the channels before it. There the fourth byte is padding (a 32-bit BMP's
// BI_RGB rows, a TGA whose header gives no alpha bits) that viewers show opaque; read as alpha it
// would bake the image fully transparent. Reads those formats' alpha channel to tell; kCorrupt
// (OpenImageIO's first line) when it cannot: OpenImageIO's TGA reader answers later reads from
// what it decoded before the error, so the error must not be lost here.
Expected<int> data_channels(OIIO::ImageInput& in);

// The channel whose alpha the colour `in` reads is premultiplied by (OpenEXR's convention, a TIFF
// of associated alpha), when it is one of the first `channels` read; -1 when colour is straight
// (every other format: PNG, TGA, SGI, DDS, ...). Readers divide it out (unassociate_alpha) so
// that every image reads straight.
int associated_alpha_channel(const OIIO::ImageInput& in, int channels);
// Colour (every channel but `alpha`) divided by alpha in `count` texels of `channels` floats;
// where alpha is 0 colour is left as stored.
void unassociate_alpha(float* texels, size_t count, int channels, int alpha);
// Its inverse, for writers of OpenEXR: colour multiplied by alpha.
void associate_alpha(float* texels, size_t count, int channels, int alpha);

// Errors name the image: kNotFound when it cannot be opened, kCorrupt when it cannot be read or
// has a size of 0 or over 65536 per side.
Expected<FloatImage> load_float_image(const scene::Image& image);

// A PCX image file (8 bits, 1 plane + palette, 3 or 4 planes; RLE or not) as an embedded PNG:
// OpenImageIO has no PCX reader (scene/pcx_image.cpp). kCorrupt names the file and what is
// wrong.
Expected<Image> pcx_as_png(const std::string& path);

// Texels an importer made (a packed MTL map, a model's uncompressed embedded skin) as an embedded
// PNG named `name`: every reader of the scene's images, and the unwrapped scene's .glb, then
// take them as they take a file. `spec` gives the size, channels and stored format (8 or 16
// bits); `pixels` are of `pixel_type`, rows top first, colour straight. kIo when OpenImageIO
// cannot encode them.
Expected<Image> embedded_png(const std::string& name, const OIIO::ImageSpec& spec,
                             OIIO::TypeDesc pixel_type, const void* pixels);

}  // namespace vt::scene
