#include "render/lit_pass.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "common/srgb.h"
#include "common/vec.h"
#include "render/validate.h"
#include "scene/image_load.h"
#include "scene/material_rules.h"
#include "scene/tangent_frame.h"

namespace vt::render {
namespace {

constexpr LayerSemantic kLitSemantics[kLitInputCount] = {
    LayerSemantic::kAlbedo, LayerSemantic::kNormal, LayerSemantic::kOrm, LayerSemantic::kEmissive};

uint8_t unorm8(float v) {
  return uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
}

// A ReferenceTexture from level-0 RGBA8 texels: full box mip chain, reduced to `max_side`, sampled
// with `ref`'s sampler (wrap per axis, magFilter) when given; `srgb` colour texels are filtered
// in linear light.
ReferenceTexture make_texture(std::vector<uint8_t> texels, uint32_t w, uint32_t h,
                              const scene::TextureRef* ref, uint32_t max_side, bool srgb = false) {
  ReferenceTexture tex;
  tex.width = w;
  tex.height = h;
  if (ref) tex.sampler = TextureSampler{ref->wrap_s, ref->wrap_t, ref->mag_filter};
  tex.levels = box_mip_chain(texels.data(), w, h, srgb);
  uint32_t drop = 0;
  while (std::max(w >> drop, h >> drop) > max_side) ++drop;
  if (drop > 0) {
    tex.levels.erase(tex.levels.begin(), tex.levels.begin() + drop);
    tex.width = std::max(1u, w >> drop);
    tex.height = std::max(1u, h >> drop);
  }
  return tex;
}

ReferenceTexture constant_texture(uint8_t r, uint8_t g, uint8_t b) {
  return make_texture({r, g, b, 255}, 1, 1, nullptr, 1);
}

// Loads each image once, on first use. An image that cannot be read is an error, or with
// `missing_as_factor` no image (the slot's factor alone), its error kept in `missing`.
class ImageCache {
 public:
  ImageCache(const scene::Scene& s, bool missing_as_factor)
      : scene_(s), images_(s.images.size()), missing_as_factor_(missing_as_factor) {}
  // Null for a texture reference without an image.
  Expected<const scene::FloatImage*> get(const scene::TextureRef& t) {
    if (!t.valid() || size_t(t.image) >= images_.size()) return nullptr;
    if (!images_[t.image]) {
      auto img = scene::load_float_image(scene_.images[t.image]);
      if (!img.ok() && !missing_as_factor_) return img.status();
      if (!img.ok()) missing.push_back(img.status().message());
      images_[t.image] = img.ok() ? std::move(*img) : scene::FloatImage{};
    }
    return images_[t.image]->rgba.empty() ? nullptr : &*images_[t.image];
  }
  std::vector<std::string> missing;  // errors of the images read as missing, in order

