// Source texel density and the density side file (see texel_density.h).
#include "bake/unwrap/texel_density.h"
#include "scene/image_load.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bake/unwrap/unwrap_internal.h"

namespace vt::unwrap {
namespace {

namespace OIIO = OIIO_NAMESPACE;

// A name OpenImageIO can pick a reader by for embedded bytes.
std::string embedded_name(const scene::Image& image) {
  return std::string("embedded") + image.embedded_extension();
}

std::string image_label(const scene::Image& image, size_t index) {
  if (!image.embedded()) return image.path;
  return "embedded image " + std::to_string(index) +
         (image.name.empty() ? "" : " '" + image.name + "'");
}

std::array<const scene::TextureRef*, 5> slots_of(const scene::Material& m) {
  return {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture,
          &m.occlusion_texture, &m.emissive_texture};
}

// |det| of a texture transform's linear part: how it scales UV area.
double transform_area_scale(const scene::TextureTransform& t) {
  if (t.identity()) return 1.0;
  const auto m = t.matrix();
  return std::abs(m[0] * m[3] - m[1] * m[2]);
}

// The meshes the unwrapper lays out and where, as collect_surfaces places them.
std::vector<scene::Instance> placements(const scene::Scene& scene, bool share_instances) {
  std::vector<scene::Instance> instances = scene.instances();
  if (!share_instances) return instances;
  std::vector<scene::Instance> per_mesh(scene.meshes.size());
  for (size_t m = 0; m < per_mesh.size(); ++m) per_mesh[m].mesh = static_cast<int>(m);
  for (auto it = instances.rbegin(); it != instances.rend(); ++it) per_mesh[it->mesh] = *it;
  return per_mesh;
}

double number(const nlohmann::json& j, const std::string& where, const std::string& path) {
  if (!j.is_number() || !(j.get<double>() > 0) || !std::isfinite(j.get<double>()))
    throw std::runtime_error(path + ": " + where + " must be a positive number, not " + j.dump());
  return j.get<double>();
}

// A number (texels per unit) or {"texels_per_unit": D} or {"scale": K}.
OwnDensity own_density(const nlohmann::json& j, const std::string& where, const std::string& path) {
  OwnDensity d;
  if (!j.is_object()) {
    d.texels_per_unit = number(j, where, path);
    return d;
  }
  if (j.size() != 1 || !(j.contains("texels_per_unit") || j.contains("scale")))
    throw std::runtime_error(path + ": " + where +
                             " must be a number (texels per unit), {\"texels_per_unit\": D} or "
                             "{\"scale\": K}, not " +
                             j.dump());
  if (j.contains("scale"))
    d.scale = number(j["scale"], where + " scale", path);
  else
    d.texels_per_unit = number(j["texels_per_unit"], where + " texels_per_unit", path);
  return d;
}

// Resolves {"name": density} against the names in `names` (all entries with that name).
std::vector<OwnDensity> by_name(const nlohmann::json& j, const char* key, const char* what,
                                const std::vector<std::string>& names, const std::string& path) {
  std::vector<OwnDensity> out(names.size());
  if (!j.contains(key)) return out;
  const auto& table = j[key];
  if (!table.is_object())
    throw std::runtime_error(path + ": \"" + std::string(key) + "\" must be an object of " + what +
                             " names to texels per unit");
  for (const auto& [name, value] : table.items()) {
    const OwnDensity d = own_density(value, std::string(what) + " '" + name + "'", path);
    bool found = false;
    for (size_t i = 0; i < names.size(); ++i)
      if (names[i] == name) out[i] = d, found = true;
    if (!found) {
      std::string known;
      for (const auto& n : names)
        if (!n.empty() && known.size() < 200)
          known += (known.empty() ? "" : ", ") + ("'" + n + "'");
      throw std::runtime_error(path + ": the scene has no " + what + " named '" + name + "'" +
                               (known.empty() ? "" : " (it has " + known + ")"));
    }
  }
  return out;
}

}  // namespace

double area_percentile(std::vector<DensitySample> samples, double p) {
  std::sort(samples.begin(), samples.end(), [](const DensitySample& a, const DensitySample& b) {
    return a.texels_per_unit < b.texels_per_unit;
  });
  double total = 0;
  for (const auto& s : samples) total += s.area;
  if (!(total > 0)) return 0;
  double target = std::clamp(p, 0.0, 1.0) * total, sum = 0;
  for (const auto& s : samples) {
    sum += s.area;
    if (sum >= target && s.area > 0) return s.texels_per_unit;
  }
  return samples.back().texels_per_unit;
}

double triangle_source_density(double width, double height, double uv_area, double world_area) {
  double d = std::sqrt(width * height * uv_area / world_area);
  return (uv_area > 0 && world_area > 0 && std::isfinite(d)) ? d : 0.0;
}

Expected<std::array<int, 2>> image_size(const scene::Image& image) {
  if (image.has_no_data()) return Error(ErrorCode::kNotFound, "the scene holds no data for it");
  std::string err;
  OIIO::Filesystem::IOMemReader proxy(image.bytes.data(), image.bytes.size());
  const std::unique_ptr<OIIO::ImageInput> in =
      image.embedded() ? scene::open_image_input(embedded_name(image), err, &proxy)
                       : scene::open_image_input(image.path, err);
  if (!in) {
    return Error(ErrorCode::kNotFound,
                 "cannot read the image header" + (err.empty() ? std::string() : " (" + err + ")"));
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0)
    return Error(ErrorCode::kInvalidArgument, "the image header gives no size");
  return std::array<int, 2>{spec.width, spec.height};
}

SourceDensity measure_source_density(const scene::Scene& scene, bool share_instances) {
  SourceDensity out;
  out.material.assign(scene.materials.size(), 0.0);
  out.material_area.assign(scene.materials.size(), 0.0);
  // Image sizes, read once; {0, 0} = unreadable.
  std::vector<std::array<int, 2>> size(scene.images.size(), {-1, -1});
  auto size_of = [&](int image) -> std::array<int, 2> {
    if (image < 0 || image >= static_cast<int>(size.size())) return {0, 0};
    if (size[image][0] < 0) {
      auto s = image_size(scene.images[image]);
      size[image] = s.ok() ? *s : std::array<int, 2>{0, 0};
      if (!s.ok())
        out.unreadable.push_back(image_label(scene.images[image], image) + ": " +
                                 s.status().message());
    }
    return size[image];
  };
  std::vector<std::vector<DensitySample>> per_material(scene.materials.size());
  std::vector<std::vector<DensitySample>> per_node(scene.nodes.size());
  for (const scene::Instance& inst : placements(scene, share_instances)) {
    for (const scene::Primitive& p : scene.meshes[inst.mesh].primitives) {
      if (p.material < 0 || p.material >= static_cast<int>(scene.materials.size())) continue;
      struct Used {
        std::array<int, 2> size;
        double area_scale;
        const std::vector<scene::Vec2>* uv;
      };
      std::vector<Used> used;
      for (const scene::TextureRef* slot : slots_of(scene.materials[p.material])) {
        const scene::TextureRef& t = *slot;
        if (!t.valid() || t.texcoord < 0 || t.texcoord >= static_cast<int>(p.uvs.size())) continue;
        if (p.uvs[t.texcoord].size() != p.positions.size()) continue;
        const auto wh = size_of(t.image);
        if (wh[0] > 0) used.push_back({wh, transform_area_scale(t.transform), &p.uvs[t.texcoord]});
      }
      if (used.empty()) continue;
      auto& samples = per_material[p.material];
      for (size_t i = 0; i + 2 < p.indices.size(); i += 3) {
        const uint32_t a = p.indices[i], b = p.indices[i + 1], c = p.indices[i + 2];
        if (std::max({a, b, c}) >= p.positions.size()) continue;
        const auto pa = scene::transform_point(inst.world, p.positions[a]);
        const auto pb = scene::transform_point(inst.world, p.positions[b]);
        const auto pc = scene::transform_point(inst.world, p.positions[c]);
        const double u[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
        const double v[3] = {pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]};
        const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                             u[0] * v[1] - u[1] * v[0]};
        const double world_area = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) / 2;
        double best = 0;
        for (const Used& s : used) {
          const auto& ta = (*s.uv)[a];
          const auto& tb = (*s.uv)[b];
          const auto& tc = (*s.uv)[c];
          const double uv_area = std::abs((double(tb[0]) - ta[0]) * (double(tc[1]) - ta[1]) -
                                          (double(tb[1]) - ta[1]) * (double(tc[0]) - ta[0])) /
                                 2 * s.area_scale;
          best = std::max(best, triangle_source_density(s.size[0], s.size[1], uv_area, world_area));
        }
        if (!(best > 0)) continue;
        samples.push_back({best, world_area});
        if (inst.node >= 0 && inst.node < static_cast<int>(per_node.size()))
          per_node[inst.node].push_back({best, world_area});
      }
    }
  }
  std::vector<DensitySample> all;
  for (size_t m = 0; m < per_material.size(); ++m) {
    out.material[m] = area_percentile(per_material[m], 0.5);
    for (const auto& s : per_material[m]) out.material_area[m] += s.area;
    all.insert(all.end(), per_material[m].begin(), per_material[m].end());
  }
  out.scene = area_percentile(std::move(all), kSourcePercentile);
  out.node.assign(scene.nodes.size(), 0.0);
  out.node_area.assign(scene.nodes.size(), 0.0);
  for (size_t n = 0; n < per_node.size(); ++n) {
    for (const auto& s : per_node[n]) out.node_area[n] += s.area;
    out.node[n] = area_percentile(std::move(per_node[n]), kSourcePercentile);
  }
  return out;
}

