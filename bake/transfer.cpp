// Material transfer (see transfer.h). Work is split into bands of atlas rows; each band walks
// the triangles that overlap it in index order, so the result does not depend on threads.
#include "bake/transfer.h"
#include "bake/color.h"
#include "bake/content_key.h"
#include "bake/level_store.h"
#include "bake/lighting.h"
#include "bake/png_check.h"
#include "bake/transfer_cache.h"
#include "bake/transfer_texture.h"
#include "bake/unwrap/atlas_raster.h"
#include "common/parallel.h"
#include "common/vec.h"
#include "scene/image_load.h"
#include "scene/material_rules.h"
#include "scene/tangent_frame.h"

#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <utility>

namespace vt {
namespace {

constexpr uint32_t kBandRows = 16;
constexpr float kOpaque = 1.0f - 0.5f / 255.0f;  // alpha at or above this is stored as opaque

using scene::material_label;
using scene::Vec2;
using scene::Vec3;
using scene::Vec4;
using unwrap::bin_by_rows;
using unwrap::for_each_touched_texel;
using unwrap::RasterTriangle;
using unwrap::TexelRect;

Vec3d v3(const Vec3& a) {
  return {a[0], a[1], a[2]};
}

// What compressed scratch stores take shows only as they are written: from a quarter of the rows
// on, every pass projects the level-0 stores' disk at the ratio so far, plus a third for the
// build's coarser levels (VirtualCity at 32,760², raw: 32.2 bytes a texel of scratch against 24
// of stores), and refuses a bake whose rest does not fit, rather than let a write fail later.
Status check_projected_scratch(const std::shared_ptr<LevelStore>* stores, int count,
                               uint32_t rows_done, uint32_t rows, const std::string& dir) {
  if (rows_done < rows / 4 || rows_done >= rows) return Status::Ok();
  uint64_t written = 0;
  for (int l = 0; l < count; ++l)
    if (stores[l]) written += stores[l]->disk_bytes();
  const uint64_t scratch = uint64_t(double(written) * rows / rows_done * 4 / 3);
  return check_scratch_room(scratch - std::min(scratch, written), dir,
                            "at " + std::to_string(uint64_t(100.0 * rows_done / rows)) +
                                "% of the transfer the level-0 stores take " + gib_text(written) +
                                " GiB compressed, projecting " + gib_text(scratch) +
                                " GiB of scratch with the coarser levels: the rest needs");
}

// Runs `body(band)` for every band on `threads` threads; the calling thread reports progress.
template <class Body>
void for_each_band(uint32_t bands, int threads, const std::function<void(double)>& progress,
                   Body&& body) {
  std::function<void(size_t)> on_done;
  if (progress) on_done = [&](size_t d) { progress(bands ? double(d) / bands : 1.0); };
  parallel_for(
      bands, threads, [&](size_t b) { body(uint32_t(b)); }, on_done);
}

// The transfer's texture loading (Transfer::setup_images) on a thread of its own: wait() joins
// it and gives its status (the first call; later ones give Ok). The destructor joins a loading
// still running, so an early error return never leaves it behind.
class ImageLoading {
 public:
  ImageLoading() = default;
  ImageLoading(const ImageLoading&) = delete;
  ImageLoading& operator=(const ImageLoading&) = delete;
  ~ImageLoading() {
    if (thread_.joinable()) thread_.join();
  }
  void start(std::function<Status()> load) {
    thread_ = std::thread([this, load = std::move(load)] {
      const auto t0 = std::chrono::steady_clock::now();
      try {
        status_ = load();
      } catch (const std::bad_alloc&) {
        status_ = Error(ErrorCode::kResourceLimit, "transfer: out of memory loading the textures");
      } catch (const std::exception& e) {
        status_ =
            Error(ErrorCode::kInternal, std::string("transfer: loading the textures: ") + e.what());
      }
      seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    });
  }
  Status wait() {
    if (!thread_.joinable()) return Status::Ok();
    const auto t0 = std::chrono::steady_clock::now();
    thread_.join();
    waited_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return std::exchange(status_, Status::Ok());
  }
  double seconds() const { return seconds_; }  // the loading's own time (once waited for)
  double waited() const { return waited_; }    // what wait() blocked for

 private:
  std::thread thread_;
  Status status_;
  double seconds_ = 0, waited_ = 0;
};

// Per-texel state of the rasteriser inside one band.
struct BandRaster {
  uint32_t width = 0, y0 = 0, y1 = 0;
  std::vector<int32_t> best_tri;   // closest touching triangle
  std::vector<double> best_dist;   // its squared distance from the texel centre
  std::vector<int32_t> chart;      // first chart touching the texel
  std::vector<uint8_t> contested;  // touched by a second chart
  std::vector<uint16_t> claimed;   // sub-samples already inside some triangle
  std::vector<uint8_t> inside;     // count of sub-samples inside
  void reset(uint32_t w, uint32_t a, uint32_t b) {
    width = w, y0 = a, y1 = b;
    size_t n = size_t(w) * (b - a);
    best_tri.assign(n, -1);
    best_dist.assign(n, std::numeric_limits<double>::infinity());
    chart.assign(n, -1);
    contested.assign(n, 0);
    claimed.assign(n, 0);
    inside.assign(n, 0);
  }
};

// Rasterises `tri` (index t, chart `chart`) into the band. on_sample(texel index in band,
// lambda, sub-sample index) is called for each sub-sample inside the triangle. Returns sub-samples
// claimed twice.
template <class OnSample>
uint64_t raster_triangle(const RasterTriangle& tri, int32_t t, int32_t chart, BandRaster& band,
                         const std::vector<std::array<double, 2>>& pattern, uint32_t height,
                         OnSample&& on_sample) {
  uint64_t twice = 0;
  const TexelRect clip = {0, band.y0, int64_t(band.width) - 1,
                          std::min<int64_t>(band.y1, height) - 1};
  for_each_touched_texel(tri, 0.0, clip, [&](int64_t x, int64_t y) {
    size_t i = size_t(y - band.y0) * band.width + size_t(x);
    if (band.chart[i] < 0) {
      band.chart[i] = chart;
    } else if (band.chart[i] != chart) {
      band.contested[i] = 1;
    }
    bool any = false;
    for (size_t s = 0; s < pattern.size(); ++s) {
      double lambda[3];
      if (!tri.contains(x + pattern[s][0], y + pattern[s][1], lambda)) continue;
      if (band.claimed[i] & (1u << s)) ++twice;
      band.claimed[i] |= uint16_t(1u << s);
      band.inside[i]++;
      any = true;
      on_sample(i, lambda, uint32_t(s));
    }
    double d = any ? 0.0 : tri.distance2_to(x + 0.5, y + 0.5);
    if (d < band.best_dist[i]) band.best_dist[i] = d, band.best_tri[i] = t;
  });
  return twice;
}

// ---- Materials -------------------------------------------------------------------------------

struct ImageSlot {
  std::unique_ptr<TransferTexture> texture;  // null: the image could not be read
  // A colour image that a data slot reads too (an occlusion map that is the base colour's
  // image): its levels averaged as stored, not in linear light. Null: `texture` serves all.
  std::unique_ptr<TransferTexture> data_texture;
  int channels = 0;
  // Colour use (base colour, emissive): from the image's colour space to the working space and
  // back (for the MIP levels); null = none (already linear). Data uses (normal, ORM) never
  // convert. A filtered sample is converted, as the validator's reference samples.
  std::shared_ptr<const ColorConverter> to_working, from_working;
  std::string name;
  std::string tried;  // the file opened (for an embedded image, its scratch copy)
  std::string error;  // why it could not be read
  // Readable, but its levels are not loaded: only bands read from the band cache use it.
  bool deferred = false;
};

constexpr TextureSlot kTextureSlots[] = {
    {"baseColorTexture", &scene::Material::base_color_texture},
    {"metallicRoughnessTexture", &scene::Material::metallic_roughness_texture},
    {"normalTexture", &scene::Material::normal_texture},
    {"occlusionTexture", &scene::Material::occlusion_texture},
    {"emissiveTexture", &scene::Material::emissive_texture},
};
// Indices into kTextureSlots.
enum TexSlot { kBaseColorTex, kMetalRoughTex, kNormalTex, kOcclusionTex, kEmissiveTex, kTexSlots };
// The order Transfer::evaluate samples the slots in.
constexpr TexSlot kEvalOrder[kTexSlots] = {kBaseColorTex, kEmissiveTex, kOcclusionTex,
                                           kMetalRoughTex, kNormalTex};

// One primitive as the transfer sees it.
struct PrimInfo {
  const scene::Primitive* prim = nullptr;
  const scene::Material* mat = nullptr;
  int atlas_set = 0;
  std::vector<Vec3> normals;             // given or area-weighted from faces
  std::vector<Vec4> tangents;            // for the normal map's UV set: given or computed
  scene::Mat4 world = scene::kIdentity;  // its mesh's (first) instance: where the lights see it
};

// Per-triangle quantities for material evaluation.
struct TriEval {
  const PrimInfo* p = nullptr;
  uint32_t v[3];                           // vertex indices in the raster triangle's order
  std::vector<std::array<double, 4>> duv;  // per UV set: ds/dx, dt/dx, ds/dy, dt/dy per texel
  Vec3d dpdx, dpdy;                        // object-space position per atlas texel
  Vec3d face_normal;
  // Lighting: the triangle in world space (its own winding) and a texel's world size there.
  Vec3d world_normal;
  double footprint = 0;
  // Per texture slot of the material (TexSlot): the texture (null: none or missing), its
  // transformed UVs at the vertices (the transform is affine, so interpolating them equals
  // transforming each sample), sampler and footprint, constant over the triangle.
  struct Lookup {
    const TransferTexture* texture = nullptr;
    double s[3], t[3];
    TextureLookup q;
    TextureFootprint footprint;
    // A slot sampled before this one (kEvalOrder) whose sample is this one's bit for bit (the
    // same texels at the same coordinates, sampler and footprint: VirtualCity's occlusion reads
    // its base colour image), or -1.
    int same_as = -1;
  };
  Lookup tex[kTexSlots];
};

// The layers transfer fills. Accumulators, samples and want_ are indexed by a layer's slot,
// never by LayerSemantic's value; the result lists layers in slot order, which must be
// LayerSemantic order (transfer.h promises it; checked below).
enum Slot { kAlbedoSlot, kNormalSlot, kOrmSlot, kEmissiveSlot, kLightingSlot, kSlots };
struct SlotInfo {
  LayerSemantic semantic;
  uint32_t channels;  // accumulated (albedo keeps alpha until the texels show it is not needed)
};
constexpr SlotInfo kSlotInfo[kSlots] = {{LayerSemantic::kAlbedo, 4},
                                        {LayerSemantic::kNormal, 3},
                                        {LayerSemantic::kOrm, 3},
                                        {LayerSemantic::kEmissive, 3},
                                        {LayerSemantic::kLighting, 3}};  // 4 with AO; or
                                                                         // kLitAlbedo, 4
constexpr bool slots_in_semantic_order() {
  for (int l = 1; l < kSlots; ++l)
    if (!(kSlotInfo[l - 1].semantic < kSlotInfo[l].semantic)) return false;
  return true;
}
static_assert(slots_in_semantic_order(), "TransferResult::layers must be in LayerSemantic order");

struct Sample {
  float albedo[4];
  float normal[3];
  bool below_horizon;  // the normal map pointed below the surface: `normal` is at the horizon
  float orm[3];
  float emissive[3];
  float lighting[4];
  const float* of(int slot) const {
    switch (slot) {
      case kAlbedoSlot:
        return albedo;
      case kNormalSlot:
        return normal;
      case kOrmSlot:
        return orm;
      case kEmissiveSlot:
        return emissive;
      default:
        return lighting;
    }
  }
};

// Object space to world space: a point, and a direction through the linear part (a normal by
// the inverse transpose unless `as_normal` is false), unit length unless it collapses.
Vec3d world_point(const scene::Mat4& m, const Vec3d& p) {
  return {m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12],
          m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13],
          m[2] * p.x + m[6] * p.y + m[10] * p.z + m[14]};
}
Vec3d world_vector(const scene::Mat4& m, const Vec3d& v, bool as_normal = true) {
  if (!as_normal)
    return {m[0] * v.x + m[4] * v.y + m[8] * v.z, m[1] * v.x + m[5] * v.y + m[9] * v.z,
            m[2] * v.x + m[6] * v.y + m[10] * v.z};
  const auto d = scene::transform_direction(m, {float(v.x), float(v.y), float(v.z)});
  return {d[0], d[1], d[2]};
}