 private:
  const scene::Scene& scene_;
  std::vector<std::optional<scene::FloatImage>> images_;
  bool missing_as_factor_;
};

// ORM as the bake's transfer computes it, each factor applied per texel (filtering commutes with
// it): roughness and metallic the factors times G and B of the metallic-roughness texture (R 1),
// and apart, on its own UV set and sampler, occlusion 1 + strength (R - 1).
ReferenceTexture metal_rough_texture(const scene::Material& m, const scene::FloatImage* mr,
                                     uint32_t max_side) {
  const uint32_t w = mr ? mr->width : 1, h = mr ? mr->height : 1;
  std::vector<uint8_t> texels(size_t(w) * h * 4);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      uint8_t* d = &texels[(size_t(y) * w + x) * 4];
      d[0] = 255;
      d[1] = unorm8(m.roughness_factor * (mr ? mr->at(x, y)[1] : 1.0f));
      d[2] = unorm8(m.metallic_factor * (mr ? mr->at(x, y)[2] : 1.0f));
      d[3] = 255;
    }
  return make_texture(std::move(texels), w, h, mr ? &m.metallic_roughness_texture : nullptr,
                      max_side);
}

ReferenceTexture occlusion_texture(const scene::Material& m, const scene::FloatImage* occ,
                                   uint32_t max_side) {
  if (!occ) return constant_texture(255, 255, 255);
  std::vector<uint8_t> texels(size_t(occ->width) * occ->height * 4, 255);
  for (uint32_t y = 0; y < occ->height; ++y)
    for (uint32_t x = 0; x < occ->width; ++x) {
      const uint8_t o = unorm8(1.0f + m.occlusion_strength * (occ->at(x, y)[0] - 1.0f));
      uint8_t* d = &texels[(size_t(y) * occ->width + x) * 4];
      d[0] = d[1] = d[2] = o;
    }
  return make_texture(std::move(texels), occ->width, occ->height, &m.occlusion_texture, max_side);
}

// A data (raw) or colour (sRGB-encoded) 8-bit texture of an image.
ReferenceTexture image_texture(const scene::FloatImage& img, bool colour,
                               const scene::TextureRef& ref, uint32_t max_side) {
  std::vector<uint8_t> texels(img.rgba.size());
  for (size_t i = 0; i < img.rgba.size(); ++i) {
    const float v = img.rgba[i];
    // Float colour images are linear; 8/16-bit ones carry the sRGB curve already.
    texels[i] = colour && img.is_float && i % 4 != 3 ? unorm8(linear_to_srgb(std::max(0.0f, v)))
                                                     : unorm8(v);
  }
  return make_texture(std::move(texels), img.width, img.height, &ref, max_side, colour);
}

Expected<LitMaterial> lit_material(const scene::Material& m, ImageCache& images,
                                   uint32_t max_side) {
  LitMaterial out;
  VT_ASSIGN_OR_RETURN(const scene::FloatImage* normal, images.get(m.normal_texture));
  if (normal) {
    out.normal = image_texture(*normal, false, m.normal_texture, max_side);
    out.has_normal_map = true;
    out.two_channel_normal = normal->channels < 3;
    out.normal_scale = m.normal_scale;
  } else {
    out.normal = constant_texture(128, 128, 255);
  }
  VT_ASSIGN_OR_RETURN(const scene::FloatImage* occ, images.get(m.occlusion_texture));
  VT_ASSIGN_OR_RETURN(const scene::FloatImage* mr, images.get(m.metallic_roughness_texture));
  out.orm = metal_rough_texture(m, mr, max_side);
  out.occlusion = occlusion_texture(m, occ, max_side);
  VT_ASSIGN_OR_RETURN(const scene::FloatImage* emissive, images.get(m.emissive_texture));
  out.emissive = emissive ? image_texture(*emissive, true, m.emissive_texture, max_side)
                          : constant_texture(255, 255, 255);
  for (int c = 0; c < 3; ++c) out.emissive_scale[c] = m.emissive_factor[c] * m.emissive_strength;
  return out;
}

Vec3d to_d(const std::array<double, 3>& a) {
  return {a[0], a[1], a[2]};
}

}  // namespace

uint32_t LitLayers::inputs() const {
  uint32_t bits = 0;
  for (uint32_t i = 1; i < kLitInputCount; ++i)
    if (layer[i]) bits |= 1u << i;
  return bits;
}

