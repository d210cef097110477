#include "bake/image_source.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstring>

namespace vt {
namespace {

namespace OIIO = OIIO_NAMESPACE;

class FileImageSource final : public ImageSource {
 public:
  FileImageSource(std::string path, std::unique_ptr<OIIO::ImageInput> in, ImageInfo info,
                  uint32_t file_channels)
      : path_(std::move(path)),
        in_(std::move(in)),
        info_(std::move(info)),
        file_channels_(file_channels) {
    const OIIO::ImageSpec& spec = in_->spec();
    tile_w_ = uint32_t(std::max(spec.tile_width, 0));
    tile_h_ = uint32_t(std::max(spec.tile_height, 0));
  }

  const ImageInfo& info() const override { return info_; }

  Status read_rows(uint32_t y0, uint32_t y1, float* out) override {
    if (y0 > y1 || y1 > info_.height) {
      return Error(ErrorCode::kInvalidArgument, path_ + ": rows out of range");
    }
    if (y0 == y1) return Status::Ok();
    const OIIO::ImageSpec& spec = in_->spec();
    const size_t row_floats = size_t(info_.width) * info_.channels;
    if (tile_w_ == 0) {
      bool ok = in_->read_scanlines(0, 0, spec.y + int(y0), spec.y + int(y1), spec.z, 0,
                                    int(info_.channels), OIIO::TypeDesc::FLOAT, out);
      if (!ok) return Error(ErrorCode::kIo, path_ + ": " + in_->geterror());
      return Status::Ok();
    }
    // Tiled: read whole tile rows covering [y0, y1) and copy the rows asked for.
    uint32_t ty0 = y0 / tile_h_ * tile_h_;
    uint32_t ty1 = std::min(info_.height, (y1 + tile_h_ - 1) / tile_h_ * tile_h_);
    uint32_t xend =
        std::min<uint32_t>((info_.width + tile_w_ - 1) / tile_w_ * tile_w_, info_.width);
    tile_buf_.resize(size_t(ty1 - ty0) * row_floats);
    bool ok = in_->read_tiles(0, 0, spec.x, spec.x + int(xend), spec.y + int(ty0),
                              spec.y + int(ty1), spec.z, spec.z + 1, 0, int(info_.channels),
                              OIIO::TypeDesc::FLOAT, tile_buf_.data());
    if (!ok) return Error(ErrorCode::kIo, path_ + ": " + in_->geterror());
    std::memcpy(out, tile_buf_.data() + size_t(y0 - ty0) * row_floats,
                size_t(y1 - y0) * row_floats * sizeof(float));
    return Status::Ok();
  }

 private:
  std::string path_;
  std::unique_ptr<OIIO::ImageInput> in_;
  ImageInfo info_;
  uint32_t file_channels_ = 0;
  uint32_t tile_w_ = 0, tile_h_ = 0;
  std::vector<float> tile_buf_;
};

}  // namespace

Expected<std::unique_ptr<ImageSource>> open_image_file(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    return Status(ErrorCode::kNotFound, path + ": cannot open image: " + OIIO::geterror());
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) {
    return Status(ErrorCode::kCorrupt, path + ": image has no texels");
  }
  if (spec.depth > 1) return Status(ErrorCode::kUnsupported, path + ": volume images");
  ImageInfo info;
  info.width = uint32_t(spec.width);
  info.height = uint32_t(spec.height);
  info.channels = uint32_t(std::min(spec.nchannels, 4));
  info.is_float = spec.format.basetype == OIIO::TypeDesc::HALF ||
                  spec.format.basetype == OIIO::TypeDesc::FLOAT ||
                  spec.format.basetype == OIIO::TypeDesc::DOUBLE;
  info.alpha_channel = spec.alpha_channel < int(info.channels) ? spec.alpha_channel : -1;
  info.color_space = spec.get_string_attribute("oiio:ColorSpace");
  if (info.color_space.empty()) info.color_space = info.is_float ? "linear" : "sRGB";
  uint32_t file_channels = uint32_t(spec.nchannels);
  return std::unique_ptr<ImageSource>(
      new FileImageSource(path, std::move(in), std::move(info), file_channels));
}

Status MemoryImageSource::read_rows(uint32_t y0, uint32_t y1, float* out) {
  if (y0 > y1 || y1 > info_.height) {
    return Error(ErrorCode::kInvalidArgument, "memory image: rows out of range");
  }
  size_t row = size_t(info_.width) * info_.channels;
  if (texels_.size() < row * info_.height) {
    return Error(ErrorCode::kInvalidArgument, "memory image: fewer texels than its size");
  }
  std::memcpy(out, texels_.data() + y0 * row, (y1 - y0) * row * sizeof(float));
  return Status::Ok();
}

Status write_image_file(ImageSource& source, const std::string& path, uint32_t tile) {
  const ImageInfo& info = source.info();
  auto out = OIIO::ImageOutput::create(path);
  if (!out) return Error(ErrorCode::kIo, path + ": cannot create image: " + OIIO::geterror());
  OIIO::TypeDesc type = info.is_float ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::UINT8;
  OIIO::ImageSpec spec(int(info.width), int(info.height), int(info.channels), type);
  spec.alpha_channel = info.alpha_channel;
  if (!info.color_space.empty()) spec.attribute("oiio:ColorSpace", info.color_space);
  bool tiled = tile > 0 && out->supports("tiles");
  if (tiled) {
    spec.tile_width = spec.tile_height = int(tile);
  }
  if (!out->open(path, spec)) return Error(ErrorCode::kIo, path + ": " + out->geterror());
  size_t row = size_t(info.width) * info.channels;
  uint32_t band = tiled ? tile : 64;
  std::vector<float> rows(row * band);
  for (uint32_t y = 0; y < info.height; y += band) {
    uint32_t y1 = std::min(info.height, y + band);
    VT_RETURN_IF_ERROR(source.read_rows(y, y1, rows.data()));
    bool ok = tiled ? out->write_tiles(0, int(info.width), int(y), int(y1), 0, 1,
                                       OIIO::TypeDesc::FLOAT, rows.data())
                    : out->write_scanlines(int(y), int(y1), 0, OIIO::TypeDesc::FLOAT, rows.data());
    if (!ok) return Error(ErrorCode::kIo, path + ": " + out->geterror());
  }
  if (!out->close()) return Error(ErrorCode::kIo, path + ": " + out->geterror());
  return Status::Ok();
}

}  // namespace vt
