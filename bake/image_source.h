// Level-0 texels for the build: an ImageSource hands out rows of float texels, top to bottom,
// without ever holding the whole image. Files are read through OpenImageIO by scanlines or by
// tile rows; MemoryImageSource wraps texels already in memory (the mesh bake, tests).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/status.h"

namespace vt {

struct ImageInfo {
  uint32_t width = 0;
  uint32_t height = 0;
  uint32_t channels = 0;    // 1..4 (extra channels of a file are dropped)
  bool is_float = false;    // half/float data (HDR): values are not limited to [0, 1]
  int alpha_channel = -1;   // index of the alpha channel or -1
  std::string color_space;  // from the file's metadata ("sRGB", "Linear", "Gamma2.2", ...) or ""
};

// Rows of texels, `channels` floats per texel, row-major. 8/16-bit files give values in
// [0, 1] in the file's encoding (no colour conversion happens here).
class ImageSource {
 public:
  virtual ~ImageSource() = default;
  virtual const ImageInfo& info() const = 0;
  // Reads rows [y0, y1) into out (width * channels * (y1 - y0) floats). Reads are cheapest in
  // increasing y; going back may re-decode a file.
  virtual Status read_rows(uint32_t y0, uint32_t y1, float* out) = 0;
  // A hash of the texels this source hands out (same texels, same hash): the content part of a
  // build plan's identity. The default reads every row; sources that know a cheaper exact
  // identity (a file's bytes, a generator's parameters) override it.
  virtual Expected<uint64_t> content_hash();
  // Hands over the whole image (width * height * channels floats) when the source holds it in
  // memory, leaving the source empty, so that a build can convert it in place rather than copy
  // it; empty when the source cannot.
  virtual std::vector<float> release_texels() { return {}; }
  // The whole image as read_rows would give it (width * height * channels floats) where the
  // source holds it so in memory; null otherwise. Scans read it in place, without a row buffer
  // to allocate (first touches of fresh memory are most of a scan's cost).
  virtual const float* texels_in_memory() const { return nullptr; }
  // The file the texels come from, for messages; "" for generated or in-memory texels.
  virtual std::string origin() const { return ""; }
};

// XXH3-64 of a file's bytes (a content key: the same file under any path hashes alike).
Expected<uint64_t> hash_file(const std::string& path);

// Opens an image file OpenImageIO can read (first subimage, level 0), or a PCX (read whole by
// scene::pcx_as_png). Errors name the file.
Expected<std::unique_ptr<ImageSource>> open_image_file(const std::string& path);

// Texels owned in memory: info.width * info.height * info.channels floats.
class MemoryImageSource final : public ImageSource {
 public:
  MemoryImageSource(ImageInfo info, std::vector<float> texels)
      : info_(std::move(info)), texels_(std::move(texels)) {}
  const ImageInfo& info() const override { return info_; }
  Status read_rows(uint32_t y0, uint32_t y1, float* out) override;
  Expected<uint64_t> content_hash() override;
  std::vector<float> release_texels() override { return std::move(texels_); }
  const float* texels_in_memory() const override {
    return texels_.size() == size_t(info_.width) * info_.height * info_.channels ? texels_.data()
                                                                                 : nullptr;
  }
  const std::vector<float>& texels() const { return texels_; }

 private:
  ImageInfo info_;
  std::vector<float> texels_;
};

// A UDIM grid of tiles as one image: `pattern` holds "<UDIM>" where the files have a number
// 1001 + u + 10 * v (u in 0..9), e.g. "tex.<UDIM>.png" finds tex.1001.png, tex.1002.png ...
// The image is (max_u + 1) x (max_v + 1) tiles; tile (u, v) lies at texel (u * W, v * H), v = 0
// at the top (image rows grow with v, as UV v does in Vulkan/glTF). Missing tiles are black
// (0 in every channel, alpha 0 included). All tiles must share size, channels and data type;
// errors name the offending file. Rows are read band by band from the tiles, never whole.
Expected<std::unique_ptr<ImageSource>> open_udim_image(const std::string& pattern);
inline bool is_udim_pattern(const std::string& path) {
  return path.find("<UDIM>") != std::string::npos;
}

// True when every texel's channel `channel` is >= 1 (NaN is not opaque). Reads the source in
// bands of a few MiB, top to bottom.
Expected<bool> channel_is_opaque(ImageSource& source, uint32_t channel);

// The source without one of its channels (e.g. an opaque alpha); rows are read through.
class DropChannelSource final : public ImageSource {
 public:
  DropChannelSource(std::shared_ptr<ImageSource> source, uint32_t channel);
  const ImageInfo& info() const override { return info_; }
  Status read_rows(uint32_t y0, uint32_t y1, float* out) override;
  Expected<uint64_t> content_hash() override;

 private:
  std::shared_ptr<ImageSource> source_;
  uint32_t channel_;
  ImageInfo info_;
  std::vector<float> rows_;
};

// Writes a source to an image file (format from the extension), row band by row band, so a
// procedural source larger than memory can be written. `tile` > 0 writes a tiled file where the
// format supports it. 8-bit formats get values rounded from [0, 1].
Status write_image_file(ImageSource& source, const std::string& path, uint32_t tile = 0);

}  // namespace vt