Expected<LitLayers> find_lit_layers(std::span<const LayerSpec> layers,
                                    std::span<const RuntimeFormat> upload_formats,
                                    const std::string& only) {
  LitLayers out;
  std::optional<uint32_t> named;
  for (uint32_t i = 0; i < layers.size(); ++i) {
    if (!only.empty() && layers[i].name == only) named = i;
  }
  if (!only.empty()) {
    if (!named) return Error(ErrorCode::kNotFound, "no layer '" + only + "'");
    const LayerSemantic s = layers[*named].semantic;
    if (s != LayerSemantic::kNormal && s != LayerSemantic::kOrm && s != LayerSemantic::kEmissive) {
      return Error(ErrorCode::kInvalidArgument,
                   "layer '" + only + "' is " + to_string(s) +
                       ": the lit check renders normal, orm and emissive layers");
    }
  }
  for (uint32_t k = 0; k < kLitInputCount; ++k) {
    for (uint32_t i = 0; i < layers.size() && i < upload_formats.size(); ++i) {
      if (layers[i].semantic != kLitSemantics[k]) continue;
      if (k > 0 && named && *named != i) continue;
      // Float layers (RGBA16F, BC6H) upload to the cache, but the lit shaders take 8-bit
      // inputs: still skipped here.
      const RuntimeFormatInfo* info = runtime_format_info(upload_formats[i]);
      if (cache_vk_format(upload_formats[i]) == VK_FORMAT_UNDEFINED || !info || info->is_float) {
        out.skipped.push_back(layers[i].name + ": runtime format " + to_string(upload_formats[i]) +
                              " cannot be rendered");
      } else {
        out.layer[k] = i;
        out.format[k] = upload_formats[i];
      }
      break;
    }
  }
  if (named && !out.any() && !out.skipped.empty()) {
    return Error(ErrorCode::kUnsupported, "layer " + out.skipped[0]);
  }
  if (!out.layer[0]) out.layer = {};  // no albedo to shade: no lit pass
  return out;
}

LitFrameOptions lit_frame_for(const Camera& camera, uint32_t inputs) {
  // Rows of the column-major view-projection: clip x, y, w. The eye is where all three vanish;
  // the w row is the view direction, the x row the camera's right.
  const auto& m = camera.view_proj.m;
  auto row = [&](int r) { return Vec3d{m[0 * 4 + r], m[1 * 4 + r], m[2 * 4 + r]}; };
  const Vec3d rx = row(0), ry = row(1), rw = row(3);
  const Vec3d b{-m[12], -m[13], -m[15]};
  const double det = dot(rx, cross(ry, rw));
  Vec3d eye{0, 0, 0};
  if (std::abs(det) > 1e-30) {
    // Cramer's rule for [rx; ry; rw] eye = b.
    eye = (cross(ry, rw) * b.x + cross(rw, rx) * b.y + cross(rx, ry) * b.z) / det;
  }
  const Vec3d forward = normalized(rw, {0, 0, -1});
  const Vec3d right = normalized(rx - forward * dot(rx, forward), {1, 0, 0});
  const Vec3d up = cross(right, forward);
  const Vec3d key = normalized(forward * -0.6 + up * 0.6 + right * 0.5, {0, 0, 1});
  const Vec3d fill = normalized(forward * -0.8 + up * -0.15 + right * -0.6, {0, 0, 1});
  LitFrameOptions o;
  const Vec3d* v[3] = {&eye, &key, &fill};
  float* d[3] = {o.eye, o.key_dir, o.fill_dir};
  for (int i = 0; i < 3; ++i)
    d[i][0] = float(v[i]->x), d[i][1] = float(v[i]->y), d[i][2] = float(v[i]->z);
  o.inputs = inputs;
  return o;
}

Expected<std::vector<LitMaterial>> lit_materials(const scene::Scene& s,
                                                 const ReferenceDrawOptions& options,
                                                 std::vector<std::string>* missing) {
  ImageCache images(s, options.missing_as_factor);
  std::vector<LitMaterial> out;
  for (size_t mi = 0; mi <= s.materials.size(); ++mi) {
    const scene::Material m = mi < s.materials.size() ? s.materials[mi] : scene::Material{};
    auto lm = lit_material(m, images, options.max_texture_side);
    if (!lm.ok()) {
      return lm.status().with_context(
          s.source_path + ": " +
          scene::material_label(m.name, mi < s.materials.size() ? int64_t(mi) : -1));
    }
    out.push_back(std::move(*lm));
  }
  if (missing) *missing = std::move(images.missing);
  return out;
}

