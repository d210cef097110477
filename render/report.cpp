#include "render/report.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "format/atomic_output.h"
#include "scene/image_load.h"

namespace vt::render {

Rgba8Image difference_map(const Rgba8Image& a, const Rgba8Image& b, int gain) {
  Rgba8Image out;
  out.width = a.width;
  out.height = a.height;
  out.texels.assign(a.texels.size(), 255);
  if (a.texels.size() != b.texels.size()) return out;
  for (size_t i = 0; i + 3 < a.texels.size(); i += 4) {
    int d = 0;
    for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a.texels[i + c]) - b.texels[i + c]));
    uint8_t v = uint8_t(std::min(255, d * gain));
    out.texels[i] = out.texels[i + 1] = out.texels[i + 2] = v;
  }
  return out;
}

Rgba8Image residency_heat_map(const VirtualFrame& frame) {
  static const uint8_t kPalette[8][3] = {{255, 255, 255}, {255, 230, 60}, {80, 220, 80},
                                         {60, 220, 230},  {60, 110, 255}, {170, 80, 255},
                                         {120, 120, 120}, {60, 60, 60}};
  Rgba8Image out;
  out.width = frame.color.width;
  out.height = frame.color.height;
  out.texels.assign(frame.status.size() * 4, 0);
  for (size_t i = 0; i < frame.status.size(); ++i) {
    uint8_t* p = &out.texels[i * 4];
    p[3] = 255;
    uint32_t s = frame.status[i];
    if (!(s & VirtualFrame::kStatusDrawn)) continue;
    uint32_t wanted = s & 0xFF, sampled = (s >> 8) & 0xFF;
    if (sampled == 31) {
      p[0] = 255, p[1] = 0, p[2] = 255;
      continue;
    }
    const uint8_t* c = kPalette[std::min<uint32_t>(sampled, 7)];
    for (int k = 0; k < 3; ++k) p[k] = c[k];
    if (sampled > wanted) {
      p[0] = 255;
      p[1] = uint8_t(p[1] / 3);
      p[2] = uint8_t(p[2] / 3);
    }
  }
  return out;
}

Status write_png(const std::string& path, const Rgba8Image& image) {
  if (image.texels.size() != size_t(image.width) * image.height * 4 || image.width == 0) {
    return Error(ErrorCode::kInvalidArgument, path + ": empty or malformed image");
  }
  std::vector<uint8_t> rgb(size_t(image.width) * image.height * 3);
  for (size_t i = 0, n = size_t(image.width) * image.height; i < n; ++i) {
    for (int c = 0; c < 3; ++c) rgb[i * 3 + c] = image.texels[i * 4 + c];
  }
  auto out = OIIO::ImageOutput::create(path);
  if (!out) return Error(ErrorCode::kIo, path + ": cannot create image: " + OIIO::geterror());
  OIIO::ImageSpec spec(int(image.width), int(image.height), 3, OIIO::TypeDesc::UINT8);
  // zlib level 1: a third of the default's encode time for ~10% more bytes; validate writes
  // four 1280x720 images per view (docs/BENCHMARKS.md).
  spec.attribute("png:compressionLevel", 1);
  return write_output(path, [&](const std::string& temp) -> Status {
    if (!out->open(temp, spec) || !out->write_image(OIIO::TypeDesc::UINT8, rgb.data()) ||
        !out->close()) {
      return Error(ErrorCode::kIo, path + ": " + out->geterror());
    }
    return Status::Ok();
  });
}

Expected<Rgba8Image> read_png(const std::string& path) {
  std::string error;
  auto in = scene::open_image_input(path, error);
  if (!in) return Error(ErrorCode::kIo, path + ": cannot read image: " + error);
  const OIIO::ImageSpec& spec = in->spec();
  const int channels = spec.nchannels;
  if (spec.width <= 0 || spec.height <= 0 || channels <= 0 || spec.width > 65536 ||
      spec.height > 65536) {
    return Error(ErrorCode::kCorrupt, path + ": unusable image size");
  }
  std::vector<uint8_t> pixels(size_t(spec.width) * spec.height * channels);
  if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, pixels.data())) {
    return Error(ErrorCode::kIo, path + ": " + in->geterror());
  }
  Rgba8Image image;
  image.width = uint32_t(spec.width);
  image.height = uint32_t(spec.height);
  image.texels.resize(size_t(image.width) * image.height * 4);
  for (size_t i = 0, n = size_t(image.width) * image.height; i < n; ++i) {
    const uint8_t* s = &pixels[i * channels];
    uint8_t* d = &image.texels[i * 4];
    for (int c = 0; c < 3; ++c) d[c] = s[channels >= 3 ? c : 0];
    d[3] = channels == 2 ? s[1] : channels >= 4 ? s[3] : 255;
  }
  return image;
}

bool ValidationReport::passed() const {
  if (!atlas.passed()) return false;
  if (views.empty()) return atlas.ran;
  for (const ViewReport& v : views) {
    if (!v.failures.empty()) return false;
  }
  return true;
}