std::vector<double> object_scales(const SourceDensity& source, const std::vector<char>& has_own) {
  std::vector<double> scale(source.node.size(), 0.0);
  if (!(source.scene > 0)) return scale;
  double total = 0;
  for (size_t n = 0; n < scale.size(); ++n) {
    total += source.node_area[n];
    if (!(n < has_own.size() && has_own[n]) && source.node[n] > kSourceOversample * source.scene)
      scale[n] = std::min(source.node[n] / source.scene, kMaxObjectScale);
  }
  // The texels the scales add (in units of the scene's texels per unit of area) when each is
  // raised to the power `k`.
  auto extra = [&](double k) {
    double e = 0;
    for (size_t n = 0; n < scale.size(); ++n)
      if (scale[n] > 0) e += source.node_area[n] * (std::pow(scale[n], 2 * k) - 1);
    return e;
  };
  if (extra(1) > kObjectScaleBudget * total) {
    double lo = 0, hi = 1;
    for (int i = 0; i < 40; ++i) {
      const double mid = (lo + hi) / 2;
      (extra(mid) > kObjectScaleBudget * total ? hi : lo) = mid;
    }
    for (double& s : scale)
      if (s > 0) s = std::pow(s, lo);
  }
  return scale;
}

Expected<DensityFile> load_density_file(const std::string& path, const scene::Scene& scene) {
  std::ifstream f(path);
  if (!f) return Error(ErrorCode::kNotFound, path + ": cannot open the density file");
  DensityFile out;
  out.path = path;
  try {
    nlohmann::json j = nlohmann::json::parse(f);
    if (!j.is_object())
      throw std::runtime_error(path + ": a density file is a JSON object, not " +
                               std::string(j.type_name()));
    for (const auto& [key, value] : j.items())
      if (key != "texels_per_unit" && key != "size_pages" && key != "materials" &&
          key != "objects" && key != "nodes")
        throw std::runtime_error(
            path + ": unknown key \"" + key +
            "\" (known: texels_per_unit, size_pages, materials, objects or nodes)");
    if (j.contains("objects") && j.contains("nodes"))
      throw std::runtime_error(path + ": give \"objects\" or \"nodes\" (the same), not both");
    if (j.contains("texels_per_unit"))
      out.texels_per_unit = number(j["texels_per_unit"], "\"texels_per_unit\"", path);
    if (j.contains("texels_per_unit") && j.contains("size_pages"))
      throw std::runtime_error(path + ": give \"texels_per_unit\" or \"size_pages\", not both");
    if (j.contains("size_pages")) {
      const auto& s = j["size_pages"];
      if (!s.is_number_integer() || s.get<int64_t>() < 1 || s.get<int64_t>() > 1024)
        throw std::runtime_error(
            path + ": \"size_pages\" must be a whole number in [1, 1024], not " + s.dump());
      out.size_pages = s.get<int>();
    }
    std::vector<std::string> materials, nodes;
    for (const auto& m : scene.materials) materials.push_back(m.name);
    for (const auto& n : scene.nodes) nodes.push_back(n.name);
    out.materials = by_name(j, "materials", "material", materials, path);
    out.nodes = by_name(j, j.contains("nodes") ? "nodes" : "objects", "object", nodes, path);
  } catch (const nlohmann::json::exception& e) {
    return Error(ErrorCode::kInvalidArgument, path + ": malformed density JSON: " + e.what());
  } catch (const std::runtime_error& e) {
    return Error(ErrorCode::kInvalidArgument, e.what());
  }
  return out;
}

