// Separate MTL maps packed into the one texture a glTF slot reads (see obj_mtl.h).
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>

#include "scene/image_load.h"
#include "scene/obj_mtl.h"

namespace vt::scene::detail {
namespace {

namespace OIIO = OIIO_NAMESPACE;

// The channel of a w x h float image that `source` names, resampled to w x h.
Expected<std::vector<float>> channel_plane(const OIIO::ImageBuf& image, int channel, int w, int h,
                                           const std::string& path) {
  OIIO::ImageBuf one = OIIO::ImageBufAlgo::channels(image, 1, {channel});
  if (one.spec().width != w || one.spec().height != h) {
    one = OIIO::ImageBufAlgo::resize(one, "", 0, OIIO::ROI(0, w, 0, h, 0, 1, 0, 1));
  }
  std::vector<float> plane(size_t(w) * h);
  if (one.has_error() ||
      !one.get_pixels(OIIO::ROI(0, w, 0, h, 0, 1, 0, 1), OIIO::TypeDesc::FLOAT, plane.data()))
    return Error(ErrorCode::kCorrupt,
                 path + ": cannot resample the image (" + one.geterror() + ")");
  return plane;
}

}  // namespace

Expected<Image> composite_image(const std::vector<ChannelSource>& channels,
                                const std::string& name) {
  std::vector<OIIO::ImageBuf> images(channels.size());
  int w = 1, h = 1;
  bool wide = false;  // a source with more than 8 bits: the result is 16-bit
  for (size_t c = 0; c < channels.size(); ++c) {
    if (channels[c].path.empty()) continue;
    std::string error;
    if (!open_image_input(channels[c].path, error))
      return Error(ErrorCode::kNotFound,
                   channels[c].path + ": cannot read the image (" + error + ")");
    images[c] = OIIO::ImageBuf(channels[c].path);
    if (!images[c].read(0, 0, true, OIIO::TypeDesc::FLOAT))
      return Error(ErrorCode::kNotFound,
                   channels[c].path + ": cannot read the image (" + images[c].geterror() + ")");
    const OIIO::ImageSpec& spec = images[c].spec();
    if (spec.nchannels < 1 || spec.width < 1 || spec.height < 1 ||
        spec.channelnames.size() != size_t(spec.nchannels))
      return Error(ErrorCode::kCorrupt, channels[c].path + ": no usable pixels (" +
                                            std::to_string(spec.width) + "x" +
                                            std::to_string(spec.height) + ", " +
                                            std::to_string(spec.nchannels) + " channels)");
    w = std::max(w, spec.width), h = std::max(h, spec.height);
    wide |= spec.format.size() > 1;
  }
  const int n = static_cast<int>(channels.size());
  std::vector<float> pixels(size_t(w) * h * n);
  for (int c = 0; c < n; ++c) {
    const ChannelSource& src = channels[c];
    if (src.path.empty()) {
      for (size_t i = 0; i < size_t(w) * h; ++i) pixels[i * n + c] = src.constant;
      continue;
    }
    const int have = images[c].spec().nchannels;
    const int channel = src.channel >= 0           ? std::min(src.channel, have - 1)
                        : (have == 2 || have == 4) ? have - 1
                                                   : 0;
    VT_ASSIGN_OR_RETURN(auto plane, channel_plane(images[c], channel, w, h, src.path));
    for (size_t i = 0; i < plane.size(); ++i) pixels[i * n + c] = plane[i];
  }
  // An embedded PNG: the rest of the pipeline reads it like any image of the scene.
  const OIIO::ImageSpec spec(w, h, n, wide ? OIIO::TypeDesc::UINT16 : OIIO::TypeDesc::UINT8);
  return embedded_png(name, spec, OIIO::TypeDesc::FLOAT, pixels.data());
}

}  // namespace vt::scene::detail
