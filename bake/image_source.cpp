#include "bake/image_source.h"
#include "scene/image_load.h"

#include <OpenImageIO/imageio.h>
#define XXH_STATIC_LINKING_ONLY  // XXH3_state_t on the stack
#include <xxhash.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

#include "bake/png_check.h"
#include "format/atomic_output.h"

namespace vt {

Expected<uint64_t> hash_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return Status(ErrorCode::kIo, path + ": cannot read to hash it");
  XXH3_state_t state;
  XXH3_64bits_reset(&state);
  std::vector<char> buf(size_t(1) << 20);
  while (f) {
    f.read(buf.data(), std::streamsize(buf.size()));
    XXH3_64bits_update(&state, buf.data(), size_t(f.gcount()));
  }
  if (f.bad()) return Status(ErrorCode::kIo, path + ": read error while hashing");
  return XXH3_64bits_digest(&state);
}

namespace {

namespace OIIO = OIIO_NAMESPACE;

// A failed decode of a file that opened: the file is corrupt or truncated (kCorrupt, exit 2).
// OpenImageIO's message is one line per error it collected; libpng's adds a bare "PNG library
// error" line that says nothing, and the same cause often comes twice: both are dropped.
Status decode_error(const std::string& path, const std::string& oiio_message) {
  std::vector<std::string> lines;
  size_t start = 0;
  while (start < oiio_message.size()) {
    size_t end = std::min(oiio_message.find('\n', start), oiio_message.size());
    std::string line = oiio_message.substr(start, end - start);
    start = end + 1;
    if (line.empty() || line == "PNG library error") continue;
    bool repeated = false;
    for (const std::string& l : lines)
      repeated |= l.find(line) != std::string::npos || line.find(l) != std::string::npos;
    if (!repeated) lines.push_back(std::move(line));
  }
  std::string text;
  for (const std::string& l : lines) text += (text.empty() ? "" : "; ") + l;
  if (text.empty()) text = "cannot decode the image";
  return Error(ErrorCode::kCorrupt, path + ": " + text);
}

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
    associated_alpha_ = scene::associated_alpha_channel(*in_, int(info_.channels));
  }

  const ImageInfo& info() const override { return info_; }

  // The file's bytes decide its texels; hashing them is far cheaper than decoding.
  Expected<uint64_t> content_hash() override { return hash_file(path_); }
  std::string origin() const override { return path_; }

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
      if (!ok) return decode_error(path_, in_->geterror());
      straighten(out, size_t(y1 - y0) * info_.width);
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
    if (!ok) return decode_error(path_, in_->geterror());
    std::memcpy(out, tile_buf_.data() + size_t(y0 - ty0) * row_floats,
                size_t(y1 - y0) * row_floats * sizeof(float));
    straighten(out, size_t(y1 - y0) * info_.width);
    return Status::Ok();
  }

 private:
  // A file of premultiplied colour (OpenEXR) reads as straight colour, as every other does.
  void straighten(float* texels, size_t count) const {
    if (associated_alpha_ >= 0)
      scene::unassociate_alpha(texels, count, int(info_.channels), associated_alpha_);
  }

  std::string path_;
  std::unique_ptr<OIIO::ImageInput> in_;
  ImageInfo info_;
  uint32_t file_channels_ = 0;
  uint32_t tile_w_ = 0, tile_h_ = 0;
  int associated_alpha_ = -1;  // scene::associated_alpha_channel, once
  std::vector<float> tile_buf_;
};

// OpenImageIO reads no PCX (Quake's skins, old texture sets): the scene importers' decoder, into
// memory (8 bits a channel; the decoder refuses a header asking for more texels than the file
// can hold).
Expected<std::unique_ptr<ImageSource>> open_pcx_file(const std::string& path) {
  VT_ASSIGN_OR_RETURN(const scene::Image png, scene::pcx_as_png(path));
  VT_ASSIGN_OR_RETURN(const scene::FloatImage image, scene::load_float_image(png));
  ImageInfo info;
  info.width = image.width;
  info.height = image.height;
  info.channels = image.channels;
  info.alpha_channel = image.channels == 4 ? 3 : -1;
  std::vector<float> texels(size_t(image.width) * image.height * image.channels);
  for (size_t i = 0; i < size_t(image.width) * image.height; ++i)
    std::memcpy(&texels[i * image.channels], &image.rgba[i * 4], image.channels * sizeof(float));
  return std::unique_ptr<ImageSource>(new MemoryImageSource(info, std::move(texels)));
}

}  // namespace

