#include "render/scene_draws.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/srgb.h"
#include "scene/image_load.h"
#include "scene/material_rules.h"

namespace vt::render {
namespace {

uint8_t linear_to_srgb8(float c) {
  return uint8_t(std::lround(linear_to_srgb(std::clamp(c, 0.0f, 1.0f)) * 255.0f));
}

struct Bounds {
  Vec3f lo{std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
           std::numeric_limits<float>::max()};
  Vec3f hi{-std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
           -std::numeric_limits<float>::max()};
  void add(float x, float y, float z) {
    lo = {std::min(lo.x, x), std::min(lo.y, y), std::min(lo.z, z)};
    hi = {std::max(hi.x, x), std::max(hi.y, y), std::max(hi.z, z)};
  }
};

std::string where(const scene::Scene& s, int mesh, size_t prim) {
  return s.source_path + ": mesh '" + s.meshes[mesh].name + "' primitive " + std::to_string(prim);
}

const scene::Material* material_of(const scene::Scene& s, const scene::Primitive& p) {
  return p.material >= 0 && size_t(p.material) < s.materials.size() ? &s.materials[p.material]
                                                                    : nullptr;
}

// Where a draw's UVs come from: a UV set, read through a texture slot's transform when `slot` is
// set (the reference pass samples as the material does); no set gives UV (0, 0).
struct UvSource {
  const std::vector<scene::Vec2>* uvs = nullptr;
  const scene::TextureRef* slot = nullptr;
};

// Flattens instances; `uv_of(prim)` gives the UV source to use (or an error). The reference
// pass also takes the vertex colours (linear RGBA, alpha 1 for OPAQUE as scene::base_color).
template <typename UvOf>
Expected<SceneDraws> draws(const scene::Scene& s, UvOf uv_of, bool reference) {
  SceneDraws out;
  Bounds b;
  for (const scene::Instance& inst : s.instances()) {
    if (inst.mesh < 0 || size_t(inst.mesh) >= s.meshes.size()) continue;
    const scene::Mesh& mesh = s.meshes[inst.mesh];
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const scene::Primitive& p = mesh.primitives[pi];
      if (p.indices.empty()) continue;
      VT_ASSIGN_OR_RETURN(const UvSource src, uv_of(inst.mesh, pi, p));
      const scene::Material* mat = material_of(s, p);
      const bool colors = reference && p.colors.size() == p.positions.size();
      const bool opaque = !mat || mat->alpha_mode == scene::AlphaMode::kOpaque;
      MeshData m;
      m.vertices.resize(p.positions.size());
      for (size_t v = 0; v < p.positions.size(); ++v) {
        auto w = scene::transform_point(inst.world, p.positions[v]);
        Vertex& o = m.vertices[v];
        o.x = float(w[0]), o.y = float(w[1]), o.z = float(w[2]);
        if (!std::isfinite(o.x) || !std::isfinite(o.y) || !std::isfinite(o.z)) {
          return Error(ErrorCode::kCorrupt, where(s, inst.mesh, pi) + ": vertex " +
                                                std::to_string(v) + " has a non-finite position");
        }
        if (src.uvs) {
          const scene::Vec2& uv = (*src.uvs)[v];
          const auto t = src.slot ? scene::texture_uv(*src.slot, uv[0], uv[1])
                                  : std::array<double, 2>{uv[0], uv[1]};
          o.u = float(t[0]), o.v = float(t[1]);
        } else {
          o.u = o.v = 0.0f;
        }
        if (!std::isfinite(o.u) || !std::isfinite(o.v)) {
          return Error(ErrorCode::kCorrupt, where(s, inst.mesh, pi) + ": vertex " +
                                                std::to_string(v) + " has a non-finite UV");
        }
        if (colors) {
          const scene::Vec4& c = p.colors[v];
          o.r = c[0], o.g = c[1], o.b = c[2], o.a = opaque ? 1.0f : c[3];
        }
        b.add(o.x, o.y, o.z);
      }
      m.indices = p.indices;
      m.alpha_cutoff = !mat ? -1.0f
                       : mat->alpha_mode == scene::AlphaMode::kBlend
                           ? kAlphaBlended
                           : scene::alpha_test_cutoff(*mat);
      // Reference texture index = material index; the default material is the last texture.
      m.reference_texture = reference ? uint32_t(mat ? p.material : int(s.materials.size())) : 0;
      out.meshes.push_back(std::move(m));
    }
  }
  out.bounds_min = b.lo;
  out.bounds_max = b.hi;
  return out;
}

// RGBA8 sRGB texels of an image, float images encoded from linear.
Expected<std::vector<uint8_t>> load_rgba8(const scene::Image& image, uint32_t* width,
                                          uint32_t* height) {
  VT_ASSIGN_OR_RETURN(const scene::FloatImage img, scene::load_float_image(image));
  *width = img.width;
  *height = img.height;
  std::vector<uint8_t> out(img.rgba.size());
  for (size_t i = 0; i < img.rgba.size(); ++i) {
    const float v = img.rgba[i];
    out[i] = img.is_float && i % 4 != 3 ? linear_to_srgb8(v)
                                        : uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
  }
  return out;
}

}  // namespace

