// Source textures for the transfer (see transfer_texture.h).
#include "bake/transfer_texture.h"
#include "bake/color.h"
#include "scene/image_load.h"
#include "scene/material_rules.h"

#include <OpenImageIO/imageio.h>

#include <sys/mman.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace vt {
namespace {

constexpr int kMaxTaps = 16;  // anisotropy: taps along the footprint's major axis

// Coordinates past this are sampled at 0 (the wrap of such a float has no fraction left).
inline double finite_or_zero(double x) {
  return std::fabs(x) < 1e15 ? x : 0.0;
}

}  // namespace

Expected<TransferTexture> TransferTexture::load(const std::string& path,
                                                const ColorConverter* to_linear,
                                                const ColorConverter* from_linear, int channels) {
  std::string error;
  auto in = scene::open_image_input(path, error);
  if (!in) return Error(ErrorCode::kNotFound, error);
  TransferTexture tex;
  if (channels <= 0) {
    const Expected<int> data = scene::data_channels(*in);
    if (!data.ok())
      return Error(ErrorCode::kCorrupt, "cannot read its texels (" + data.status().message() + ")");
    channels = *data;
  }
  tex.channels_ = std::clamp(channels, 1, 4);
  channels = tex.channels_;
  for (int m = 0; in->seek_subimage(0, m); ++m) {
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels < channels) break;
    Level level;
    level.width = uint32_t(spec.width), level.height = uint32_t(spec.height);
    level.offset = tex.texels_.size();
    const size_t count = size_t(level.width) * level.height;
    tex.texels_.resize(level.offset + count * channels);
    float* texels = tex.texels_.data() + level.offset;
    if (!in->read_image(0, m, 0, channels, OIIO::TypeDesc::FLOAT, texels)) {
      return Error(ErrorCode::kCorrupt,
                   "cannot read its texels (" + scene::oiio_first_line(in->geterror()) + ")");
    }
    if (const int a = scene::associated_alpha_channel(*in, channels); a >= 0)
      scene::unassociate_alpha(texels, count, channels, a);
    tex.levels_.push_back(level);
  }
  (void)OIIO::geterror();  // seek_subimage past the last level leaves a message
  if (tex.levels_.empty()) return Error(ErrorCode::kCorrupt, "no texels in the file");
  if (tex.levels_.size() == 1) tex.make_box_levels(to_linear, from_linear);
  tex.data_ = tex.texels_.data(), tex.floats_ = tex.texels_.size();
  return tex;
}

Status TransferTexture::move_to_scratch(const std::string& scratch_dir) {
  if (mapping_ || floats_ == 0) return Status::Ok();
  std::string name =
      (scratch_dir.empty() ? std::string(".") : scratch_dir) + "/.vtbake-texture-XXXXXX";
  const int fd = mkstemp(name.data());
  if (fd < 0)
    return Error(ErrorCode::kIo, name + ": cannot create scratch file: " + std::strerror(errno));
  unlink(name.c_str());  // the file lives as long as the descriptor or the mapping
  const size_t bytes = floats_ * sizeof(float);
  const char* p = reinterpret_cast<const char*>(texels_.data());
  for (size_t done = 0; done < bytes;) {
    const ssize_t n = ::write(fd, p + done, bytes - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string why = std::strerror(n < 0 ? errno : ENOSPC);
      ::close(fd);
      return Error(ErrorCode::kIo, name + ": cannot write texture scratch: " + why);
    }
    done += size_t(n);
  }
  void* map = mmap(nullptr, bytes, PROT_READ, MAP_SHARED, fd, 0);
  ::close(fd);
  if (map == MAP_FAILED)
    return Error(ErrorCode::kIo, name + ": cannot map texture scratch: " + std::strerror(errno));
  mapping_ = std::shared_ptr<const void>(
      map, [bytes](const void* m) { munmap(const_cast<void*>(m), bytes); });
  data_ = static_cast<const float*>(map);
  texels_ = {};
  return Status::Ok();
}