Vec3d lerp3(const std::vector<Vec3>& a, const uint32_t v[3], const double l[3]) {
  return v3(a[v[0]]) * l[0] + v3(a[v[1]]) * l[1] + v3(a[v[2]]) * l[2];
}

bool material_has_orm(const scene::Material& m) {
  return m.metallic_roughness_texture.valid() || m.occlusion_texture.valid() ||
         m.metallic_factor != 1.0f || m.roughness_factor != 1.0f;
}
bool material_has_emissive(const scene::Material& m) {
  return m.emissive_strength > 0 && (m.emissive_texture.valid() || m.emissive_factor[0] > 0 ||
                                     m.emissive_factor[1] > 0 || m.emissive_factor[2] > 0);
}

// The materials that primitives with triangles use, in scene order.
std::vector<const scene::Material*> materials_in_use(const scene::Scene& scene) {
  std::vector<bool> used(scene.materials.size(), false);
  for (const auto& mesh : scene.meshes)
    for (const auto& p : mesh.primitives)
      if (!p.indices.empty() && p.material >= 0 && size_t(p.material) < used.size())
        used[p.material] = true;
  std::vector<const scene::Material*> out;
  for (size_t m = 0; m < used.size(); ++m)
    if (used[m]) out.push_back(&scene.materials[m]);
  return out;
}

