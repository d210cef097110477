// Helpers for the transfer tests: procedural textured scenes, level-0 read-back
// from page files and resampling through the atlas UVs.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "bake/transfer.h"
#include "bake/unwrap/unwrap.h"
#include "common/half.h"
#include "format/page_file.h"
#include "samples/sample_scene.h"
#include "scene/scene.h"
#include "tests/transfer/scratch_dir.h"

namespace vt::test {

// One-mesh scene at the origin with a material of its own.
inline scene::Scene single_mesh_scene(scene::Primitive prim, scene::Material mat) {
  scene::Scene s;
  prim.material = 0;
  s.materials.push_back(std::move(mat));
  scene::Mesh m;
  m.name = "mesh";
  m.primitives.push_back(std::move(prim));
  s.meshes.push_back(std::move(m));
  scene::Node n;
  n.name = "node";
  n.mesh = 0;
  s.nodes.push_back(n);
  s.roots.push_back(0);
  return s;
}

inline int add_image(scene::Scene& s, const std::string& path) {
  scene::Image im;
  im.name = std::filesystem::path(path).stem().string();
  im.path = path;
  im.uri = std::filesystem::path(path).filename().string();
  s.images.push_back(im);
  return int(s.images.size() - 1);
}

// single_mesh_scene whose material takes its base colour from the image at `path`.
inline scene::Scene textured_scene(scene::Primitive prim, const std::string& path,
                                   scene::Material mat = {}) {
  scene::Scene s = single_mesh_scene(std::move(prim), std::move(mat));
  s.materials[0].base_color_texture.image = add_image(s, path);
  return s;
}

// The procedural sample scene, small: `texture_size` textures, few triangles, at dir/scene.gltf.
inline Status write_small_sample_scene(const std::string& dir, uint32_t texture_size = 32,
                                       uint32_t sphere_segments = 12) {
  SampleSceneOptions so;
  so.texture_size = texture_size;
  so.sphere_segments = sphere_segments;
  so.ground_cells = 4;
  return write_sample_scene(dir, so);
}

// Transfer options at the unwrapped atlas's size, the others at their defaults.
inline TransferOptions atlas_transfer_options(const unwrap::UnwrapStats& stats) {
  TransferOptions o;
  o.width = uint32_t(stats.atlas_width), o.height = uint32_t(stats.atlas_height);
  return o;
}

// Level 0 of one layer as floats in [0, 1] (8-bit) or as stored (float), payload texels only;
// absent pages leave zeros and covered = false.
struct Level0 {
  uint32_t width = 0, height = 0, channels = 0;
  std::vector<float> texels;
  std::vector<uint8_t> present;
  float at(double x, double y, uint32_t c) const {  // bilinear, texel centres at +0.5
    x -= 0.5, y -= 0.5;
    double fx = std::floor(x), fy = std::floor(y);
    double ax = x - fx, ay = y - fy;
    auto texel = [&](int64_t i, int64_t j) {
      i = std::clamp<int64_t>(i, 0, width - 1), j = std::clamp<int64_t>(j, 0, height - 1);
      return texels[(size_t(j) * width + size_t(i)) * channels + c];
    };
    int64_t i = int64_t(fx), j = int64_t(fy);
    return float((texel(i, j) * (1 - ax) + texel(i + 1, j) * ax) * (1 - ay) +
                 (texel(i, j + 1) * (1 - ax) + texel(i + 1, j + 1) * ax) * ay);
  }
};

inline Level0 read_level0(const PageFileReader& r, uint32_t layer) {
  const PageGeometry& g = r.geometry();
  const LayerSpec& spec = r.layers()[layer];
  Level0 out;
  out.width = g.width, out.height = g.height, out.channels = spec.channels;
  out.texels.assign(size_t(g.width) * g.height * spec.channels, 0.0f);
  out.present.assign(size_t(g.width) * g.height, 0);
  std::vector<uint8_t> page(r.decoded_page_bytes(layer));
  const uint32_t ps = g.page_size();
  for (uint32_t py = 0; py < g.pages_y(0); ++py) {
    for (uint32_t px = 0; px < g.pages_x(0); ++px) {
      if (!r.read_texels({0, px, py}, layer, page).ok()) continue;
      for (uint32_t j = 0; j < g.payload; ++j) {
        for (uint32_t i = 0; i < g.payload; ++i) {
          uint32_t x = px * g.payload + i, y = py * g.payload + j;
          if (x >= g.width || y >= g.height) continue;
          size_t src = (size_t(j + g.border) * ps + (i + g.border)) * spec.texel_bytes();
          out.present[size_t(y) * g.width + x] = 1;
          for (uint32_t c = 0; c < spec.channels; ++c) {
            float v;
            if (spec.texel_type == TexelType::kF32) {
              std::memcpy(&v, &page[src + 4 * c], 4);
            } else if (spec.texel_type == TexelType::kF16) {
              uint16_t half;
              std::memcpy(&half, &page[src + 2 * c], 2);
              v = half_to_float(half);
            } else {
              v = page[src + c] / 255.0f;
            }
            out.texels[(size_t(y) * g.width + x) * spec.channels + c] = v;
          }
        }
      }
    }
  }
  return out;
}

inline int find_layer(const PageFileReader& r, LayerSemantic s) {
  for (size_t i = 0; i < r.layers().size(); ++i)
    if (r.layers()[i].semantic == s) return int(i);
  return -1;
}

// Calls f(triangle corner indices, barycentrics, source uv) for every centre of a source texel
// (size w x h) that lies inside a triangle's TEXCOORD_0 footprint.
inline void for_each_source_texel(
    const scene::Primitive& p, uint32_t w, uint32_t h,
    const std::function<void(const uint32_t v[3], const double l[3], double u, double vv)>& f) {
  const auto& uv = p.uvs[0];
  for (size_t t = 0; t + 2 < p.indices.size(); t += 3) {
    uint32_t v[3] = {p.indices[t], p.indices[t + 1], p.indices[t + 2]};
    double x[3], y[3];
    for (int k = 0; k < 3; ++k) x[k] = uv[v[k]][0] * w, y[k] = uv[v[k]][1] * h;
    double area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
    if (std::abs(area) < 1e-12) continue;
    int x0 = std::max(0, int(std::floor(std::min({x[0], x[1], x[2]})))),
        x1 = std::min(int(w) - 1, int(std::ceil(std::max({x[0], x[1], x[2]}))));
    int y0 = std::max(0, int(std::floor(std::min({y[0], y[1], y[2]})))),
        y1 = std::min(int(h) - 1, int(std::ceil(std::max({y[0], y[1], y[2]}))));
    for (int j = y0; j <= y1; ++j) {
      for (int i = x0; i <= x1; ++i) {
        double px = i + 0.5, py = j + 0.5;
        double l[3];
        l[0] = ((x[1] - px) * (y[2] - py) - (y[1] - py) * (x[2] - px)) / area;
        l[1] = ((x[2] - px) * (y[0] - py) - (y[2] - py) * (x[0] - px)) / area;
        l[2] = 1 - l[0] - l[1];
        // Strictly inside, so a texel on a shared edge counts once.
        if (l[0] <= 1e-9 || l[1] <= 1e-9 || l[2] <= 1e-9) continue;
        f(v, l, px / w, py / h);
      }
    }
  }
}

inline double psnr(double squared_error_sum, uint64_t count) {
  if (count == 0) return 0;
  double mse = squared_error_sum / double(count);
  return mse > 0 ? 10 * std::log10(1.0 / mse) : 200.0;
}

}  // namespace vt::test