// Level k+1 from level k: the mean of each 2 x 2 block (edge texels repeated where a side is
// odd or 1), down to 1 x 1; colour channels decoded to linear light for the mean and encoded
// again (alpha and data as stored).
void TransferTexture::make_box_levels(const ColorConverter* to_linear,
                                      const ColorConverter* from_linear) {
  const int ch = channels_;
  const bool colour = to_linear && from_linear;
  std::vector<float> linear;  // the source level decoded
  while (levels_.back().width > 1 || levels_.back().height > 1) {
    const Level src = levels_.back();
    Level dst;
    dst.width = std::max(1u, src.width / 2), dst.height = std::max(1u, src.height / 2);
    dst.offset = texels_.size();
    const size_t src_count = size_t(src.width) * src.height;
    const size_t dst_count = size_t(dst.width) * dst.height;
    texels_.resize(dst.offset + dst_count * ch);
    const float* s = texels_.data() + src.offset;
    if (colour) {
      linear.assign(s, s + src_count * ch);
      to_linear->apply(linear.data(), src_count, ch);
      s = linear.data();
    }
    float* d = texels_.data() + dst.offset;
    for (uint32_t y = 0; y < dst.height; ++y) {
      const size_t y0 = std::min(2 * y, src.height - 1), y1 = std::min(2 * y + 1, src.height - 1);
      for (uint32_t x = 0; x < dst.width; ++x) {
        const size_t x0 = std::min(2 * x, src.width - 1), x1 = std::min(2 * x + 1, src.width - 1);
        const float* a = s + (y0 * src.width + x0) * ch;
        const float* b = s + (y0 * src.width + x1) * ch;
        const float* c = s + (y1 * src.width + x0) * ch;
        const float* e = s + (y1 * src.width + x1) * ch;
        for (int k = 0; k < ch; ++k)
          d[(size_t(y) * dst.width + x) * ch + k] = 0.25f * ((a[k] + b[k]) + (c[k] + e[k]));
      }
    }
    if (colour) from_linear->apply(d, dst_count, ch);
    levels_.push_back(dst);
  }
}

namespace {

// std::floor, exactly, without libm's call (the baseline x86-64 build has no roundsd): doubles
// of magnitude 2^52 and up are integers already.
inline double floor_exact(double x) {
  if (!(std::fabs(x) < 4503599627370496.0)) return x;
  const double t = double(int64_t(x));
  return t > x ? t - 1.0 : t;
}

// Texels i and i + 1 of a level n texels wide as the wrap mode addresses them; one division at
// most (none inside the level, none for REPEAT of a power-of-two side: tiled UVs wrap at every
// lookup).
inline void wrap_pair(int64_t i, int64_t n, scene::WrapMode mode, int64_t& a, int64_t& b) {
  if (i >= 0 && i + 1 < n) {
    a = i, b = i + 1;
    return;
  }
  if (mode == scene::WrapMode::kRepeat && (n & (n - 1)) == 0) {
    a = i & (n - 1), b = (i + 1) & (n - 1);  // two's complement: the non-negative remainder
    return;
  }
  switch (mode) {
    case scene::WrapMode::kClampToEdge:
      a = std::clamp<int64_t>(i, 0, n - 1), b = std::clamp<int64_t>(i + 1, 0, n - 1);
      return;
    case scene::WrapMode::kMirroredRepeat:
      a = scene::wrap_texel(mode, i, n), b = scene::wrap_texel(mode, i + 1, n);
      return;
    case scene::WrapMode::kRepeat:
      break;
  }
  a = scene::wrap_texel(mode, i, n);
  b = a + 1 == n ? 0 : a + 1;
}

// One bilinear (or nearest) tap of a level at (s, t), added to out[0..CH).
template <int CH>
inline void tap(const float* base, int64_t w, int64_t h, double s, double t, const TextureLookup& q,
                float* out) {
  if (q.nearest) {
    const int64_t x = scene::wrap_texel(q.wrap_s, int64_t(floor_exact(s * double(w))), w);
    const int64_t y = scene::wrap_texel(q.wrap_t, int64_t(floor_exact(t * double(h))), h);
    const float* p = base + size_t(y * w + x) * CH;
    for (int k = 0; k < CH; ++k) out[k] += p[k];
    return;
  }
  const double x = s * double(w) - 0.5, y = t * double(h) - 0.5;
  const double fx0 = floor_exact(x), fy0 = floor_exact(y);
  const float fx = float(x - fx0), fy = float(y - fy0);
  int64_t xa, xb, ya, yb;
  wrap_pair(int64_t(fx0), w, q.wrap_s, xa, xb);
  wrap_pair(int64_t(fy0), h, q.wrap_t, ya, yb);
  const float* r0 = base + size_t(ya * w) * CH;
  const float* r1 = base + size_t(yb * w) * CH;
  const float *p00 = r0 + xa * CH, *p10 = r0 + xb * CH, *p01 = r1 + xa * CH, *p11 = r1 + xb * CH;
  // Lerps of differences: equal texels give exactly their value (a constant 1 stays 1).
  for (int k = 0; k < CH; ++k) {
    const float top = p00[k] + fx * (p10[k] - p00[k]);
    const float bottom = p01[k] + fx * (p11[k] - p01[k]);
    out[k] += top + fy * (bottom - top);
  }
}

}  // namespace