Expected<std::unique_ptr<ImageSource>> open_image_file(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (ext == ".pcx") return open_pcx_file(path);
  VT_RETURN_IF_ERROR(check_png_chunks(path));  // before libpng can print its own line
  std::string error;
  auto in = scene::open_image_input(path, error);
  if (!in) return Status(ErrorCode::kNotFound, path + ": cannot open image: " + error);
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) {
    return Status(ErrorCode::kCorrupt, path + ": image has no texels");
  }
  if (spec.depth > 1) return Status(ErrorCode::kUnsupported, path + ": volume images");
  ImageInfo info;
  info.width = uint32_t(spec.width);
  info.height = uint32_t(spec.height);
  const Expected<int> channels = scene::data_channels(*in);
  if (!channels.ok()) return decode_error(path, channels.status().message());
  info.channels = uint32_t(std::min(*channels, 4));
  info.is_float = spec.format.basetype == OIIO::TypeDesc::HALF ||
                  spec.format.basetype == OIIO::TypeDesc::FLOAT ||
                  spec.format.basetype == OIIO::TypeDesc::DOUBLE;
  info.alpha_channel = spec.alpha_channel < int(info.channels) ? spec.alpha_channel : -1;
  // What the file declares ("sRGB", "Linear", "Gamma2.2" for a PNG gAMA, ...); the build
  // decides what "" means (ColorConfig::texture_space).
  info.color_space = spec.get_string_attribute("oiio:ColorSpace");
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

Expected<uint64_t> ImageSource::content_hash() {
  const ImageInfo& in = info();
  const size_t row = size_t(in.width) * in.channels;
  const uint32_t band =
      uint32_t(std::clamp<size_t>((size_t(4) << 20) / std::max<size_t>(row, 1), 1, in.height));
  std::vector<float> rows(size_t(band) * row);
  XXH3_state_t state;
  XXH3_64bits_reset(&state);
  for (uint32_t y = 0; y < in.height; y += band) {
    const uint32_t y1 = std::min(in.height, y + band);
    VT_RETURN_IF_ERROR(read_rows(y, y1, rows.data()));
    XXH3_64bits_update(&state, rows.data(), size_t(y1 - y) * row * sizeof(float));
  }
  return XXH3_64bits_digest(&state);
}

Expected<uint64_t> MemoryImageSource::content_hash() {
  return XXH3_64bits(texels_.data(), texels_.size() * sizeof(float));
}

Expected<uint64_t> DropChannelSource::content_hash() {
  VT_ASSIGN_OR_RETURN(uint64_t inner, source_->content_hash());
  const uint64_t parts[2] = {inner, channel_};
  return XXH3_64bits(parts, sizeof parts);
}

Status write_image_file(ImageSource& source, const std::string& path, uint32_t tile) {
  const ImageInfo& info = source.info();
  auto out = OIIO::ImageOutput::create(path);
  if (!out) return Error(ErrorCode::kIo, path + ": cannot create image: " + OIIO::geterror());
  OIIO::TypeDesc type = info.is_float ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::UINT8;
  OIIO::ImageSpec spec(int(info.width), int(info.height), int(info.channels), type);
  spec.alpha_channel = info.alpha_channel;
  if (!info.color_space.empty()) spec.attribute("oiio:ColorSpace", info.color_space);
  // The source's colour is straight, as PNG and most formats store it (OpenImageIO would divide
  // it by alpha again); OpenEXR stores colour premultiplied.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  const bool premultiply = info.alpha_channel >= 0 && std::string(out->format_name()) == "openexr";
  bool tiled = tile > 0 && out->supports("tiles");
  if (tiled) {
    spec.tile_width = spec.tile_height = int(tile);
  }
  return write_output(path, [&](const std::string& temp) -> Status {
    if (!out->open(temp, spec)) return Error(ErrorCode::kIo, path + ": " + out->geterror());
    size_t row = size_t(info.width) * info.channels;
    uint32_t band = tiled ? tile : 64;
    std::vector<float> rows(row * band);
    for (uint32_t y = 0; y < info.height; y += band) {
      uint32_t y1 = std::min(info.height, y + band);
      VT_RETURN_IF_ERROR(source.read_rows(y, y1, rows.data()));
      if (premultiply)
        scene::associate_alpha(rows.data(), size_t(y1 - y) * info.width, int(info.channels),
                               info.alpha_channel);
      bool ok = tiled
                    ? out->write_tiles(0, int(info.width), int(y), int(y1), 0, 1,
                                       OIIO::TypeDesc::FLOAT, rows.data())
                    : out->write_scanlines(int(y), int(y1), 0, OIIO::TypeDesc::FLOAT, rows.data());
      if (!ok) return Error(ErrorCode::kIo, path + ": " + out->geterror());
    }
    if (!out->close()) return Error(ErrorCode::kIo, path + ": " + out->geterror());
    return Status::Ok();
  });
}

