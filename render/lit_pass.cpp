#include "render/lit_pass.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "common/srgb.h"
#include "common/vec.h"
#include "render/validate.h"
#include "scene/tangent_frame.h"

namespace vt::render {
namespace {

constexpr LayerSemantic kLitSemantics[kLitInputCount] = {
    LayerSemantic::kAlbedo, LayerSemantic::kNormal, LayerSemantic::kOrm, LayerSemantic::kEmissive};

// An image's texels as float RGBA with the transfer's channel rules (bake/transfer.cpp
// sample_texture): grey -> (g, g, g, 1), grey + alpha -> (g, g, g, a), RGB -> alpha 1.
struct FloatImage {
  uint32_t width = 0, height = 0;
  uint32_t channels = 0;  // in the file
  bool is_float = false;
  std::vector<float> rgba;
  const float* at(uint32_t x, uint32_t y) const { return &rgba[(size_t(y) * width + x) * 4]; }
  // The texel nearest to the centre of texel (x, y) of a w x h image over the same UV square.
  const float* nearest(uint32_t x, uint32_t y, uint32_t w, uint32_t h) const {
    return at(std::min(width - 1, uint32_t((x + 0.5) * width / w)),
              std::min(height - 1, uint32_t((y + 0.5) * height / h)));
  }
};

Expected<FloatImage> load_image(const scene::Image& image) {
  OIIO::Filesystem::IOMemReader mem(image.bytes.data(), image.bytes.size());
  const std::string name = image.embedded()
                               ? (image.mime_type == "image/jpeg" ? "embedded.jpg" : "embedded.png")
                               : image.path;
  std::unique_ptr<OIIO::ImageInput> in =
      image.embedded() ? OIIO::ImageInput::open(name, nullptr, &mem) : OIIO::ImageInput::open(name);
  if (!in) {
    return Error(ErrorCode::kNotFound,
                 "render: cannot open image '" + name + "': " + OIIO::geterror());
  }
  const OIIO::ImageSpec& spec = in->spec();
  const int ch = spec.nchannels;
  if (spec.width <= 0 || spec.height <= 0 || ch <= 0 || spec.width > 65536 || spec.height > 65536) {
    return Error(ErrorCode::kCorrupt, "render: image '" + name + "' has a bad size");
  }
  std::vector<float> px(size_t(spec.width) * spec.height * ch);
  if (!in->read_image(0, 0, 0, ch, OIIO::TypeDesc::FLOAT, px.data())) {
    return Error(ErrorCode::kCorrupt,
                 "render: cannot read image '" + name + "': " + in->geterror());
  }
  FloatImage out;
  out.width = uint32_t(spec.width);
  out.height = uint32_t(spec.height);
  out.channels = uint32_t(ch);
  out.is_float = spec.format.is_floating_point();
  out.rgba.resize(size_t(out.width) * out.height * 4);
  for (size_t i = 0, n = size_t(out.width) * out.height; i < n; ++i) {
    const float* s = &px[i * ch];
    float* d = &out.rgba[i * 4];
    d[0] = s[0];
    d[1] = ch >= 3 ? s[1] : s[0];
    d[2] = ch >= 3 ? s[2] : s[0];
    d[3] = ch == 2 ? s[1] : ch >= 4 ? s[3] : 1.0f;
  }
  return out;
}

uint8_t unorm8(float v) {
  return uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
}

AddressMode address_of(const scene::TextureRef& t) {
  return t.wrap_s == scene::WrapMode::kClampToEdge ? AddressMode::kClamp : AddressMode::kWrap;
}

// A ReferenceTexture from level-0 RGBA8 texels: full box mip chain, reduced to `max_side`.
ReferenceTexture make_texture(std::vector<uint8_t> texels, uint32_t w, uint32_t h, AddressMode mode,
                              uint32_t max_side) {
  ReferenceTexture tex;
  tex.width = w;
  tex.height = h;
  tex.address_mode = mode;
  tex.levels = box_mip_chain(texels.data(), w, h);
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
  return make_texture({r, g, b, 255}, 1, 1, AddressMode::kClamp, 1);
}

// Loads each image once, on first use.
class ImageCache {
 public:
  explicit ImageCache(const scene::Scene& s) : scene_(s), images_(s.images.size()) {}
  // Null for a texture reference without an image.
  Expected<const FloatImage*> get(const scene::TextureRef& t) {
    if (!t.valid() || size_t(t.image) >= images_.size()) return nullptr;
    if (!images_[t.image]) {
      VT_ASSIGN_OR_RETURN(FloatImage img, load_image(scene_.images[t.image]));
      images_[t.image] = std::move(img);
    }
    return &*images_[t.image];
  }