std::vector<std::string> failure_lines(const ValidationReport& r) {
  std::vector<std::string> lines;
  if (r.passed()) return lines;
  std::string views, layers;
  for (const ViewReport& v : r.views) {
    if (v.failures.empty()) continue;
    views += (views.empty() ? "" : ", ") + std::to_string(v.view);
    std::string line = "view " + std::to_string(v.view) + ": ";
    for (size_t i = 0; i < v.failures.size(); ++i) line += (i ? "; " : "") + v.failures[i];
    lines.push_back(line);
  }
  for (const AtlasLayerReport& l : r.atlas.layers) {
    if (l.pages_failed > 0) layers += (layers.empty() ? "" : ", ") + l.name;
  }
  // The atlas check's own lines name each failing layer's worst pages.
  for (const std::string& f : r.atlas.failures) lines.push_back("layer " + f);
  std::string summary = "FAIL:";
  if (!views.empty()) summary += " views " + views;
  if (!layers.empty()) {
    summary +=
        (views.empty() ? "" : ";") + std::string(" layers ") + layers + " (pages as (level, x, y))";
  }
  if (views.empty() && layers.empty())
    summary += " the atlas check did not run and no view was rendered";
  lines.insert(lines.begin(), summary);
  return lines;
}

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double sum(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s;
}

}  // namespace

std::string report_json(const ValidationReport& r) {
  using nlohmann::json;
  json views = json::array();
  for (const ViewReport& v : r.views) {
    const ViewMetrics& m = v.metrics;
    views.push_back({{"view", v.view},
                     {"passed", v.failures.empty()},
                     {"failures", v.failures},
                     {"psnr_rgb", m.psnr_rgb},
                     {"psnr_alpha", m.psnr_alpha},
                     {"worst_tile_psnr", m.worst_tile_psnr},
                     {"worst_tile", {m.worst_tile_x, m.worst_tile_y}},
                     {"ssim", m.ssim},
                     {"max_abs_error", m.max_abs},
                     {"pixels_compared", m.pixels},
                     {"outline_pixels", m.outline_pixels},
                     {"coarser_share", m.coarser_share},
                     {"unresident_pixels", m.unresident_pixels},
                     {"coverage_mismatch_share", m.coverage_mismatch_share},
                     {"converged", v.converge.converged},
                     {"frames_to_converge", v.converge.frames_to_converge},
                     {"frames_rendered", v.converge.frames_rendered},
                     {"pages_uploaded", v.converge.pages_uploaded},
                     {"load_errors", v.converge.load_errors},
                     {"thrashing", v.converge.thrashing},
                     {"feedback_ms_median", median(v.converge.feedback_ms)},
                     {"stream_ms_median", median(v.converge.stream_ms)},
                     {"converge_ms", sum(v.converge.feedback_ms) + sum(v.converge.stream_ms)},
                     {"virtual_ms", v.virtual_ms},
                     {"reference_ms", v.reference_ms},
                     {"images", v.images},
                     {"framing", v.framing},
                     {"density", to_json(v.density)}});
    if (v.lit) views.back()["lit"] = to_json(*v.lit);
    if (v.lighting) views.back()["lighting"] = to_json(*v.lighting);
  }
  json doc = {{"page_file", r.page_file},
              {"layer", r.layer},
              {"cache_format", r.cache_format},
              {"device", r.device},
              {"width", r.width},
              {"height", r.height},
              {"thresholds",
               {{"min_psnr", r.thresholds.min_psnr},
                {"min_tile_psnr", r.thresholds.min_tile_psnr},
                {"max_coarser_share", r.thresholds.max_coarser_share},
                {"max_coverage_mismatch", r.thresholds.max_coverage_mismatch},
                {"min_density", r.thresholds.min_density},
                {"lighting",
                 {{"min_psnr", r.lighting_thresholds.min_psnr},
                  {"min_tile_psnr", r.lighting_thresholds.min_tile_psnr},
                  {"max_coverage_mismatch", r.lighting_thresholds.max_coverage_mismatch}}}}},
              {"lit",
               {{"layers", r.lit_layers},
                {"skipped", r.lit_skipped},
                {"min_psnr", r.lit_thresholds.min_psnr},
                {"min_tile_psnr", r.lit_thresholds.min_tile_psnr},
                {"emissive",
                 {{"min_psnr", r.emissive_bounds.min_psnr},
                  {"min_tile_psnr", r.emissive_bounds.min_tile_psnr},
                  {"max_energy_stops", r.emissive_bounds.max_energy_stops}}},
                {"normals",
                 {{"max_mean_deg", r.normal_bounds.max_mean_deg},
                  {"min_detail_correlation", r.normal_bounds.min_detail_correlation}}}}},
              {"passed", r.passed()},
              {"views", views},
              {"atlas", to_json(r.atlas)},
              {"warnings", r.warnings},
              {"contact_sheet", r.contact_sheet},
              {"seconds",
               {{"load", r.seconds.load},
                {"atlas_check", r.seconds.atlas_check},
                {"setup", r.seconds.setup},
                {"views", r.seconds.views},
                {"contact_sheet", r.seconds.contact_sheet},
                {"total", r.seconds.total}}},
              {"exact", to_json(r.exact)},
              {"view_plan", to_json(r.view_plan)}};
  // Paths are quoted as the disk spells them, which need not be UTF-8 (U+FFFD then).
  return doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
}

Status write_report_json(const std::string& path, const ValidationReport& r) {
  return write_output_bytes(path, report_json(r) + "\n");
}

}  // namespace vt::render