Status add_shading_frames(const scene::Scene& s, SceneDraws& draws, bool reference) {
  size_t next = 0;
  for (const scene::Instance& inst : s.instances()) {
    if (inst.mesh < 0 || size_t(inst.mesh) >= s.meshes.size()) continue;
    const scene::Mesh& mesh = s.meshes[inst.mesh];
    // The linear part of the world transform moves tangents; its sign flips handedness.
    const Vec3d o = to_d(scene::transform_point(inst.world, {0, 0, 0}));
    const Vec3d ax = to_d(scene::transform_point(inst.world, {1, 0, 0})) - o;
    const Vec3d ay = to_d(scene::transform_point(inst.world, {0, 1, 0})) - o;
    const Vec3d az = to_d(scene::transform_point(inst.world, {0, 0, 1})) - o;
    const float flip = scene::mirrors(inst.world) ? -1.0f : 1.0f;
    for (const scene::Primitive& p : mesh.primitives) {
      if (p.indices.empty()) continue;
      if (next >= draws.meshes.size() || draws.meshes[next].vertices.size() != p.positions.size()) {
        return Error(ErrorCode::kInternal, "render: lit shading frames out of step with the draws");
      }
      MeshData& md = draws.meshes[next++];
      const scene::Material m = p.material >= 0 && size_t(p.material) < s.materials.size()
                                    ? s.materials[p.material]
                                    : scene::Material{};
      const std::vector<scene::Vec3> normals =
          p.normals.size() == p.positions.size() ? p.normals : scene::compute_normals(p);
      std::vector<scene::Vec4> tangents;
      if (reference && m.normal_texture.valid() &&
          size_t(m.normal_texture.texcoord) < p.uvs.size()) {
        tangents = p.tangents.size() == p.positions.size()
                       ? p.tangents
                       : scene::compute_tangents(p, normals, m.normal_texture.texcoord);
      }
      // The lit reference reads each texture on its own UV set through its own transform.
      const scene::TextureRef* slots[4] = {&m.normal_texture, &m.occlusion_texture,
                                           &m.metallic_roughness_texture, &m.emissive_texture};
      const std::vector<scene::Vec2>* slot_uvs[4] = {};
      for (int k = 0; k < 4 && reference; ++k)
        if (slots[k]->valid()) slot_uvs[k] = scene::texture_uv_set(p, *slots[k]);
      for (size_t v = 0; v < p.positions.size(); ++v) {
        Vertex& out = md.vertices[v];
        const auto n = scene::transform_direction(inst.world, normals[v]);
        const Vec3d wn = normalized(Vec3d{n[0], n[1], n[2]}, {0, 0, 1});
        out.nx = float(wn.x), out.ny = float(wn.y), out.nz = float(wn.z);
        if (!tangents.empty()) {
          const scene::Vec4& t = tangents[v];
          const Vec3d wt =
              normalized(ax * double(t[0]) + ay * double(t[1]) + az * double(t[2]), {1, 0, 0});
          out.tx = float(wt.x), out.ty = float(wt.y), out.tz = float(wt.z);
          out.tw = (t[3] < 0 ? -1.0f : 1.0f) * flip;
        }
        for (int k = 0; k < 4; ++k) {
          if (!slot_uvs[k]) continue;
          const scene::Vec2& uv = (*slot_uvs[k])[v];
          const auto t = scene::texture_uv(*slots[k], uv[0], uv[1]);
          out.tex_uv[k][0] = float(t[0]), out.tex_uv[k][1] = float(t[1]);
        }
      }
    }
  }
  if (next != draws.meshes.size()) {
    return Error(ErrorCode::kInternal, "render: lit shading frames out of step with the draws");
  }
  return Status::Ok();
}

Status set_lit_caches_for(Renderer& renderer, const LitLayers& lit) {
  std::array<std::optional<RuntimeFormat>, kLitInputCount> formats;
  for (uint32_t i = 0; i < kLitInputCount; ++i)
    if (lit.layer[i]) formats[i] = lit.format[i];
  return renderer.set_lit_caches(formats);
}

