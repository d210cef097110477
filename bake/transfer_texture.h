// A source texture as the material transfer samples it: every MIP level held as float texels
// in the file's own encoding, and one filtered lookup at a texel footprint: anisotropic along
// the footprint's major axis (up to 16 taps), trilinear between MIP levels, bilinear or nearest
// taps, glTF's wrap modes per axis. Colour textures' MIP levels are averaged in linear light
// and stored re-encoded, as the validator's reference (render/renderer.cpp box_mip_chain, UNORM
// sampling) makes and filters them; the caller converts a filtered colour sample.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/status.h"
#include "scene/scene.h"

namespace vt {

class ColorConverter;

// A footprint to sample: (s, t) in texture space (0..1 over the image, t = 0 at its first row,
// as glTF's UVs), and the footprint of one sample as {ds/dx, dt/dx, ds/dy, dt/dy}.
struct TextureLookup {
  double s = 0, t = 0;
  std::array<double, 4> d = {0, 0, 0, 0};
  scene::WrapMode wrap_s = scene::WrapMode::kRepeat, wrap_t = scene::WrapMode::kRepeat;
  bool nearest = false;  // magFilter NEAREST: every tap takes its whole texel
};

// What a footprint asks of one texture (constant over a triangle, whose UVs are affine in the
// atlas): taps along the major axis, the MIP level and the weight of the next one.
struct TextureFootprint {
  int taps = 1;
  uint32_t level = 0;
  float blend = 0;                // weight of level + 1
  double step_s = 0, step_t = 0;  // the major axis, (s, t) over one footprint
};

class TransferTexture {
 public:
  // Reads `path` whole: its own MIP levels when the file has them (a tiled .tx/.exr), else
  // level 0 and box-filtered levels made here (each level half the size, rounded down, at least
  // 1). The first `channels` are kept (0: the file's data channels, scene::data_channels), at
  // most 4. With `to_linear` and `from_linear` (a colour texture: its space to linear and back)
  // the made levels average decoded colour channels and store them re-encoded; null = data,
  // averaged as stored. Errors name the file and give OpenImageIO's reason; kNotFound when the
  // file cannot be opened, kCorrupt when its texels cannot be decoded (damaged or cut short: bad
  // input, exit 2, as the build says of its images).
  static Expected<TransferTexture> load(const std::string& path,
                                        const ColorConverter* to_linear = nullptr,
                                        const ColorConverter* from_linear = nullptr,
                                        int channels = 0);

  int channels() const { return channels_; }
  uint32_t width() const { return levels_.empty() ? 0 : levels_[0].width; }
  uint32_t height() const { return levels_.empty() ? 0 : levels_[0].height; }
  size_t levels() const { return levels_.size(); }
  uint64_t bytes() const { return floats_ * sizeof(float); }
  bool in_memory() const { return !mapping_; }

  // Moves the texels to an unlinked scratch file under `scratch_dir` ("" = the current folder),
  // mapped read-only: the OS pages them in and out instead of the process holding them. The
  // samples do not change.
  Status move_to_scratch(const std::string& scratch_dir);

  // The filtered value at `q`: channels() floats in out[0..channels()-1] (the rest untouched).
  // Deterministic and thread-safe. Non-finite coordinates sample (0, 0); non-finite footprints
  // a point. The same as sample(q, footprint(q.d), out).
  void sample(const TextureLookup& q, float* out) const { sample(q, footprint(q.d), out); }
  // The footprint {ds/dx, dt/dx, ds/dy, dt/dy} as taps and levels, and a lookup with it (q.d
  // unused): for many lookups with one footprint.
  TextureFootprint footprint(const std::array<double, 4>& d) const;
  void sample(const TextureLookup& q, const TextureFootprint& f, float* out) const;

 private:
  struct Level {
    uint32_t width = 0, height = 0;
    size_t offset = 0;  // first float of the level in texels_
  };
  template <int CH>
  void sample_channels(const TextureLookup& q, const TextureFootprint& f, float* out) const;
  void make_box_levels(const ColorConverter* to_linear, const ColorConverter* from_linear);

  int channels_ = 0;
  std::vector<Level> levels_;
  // Every level, channels_ floats per texel, rows top to bottom: in texels_, or in a mapped
  // scratch file (mapping_ unmaps it).
  std::vector<float> texels_;
  std::shared_ptr<const void> mapping_;
  const float* data_ = nullptr;
  size_t floats_ = 0;
};

}  // namespace vt