std::vector<OwnDensity> spread_to_subtrees(const scene::Scene& scene,
                                           const std::vector<OwnDensity>& named) {
  std::vector<OwnDensity> out(scene.nodes.size());
  std::vector<char> visited(scene.nodes.size(), 0);
  std::vector<std::pair<int, OwnDensity>> stack;
  for (int r : scene.roots) stack.push_back({r, OwnDensity{}});
  while (!stack.empty()) {
    auto [node, inherited] = stack.back();
    stack.pop_back();
    if (node < 0 || node >= static_cast<int>(scene.nodes.size()) || visited[node]) continue;
    visited[node] = 1;
    out[node] =
        node < static_cast<int>(named.size()) && named[node].set() ? named[node] : inherited;
    for (int c : scene.nodes[node].children) stack.push_back({c, out[node]});
  }
  return out;
}

std::string default_density_file(const std::string& scene_path) {
  if (scene_path.empty()) return "";
  std::filesystem::path p(scene_path);
  p.replace_extension(".density.json");
  return p.string();
}

std::string density_file_to_read(const scene::Scene& scene, const std::string& density_file) {
  if (density_file == "-") return "";
  if (!density_file.empty()) return density_file;
  std::string path = default_density_file(scene.source_path);
  std::error_code ec;
  if (!path.empty() && !std::filesystem::exists(path, ec)) path.clear();
  return path;
}