// Chart ids per triangle of one primitive: triangles connected through a shared vertex or
// through vertices at bit-identical atlas UVs (a chart's vertices split for normals or source
// UVs), numbered from `base`. Two charts never share an atlas position (the gutter).
std::vector<int32_t> connected_charts(const scene::Primitive& p, const std::vector<Vec2>& atlas,
                                      int64_t base) {
  std::vector<uint32_t> parent(p.positions.size());
  for (uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto find = [&](uint32_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  auto join = [&](uint32_t a, uint32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  };
  for (size_t f = 0; f + 2 < p.indices.size(); f += 3) {
    join(p.indices[f], p.indices[f + 1]);
    join(p.indices[f], p.indices[f + 2]);
  }
  std::unordered_map<uint64_t, uint32_t> at;  // atlas UV bits -> first vertex there
  for (uint32_t i = 0; i < atlas.size(); ++i) {
    uint32_t u, v;
    std::memcpy(&u, &atlas[i][0], 4);
    std::memcpy(&v, &atlas[i][1], 4);
    auto [it, inserted] = at.try_emplace((uint64_t(u) << 32) | v, i);
    if (!inserted) join(it->second, i);
  }
  std::vector<int32_t> chart(p.indices.size() / 3);
  for (size_t f = 0; f < chart.size(); ++f) chart[f] = int32_t(base + find(p.indices[3 * f]));
  return chart;
}

// What the layers' texels show as bands finish: values above 1, HDR, whether alpha is needed.
struct LayerFacts {
  uint64_t texels_above_one = 0;
  float max_value = 0;
  bool hdr = false;        // colour or data channel above 1 (albedo: RGB only)
  bool alpha_hdr = false;  // albedo's alpha above 1
  bool alpha = false;      // albedo: some covered texel is not opaque
};

// Texel and sample counts over the passes.
struct RowCounts {
  uint64_t sampled = 0, edge_only = 0, contested = 0, samples = 0, below_horizon = 0;
};

struct BandBytes;

class Transfer {
 public:
  Transfer(const scene::Scene& scene, const TransferOptions& opt) : scene_(scene), opt_(opt) {}
  ~Transfer() {
    for (const auto& f : temp_files_) {
      std::error_code ec;
      std::filesystem::remove(f, ec);
    }
  }

  Expected<TransferResult> run();

 private:
  Status setup_images(const std::vector<bool>* wanted = nullptr);
  Status check_missing_textures();
  Status set_colour_space(ImageSlot& slot, const std::string& path,
                          const OIIO::ImageSpec& spec) const;
  Status setup_prims();
  Status setup_raster();
  bool sample_texture(TexSlot slot, const TriEval& te, const double l[3], float out[4]) const;
  void evaluate(const TriEval& te, const double l[3], uint64_t seed, Sample& s) const;
  void make_eval(uint32_t t, TriEval& te) const;
  Status setup_cache();
  std::vector<bool> images_for_uncached_bands() const;
  void transfer_band(uint32_t b, float* const (&acc)[kSlots], uint8_t* coverage,
                     RowCounts& counts) const;
  void pack_band(const BandBytes& f, float* const (&acc)[kSlots], const uint8_t* coverage,
                 const RowCounts& counts, const LayerFacts (&facts)[kSlots], uint8_t* out) const;
  void unpack_band(const BandBytes& f, const uint8_t* in, float* const (&acc)[kSlots],
                   uint8_t* coverage, RowCounts& counts, LayerFacts (&facts)[kSlots]) const;
  Status transfer_rows(uint32_t r0, uint32_t r1, float* const (&acc)[kSlots],
                       std::vector<uint8_t>& coverage, RowCounts& counts,
                       LayerFacts (&facts)[kSlots], const std::function<void(double)>& progress,
                       ImageLoading& images);
  void finish_rows(float* const (&acc)[kSlots], const uint8_t* coverage, size_t n,
                   LayerFacts (&facts)[kSlots]) const;
  Expected<std::vector<TransferLayer>> make_layers(std::shared_ptr<LevelStore> (&stores)[kSlots],
                                                   const LayerFacts (&facts)[kSlots]) const;
  uint32_t rows_per_pass() const;

  const scene::Scene& scene_;
  const TransferOptions& opt_;
  std::vector<ImageSlot> images_;
  std::vector<MissingTexture> missing_;
  std::vector<std::string> temp_files_;
  std::vector<PrimInfo> prims_;
  std::vector<RasterTriangle> tris_;
  std::vector<std::vector<uint32_t>> bins_;             // triangles per band of kBandRows rows
  std::vector<int32_t> chart_;                          // per triangle
  std::vector<std::pair<uint32_t, uint32_t>> tri_src_;  // (prim info, face)
  scene::Material default_material_;
  bool want_[kSlots] = {};          // by slot
  uint32_t channels_[kSlots] = {};  // accumulated channels by slot (kSlotInfo; lighting: + AO)
  std::unique_ptr<LightingBaker> lighting_;  // only when the scene has lights
  // The lighting slot holds lit albedo (LightingLayer::kCombined): RGB + alpha, as albedo.
  bool combined_ = false;
  // Every material in use is OPAQUE: alpha is 1 wherever a sample lands, so albedo (and lit
  // albedo) are accumulated as RGB from the start (the layers make_layers would leave, without
  // a quarter of their store memory to fault in and compact).
  bool opaque_ = false;
  bool has_alpha(int slot) const {
    return !opaque_ && (slot == kAlbedoSlot || (slot == kLightingSlot && combined_));
  }
  double sub_scale_ = 1.0;
  uint64_t texture_bytes_ = 0;  // the loaded textures' texels
  // The band cache (TransferOptions::cache_in, cache_out) and every band's key.
  std::unique_ptr<TransferCacheReader> cache_in_;
  std::unique_ptr<TransferCacheWriter> cache_out_;
  std::vector<uint64_t> band_keys_;
  uint64_t bands_cached_ = 0;
};

// Base colour and emissive textures are colour; the other slots are data.
bool used_as_colour(const scene::Scene& scene, size_t image) {
  return std::any_of(scene.materials.begin(), scene.materials.end(), [&](const auto& m) {
    return (m.base_color_texture.valid() && size_t(m.base_color_texture.image) == image) ||
           (m.emissive_texture.valid() && size_t(m.emissive_texture.image) == image);
  });
}

bool used_as_data(const scene::Scene& scene, size_t image) {
  return std::any_of(scene.materials.begin(), scene.materials.end(), [&](const auto& m) {
    for (const scene::TextureRef* r :
         {&m.metallic_roughness_texture, &m.normal_texture, &m.occlusion_texture})
      if (r->valid() && size_t(r->image) == image) return true;
    return false;
  });
}

// The colour space: the config's file rules for `path` (a file, not an embedded image), else
// the image's metadata, else sRGB (8/16-bit) or the working space (float).
Status Transfer::set_colour_space(ImageSlot& slot, const std::string& path,
                                  const OIIO::ImageSpec& spec) const {
  const ColorConfig& colours = opt_.color_config ? *opt_.color_config : *ColorConfig::builtin();
  const bool is_float = spec.format.basetype == OIIO::TypeDesc::FLOAT ||
                        spec.format.basetype == OIIO::TypeDesc::HALF ||
                        spec.format.basetype == OIIO::TypeDesc::DOUBLE;
  // A scene's 8/16-bit colour texture is sRGB by its slot whatever its file says (a PNG gAMA, a
  // TGA gamma): glTF requires it, other tools read them so, and so does the validator's
  // reference. Float files keep their metadata (their space), and the config's file rules win.
  const std::string space = colours.texture_space(
      path, is_float ? std::string(spec.get_string_attribute("oiio:ColorSpace")) : "", is_float);
  auto converter = colours.converter(space, colours.working_space());
  if (!converter.ok()) return converter.status().with_context(slot.name);
  if ((*converter)->is_identity()) return Status::Ok();
  auto back = colours.converter(colours.working_space(), space);
  if (!back.ok()) return back.status().with_context(slot.name);
  slot.to_working = std::move(converter).value();
  slot.from_working = std::move(back).value();
  return Status::Ok();
}

// Opens every image a material in use reads and loads the levels of those `wanted` names (null:
// all); the others are deferred. Run again, it loads the deferred ones.
Status Transfer::setup_images(const std::vector<bool>* wanted) {
  const bool first = images_.empty();
  // Before OpenImageIO opens them: libpng would print its own line for a damaged file.
  VT_RETURN_IF_ERROR(check_scene_textures(scene_));
  std::vector<bool> used(scene_.images.size(), false);
  for (const scene::Material* m : materials_in_use(scene_)) {
    for (const TextureSlot& ts : kTextureSlots) {
      const scene::TextureRef& r = m->*ts.ref;
      if (!r.valid()) continue;
      if (size_t(r.image) >= scene_.images.size()) {
        return Error(ErrorCode::kCorrupt, material_label(scene_, *m) + " " + ts.name +
                                              ": names image " + std::to_string(r.image) +
                                              ", which does not exist");
      }
      used[r.image] = true;
    }
  }
  images_.resize(scene_.images.size());
  namespace fs = std::filesystem;
  fs::path scratch =
      opt_.scratch_dir.empty() ? fs::temp_directory_path() : fs::path(opt_.scratch_dir);
  for (size_t i = 0; i < scene_.images.size(); ++i) {
    if (!used[i] || (!first && !images_[i].deferred)) continue;
    const scene::Image& img = scene_.images[i];
    ImageSlot& slot = images_[i];
    slot.deferred = false;
    std::string path = img.embedded() ? slot.tried : img.path;
    slot.name =
        img.embedded() ? "embedded image " + std::to_string(i) + " '" + img.name + "'" : img.path;
    if (img.has_no_data()) {
      slot.error = "the scene holds no data for it";
      continue;  // reported per material slot by check_missing_textures
    }
    if (img.embedded() && path.empty()) {
      // OpenImageIO reads by file name: a private copy is the robust way.
      const std::string ext = img.embedded_extension();
      // Unique per process and per call, so concurrent transfers never share a copy.
      static std::atomic<uint64_t> calls{0};
      path = (scratch / ("vtbake-transfer-" + std::to_string(getpid()) + "-" +
                         std::to_string(calls.fetch_add(1)) + "-" + std::to_string(i) + ext))
                 .string();
      std::ofstream f(path, std::ios::binary);
      f.write(reinterpret_cast<const char*>(img.bytes.data()), std::streamsize(img.bytes.size()));
      f.close();
      if (!f) return Error(ErrorCode::kIo, path + ": cannot write a copy of " + slot.name);
      temp_files_.push_back(path);
    }
    slot.tried = path;
    bool untiled = false;
    int channels = 0;  // decided on the file itself: made MIP levels would carry a padding alpha
    {
      auto in = scene::open_image_input(path, slot.error);
      if (!in) continue;  // reported per material slot by check_missing_textures
      const OIIO::ImageSpec& spec = in->spec();
      untiled = spec.tile_width == 0;
      // Unreadable: 0, and the texture's load below reports it.
      const Expected<int> data = scene::data_channels(*in);
      channels = data.ok() ? *data : 0;
      if (used_as_colour(scene_, i)) {
        VT_RETURN_IF_ERROR(set_colour_space(slot, img.embedded() ? "" : img.path, spec));
      }
    }
    if (wanted && !(*wanted)[i]) {
      slot.deferred = true;
      continue;
    }
    // Optionally, untiled sources get MIP levels made with another filter (as maketx does),
    // read back as the texture's levels; should that fail, box-filtered levels are made.
    std::string source = path;
    if (!opt_.mip_filter.empty() && untiled) {
      static std::atomic<uint64_t> made{0};
      std::string tx = (scratch / ("vtbake-transfer-" + std::to_string(getpid()) + "-mip" +
                                   std::to_string(made.fetch_add(1)) + ".tx"))
                           .string();
      OIIO::ImageSpec config;
      config.attribute("maketx:filtername", opt_.mip_filter);
      config.tile_width = config.tile_height = 64;
      if (OIIO::ImageBufAlgo::make_texture(OIIO::ImageBufAlgo::MakeTxTexture, path, tx, config)) {
        temp_files_.push_back(tx);
        source = tx;
      } else {
        (void)OIIO::geterror();
        std::error_code ec;
        std::filesystem::remove(tx, ec);
      }
    }
    auto texture =
        TransferTexture::load(source, slot.to_working.get(), slot.from_working.get(), channels);
    if (!texture.ok()) {
      if (texture.status().code() != ErrorCode::kNotFound)
        return texture.status().with_context(slot.name);
      slot.error = texture.status().message();
      continue;
    }
    slot.channels = texture->channels();
    // Textures past the budget are read from a mapped scratch file (the same samples).
    auto keep = [&](TransferTexture& t) -> Expected<std::unique_ptr<TransferTexture>> {
      if (texture_bytes_ + t.bytes() > opt_.texture_cache)
        VT_RETURN_IF_ERROR(t.move_to_scratch(scratch.string()).with_context(slot.name));
      texture_bytes_ += t.bytes();
      return std::make_unique<TransferTexture>(std::move(t));
    };
    VT_ASSIGN_OR_RETURN(slot.texture, keep(*texture));
    if (slot.to_working && used_as_data(scene_, i)) {
      auto data = TransferTexture::load(source, nullptr, nullptr, channels);
      if (!data.ok()) return data.status().with_context(slot.name);
      VT_ASSIGN_OR_RETURN(slot.data_texture, keep(*data));
    }
  }
  return first ? check_missing_textures() : Status::Ok();
}

Status Transfer::check_missing_textures() {
  for (const scene::Material* m : materials_in_use(scene_)) {
    for (const TextureSlot& ts : kTextureSlots) {
      const scene::TextureRef& r = m->*ts.ref;
      if (!r.valid() || images_[r.image].texture || images_[r.image].deferred) continue;
      const scene::Image& img = scene_.images[r.image];
      MissingTexture miss;
      miss.material = m->name;
      miss.material_index = int(m - scene_.materials.data());
      miss.slot = ts.name;
      miss.image = !img.name.empty()  ? img.name
                   : !img.uri.empty() ? img.uri
                                      : "image " + std::to_string(r.image);
      if (img.embedded() && !img.has_no_data()) miss.image += " (embedded)";
      miss.path = images_[r.image].tried;
      miss.reason = images_[r.image].error;
      if (opt_.missing_textures == MissingTextures::kError) {
        return Error(ErrorCode::kNotFound,
                     miss.message() + " (--missing-textures warn bakes the slot from its factor)");
      }
      missing_.push_back(std::move(miss));
    }
  }
  return Status::Ok();
}

Status Transfer::setup_prims() {
  VT_RETURN_IF_ERROR(check_texcoord_sets(scene_));
  // Lighting sees each mesh where its first instance puts it (an unwrapped scene gives every
  // instance a mesh of its own); a mesh no node shows stays where it is.
  std::vector<const scene::Mat4*> mesh_world(scene_.meshes.size(), nullptr);
  const std::vector<scene::Instance> instances = scene_.instances();
  for (const scene::Instance& inst : instances)
    if (!mesh_world[inst.mesh]) mesh_world[inst.mesh] = &inst.world;
  bool any_normal = false, any_orm = false, any_emissive = false;
  for (size_t m = 0; m < scene_.meshes.size(); ++m) {
    const scene::Mesh& mesh = scene_.meshes[m];
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const scene::Primitive& p = mesh.primitives[pi];
      if (p.indices.empty()) continue;
      std::string where = "mesh '" + mesh.name + "' primitive " + std::to_string(pi);
      if (p.uvs.empty()) return Error(ErrorCode::kInvalidArgument, where + ": no atlas UVs");
      PrimInfo info;
      info.prim = &p;
      info.atlas_set = opt_.atlas_uv_set < 0 ? int(p.uvs.size()) - 1 : opt_.atlas_uv_set;
      if (size_t(info.atlas_set) >= p.uvs.size() ||
          p.uvs[info.atlas_set].size() != p.positions.size()) {
        return Error(ErrorCode::kInvalidArgument,
                     where + ": no atlas UV set " + std::to_string(info.atlas_set));
      }
      if (p.material >= 0 && size_t(p.material) >= scene_.materials.size()) {
        return Error(ErrorCode::kCorrupt,
                     where + ": material " + std::to_string(p.material) + " does not exist");
      }
      info.mat = p.material >= 0 ? &scene_.materials[p.material] : &default_material_;
      if (mesh_world[m]) info.world = *mesh_world[m];
      const scene::Material& mat = *info.mat;
      for (uint32_t idx : p.indices) {
        if (idx >= p.positions.size())
          return Error(ErrorCode::kCorrupt, where + ": index out of range");
      }
      any_normal |= mat.normal_texture.valid();
      any_orm |= material_has_orm(mat);
      any_emissive |= material_has_emissive(mat);
      info.normals = p.normals.size() == p.positions.size() ? p.normals : scene::compute_normals(p);
      if (mat.normal_texture.valid()) {
        info.tangents = p.tangents.size() == p.positions.size()
                            ? p.tangents
                            : scene::compute_tangents(p, info.normals, mat.normal_texture.texcoord);
      }
      prims_.push_back(std::move(info));
    }
  }
  want_[kAlbedoSlot] = true;
  want_[kNormalSlot] = any_normal;
  want_[kOrmSlot] = any_orm;
  want_[kEmissiveSlot] = any_emissive;
  want_[kLightingSlot] = scene_has_lights(scene_);
  opaque_ = std::all_of(prims_.begin(), prims_.end(), [](const PrimInfo& p) {
    return p.mat->alpha_mode == scene::AlphaMode::kOpaque;
  });
  for (int l = 0; l < kSlots; ++l) channels_[l] = kSlotInfo[l].channels;
  if (opaque_) channels_[kAlbedoSlot] = 3;
  if (want_[kLightingSlot]) {
    VT_ASSIGN_OR_RETURN(lighting_, LightingBaker::create(scene_, opt_.lighting, opt_.threads));
    combined_ = opt_.lighting.layer == LightingLayer::kCombined;
    channels_[kLightingSlot] = combined_ ? (opaque_ ? 3 : 4) : lighting_->channels();
  }
  return setup_raster();
}

// Atlas triangles and their charts: the unwrapper's when given, else connected_charts.
Status Transfer::setup_raster() {
  const double W = opt_.width, H = opt_.height;
  int64_t chart_base = 0;  // fallback chart ids: vertex roots, offset per primitive
  for (uint32_t pi = 0; pi < prims_.size(); ++pi) {
    const scene::Primitive& p = *prims_[pi].prim;
    const auto& uv = p.uvs[prims_[pi].atlas_set];
    if (opt_.charts.empty()) {
      auto charts = connected_charts(p, uv, chart_base);
      chart_.insert(chart_.end(), charts.begin(), charts.end());
    }
    for (size_t f = 0; f + 2 < p.indices.size(); f += 3) {
      std::array<double, 6> q;
      for (int k = 0; k < 3; ++k) {
        const Vec2& a = uv[p.indices[f + k]];
        q[2 * k] = double(a[0]) * W, q[2 * k + 1] = double(a[1]) * H;
      }
      tris_.emplace_back(q);
      tri_src_.push_back({pi, uint32_t(f / 3)});
    }
    chart_base += int64_t(p.positions.size());
  }
  if (!opt_.charts.empty()) {
    if (opt_.charts.size() != tris_.size()) {
      return Error(ErrorCode::kInvalidArgument, "transfer: " + std::to_string(opt_.charts.size()) +
                                                    " chart ids for " +
                                                    std::to_string(tris_.size()) + " triangles");
    }
    chart_ = opt_.charts;
  }
  return Status::Ok();
}

void Transfer::make_eval(uint32_t t, TriEval& te) const {
  const RasterTriangle& r = tris_[t];
  const PrimInfo& pi = prims_[tri_src_[t].first];
  const scene::Primitive& p = *pi.prim;
  size_t f = tri_src_[t].second;
  te.p = &pi;
  for (int k = 0; k < 3; ++k) te.v[k] = p.indices[3 * f + r.order[k]];
  // Inverse of the atlas edge matrix: maps per-vertex differences to d/dx, d/dy.
  double ex1 = r.x[1] - r.x[0], ey1 = r.y[1] - r.y[0], ex2 = r.x[2] - r.x[0], ey2 = r.y[2] - r.y[0];
  double det = ex1 * ey2 - ex2 * ey1;
  double inv = det != 0 ? 1.0 / det : 0.0;
  auto grad = [&](double f0, double f1, double f2, double& dx, double& dy) {
    double d1 = f1 - f0, d2 = f2 - f0;
    dx = (d1 * ey2 - d2 * ey1) * inv;
    dy = (d2 * ex1 - d1 * ex2) * inv;
  };
  te.duv.resize(p.uvs.size());
  for (size_t s = 0; s < p.uvs.size(); ++s) {
    const auto& uv = p.uvs[s];
    auto& d = te.duv[s];
    grad(uv[te.v[0]][0], uv[te.v[1]][0], uv[te.v[2]][0], d[0], d[2]);
    grad(uv[te.v[0]][1], uv[te.v[1]][1], uv[te.v[2]][1], d[1], d[3]);
    for (double& c : d) c = std::isfinite(c) ? c * sub_scale_ : 0.0;
  }
  Vec3d P0 = v3(p.positions[te.v[0]]), P1 = v3(p.positions[te.v[1]]), P2 = v3(p.positions[te.v[2]]);
  grad(P0.x, P1.x, P2.x, te.dpdx.x, te.dpdy.x);
  grad(P0.y, P1.y, P2.y, te.dpdx.y, te.dpdy.y);
  grad(P0.z, P1.z, P2.z, te.dpdx.z, te.dpdy.z);
  te.face_normal = normalized(cross(P1 - P0, P2 - P0), {0, 0, 1});
  if (want_[kLightingSlot]) {
    const scene::Mat4& w = pi.world;
    auto point = [&](uint32_t k) { return world_point(w, v3(p.positions[p.indices[3 * f + k]])); };
    const Vec3d A = point(0), B = point(1), C = point(2);
    // The moved triangle's edges turn with the winding a mirror reverses: the face normal is
    // the one on the side the surface faces (as world_vector carries the shading normal).
    const double facing = scene::mirrors(w) ? -1.0 : 1.0;
    te.world_normal = normalized(cross(B - A, C - A) * facing, world_vector(w, te.face_normal));
    te.footprint =
        std::max(length(world_vector(w, te.dpdx, false)), length(world_vector(w, te.dpdy, false)));
  }
  for (int k = 0; k < kTexSlots; ++k) {
    const scene::TextureRef& ref = (*pi.mat).*kTextureSlots[k].ref;
    TriEval::Lookup& lk = te.tex[k];
    lk.same_as = -1;
    const ImageSlot* image = ref.valid() ? &images_[ref.image] : nullptr;
    const bool colour = k == kBaseColorTex || k == kEmissiveTex;
    lk.texture = !image                           ? nullptr
                 : !colour && image->data_texture ? image->data_texture.get()
                                                  : image->texture.get();
    if (!lk.texture) continue;  // none, or missing (MissingTextures::kWarn): factor alone
    const auto& uv = p.uvs[ref.texcoord];
    for (int j = 0; j < 3; ++j) {
      const auto st = scene::texture_uv(ref, uv[te.v[j]][0], uv[te.v[j]][1]);
      lk.s[j] = st[0], lk.t[j] = st[1];
    }
    lk.q.wrap_s = ref.wrap_s, lk.q.wrap_t = ref.wrap_t;
    lk.q.nearest = ref.mag_filter == scene::FilterMode::kNearest;
    lk.q.d = scene::texture_uv_derivatives(ref, te.duv[ref.texcoord]);
    lk.footprint = lk.texture->footprint(lk.q.d);
  }
  // Slots whose samples equal an earlier slot's: one texture, or a colour image's two pyramids
  // (ImageSlot::data_texture) while both read level 0 alone (the levels made differ, the file's
  // level 0 is the same floats); the same coordinates, sampler and footprint.
  for (int i = 1; i < kTexSlots; ++i) {
    TriEval::Lookup& lk = te.tex[kEvalOrder[i]];
    if (!lk.texture) continue;
    const int image = ((*pi.mat).*kTextureSlots[kEvalOrder[i]].ref).image;
    for (int j = 0; j < i && lk.same_as < 0; ++j) {
      const TriEval::Lookup& o = te.tex[kEvalOrder[j]];
      if (!o.texture) continue;
      const TextureFootprint &a = lk.footprint, &b = o.footprint;
      const bool level0 = a.level == 0 && a.blend == 0 && b.level == 0 && b.blend == 0;
      const bool texels = lk.texture == o.texture ||
                          (level0 && image == ((*pi.mat).*kTextureSlots[kEvalOrder[j]].ref).image);
      if (texels && std::equal(lk.s, lk.s + 3, o.s) && std::equal(lk.t, lk.t + 3, o.t) &&
          lk.q.wrap_s == o.q.wrap_s && lk.q.wrap_t == o.q.wrap_t && lk.q.nearest == o.q.nearest &&
          a.taps == b.taps && a.level == b.level && a.blend == b.blend && a.step_s == b.step_s &&
          a.step_t == b.step_t)
        lk.same_as = kEvalOrder[j];
    }
  }
}

bool Transfer::sample_texture(TexSlot slot, const TriEval& te, const double l[3],
                              float out[4]) const {
  const TriEval::Lookup& lk = te.tex[slot];
  if (!lk.texture) return false;
  TextureLookup q = lk.q;
  q.s = lk.s[0] * l[0] + lk.s[1] * l[1] + lk.s[2] * l[2];
  q.t = lk.t[0] * l[0] + lk.t[1] * l[1] + lk.t[2] * l[2];
  float r[4] = {0, 0, 0, 1};
  lk.texture->sample(q, lk.footprint, r);
  switch (lk.texture->channels()) {
    case 1:
      out[0] = out[1] = out[2] = r[0], out[3] = 1;
      break;
    case 2:
      out[0] = out[1] = out[2] = r[0], out[3] = r[1];
      break;
    case 3:
      out[0] = r[0], out[1] = r[1], out[2] = r[2], out[3] = 1;
      break;
    default:
      for (int c = 0; c < 4; ++c) out[c] = r[c];
  }
  return true;
}

void Transfer::evaluate(const TriEval& te, const double l[3], uint64_t seed, Sample& s) const {
  const scene::Material& m = *te.p->mat;
  const scene::Primitive& p = *te.p->prim;
  float tex[4];
  // Each slot's sample, kept for the later slots that share it (TriEval::Lookup::same_as).
  float taken[kTexSlots][4];
  unsigned have = 0;
  auto lookup = [&](TexSlot slot, float out[4]) {
    const int same = te.tex[slot].same_as;
    if (same >= 0 && (have >> same & 1)) {
      std::memcpy(out, taken[same], sizeof taken[same]);
    } else {
      if (!sample_texture(slot, te, l, out)) return false;
      std::memcpy(taken[slot], out, sizeof taken[slot]);
      have |= 1u << slot;
    }
    return true;
  };
  auto colour = [&](TexSlot slot, const scene::TextureRef& ref, float* rgb) {
    if (!lookup(slot, tex)) return false;
    for (int c = 0; c < 4; ++c) rgb[c] = tex[c];
    if (const auto& to_working = images_[ref.image].to_working) to_working->apply_rgb(rgb);
    return true;
  };
  // Albedo: factor x texture x vertex colour (glTF).
  Vec4 a = {1, 1, 1, 1}, vertex = {1, 1, 1, 1};
  colour(kBaseColorTex, m.base_color_texture, a.data());
  if (!p.colors.empty()) {
    for (int c = 0; c < 4; ++c) {
      vertex[c] = float(p.colors[te.v[0]][c] * l[0] + p.colors[te.v[1]][c] * l[1] +
                        p.colors[te.v[2]][c] * l[2]);
    }
  }
  const Vec4 albedo = scene::base_color(m, a, vertex);
  for (int c = 0; c < 4; ++c) s.albedo[c] = albedo[c];
  if (want_[kEmissiveSlot]) {
    float e[4] = {1, 1, 1, 1};
    colour(kEmissiveTex, m.emissive_texture, e);
    for (int c = 0; c < 3; ++c) s.emissive[c] = e[c] * m.emissive_factor[c] * m.emissive_strength;
  }
  if (want_[kOrmSlot]) {
    float occ = 1, rough = m.roughness_factor, metal = m.metallic_factor;
    if (lookup(kOcclusionTex, tex)) {
      occ = 1.0f + m.occlusion_strength * (tex[0] - 1.0f);
    }
    if (lookup(kMetalRoughTex, tex)) {
      rough *= tex[1], metal *= tex[2];
    }
    s.orm[0] = occ, s.orm[1] = rough, s.orm[2] = metal;
  }
  if (want_[kNormalSlot] || want_[kLightingSlot]) {
    Vec3d n = normalized(lerp3(te.p->normals, te.v, l), te.face_normal);
    Vec3d world = n;
    if (want_[kNormalSlot] && lookup(kNormalTex, tex)) {
      const auto& tg = te.p->tangents;
      Vec3d t = {tg[te.v[0]][0] * l[0] + tg[te.v[1]][0] * l[1] + tg[te.v[2]][0] * l[2],
                 tg[te.v[0]][1] * l[0] + tg[te.v[1]][1] * l[1] + tg[te.v[2]][1] * l[2],
                 tg[te.v[0]][2] * l[0] + tg[te.v[1]][2] * l[1] + tg[te.v[2]][2] * l[2]};
      t = normalized(
          t - n * dot(n, t),
          normalized(cross(std::abs(n.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0}, n), {1, 0, 0}));
      // Handedness per sample, as a renderer takes the sign of the interpolated w: a face whose
      // corners disagree (a mirror seam through shared vertices) flips part-way, not whole.
      double w =
          tg[te.v[0]][3] * l[0] + tg[te.v[1]][3] * l[1] + tg[te.v[2]][3] * l[2] < 0 ? -1.0 : 1.0;
      Vec3d b = cross(n, t) * w;
      double x = (tex[0] * 2.0 - 1.0) * m.normal_scale, y = (tex[1] * 2.0 - 1.0) * m.normal_scale;
      double z = tex[2] * 2.0 - 1.0;
      if (images_[m.normal_texture.image].channels < 3)
        z = std::sqrt(std::max(0.0, 1.0 - x * x - y * y));
      world = normalized(t * x + b * y + n * z, n);
    }
    // The atlas frame: tangent along +x of the atlas, bitangent up the atlas image (glTF).
    Vec3d ta = normalized(
        te.dpdx - n * dot(n, te.dpdx),
        normalized(cross(std::abs(n.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0}, n), {1, 0, 0}));
    double wa = dot(cross(n, ta), te.dpdy) > 0 ? -1.0 : 1.0;
    Vec3d ba = cross(n, ta) * wa;
    // The layer keeps x and y (BC5) and its reader rebuilds z >= 0, so a normal map's texel
    // pointing below the surface (blue under half: hand-painted maps have them at steep edges)
    // is stored at the horizon, the nearest direction the layer holds, not mirrored above it
    // (Red Eclipse's zapper: lit check 27 -> 35 dB). Counted, and the bake warns.
    double x = dot(world, ta), y = dot(world, ba), z = dot(world, n);
    s.below_horizon = z < 0;
    if (s.below_horizon) {
      const double h = std::sqrt(x * x + y * y);
      x = h > 0 ? x / h : 0, y = h > 0 ? y / h : 0, z = h > 0 ? 0 : 1;
    }
    s.normal[0] = float(x);
    s.normal[1] = float(y);
    s.normal[2] = float(z);
    if (want_[kLightingSlot]) {
      LightingSample ls;
      ls.position = world_point(te.p->world, lerp3(te.p->prim->positions, te.v, l));
      ls.geometric_normal = te.world_normal;
      ls.shading_normal = normalized(world_vector(te.p->world, world), te.world_normal);
      ls.footprint = te.footprint;
      ls.seed = seed;
      lighting_->evaluate(ls, s.lighting);
      if (combined_) {
        for (int c = 0; c < 3; ++c) s.lighting[c] = lit_albedo(albedo[c], s.lighting[c]);
        s.lighting[3] = albedo[3];
      }
    }
  }
}

// One band's accumulators as final layer texels: values above 1 counted, normals renormalised.
void Transfer::finish_rows(float* const (&acc)[kSlots], const uint8_t* coverage, size_t n,
                           LayerFacts (&facts)[kSlots]) const {
  for (int l = 0; l < kSlots; ++l) {
    if (!want_[l]) continue;
    LayerFacts& f = facts[l];
    const uint32_t channels = channels_[l];
    if (l == kNormalSlot) {
      for (size_t i = 0; i < n; ++i) {
        float* v = &acc[l][3 * i];
        if (!coverage[i]) continue;
        Vec3d u = normalized(Vec3d{v[0], v[1], v[2]}, {0, 0, 1});
        v[0] = float(u.x), v[1] = float(u.y), v[2] = float(u.z);
      }
      continue;
    }
    // Channels 0-2 of albedo (and lit albedo) are colour, 3 is alpha (counted before alpha is
    // dropped); those of lighting are irradiance, 3 is AO.
    const uint32_t counted = l == kAlbedoSlot || l == kLightingSlot ? 3 : channels;
    const bool alpha = has_alpha(l);
    for (size_t i = 0; i < n; ++i) {
      const float* v = &acc[l][i * channels];
      for (uint32_t c = 0; c < counted; ++c) f.hdr |= v[c] > 1.0f;
      if (alpha) f.alpha_hdr |= v[3] > 1.0f;
      if (!coverage[i]) continue;
      if (alpha) f.alpha |= v[3] < kOpaque;
      const float top = *std::max_element(v, v + counted);
      if (top > 1.0f) ++f.texels_above_one, f.max_value = std::max(f.max_value, top);
    }
  }
}

// The layers called for, from their stores: alpha only if some covered texel is not opaque
// (the albedo store then loses its alpha, in place).
Expected<std::vector<TransferLayer>> Transfer::make_layers(
    std::shared_ptr<LevelStore> (&stores)[kSlots], const LayerFacts (&facts)[kSlots]) const {
  std::vector<TransferLayer> layers;
  for (int l = 0; l < kSlots; ++l) {
    if (!want_[l]) continue;
    const LayerFacts& f = facts[l];
    TransferLayer layer;
    layer.semantic =
        l == kLightingSlot && combined_ ? LayerSemantic::kLitAlbedo : kSlotInfo[l].semantic;
    layer.channels = channels_[l];
    layer.texels_above_one = f.texels_above_one;
    layer.max_value = f.max_value;
    layer.hdr = (l != kNormalSlot && f.hdr) || l == kLightingSlot;  // lighting: half always
    if (has_alpha(l)) {
      layer.hdr |= f.alpha && f.alpha_hdr;
      if (!f.alpha) {
        layer.channels = 3;
        VT_RETURN_IF_ERROR(stores[l]->keep_channels(3).with_context("transfer"));
      }
    }
    layer.store = std::move(stores[l]);
    layers.push_back(std::move(layer));
  }
  return layers;
}

// Band `b` (rows y0..y1) into `acc` and `coverage` (those rows only), counted in `counts`.
void Transfer::transfer_band(uint32_t b, float* const (&acc)[kSlots], uint8_t* coverage,
                             RowCounts& counts) const {
  const uint32_t W = opt_.width, H = opt_.height;
  const auto pattern = supersample_pattern(opt_.supersample);
  auto store = [&](size_t texel, const Sample& s, float weight, bool add) {
    for (int l = 0; l < kSlots; ++l) {
      if (!want_[l]) continue;
      const uint32_t channels = channels_[l];
      const float* src = s.of(l);
      float* d = &acc[l][texel * channels];
      for (uint32_t c = 0; c < channels; ++c) d[c] = add ? d[c] + src[c] * weight : src[c];
    }
  };
  BandRaster band;
  uint32_t y0 = b * kBandRows, y1 = std::min(H, y0 + kBandRows);
  band.reset(W, y0, y1);
  TriEval te;
  Sample s{};
  const float weight = 1.0f / float(pattern.size());
  for (uint32_t t : bins_[b]) {
    make_eval(t, te);
    raster_triangle(tris_[t], int32_t(t), chart_[t], band, pattern, H,
                    [&](size_t i, const double* l, uint32_t sub) {
                      evaluate(te, l, (uint64_t(y0) * W + i) * 32 + sub, s);
                      store(i, s, weight, true);
                      ++counts.samples, counts.below_horizon += s.below_horizon;
                    });
  }
  for (size_t i = 0; i < band.best_tri.size(); ++i) {
    if (band.best_tri[i] < 0) continue;
    coverage[i] = 1;
    counts.contested += band.contested[i];
    if (band.inside[i] > 0) {
      ++counts.sampled;
      // Partially covered texels average only the samples that fell inside.
      float scale = float(pattern.size()) / float(band.inside[i]);
      if (scale != 1.0f) {
        for (int l = 0; l < kSlots; ++l) {
          if (!want_[l]) continue;
          const uint32_t channels = channels_[l];
          for (uint32_t c = 0; c < channels; ++c) acc[l][i * channels + c] *= scale;
        }
      }
      continue;
    }
    // Touched but no sample inside: the closest point of the closest triangle.
    ++counts.edge_only;
    uint32_t t = uint32_t(band.best_tri[i]);
    make_eval(t, te);
    double l[3];
    tris_[t].closest_barycentrics((i % W) + 0.5, (y0 + i / W) + 0.5, l);
    evaluate(te, l, (uint64_t(y0) * W + i) * 32 + 16, s);
    store(i, s, 1.0f, false);
    ++counts.samples, counts.below_horizon += s.below_horizon;
  }
}

// A band's finished texels as the band cache stores them: its counts, its layers' facts, its
// coverage (a byte a texel), then each layer's texels. `n` texels; sizes only with null data.
struct BandBytes {
  static constexpr size_t kCounts = 5 * sizeof(uint64_t), kFacts = 16;
  size_t n = 0, size = 0;
  size_t offset[kSlots] = {};  // of each wanted layer's texels
  BandBytes(size_t texels, const bool (&want)[kSlots], const uint32_t (&channels)[kSlots])
      : n(texels) {
    size = kCounts + kSlots * kFacts + n;
    for (int l = 0; l < kSlots; ++l)
      if (want[l]) offset[l] = size, size += n * channels[l] * sizeof(float);
  }
};

void Transfer::pack_band(const BandBytes& f, float* const (&acc)[kSlots], const uint8_t* coverage,
                         const RowCounts& counts, const LayerFacts (&facts)[kSlots],
                         uint8_t* out) const {
  const uint64_t c[5] = {counts.sampled, counts.edge_only, counts.contested, counts.samples,
                         counts.below_horizon};
  std::memcpy(out, c, sizeof c);
  for (int l = 0; l < kSlots; ++l) {
    uint8_t* p = out + BandBytes::kCounts + l * BandBytes::kFacts;
    std::memset(p, 0, BandBytes::kFacts);
    std::memcpy(p, &facts[l].texels_above_one, 8);
    std::memcpy(p + 8, &facts[l].max_value, 4);
    p[12] = facts[l].hdr, p[13] = facts[l].alpha_hdr, p[14] = facts[l].alpha;
  }
  std::memcpy(out + BandBytes::kCounts + kSlots * BandBytes::kFacts, coverage, f.n);
  for (int l = 0; l < kSlots; ++l)
    if (want_[l]) std::memcpy(out + f.offset[l], acc[l], f.n * channels_[l] * sizeof(float));
}

void Transfer::unpack_band(const BandBytes& f, const uint8_t* in, float* const (&acc)[kSlots],
                           uint8_t* coverage, RowCounts& counts,
                           LayerFacts (&facts)[kSlots]) const {
  uint64_t c[5];
  std::memcpy(c, in, sizeof c);
  counts.sampled = c[0], counts.edge_only = c[1], counts.contested = c[2], counts.samples = c[3];
  counts.below_horizon = c[4];
  for (int l = 0; l < kSlots; ++l) {
    const uint8_t* p = in + BandBytes::kCounts + l * BandBytes::kFacts;
    std::memcpy(&facts[l].texels_above_one, p, 8);
    std::memcpy(&facts[l].max_value, p + 8, 4);
    facts[l].hdr = p[12], facts[l].alpha_hdr = p[13], facts[l].alpha = p[14];
  }
  std::memcpy(coverage, in + BandBytes::kCounts + kSlots * BandBytes::kFacts, f.n);
  for (int l = 0; l < kSlots; ++l)
    if (want_[l]) std::memcpy(acc[l], in + f.offset[l], f.n * channels_[l] * sizeof(float));
}

// Rows [r0, r1) of the atlas (r0 a multiple of kBandRows) into `acc` and `coverage` (those rows
// only), finished (finish_rows); the bands run on all threads, each read from the band cache
// when it holds it, else transferred (and stored there).
Status Transfer::transfer_rows(uint32_t r0, uint32_t r1, float* const (&acc)[kSlots],
                               std::vector<uint8_t>& coverage, RowCounts& counts,
                               LayerFacts (&facts)[kSlots],
                               const std::function<void(double)>& progress, ImageLoading& images) {
  const uint32_t W = opt_.width, H = opt_.height;
  const uint32_t b0 = r0 / kBandRows, bands = (r1 - r0 + kBandRows - 1) / kBandRows;
  struct Outcome {
    RowCounts counts;
    LayerFacts facts[kSlots];
    bool cached = false;
    bool unread = false;  // listed in the cache but unreadable there: transferred after
  };
  std::vector<Outcome> outcome(bands);
  auto band = [&](uint32_t bi, bool from_cache) {
    const uint32_t b = b0 + bi, y0 = b * kBandRows, y1 = std::min(H, y0 + kBandRows);
    const size_t base = size_t(y0 - r0) * W;  // the band's first texel in `acc`
    float* band_acc[kSlots] = {};
    for (int l = 0; l < kSlots; ++l)
      if (want_[l]) band_acc[l] = acc[l] + base * channels_[l];
    uint8_t* band_coverage = coverage.data() + base;
    Outcome& o = outcome[bi];
    const BandBytes layout(size_t(y1 - y0) * W, want_, channels_);
    thread_local std::vector<uint8_t> bytes;
    if (cache_in_ || cache_out_) bytes.resize(layout.size);
    if (from_cache && cache_in_ && cache_in_->has(b, band_keys_[b])) {
      thread_local std::vector<uint8_t> frame;
      if (cache_in_->read(b, band_keys_[b], bytes, &frame)) {
        unpack_band(layout, bytes.data(), band_acc, band_coverage, o.counts, o.facts);
        o.cached = true;
        if (cache_out_) cache_out_->add_frame(b, band_keys_[b], bytes, frame);  // kept
      } else {
        o.unread = true;  // its images may be deferred (setup_images)
      }
      return;
    }
    transfer_band(b, band_acc, band_coverage, o.counts);
    finish_rows(band_acc, band_coverage, layout.n, o.facts);
    if (cache_out_) {
      pack_band(layout, band_acc, band_coverage, o.counts, o.facts, bytes.data());
      cache_out_->add(b, band_keys_[b], bytes);
    }
  };
  // The bands the cache holds first (no texture needed), then, the textures loaded, the rest.
  std::vector<uint32_t> order[2];
  for (uint32_t bi = 0; bi < bands; ++bi)
    order[!(cache_in_ && cache_in_->has(b0 + bi, band_keys_[b0 + bi]))].push_back(bi);
  for (int phase = 0; phase < 2; ++phase) {
    if (phase == 1) VT_RETURN_IF_ERROR(images.wait());
    const std::vector<uint32_t>& these = order[phase];
    const size_t before = phase == 0 ? 0 : order[0].size();
    std::function<void(double)> step;
    if (progress)
      step = [&](double f) { progress(bands ? (before + f * these.size()) / bands : 1.0); };
    for_each_band(uint32_t(these.size()), opt_.threads, step,
                  [&](uint32_t i) { band(these[i], true); });
  }
  std::vector<uint32_t> unread;
  for (uint32_t bi = 0; bi < bands; ++bi)
    if (outcome[bi].unread) unread.push_back(bi);
  if (!unread.empty()) {
    VT_RETURN_IF_ERROR(setup_images());  // the deferred images too
    parallel_for(unread.size(), opt_.threads, [&](size_t i) { band(unread[i], false); });
  }
  for (const Outcome& o : outcome) {
    counts.sampled += o.counts.sampled, counts.edge_only += o.counts.edge_only;
    counts.contested += o.counts.contested, counts.samples += o.counts.samples;
    counts.below_horizon += o.counts.below_horizon;
    bands_cached_ += o.cached;
    for (int l = 0; l < kSlots; ++l) {
      LayerFacts& f = facts[l];
      const LayerFacts& g = o.facts[l];
      f.texels_above_one += g.texels_above_one, f.max_value = std::max(f.max_value, g.max_value);
      f.hdr |= g.hdr, f.alpha_hdr |= g.alpha_hdr, f.alpha |= g.alpha;
    }
  }
  return Status::Ok();
}

// The band cache's keys: the file's (cache layout, tool version, atlas, settings, layers, how
// each image is used), and each band's (the file key, the band, and per triangle it reads: its
// index, chart and face, and the key of its primitive: vertex data, material, the content and
// path of the images that reads). Opens the cache to read and the one to write.
Status Transfer::setup_cache() {
  if ((opt_.cache_in.empty() && opt_.cache_out.empty()) || want_[kLightingSlot])
    return Status::Ok();
  if (opt_.image_keys.size() != scene_.images.size())
    return Error(ErrorCode::kInvalidArgument, "transfer: the band cache needs a key per image");
  KeyStream f;
  f.add(std::string("transfer bands 1 " VTBAKE_VERSION)), f.add(code_identity());
  f.add(opt_.width), f.add(opt_.height), f.add(opt_.atlas_uv_set), f.add(opt_.supersample);
  f.add(opt_.mip_filter), f.add(opt_.missing_textures), f.add(kBandRows);
  f.add(opt_.color_config && !opt_.color_config->is_builtin() ? opt_.color_config->cache_id()
                                                              : std::string());
  for (int l = 0; l < kSlots; ++l) f.add(want_[l]), f.add(channels_[l]);
  for (size_t i = 0; i < scene_.images.size(); ++i)
    f.add(used_as_colour(scene_, i)), f.add(used_as_data(scene_, i));
  const uint64_t file_key = f.digest();
  std::vector<uint64_t> prim_keys(prims_.size());
  for (size_t pi = 0; pi < prims_.size(); ++pi) {
    KeyStream k;
    add_primitive(k, *prims_[pi].prim);
    add_material(k, *prims_[pi].mat);
    for (const TextureSlot& ts : kTextureSlots) {
      const scene::TextureRef& r = (*prims_[pi].mat).*ts.ref;
      if (!r.valid() || size_t(r.image) >= scene_.images.size()) continue;  // setup_images fails
      k.add(opt_.image_keys[size_t(r.image)]), k.add(scene_.images[size_t(r.image)].path);
    }
    prim_keys[pi] = k.digest();
  }
  band_keys_.resize(bins_.size());
  for (size_t b = 0; b < bins_.size(); ++b) {
    KeyStream k;
    k.add(file_key), k.add(uint64_t(b));
    for (uint32_t t : bins_[b])
      k.add(t), k.add(chart_[t]), k.add(tri_src_[t].second), k.add(prim_keys[tri_src_[t].first]);
    band_keys_[b] = k.digest() | 1;  // never 0, which marks a band not stored
  }
  const uint32_t bands = uint32_t(bins_.size());
  if (!opt_.cache_in.empty()) cache_in_ = TransferCacheReader::open(opt_.cache_in, file_key, bands);
  if (!opt_.cache_out.empty()) {
    auto writer = TransferCacheWriter::create(opt_.cache_out, file_key, bands);
    if (writer.ok()) cache_out_ = std::move(writer).value();
  }
  return Status::Ok();
}

// The images read by the triangles of the bands the band cache lacks.
std::vector<bool> Transfer::images_for_uncached_bands() const {
  std::vector<bool> wanted(scene_.images.size(), false);
  for (size_t b = 0; b < bins_.size(); ++b) {
    if (cache_in_->has(uint32_t(b), band_keys_[b])) continue;
    for (uint32_t t : bins_[b])
      for (const TextureSlot& ts : kTextureSlots) {
        const scene::TextureRef& r = (*prims_[tri_src_[t].first].mat).*ts.ref;
        if (r.valid() && size_t(r.image) < wanted.size()) wanted[size_t(r.image)] = true;
      }
  }
  return wanted;
}

// Rows transferred at a time: a multiple of kBandRows, as many as TransferOptions allow.
uint32_t Transfer::rows_per_pass() const {
  const uint32_t H = opt_.height;
  uint64_t rows = opt_.band_rows;
  if (rows == 0 && opt_.stores_in_memory) rows = H;  // accumulated in the stores themselves
  if (rows == 0) {
    uint64_t per_row = 0;
    for (int l = 0; l < kSlots; ++l)
      if (want_[l]) per_row += uint64_t(opt_.width) * channels_[l] * sizeof(float);
    rows = opt_.band_memory / std::max<uint64_t>(per_row, 1);
  }
  rows = std::max<uint64_t>(kBandRows, rows / kBandRows * kBandRows);
  return uint32_t(std::min<uint64_t>(rows, (H + kBandRows - 1) / kBandRows * kBandRows));
}

Expected<TransferResult> Transfer::run() {
  auto start = std::chrono::steady_clock::now();
  std::vector<std::pair<const char*, double>> stages;
  auto lap = [&, t = start](const char* name) mutable {
    const auto now = std::chrono::steady_clock::now();
    stages.emplace_back(name, std::chrono::duration<double>(now - t).count());
    t = now;
  };
  const uint32_t W = opt_.width, H = opt_.height;
  if (W == 0 || H == 0) return Error(ErrorCode::kInvalidArgument, "transfer: empty atlas");
  if (opt_.supersample != 1 && opt_.supersample != 4 && opt_.supersample != 16) {
    return Error(ErrorCode::kInvalidArgument, "transfer: supersample must be 1, 4 or 16");
  }
  if (uint64_t(W) * H > opt_.max_texels) {
    return Error(ErrorCode::kResourceLimit, "transfer: atlas of " + std::to_string(W) + "x" +
                                                std::to_string(H) + " texels exceeds the limit");
  }
  sub_scale_ = 1.0 / std::sqrt(double(opt_.supersample));
  VT_RETURN_IF_ERROR(setup_prims());
  bins_ = bin_by_rows(tris_, H, kBandRows);
  // With a band cache, only the images that bands it lacks read are loaded.
  VT_RETURN_IF_ERROR(setup_cache());
  lap("setup");
  // The textures load on a thread of their own while the stores are made and the bands the cache
  // holds are read (neither reads a texture; both are mostly first touches of fresh memory), and
  // are waited for before the first band that samples them. The texels do not depend on it.
  std::vector<bool> wanted;
  if (cache_in_) wanted = images_for_uncached_bands();
  ImageLoading images;
  images.start([this, &wanted] { return setup_images(cache_in_ ? &wanted : nullptr); });

  TransferResult result;
  result.width = W, result.height = H;
  std::shared_ptr<LevelStore> stores[kSlots];
  for (int l = 0; l < kSlots; ++l) {
    if (!want_[l]) continue;
    VT_ASSIGN_OR_RETURN(stores[l], LevelStore::create(W, H, channels_[l], opt_.stores_in_memory,
                                                      opt_.scratch_dir, opt_.compress_scratch));
  }
  VT_ASSIGN_OR_RETURN(std::shared_ptr<CoverageMask> coverage,
                      CoverageMask::create(W, H, opt_.coverage_in_memory, opt_.scratch_dir));
  lap("stores");
  std::vector<uint8_t> band_coverage;  // a pass's rows, one byte per texel
  const uint32_t pass = rows_per_pass();
  // Accumulators: an in-memory store's own rows (zero when created), else a pass's buffer
  // written to the scratch store after.
  std::vector<float> buffer[kSlots];
  float* acc[kSlots] = {};
  LayerFacts facts[kSlots];
  RowCounts counts;
  for (uint32_t r0 = 0; r0 < H; r0 += pass) {
    const uint32_t r1 = std::min(H, r0 + pass);
    const size_t n = size_t(r1 - r0) * W;
    for (int l = 0; l < kSlots; ++l) {
      if (!want_[l]) continue;
      if (stores[l]->in_memory()) {
        acc[l] = stores[l]->data() + size_t(r0) * W * channels_[l];
      } else {
        buffer[l].assign(n * channels_[l], 0.0f);
        acc[l] = buffer[l].data();
      }
    }
    std::function<void(double)> progress;
    if (opt_.progress)
      progress = [&](double f) { opt_.progress((double(r0) + f * double(r1 - r0)) / double(H)); };
    band_coverage.assign(n, 0);
    VT_RETURN_IF_ERROR(transfer_rows(r0, r1, acc, band_coverage, counts, facts, progress, images));
    VT_RETURN_IF_ERROR(
        coverage->write_rows(r0, r1 - r0, band_coverage.data()).with_context("transfer"));
    for (int l = 0; l < kSlots; ++l) {
      if (!want_[l] || stores[l]->in_memory()) continue;
      VT_RETURN_IF_ERROR(stores[l]->write_rows(r0, r1 - r0, acc[l]).with_context("transfer"));
    }
    if (!opt_.stores_in_memory)
      VT_RETURN_IF_ERROR(check_projected_scratch(stores, kSlots, r1, H, opt_.scratch_dir)
                             .with_context("transfer"));
  }
  for (auto& b : buffer) b = {};
  band_coverage = {};
  lap("bands");
  VT_RETURN_IF_ERROR(images.wait());  // (a transfer of no rows)
  // Beside the stages: the textures' loading, which ran during "stores" and "bands", and what
  // "bands" waited for it.
  const std::pair<const char*, double> loading[] = {{"images", images.seconds()},
                                                    {"images_wait", images.waited()}};
  // A cache that cannot be written only costs the next update its reuse.
  if (cache_out_) (void)cache_out_->finish();
  lap("cache");

  VT_ASSIGN_OR_RETURN(result.layers, make_layers(stores, facts));
  lap("layers");
  result.coverage = coverage;
  result.missing_textures = missing_;
  result.stats.triangles = tris_.size();
  result.stats.sampled_texels = counts.sampled;
  result.stats.edge_only_texels = counts.edge_only;
  result.stats.covered_texels = counts.sampled + counts.edge_only;
  result.stats.contested_texels = counts.contested;
  result.stats.samples = counts.samples;
  result.stats.below_horizon_samples = counts.below_horizon;
  if (lighting_) result.stats.lighting = lighting_->stats();
  result.stats.texture_bytes = texture_bytes_;
  result.stats.bands = bins_.size();
  result.stats.bands_cached = bands_cached_;
  result.stats.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stages.insert(stages.end(), std::begin(loading), std::end(loading));
  result.stats.stage_seconds = std::move(stages);
  return result;
}

}  // namespace

