#include "bake/update_scene.h"

#include <filesystem>

#include "bake/color.h"
#include "bake/content_key.h"
#include "bake/image_source.h"
#include "bake/unwrap/texel_density.h"

namespace vt {
namespace {

// A file's content, or a marker for a file that cannot be read (a missing texture bakes from
// the factor alone; the key changes when it appears).
void add_file(KeyStream& k, const std::string& path) {
  auto h = hash_file(path);
  k.add(uint8_t(h.ok()));
  k.add(h.ok() ? *h : uint64_t(0));
}

void add_image(KeyStream& k, const scene::Image& image) {
  // The uri as written (relative to the scene) is in the unwrapped scene; the path is not.
  k.add(image.name), k.add(image.uri), k.add(image.mime_type), k.add(image.bytes);
  if (!image.embedded()) add_file(k, image.path);
}

void add_scene(KeyStream& k, const scene::Scene& s) {
  k.add(uint64_t(s.meshes.size()));
  for (const scene::Mesh& mesh : s.meshes) {
    k.add(mesh.name), k.add(uint64_t(mesh.primitives.size()));
    for (const scene::Primitive& p : mesh.primitives) {
      add_primitive(k, p);
    }
  }
  k.add(uint64_t(s.materials.size()));
  for (const scene::Material& m : s.materials) add_material(k, m);
  k.add(uint64_t(s.images.size()));
  for (const scene::Image& image : s.images) add_image(k, image);
  k.add(uint64_t(s.nodes.size()));
  for (const scene::Node& n : s.nodes) {
    k.add(n.name), k.add(n.local), k.add(n.mesh), k.add(n.children), k.add(n.texels_per_unit);
  }
  k.add(s.roots);
  // Lights only when some node places one: the keys of light-less bakes stay as they were.
  if (scene_has_lights(s)) {
    k.add(uint64_t(s.lights.size()));
    for (const scene::Light& l : s.lights) {
      k.add(l.name), k.add(l.type), k.add(l.color), k.add(l.intensity), k.add(l.range);
      k.add(l.inner_cone_angle), k.add(l.outer_cone_angle);
    }
    for (const scene::Node& n : s.nodes) k.add(n.light);
  }
}

// Every option that decides the output's bytes; thread count and paths do not.
void add_options(KeyStream& k, const SceneBakeOptions& o) {
  const BuildOptions& b = o.build;
  k.add(b.codec.codec), k.add(b.codec.dct_quality), k.add(b.codec.dct_adaptive);
  k.add(b.codec.bc_quality), k.add(b.codec.zstd_level);
  k.add(b.codec.dct_page_modes), k.add(b.codec.min_psnr), k.add(b.codec.float_texels);
  k.add(b.codec.half_runtime);  // BC6H or RGBA16F for half layers (keys of earlier bakes change)
  for (const auto& [name, db] : b.codec.layer_min_psnr) k.add(name), k.add(db);
  k.add(b.payload), k.add(b.border), k.add(b.filter), k.add(b.non_finite);
  k.add(b.alpha_coverage_reference);
  // The limit caps the atlas size the sources' density asks for; a given size it does not change
  // (the bytes are the same at every limit that lets the bake run).
  if (o.unwrap.size_pages == 0) k.add(b.memory_limit);
  k.add(b.color_config && !b.color_config->is_builtin() ? b.color_config->cache_id()
                                                        : std::string());
  const unwrap::UnwrapOptions& u = o.unwrap;
  k.add(u.texels_per_unit), k.add(u.size_pages), k.add(u.padding), k.add(u.method);
  k.add(u.share_instances), k.add(u.max_chart_angle_deg), k.add(u.max_chart_stretch);
  k.add(u.max_split_rounds), k.add(u.max_atlas_texels), k.add(u.max_size_pages);
  k.add(u.min_size_pages);
  k.add(o.supersample), k.add(o.missing_textures);
  k.add(uint8_t(o.unwrapped == "-"));
}

}  // namespace

Expected<uint64_t> scene_bake_key(const scene::Scene& scene, const SceneBakeOptions& options) {
  KeyStream k;
  k.add(std::string(VTBAKE_VERSION));
  add_options(k, options);
  add_scene(k, scene);
  if (scene_has_lights(scene)) {
    const LightingOptions& l = options.lighting;
    k.add(l.shadows), k.add(l.ao_samples), k.add(l.ao_distance);
    // Only when not the default, so that the keys of earlier bakes stay as they were.
    if (l.bounces > 0) k.add(l.bounces), k.add(l.bounce_samples);
    if (l.layer != LightingLayer::kSeparate) k.add(std::string(to_string(l.layer)));
  }
  // The density file the unwrap reads (the scene's NAME.density.json unless one is named).
  const std::string density = unwrap::density_file_to_read(scene, options.unwrap.density_file);
  std::error_code ec;
  const bool has_density = !density.empty() && std::filesystem::exists(density, ec);
  k.add(uint8_t(has_density));
  if (has_density) add_file(k, density);
  return k.digest();
}

std::vector<uint64_t> image_content_keys(const scene::Scene& scene) {
  std::vector<uint64_t> keys;
  for (const scene::Image& image : scene.images) {
    KeyStream k;
    add_image(k, image);
    keys.push_back(k.digest());
  }
  return keys;
}

std::optional<SceneBakeSummary> unchanged_bake(const SceneBakeOptions& options,
                                               const std::string& unwrapped, uint64_t key) {
  const BuildOptions& b = options.build;
  if (!b.update || b.retrain_tables || !b.tables_from.empty()) return std::nullopt;
  std::error_code ec;
  if (!unwrapped.empty() && !std::filesystem::is_regular_file(unwrapped, ec)) return std::nullopt;
  auto previous = PreviousBuild::open(b.output);
  if (!previous.ok() || !(*previous)->has_record()) return std::nullopt;
  const UpdateRecord& r = (*previous)->record();
  if (r.tool != VTBAKE_VERSION || r.input_key != key) return std::nullopt;
  auto build = summarize_unchanged(**previous);
  if (!build.ok()) return std::nullopt;
  SceneBakeSummary summary;
  summary.output = b.output;
  summary.unwrapped = unwrapped;
  summary.build = std::move(build).value();
  summary.build.update.requested = true;
  const PageGeometry& g = summary.build.geometry;
  summary.unwrap.atlas_width = int(g.width), summary.unwrap.atlas_height = int(g.height);
  return summary;
}

}  // namespace vt
