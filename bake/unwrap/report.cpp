// The unwrap report (JSON), the atlas picture (PNG through OpenImageIO) and the unwrapped .glb.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "bake/unwrap/atlas_raster.h"
#include "bake/unwrap/unwrap.h"
#include "format/atomic_output.h"
#include "scene/gltf_export.h"

namespace vt::unwrap {

std::string report_json(const UnwrapStats& s) {
  nlohmann::json j = {{"faces", s.faces},
                      {"degenerate_faces", s.degenerate_faces},
                      {"charts", s.charts},
                      {"charts_split", s.charts_split},
                      {"split_rounds", s.split_rounds},
                      {"atlas",
                       {{"width", s.atlas_width},
                        {"height", s.atlas_height},
                        {"pages_x", s.pages_x},
                        {"pages_y", s.pages_y}}},
                      {"texels_per_unit", s.texels_per_unit},
                      {"density", density_json(s)},
                      {"utilisation", s.utilisation},
                      {"stretch", {{"l2", s.stretch_l2}, {"linf", s.stretch_linf}}},
                      {"flipped_triangles", s.flipped_triangles},
                      {"overlapping_triangles", s.overlapping_triangles},
                      {"overlapping_texels", s.overlapping_texels},
                      {"unmapped_faces", s.unmapped_faces},
                      {"seconds",
                       {{"segment", s.seconds.segment},
                        {"parameterize", s.seconds.parameterize},
                        {"pack", s.seconds.pack},
                        {"output", s.seconds.output},
                        {"check", s.seconds.check}}}};
  return j.dump(2);
}

nlohmann::json density_json(const UnwrapStats& s) {
  nlohmann::json materials = nlohmann::json::array();
  for (const auto& m : s.materials)
    materials.push_back({{"name", m.name},
                         {"source", m.source},
                         {"requested", m.requested},
                         {"requested_scale", m.requested_scale},
                         {"achieved", m.achieved}});
  nlohmann::json objects = nlohmann::json::array();
  for (const auto& o : s.objects)
    objects.push_back({{"name", o.name}, {"source", o.source}, {"scale", o.scale}});
  return {{"texels_per_unit", s.texels_per_unit},
          {"source_texels_per_unit", s.source_texels_per_unit},
          {"rule", s.density_rule},
          {"file", s.density_file},
          {"materials", materials},
          {"objects", objects},
          {"warnings", s.warnings}};
}

namespace {

std::array<uint8_t, 3> chart_colour(int32_t chart) {
  uint32_t h = static_cast<uint32_t>(chart) * 2654435761u;
  h ^= h >> 15;
  // Bright, saturated colours: never near the dark background.
  return {static_cast<uint8_t>(80 + (h & 0xff) % 176),
          static_cast<uint8_t>(80 + ((h >> 8) & 0xff) % 176),
          static_cast<uint8_t>(80 + ((h >> 16) & 0xff) % 176)};
}

std::array<uint8_t, 3> stretch_colour(float l2) {
  // 1 -> blue, 1.5 or more -> red, through green: stretch worth seeing is a few percent.
  double t = std::clamp((static_cast<double>(l2) - 1.0) * 2.0, 0.0, 1.0);
  if (!std::isfinite(l2)) t = 1;
  double r = std::clamp(2 * t, 0.0, 1.0), g = 1 - std::abs(2 * t - 1),
         b = std::clamp(1 - 2 * t, 0.0, 1.0);
  return {static_cast<uint8_t>(255 * r), static_cast<uint8_t>(255 * g),
          static_cast<uint8_t>(255 * b)};
}

}  // namespace

Status write_atlas_picture(const UnwrapResult& result, const std::string& path, int max_side) {
  int aw = std::max(1, result.stats.atlas_width), ah = std::max(1, result.stats.atlas_height);
  double scale = std::min(1.0, static_cast<double>(max_side) / std::max(aw, ah));
  int w = std::max(1, static_cast<int>(std::ceil(aw * scale)));
  int h = std::max(1, static_cast<int>(std::ceil(ah * scale)));
  int gap = 8;
  int pw = 2 * w + gap;
  std::vector<uint8_t> pixels(static_cast<size_t>(pw) * h * 3, 0);
  for (size_t i = 0; i < pixels.size(); i += 3) pixels[i] = pixels[i + 1] = pixels[i + 2] = 24;
  for (int y = 0; y < h; ++y)
    for (int x = w; x < w + gap; ++x) {
      size_t o = (static_cast<size_t>(y) * pw + x) * 3;
      pixels[o] = pixels[o + 1] = pixels[o + 2] = 255;
    }
  // Page grid lines in the chart panel, so the artist sees page boundaries.
  int page = result.stats.pages_x > 0 ? aw / result.stats.pages_x : 120;
  const TexelRect picture = {0, 0, w - 1, h - 1};
  for (const AtlasTriangle& t : result.triangles) {
    std::array<double, 6> xy;
    for (int k = 0; k < 6; ++k) xy[k] = t.uv[k] * scale;
    const RasterTriangle tri(xy);
    auto cc = chart_colour(t.chart);
    auto sc = stretch_colour(t.stretch_l2);
    auto paint = [&](int64_t px, int64_t py) {
      size_t o = (static_cast<size_t>(py) * pw + px) * 3;
      std::copy(cc.begin(), cc.end(), pixels.begin() + o);
      size_t o2 = (static_cast<size_t>(py) * pw + px + w + gap) * 3;
      std::copy(sc.begin(), sc.end(), pixels.begin() + o2);
    };
    for_each_touched_texel(tri, 0.0, picture, [&](int64_t px, int64_t py) {
      double lambda[3];
      if (tri.contains(px + 0.5, py + 0.5, lambda)) paint(px, py);
    });
    // Tiny triangles still show: always paint the pixel holding their first corner.
    const int64_t cx = static_cast<int64_t>(xy[0]), cy = static_cast<int64_t>(xy[1]);
    if (cx >= 0 && cx < w && cy >= 0 && cy < h) paint(cx, cy);
  }
  for (int p = page; p < std::max(aw, ah); p += page) {
    int g = static_cast<int>(p * scale);
    for (int i = 0; i < std::max(w, h); ++i) {
      if (g < w && i < h) {
        size_t o = (static_cast<size_t>(i) * pw + g) * 3;
        pixels[o] = pixels[o + 1] = pixels[o + 2] = 90;
      }
      if (g < h && i < w) {
        size_t o = (static_cast<size_t>(g) * pw + i) * 3;
        pixels[o] = pixels[o + 1] = pixels[o + 2] = 90;
      }
    }
  }
  auto out = OIIO::ImageOutput::create(path);
  if (!out)
    return Error(ErrorCode::kIo, path + ": cannot create image writer: " + OIIO::geterror());
  OIIO::ImageSpec spec(pw, h, 3, OIIO::TypeDesc::UINT8);
  return write_output(path, [&](const std::string& temp) -> Status {
    if (!out->open(temp, spec) || !out->write_image(OIIO::TypeDesc::UINT8, pixels.data()) ||
        !out->close())
      return Error(ErrorCode::kIo, path + ": " + out->geterror());
    return Status::Ok();
  });
}

Status save_unwrapped_glb(const UnwrapResult& result, const std::string& path) {
  scene::GltfWriteOptions options;
  options.atlas_tangents = true;
  return scene::save_glb(result.scene, path, options);
}

}  // namespace vt::unwrap