std::span<const TextureSlot> texture_slots() {
  return kTextureSlots;
}

Status check_texcoord_sets(const scene::Scene& scene) {
  for (const scene::Mesh& mesh : scene.meshes) {
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const scene::Primitive& p = mesh.primitives[pi];
      if (p.indices.empty() || p.material < 0 || size_t(p.material) >= scene.materials.size())
        continue;
      const scene::Material& m = scene.materials[p.material];
      for (const TextureSlot& ts : kTextureSlots) {
        const scene::TextureRef& r = m.*ts.ref;
        if (!r.valid() || scene::texture_uv_set(p, r)) continue;
        return Error(ErrorCode::kInvalidArgument,
                     "mesh '" + mesh.name + "' primitive " + std::to_string(pi) + ": " +
                         material_label(scene, m) + " " + ts.name + " reads TEXCOORD_" +
                         std::to_string(r.texcoord) + ", which the primitive lacks (it has " +
                         std::to_string(p.uvs.size()) +
                         (p.uvs.size() == 1 ? " UV set)" : " UV sets)"));
      }
    }
  }
  return Status::Ok();
}

uint64_t texture_cache_bytes(uint64_t memory_limit) {
  return std::clamp(memory_limit / 4, uint64_t(32) << 20, uint64_t(2) << 30);
}