// The footprint's two axes in level-0 texels; the longer is the major axis. Taps: as many as
// the ratio of the axes (at most kMaxTaps), spread evenly along the major axis over one
// footprint; MIP level: log2 of the major axis over the taps (each tap covers its share),
// trilinear between the two levels around it.
TextureFootprint TransferTexture::footprint(const std::array<double, 4>& d) const {
  TextureFootprint f;
  const Level& l0 = levels_[0];
  const double ax = d[0] * l0.width, ay = d[1] * l0.height;
  const double bx = d[2] * l0.width, by = d[3] * l0.height;
  double la = ax * ax + ay * ay, lb = bx * bx + by * by;
  if (!std::isfinite(la) || !std::isfinite(lb)) return f;
  f.step_s = d[0], f.step_t = d[1];
  if (lb > la) std::swap(la, lb), f.step_s = d[2], f.step_t = d[3];
  if (la <= 1.0) return f;
  const double major = std::sqrt(la), minor = std::sqrt(lb);
  f.taps = int(std::min<double>(kMaxTaps, std::ceil(major / std::max(minor, 1.0))));
  const double lod = std::log2(major / f.taps);
  const size_t last = levels_.size() - 1;
  if (lod > 0) {
    const double fl = std::floor(lod);
    if (fl >= double(last)) {
      f.level = uint32_t(last);
    } else {
      f.level = uint32_t(fl);
      f.blend = float(lod - fl);
    }
  }
  return f;
}

void TransferTexture::sample(const TextureLookup& q, const TextureFootprint& f, float* out) const {
  switch (channels_) {
    case 1:
      return sample_channels<1>(q, f, out);
    case 2:
      return sample_channels<2>(q, f, out);
    case 3:
      return sample_channels<3>(q, f, out);
    default:
      return sample_channels<4>(q, f, out);
  }
}

template <int CH>
void TransferTexture::sample_channels(const TextureLookup& q, const TextureFootprint& f,
                                      float* out) const {
  const double s = finite_or_zero(q.s), t = finite_or_zero(q.t);
  const Level& la0 = levels_[f.level];
  const float* base0 = data_ + la0.offset;
  float a[CH] = {}, b[CH] = {};
  if (f.taps == 1) {
    tap<CH>(base0, la0.width, la0.height, s, t, q, a);
    if (f.blend != 0) {
      const Level& la1 = levels_[f.level + 1];
      tap<CH>(data_ + la1.offset, la1.width, la1.height, s, t, q, b);
      for (int k = 0; k < CH; ++k) a[k] += f.blend * (b[k] - a[k]);
    }
    for (int k = 0; k < CH; ++k) out[k] = a[k];
    return;
  }
  for (int i = 0; i < f.taps; ++i) {
    const double o = (i + 0.5) / f.taps - 0.5;
    tap<CH>(base0, la0.width, la0.height, s + o * f.step_s, t + o * f.step_t, q, a);
  }
  if (f.blend != 0) {
    const Level& la1 = levels_[f.level + 1];
    for (int i = 0; i < f.taps; ++i) {
      const double o = (i + 0.5) / f.taps - 0.5;
      tap<CH>(data_ + la1.offset, la1.width, la1.height, s + o * f.step_s, t + o * f.step_t, q, b);
    }
    for (int k = 0; k < CH; ++k) a[k] += f.blend * (b[k] - a[k]);
  }
  for (int k = 0; k < CH; ++k) out[k] = a[k] / float(f.taps);
}

}  // namespace vt