Expected<SceneDraws> virtual_scene_draws(const scene::Scene& s, int uv_set) {
  return draws(
      s,
      [&](int mesh, size_t pi, const scene::Primitive& p) -> Expected<UvSource> {
        int set = uv_set < 0 ? int(p.uvs.size()) - 1 : uv_set;
        if (set < 0 || size_t(set) >= p.uvs.size() || p.uvs[set].size() != p.positions.size()) {
          return Error(ErrorCode::kInvalidArgument, where(s, mesh, pi) + ": no atlas UV set " +
                                                        std::to_string(set) +
                                                        " (is this the unwrapped scene?)");
        }
        return UvSource{&p.uvs[set], nullptr};
      },
      false);
}

namespace {

// The material's base colour texels through scene::base_color (factor; alpha 1 for OPAQUE), in
// place: sRGB 8-bit in and out, the product taken in linear light.
void apply_base_color(const scene::Material& m, std::vector<uint8_t>& texels) {
  for (size_t i = 0; i + 3 < texels.size(); i += 4) {
    scene::Vec4 t;
    for (int c = 0; c < 3; ++c) t[c] = srgb_to_linear(texels[i + c] / 255.0f);
    t[3] = texels[i + 3] / 255.0f;
    const scene::Vec4 out = scene::base_color(m, t, {1, 1, 1, 1});
    for (int c = 0; c < 3; ++c) texels[i + c] = linear_to_srgb8(out[c]);
    texels[i + 3] = uint8_t(std::lround(std::clamp(out[3], 0.0f, 1.0f) * 255.0f));
  }
}

}  // namespace

Expected<SceneDraws> reference_scene_draws(const scene::Scene& s,
                                           const ReferenceDrawOptions& options) {
  VT_ASSIGN_OR_RETURN(
      SceneDraws out,
      draws(
          s,
          [&](int mesh, size_t pi, const scene::Primitive& p) -> Expected<UvSource> {
            const scene::Material* m = material_of(s, p);
            if (!m || !m->base_color_texture.valid()) return UvSource{};
            const scene::TextureRef& t = m->base_color_texture;
            const std::vector<scene::Vec2>* uvs = scene::texture_uv_set(p, t);
            if (!uvs) {
              return Error(ErrorCode::kCorrupt, where(s, mesh, pi) + ": base colour reads UV set " +
                                                    std::to_string(t.texcoord) +
                                                    " which it does not have");
            }
            return UvSource{uvs, &t};
          },
          true));
  // One texture per material plus the default material's; only the drawn ones read an image.
  std::vector<bool> drawn(s.materials.size() + 1, false);
  for (const MeshData& mesh : out.meshes) drawn[mesh.reference_texture] = true;
  for (size_t mi = 0; mi <= s.materials.size(); ++mi) {
    ReferenceTexture tex;
    std::vector<uint8_t> texels = {255, 255, 255, 255};
    tex.width = tex.height = 1;
    const scene::Material m = mi < s.materials.size() ? s.materials[mi] : scene::Material{};
    const scene::TextureRef& t = m.base_color_texture;
    if (drawn[mi] && t.valid() && size_t(t.image) < s.images.size()) {
      uint32_t width = 0, height = 0;
      auto image = load_rgba8(s.images[t.image], &width, &height);
      if (image.ok()) {
        texels = std::move(*image);
        tex.width = width, tex.height = height;
        tex.sampler = TextureSampler{t.wrap_s, t.wrap_t, t.mag_filter};
      } else {
        const std::string what = scene::material_label(m.name, int64_t(mi)) +
                                 " baseColorTexture: " + image.status().message();
        if (!options.missing_as_factor) return Error(image.status().code(), what);
        out.missing_textures.push_back(what + kDrawnFromFactor);
      }
    }
    apply_base_color(m, texels);
    tex.levels = box_mip_chain(texels.data(), tex.width, tex.height);
    // Too large for the device or memory: drop the finest levels.
    uint32_t drop = 0;
    while (std::max(tex.width >> drop, tex.height >> drop) > options.max_texture_side) ++drop;
    if (drop > 0) {
      tex.levels.erase(tex.levels.begin(), tex.levels.begin() + drop);
      tex.width = std::max(1u, tex.width >> drop);
      tex.height = std::max(1u, tex.height >> drop);
    }
    out.textures.push_back(std::move(tex));
  }
  return out;
}

}  // namespace vt::render