namespace {
// Rows per band so that a band stays around 16 MiB of floats.
uint32_t band_rows(const ImageInfo& info) {
  size_t row = size_t(info.width) * info.channels;
  return uint32_t(std::clamp<size_t>((size_t(4) << 20) / std::max<size_t>(row, 1), 1,
                                     std::max<uint32_t>(info.height, 1)));
}
}  // namespace

Expected<bool> channel_is_opaque(ImageSource& source, uint32_t channel) {
  const ImageInfo& info = source.info();
  if (channel >= info.channels) return Status(ErrorCode::kInvalidArgument, "no such channel");
  const uint32_t band = band_rows(info), ch = info.channels;
  if (const float* texels = source.texels_in_memory()) {
    const size_t n = size_t(info.width) * info.height * ch;
    for (size_t i = channel; i < n; i += ch)
      if (!(texels[i] >= 1.0f)) return false;
    return true;
  }
  std::vector<float> rows(size_t(band) * info.width * ch);
  for (uint32_t y = 0; y < info.height; y += band) {
    uint32_t y1 = std::min(info.height, y + band);
    VT_RETURN_IF_ERROR(source.read_rows(y, y1, rows.data()));
    const size_t n = size_t(y1 - y) * info.width * ch;
    for (size_t i = channel; i < n; i += ch) {
      if (!(rows[i] >= 1.0f)) return false;
    }
  }
  return true;
}

DropChannelSource::DropChannelSource(std::shared_ptr<ImageSource> source, uint32_t channel)
    : source_(std::move(source)), channel_(channel), info_(source_->info()) {
  info_.channels -= 1;
  if (info_.alpha_channel == int(channel)) {
    info_.alpha_channel = -1;
  } else if (info_.alpha_channel > int(channel)) {
    info_.alpha_channel -= 1;
  }
}

Status DropChannelSource::read_rows(uint32_t y0, uint32_t y1, float* out) {
  const uint32_t sc = info_.channels + 1;
  const size_t texels = size_t(y1 - y0) * info_.width;
  rows_.resize(texels * sc);
  VT_RETURN_IF_ERROR(source_->read_rows(y0, y1, rows_.data()));
  for (size_t t = 0; t < texels; ++t) {
    const float* s = &rows_[t * sc];
    for (uint32_t c = 0; c < sc; ++c) {
      if (c != channel_) *out++ = s[c];
    }
  }
  return Status();
}

namespace {

class UdimImageSource final : public ImageSource {
 public:
  UdimImageSource(ImageInfo info, uint32_t tiles_u, uint32_t tiles_v, uint32_t tile_w,
                  uint32_t tile_h, std::vector<std::unique_ptr<ImageSource>> tiles)
      : info_(std::move(info)),
        tiles_u_(tiles_u),
        tiles_v_(tiles_v),
        tile_w_(tile_w),
        tile_h_(tile_h),
        tiles_(std::move(tiles)) {}
  const ImageInfo& info() const override { return info_; }

  Expected<uint64_t> content_hash() override {
    std::vector<uint64_t> parts{tiles_u_, tiles_v_};
    for (const auto& tile : tiles_) {
      uint64_t h = 0;  // a missing tile is black
      if (tile) {
        VT_ASSIGN_OR_RETURN(h, tile->content_hash());
      }
      parts.push_back(h);
    }
    return XXH3_64bits(parts.data(), parts.size() * sizeof(uint64_t));
  }