int pages_within(double texels, int page_payload) {
  if (!(texels > 0) || page_payload <= 0) return 0;
  return static_cast<int>(std::floor(std::sqrt(texels) / page_payload));
}

namespace detail {

OwnDensity DensityPlan::wanted(int material, int node) const {
  if (node >= 0 && node < static_cast<int>(nodes.size()) && nodes[node].set()) return nodes[node];
  if (material >= 0 && material < static_cast<int>(materials.size()) && materials[material].set())
    return materials[material];
  OwnDensity d;
  if (node >= 0 && node < static_cast<int>(object_scale.size())) d.scale = object_scale[node];
  return d;
}

Expected<DensityPlan> plan_density(const scene::Scene& scene, const UnwrapOptions& opt) {
  DensityPlan plan;
  DensityFile file;
  const std::string path = density_file_to_read(scene, opt.density_file);
  if (!path.empty()) {
    auto loaded = load_density_file(path, scene);
    if (!loaded.ok()) return loaded.status();
    file = std::move(loaded).value();
    plan.file = path;
  }
  // glTF extras where the file names nothing.
  plan.materials = file.materials;
  plan.materials.resize(scene.materials.size());
  for (size_t m = 0; m < scene.materials.size(); ++m)
    if (!plan.materials[m].set())
      plan.materials[m].texels_per_unit = scene.materials[m].texels_per_unit;
  std::vector<OwnDensity> named = file.nodes;
  named.resize(scene.nodes.size());
  for (size_t n = 0; n < scene.nodes.size(); ++n)
    if (!named[n].set()) named[n].texels_per_unit = scene.nodes[n].texels_per_unit;
  plan.nodes = spread_to_subtrees(scene, named);
  plan.source = measure_source_density(scene, opt.share_instances);
  double tpu = opt.texels_per_unit;
  int size = opt.size_pages;
  if (tpu == 0 && size == 0) tpu = file.texels_per_unit, size = file.size_pages;
  plan.max_pages = std::max(
      1,
      std::min(opt.max_size_pages, pages_within(double(opt.max_atlas_texels), opt.page_payload)));
  plan.min_pages = std::clamp(opt.min_size_pages, 1, plan.max_pages);
  if (tpu > 0) {
    plan.mode = DensityPlan::Mode::kExact, plan.texels_per_unit = tpu,
    plan.rule = "texels_per_unit";
  } else if (size > 0) {
    // The sources' density is then only the reference that per-material densities scale with.
    plan.mode = DensityPlan::Mode::kFitPages, plan.pages = size, plan.rule = "size";
    plan.texels_per_unit = plan.source.scene;
  } else if (plan.source.scene > 0) {
    plan.mode = DensityPlan::Mode::kBounded;
    plan.texels_per_unit = plan.source.scene * kSourceOversample;
    plan.rule = "sources";
    // Only here: a density or size the user gave is not second-guessed object by object.
    std::vector<char> has_own(scene.nodes.size());
    for (size_t n = 0; n < has_own.size(); ++n) has_own[n] = plan.nodes[n].set();
    plan.object_scale = object_scales(plan.source, has_own);
  } else {
    plan.mode = DensityPlan::Mode::kFitPages, plan.pages = kDefaultSizePages;
    plan.rule = "default size";
    plan.may_grow = true;
  }
  return plan;
}

void report_density(const DensityPlan& plan, const scene::Scene& scene,
                    const std::vector<double>& achieved, UnwrapStats* st) {
  st->source_texels_per_unit = plan.source.scene;
  st->density_file = plan.file;
  st->materials.clear();
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    UnwrapStats::MaterialDensity d;
    d.name =
        scene.materials[m].name.empty() ? "material " + std::to_string(m) : scene.materials[m].name;
    d.source = m < plan.source.material.size() ? plan.source.material[m] : 0;
    if (m < plan.materials.size()) {
      d.requested = plan.materials[m].texels_per_unit;
      d.requested_scale = plan.materials[m].scale;
    }
    d.achieved = m < achieved.size() ? achieved[m] : 0;
    if (d.source > 0 || d.requested > 0 || d.requested_scale > 0) st->materials.push_back(d);
  }
  st->objects.clear();
  for (size_t n = 0; n < plan.object_scale.size(); ++n)
    if (plan.object_scale[n] > 1)
      st->objects.push_back(
          {scene.nodes[n].name.empty() ? "node " + std::to_string(n) : scene.nodes[n].name,
           plan.source.node[n], plan.object_scale[n]});
  // Materials baked at under half their sources' density, worst first.
  std::vector<const UnwrapStats::MaterialDensity*> coarse;
  for (const auto& d : st->materials)
    if (d.source > 0 && d.achieved > 0 && 2 * d.achieved < d.source) coarse.push_back(&d);
  std::stable_sort(coarse.begin(), coarse.end(), [](const auto* a, const auto* b) {
    return a->achieved / a->source < b->achieved / b->source;
  });
  if (!coarse.empty()) {
    std::ostringstream w;
    w.precision(3);
    w << "the bake is " << coarse[0]->source / coarse[0]->achieved
      << "x coarser than its sources on " << coarse.size()
      << (coarse.size() == 1 ? " material: " : " materials (worst first): ");
    for (size_t i = 0; i < coarse.size() && i < 3; ++i)
      w << (i ? ", '" : "'") << coarse[i]->name << "' " << coarse[i]->achieved << " vs "
        << coarse[i]->source << " texels/unit";
    if (coarse.size() > 3) w << ", ...";
    w << " (a larger --size, --max-size or --memory-limit, or a density of their own with "
         "--texels-per-unit or --density)";
    st->warnings.push_back(w.str());
  }
  if (!plan.source.unreadable.empty())
    st->warnings.push_back(std::to_string(plan.source.unreadable.size()) +
                           " image(s) gave no size, so their textures do not size the atlas: " +
                           plan.source.unreadable[0]);
}

}  // namespace detail
}  // namespace vt::unwrap