Status check_scene_textures(const scene::Scene& scene) {
  std::vector<bool> checked(scene.images.size(), false);
  for (const scene::Material* m : materials_in_use(scene)) {
    for (const TextureSlot& ts : kTextureSlots) {
      const scene::TextureRef& r = m->*ts.ref;
      if (!r.valid() || size_t(r.image) >= scene.images.size() || checked[r.image]) continue;
      checked[r.image] = true;
      const scene::Image& img = scene.images[r.image];
      const Status s =
          img.embedded() ? check_png_chunks(img.bytes, "embedded image " + std::to_string(r.image) +
                                                           " '" + img.name + "'")
                         : check_png_chunks(img.path);
      if (!s.ok()) return s.with_context(material_label(scene, *m) + " " + ts.name);
    }
  }
  return Status::Ok();
}

Expected<MissingTextures> parse_missing_textures(const std::string& name) {
  if (name == "error") return MissingTextures::kError;
  if (name == "warn") return MissingTextures::kWarn;
  return Error(ErrorCode::kInvalidArgument,
               "unknown missing-texture policy '" + name + "' (known: error, warn)");
}

std::string MissingTexture::message() const {
  return material_label(material, material_index) + " " + slot + ": cannot read image '" + image +
         "'" + (path.empty() ? "" : " (tried " + path + ")") + ": " + reason;
}