 private:
  const scene::Scene& scene_;
  std::vector<std::optional<FloatImage>> images_;
};

// ORM as the bake's transfer computes it: occlusion 1 + strength (R - 1), roughness and
// metallic the factors times G and B of the metallic-roughness texture. One texture at the
// metallic-roughness image's size (else the occlusion image's); a separate occlusion image is
// read at the nearest texel.
ReferenceTexture orm_texture(const scene::Material& m, const FloatImage* occ, const FloatImage* mr,
                             uint32_t max_side) {
  const FloatImage* base = mr ? mr : occ;
  const uint32_t w = base ? base->width : 1, h = base ? base->height : 1;
  std::vector<uint8_t> texels(size_t(w) * h * 4);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      float o = occ ? 1.0f + m.occlusion_strength * (occ->nearest(x, y, w, h)[0] - 1.0f) : 1.0f;
      float r = m.roughness_factor * (mr ? mr->at(x, y)[1] : 1.0f);
      float t = m.metallic_factor * (mr ? mr->at(x, y)[2] : 1.0f);
      uint8_t* d = &texels[(size_t(y) * w + x) * 4];
      d[0] = unorm8(o), d[1] = unorm8(r), d[2] = unorm8(t), d[3] = 255;
    }
  const scene::TextureRef& ref =
      m.metallic_roughness_texture.valid() ? m.metallic_roughness_texture : m.occlusion_texture;
  return make_texture(std::move(texels), w, h, address_of(ref), max_side);
}

// A data (raw) or colour (sRGB-encoded) 8-bit texture of an image.
ReferenceTexture image_texture(const FloatImage& img, bool colour, const scene::TextureRef& ref,
                               uint32_t max_side) {
  std::vector<uint8_t> texels(img.rgba.size());
  for (size_t i = 0; i < img.rgba.size(); ++i) {
    const float v = img.rgba[i];
    // Float colour images are linear; 8/16-bit ones carry the sRGB curve already.
    texels[i] = colour && img.is_float && i % 4 != 3 ? unorm8(linear_to_srgb(std::max(0.0f, v)))
                                                     : unorm8(v);
  }
  return make_texture(std::move(texels), img.width, img.height, address_of(ref), max_side);
}

Expected<LitMaterial> lit_material(const scene::Material& m, ImageCache& images,
                                   uint32_t max_side) {
  LitMaterial out;
  VT_ASSIGN_OR_RETURN(const FloatImage* normal, images.get(m.normal_texture));
  if (normal) {
    out.normal = image_texture(*normal, false, m.normal_texture, max_side);
    out.has_normal_map = true;
    out.two_channel_normal = normal->channels < 3;
    out.normal_scale = m.normal_scale;
  } else {
    out.normal = constant_texture(128, 128, 255);
  }
  VT_ASSIGN_OR_RETURN(const FloatImage* occ, images.get(m.occlusion_texture));
  VT_ASSIGN_OR_RETURN(const FloatImage* mr, images.get(m.metallic_roughness_texture));
  out.orm = orm_texture(m, occ, mr, max_side);
  VT_ASSIGN_OR_RETURN(const FloatImage* emissive, images.get(m.emissive_texture));
  out.emissive = emissive ? image_texture(*emissive, true, m.emissive_texture, max_side)
                          : constant_texture(255, 255, 255);
  for (int c = 0; c < 3; ++c) out.emissive_scale[c] = m.emissive_factor[c] * m.emissive_strength;
  return out;
}

Vec3d to_d(const std::array<double, 3>& a) {
  return {a[0], a[1], a[2]};
}

// The UV set the lit reference reads for `m` when it has no base colour texture: the set of its
// normal, metallic-roughness, occlusion or emissive texture; -1 when it has none.
int lit_uv_set(const scene::Material& m) {
  for (const scene::TextureRef* t : {&m.normal_texture, &m.metallic_roughness_texture,
                                     &m.occlusion_texture, &m.emissive_texture}) {
    if (t->valid()) return t->texcoord;
  }
  return -1;
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
      if (cache_vk_format(upload_formats[i]) == VK_FORMAT_UNDEFINED) {
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

Expected<std::vector<LitMaterial>> lit_materials(const scene::Scene& s, uint32_t max_side) {
  ImageCache images(s);
  std::vector<LitMaterial> out;
  for (size_t mi = 0; mi <= s.materials.size(); ++mi) {
    const scene::Material m = mi < s.materials.size() ? s.materials[mi] : scene::Material{};
    auto lm = lit_material(m, images, max_side);
    if (!lm.ok()) {
      return lm.status().with_context(
          s.source_path + ": " +
          (m.name.empty() ? "material " + std::to_string(mi) : "material '" + m.name + "'"));
    }
    out.push_back(std::move(*lm));
  }
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
    const float flip = dot(ax, cross(ay, az)) < 0 ? -1.0f : 1.0f;
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
      const int uv_set = reference && !m.base_color_texture.valid() ? lit_uv_set(m) : -1;
      const bool take_uv = uv_set >= 0 && size_t(uv_set) < p.uvs.size() &&
                           p.uvs[uv_set].size() == p.positions.size();
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
        if (take_uv) out.u = p.uvs[uv_set][v][0], out.v = p.uvs[uv_set][v][1];
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
  return out;
}

nlohmann::json to_json(const LitViewReport& lit) {
  const ViewMetrics& m = lit.metrics;
  return {{"psnr_rgb", m.psnr_rgb},
          {"worst_tile_psnr", m.worst_tile_psnr},
          {"ssim", m.ssim},
          {"max_abs_error", m.max_abs},
          {"pixels_compared", m.pixels},
          {"reference_ms", lit.reference_ms},
          {"virtual_ms", lit.virtual_ms}};
}

}  // namespace vt::render