Status upload_lit_pages(Renderer& renderer, const LitLayers& lit,
                        std::span<const PageUpload> uploads) {
  if (uploads.empty() || !lit.any()) return Status::Ok();
  std::vector<SlotUpload> slots;
  for (uint32_t i = 0; i < kLitInputCount; ++i) {
    if (!lit.layer[i]) continue;
    slots.clear();
    for (const PageUpload& u : uploads) {
      if (*lit.layer[i] >= u.layers.size()) {
        return Error(ErrorCode::kInternal, "render: an upload lacks a lit layer");
      }
      slots.push_back({u.slot_x, u.slot_y, u.layers[*lit.layer[i]]});
    }
    VT_RETURN_IF_ERROR(renderer.upload_lit_slots(LitInput(i), slots));
  }
  return Status::Ok();
}

Expected<LitFrames> render_lit_view(Renderer& renderer, const Camera& camera,
                                    const LitLayers& lit) {
  const LitFrameOptions o = lit_frame_for(camera, lit.inputs());
  LitFrames out;
  auto t0 = std::chrono::steady_clock::now();
  VT_ASSIGN_OR_RETURN(out.virt, renderer.render_lit_virtual(camera, o));
  auto t1 = std::chrono::steady_clock::now();
  VT_ASSIGN_OR_RETURN(out.reference, renderer.render_lit_reference(camera, o));
  auto t2 = std::chrono::steady_clock::now();
  out.virtual_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  out.reference_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
  if (lit.layer[uint32_t(LitInput::kEmissive)]) {
    const LitFrameOptions e = emissive_frame_for(camera);
    VT_ASSIGN_OR_RETURN(out.emissive_virtual, renderer.render_lit_virtual(camera, e));
    VT_ASSIGN_OR_RETURN(out.emissive_reference, renderer.render_lit_reference(camera, e));
    out.emissive_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t2).count();
  }
  if (lit.layer[uint32_t(LitInput::kNormal)]) {
    const auto t3 = std::chrono::steady_clock::now();
    const LitFrameOptions n = normals_frame_for(camera);
    VT_ASSIGN_OR_RETURN(out.normals_virtual, renderer.render_lit_virtual(camera, n));
    VT_ASSIGN_OR_RETURN(out.normals_reference, renderer.render_lit_reference(camera, n));
    out.normals_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t3).count();
  }
  return out;
}

LitFrameOptions emissive_frame_for(const Camera& camera) {
  LitFrameOptions o = lit_frame_for(camera, 1u << uint32_t(LitInput::kEmissive));
  o.key = o.fill = o.ambient = 0.0f;
  return o;
}

LitFrameOptions normals_frame_for(const Camera& camera) {
  LitFrameOptions o = lit_frame_for(camera, 1u << uint32_t(LitInput::kNormal));
  o.shading_normals = true;
  return o;
}

nlohmann::json to_json(const LitViewReport& lit) {
  const ViewMetrics& m = lit.metrics;
  nlohmann::json j = {{"psnr_rgb", m.psnr_rgb},
                      {"worst_tile_psnr", m.worst_tile_psnr},
                      {"worst_tile", {m.worst_tile_x, m.worst_tile_y}},
                      {"ssim", m.ssim},
                      {"max_abs_error", m.max_abs},
                      {"pixels_compared", m.pixels},
                      {"reference_ms", lit.reference_ms},
                      {"virtual_ms", lit.virtual_ms}};
  if (lit.emissive) {
    j["emissive"] = to_json(*lit.emissive);
    j["emissive"]["ms"] = lit.emissive_ms;
  }
  if (lit.normals) {
    j["normals"] = to_json(*lit.normals);
    j["normals"]["ms"] = lit.normals_ms;
  }
  return j;
}

}  // namespace vt::render