std::vector<std::array<double, 2>> supersample_pattern(int supersample) {
  int k = supersample >= 16 ? 4 : supersample >= 4 ? 2 : 1;
  std::vector<std::array<double, 2>> p;
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) p.push_back({(i + 0.5) / k, (j + 0.5) / k});
  return p;
}

std::vector<LayerSemantic> layers_used(const scene::Scene& scene, LightingLayer lighting) {
  bool normal = false, orm = false, emissive = false;
  scene::Material fallback;
  for (const auto& mesh : scene.meshes) {
    for (const auto& p : mesh.primitives) {
      const scene::Material& m = p.material >= 0 && size_t(p.material) < scene.materials.size()
                                     ? scene.materials[p.material]
                                     : fallback;
      normal |= m.normal_texture.valid();
      orm |= material_has_orm(m);
      emissive |= material_has_emissive(m);
    }
  }
  std::vector<LayerSemantic> out = {LayerSemantic::kAlbedo};
  if (normal) out.push_back(LayerSemantic::kNormal);
  if (orm) out.push_back(LayerSemantic::kOrm);
  if (emissive) out.push_back(LayerSemantic::kEmissive);
  if (scene_has_lights(scene)) {
    out.push_back(lighting == LightingLayer::kCombined ? LayerSemantic::kLitAlbedo
                                                       : LayerSemantic::kLighting);
  }
  return out;
}