  Status read_rows(uint32_t y0, uint32_t y1, float* out) override {
    if (y0 > y1 || y1 > info_.height) {
      return Status(ErrorCode::kInvalidArgument, "UDIM image: rows out of range");
    }
    const uint32_t ch = info_.channels;
    const size_t row = size_t(info_.width) * ch, tile_row = size_t(tile_w_) * ch;
    for (uint32_t y = y0; y < y1;) {
      const uint32_t v = y / tile_h_, ly0 = y - v * tile_h_;
      const uint32_t ly1 = std::min(tile_h_, ly0 + (y1 - y));
      const uint32_t n = ly1 - ly0;
      float* dst = out + size_t(y - y0) * row;
      for (uint32_t u = 0; u < tiles_u_; ++u) {
        ImageSource* tile = tiles_[size_t(v) * tiles_u_ + u].get();
        if (!tile) {
          for (uint32_t r = 0; r < n; ++r)
            std::fill_n(dst + r * row + u * tile_row, tile_row, 0.0f);
          continue;
        }
        band_.resize(n * tile_row);
        VT_RETURN_IF_ERROR(tile->read_rows(ly0, ly1, band_.data()));
        for (uint32_t r = 0; r < n; ++r)
          std::memcpy(dst + r * row + u * tile_row, &band_[r * tile_row], tile_row * sizeof(float));
      }
      y += n;
    }
    return Status();
  }

 private:
  ImageInfo info_;
  uint32_t tiles_u_, tiles_v_, tile_w_, tile_h_;
  std::vector<std::unique_ptr<ImageSource>> tiles_;  // row-major, null where missing
  std::vector<float> band_;
};

}  // namespace

Expected<std::unique_ptr<ImageSource>> open_udim_image(const std::string& pattern) {
  const size_t at = pattern.find("<UDIM>");
  if (at == std::string::npos) {
    return Status(ErrorCode::kInvalidArgument, pattern + ": no <UDIM> in the path");
  }
  namespace fs = std::filesystem;
  const fs::path pat(pattern);
  const std::string name = pat.filename().string();
  const size_t nat = name.find("<UDIM>");
  if (nat == std::string::npos) {
    return Status(ErrorCode::kInvalidArgument, pattern + ": <UDIM> must be in the file name");
  }
  const std::string prefix = name.substr(0, nat), suffix = name.substr(nat + 6);
  const fs::path dir = pat.has_parent_path() ? pat.parent_path() : fs::path(".");
  std::map<uint32_t, std::string> found;  // (v * 10 + u) -> path
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string f = it->path().filename().string();
    if (f.size() != prefix.size() + 4 + suffix.size() || f.compare(0, prefix.size(), prefix) ||
        f.compare(f.size() - suffix.size(), suffix.size(), suffix)) {
      continue;
    }
    const std::string digits = f.substr(prefix.size(), 4);
    if (!std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
      continue;
    const uint32_t n = uint32_t(std::stoul(digits));
    if (n < 1001) continue;
    found[n - 1001] = it->path().string();
  }
  if (ec) return Status(ErrorCode::kNotFound, pattern + ": cannot list " + dir.string());
  if (found.empty()) {
    return Status(ErrorCode::kNotFound,
                  pattern + ": no tile files (" + prefix + "1001" + suffix + " ...)");
  }
  uint32_t max_u = 0, max_v = 0;
  for (auto& [i, p] : found) max_u = std::max(max_u, i % 10), max_v = std::max(max_v, i / 10);
  const uint32_t tu = max_u + 1, tv = max_v + 1;
  std::vector<std::unique_ptr<ImageSource>> tiles(size_t(tu) * tv);
  ImageInfo first;
  std::string first_path;
  for (auto& [i, p] : found) {
    VT_ASSIGN_OR_RETURN(auto tile, open_image_file(p));
    const ImageInfo& ti = tile->info();
    if (first_path.empty()) {
      first = ti, first_path = p;
    } else if (ti.width != first.width || ti.height != first.height ||
               ti.channels != first.channels || ti.is_float != first.is_float) {
      return Status(ErrorCode::kInvalidArgument,
                    p + ": UDIM tile is " + std::to_string(ti.width) + "x" +
                        std::to_string(ti.height) + " with " + std::to_string(ti.channels) +
                        " channels, but " + first_path + " is " + std::to_string(first.width) +
                        "x" + std::to_string(first.height) + " with " +
                        std::to_string(first.channels) + " (all tiles must match)");
    }
    tiles[size_t(i / 10) * tu + i % 10] = std::move(tile);
  }
  const uint64_t w = uint64_t(first.width) * tu, h = uint64_t(first.height) * tv;
  if (w > 0xffffffffu || h > 0xffffffffu) {
    return Status(ErrorCode::kUnsupported, pattern + ": UDIM grid too large");
  }
  ImageInfo info = first;
  info.width = uint32_t(w), info.height = uint32_t(h);
  return std::unique_ptr<ImageSource>(
      new UdimImageSource(info, tu, tv, first.width, first.height, std::move(tiles)));
}

}  // namespace vt
