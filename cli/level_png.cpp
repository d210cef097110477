#include "cli/level_png.h"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "format/atomic_output.h"

namespace vt {
namespace {

void put_u32(std::vector<uint8_t>& out, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(uint8_t(v >> shift));
}

// Buffers the PNG stream and hands it to the file in large writes; every write checked.
class PngFile {
 public:
  // The stream opens with PNG's signature.
  PngFile(int fd, const std::string& path)
      : fd_(fd), path_(path), out_{0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'} {}
  void chunk(const char type[4], const uint8_t* data, size_t size) {
    put_u32(out_, uint32_t(size));
    const size_t start = out_.size();
    out_.insert(out_.end(), type, type + 4);
    out_.insert(out_.end(), data, data + size);
    put_u32(out_, uint32_t(crc32(0, out_.data() + start, uInt(out_.size() - start))));
    if (out_.size() >= (1u << 20)) (void)flush();  // an error stays in status_
  }
  Status flush() {
    if (status_.ok()) status_ = write_all(fd_, out_.data(), out_.size(), path_);
    out_.clear();
    return status_;
  }

 private:
  int fd_;
  std::string path_;
  std::vector<uint8_t> out_;
  Status status_ = Status::Ok();
};

}  // namespace

bool level_png_supported(const LevelImage& image) {
  return image.texel_type == TexelType::kU8 && image.channels >= 1 && image.channels <= 4 &&
         image.width > 0 && image.height > 0 &&
         image.texels.size() == size_t(image.width) * image.height * image.channels;
}

Status write_level_png(const std::string& path, const LevelImage& image, const LayerSpec& layer) {
  if (!level_png_supported(image))
    return Error(ErrorCode::kInvalidArgument,
                 path + ": PNG here holds 8-bit texels of 1 to 4 channels, not " +
                     std::to_string(image.channels) + " x " + to_string(image.texel_type));
  static constexpr uint8_t kColourType[5] = {0, 0, 4, 2, 6};  // grey, grey+alpha, RGB, RGBA
  return write_output(path, [&](const std::string& temp) -> Status {
    const int fd = ::open(temp.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
    if (fd < 0) return Error(ErrorCode::kIo, path + ": cannot open for writing");
    PngFile png(fd, path);
    std::vector<uint8_t> header;
    put_u32(header, image.width);
    put_u32(header, image.height);
    header.insert(header.end(), {8, kColourType[image.channels], 0, 0, 0});
    png.chunk("IHDR", header.data(), header.size());
    if (is_colour(layer.semantic) && layer.color_space == ColorSpace::kSrgb) {
      const uint8_t perceptual = 0;
      png.chunk("sRGB", &perceptual, 1);
    }
    // Each row with PNG filter 1 (Sub: the difference to the texel on the left), deflated at
    // level 6 as it goes: memory stays one row and one output buffer whatever the level size.
    z_stream z{};
    if (deflateInit(&z, 6) != Z_OK) {
      ::close(fd);
      return Error(ErrorCode::kResourceLimit, path + ": zlib could not start");
    }
    const size_t row_bytes = size_t(image.width) * image.channels;
    std::vector<uint8_t> row(row_bytes + 1), out(1 << 16);
    Status status = Status::Ok();
    for (uint32_t y = 0; y <= image.height && status.ok(); ++y) {
      const bool last = y == image.height;
      if (!last) {
        const uint8_t* src = image.texels.data() + y * row_bytes;
        row[0] = 1;
        for (size_t i = 0; i < row_bytes; ++i)
          row[1 + i] = uint8_t(src[i] - (i >= image.channels ? src[i - image.channels] : 0));
        z.next_in = row.data();
        z.avail_in = uInt(row.size());
      }
      int rc = Z_OK;
      do {
        z.next_out = out.data();
        z.avail_out = uInt(out.size());
        rc = deflate(&z, last ? Z_FINISH : Z_NO_FLUSH);
        const size_t produced = out.size() - z.avail_out;
        if (produced > 0) png.chunk("IDAT", out.data(), produced);
      } while (z.avail_out == 0 || (last && rc != Z_STREAM_END && rc >= 0));
      if (rc < 0 && rc != Z_BUF_ERROR)
        status = Error(ErrorCode::kInternal, path + ": deflate failed");
    }
    deflateEnd(&z);
    png.chunk("IEND", nullptr, 0);
    if (status.ok()) status = png.flush();
    if (::close(fd) != 0 && status.ok())
      status = Error(ErrorCode::kIo, path + ": write failed: " + std::strerror(errno));
    return status;
  });
}

}  // namespace vt