Expected<TransferResult> transfer_to_stores(const scene::Scene& scene,
                                            const TransferOptions& options) {
  Transfer t(scene, options);
  return t.run();
}

Expected<TransferResult> transfer_materials(const scene::Scene& scene,
                                            const TransferOptions& options) {
  TransferOptions in_memory = options;
  in_memory.stores_in_memory = true;
  VT_ASSIGN_OR_RETURN(TransferResult r, transfer_to_stores(scene, in_memory));
  for (TransferLayer& layer : r.layers) {
    layer.texels = layer.store->release();
    layer.store.reset();
  }
  return r;
}

AtlasRaster rasterize_atlas(const std::vector<std::array<double, 6>>& triangles,
                            const std::vector<int32_t>& chart, uint32_t width, uint32_t height,
                            int supersample) {
  AtlasRaster out;
  out.owner.assign(size_t(width) * height, -1);
  out.inside.assign(size_t(width) * height, 0);
  std::vector<RasterTriangle> tris(triangles.begin(), triangles.end());
  const auto pattern = supersample_pattern(supersample);
  const uint32_t bands = (height + kBandRows - 1) / kBandRows;
  auto bins = bin_by_rows(tris, height, kBandRows);
  BandRaster band;
  for (uint32_t b = 0; b < bands; ++b) {
    uint32_t y0 = b * kBandRows, y1 = std::min(height, y0 + kBandRows);
    band.reset(width, y0, y1);
    for (uint32_t t : bins[b]) {
      out.double_sampled +=
          raster_triangle(tris[t], int32_t(t), t < chart.size() ? chart[t] : 0, band, pattern,
                          height, [](size_t, const double*, uint32_t) {});
    }
    for (size_t i = 0; i < band.best_tri.size(); ++i) {
      out.owner[size_t(y0) * width + i] = band.best_tri[i];
      out.inside[size_t(y0) * width + i] = band.inside[i];
      out.contested_texels += band.contested[i];
    }
  }
  return out;
}

}  // namespace vt
