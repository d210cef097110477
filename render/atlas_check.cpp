#include "render/atlas_check.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <type_traits>

#include "bake/color.h"
#include "bake/paging.h"
#include "bake/pyramid.h"
#include "bake/transfer.h"
#include "codec/bc.h"
#include "codec/metrics.h"
#include "common/half.h"
#include "common/parallel.h"
#include "common/vec.h"
#include "format/page_error_bounds.h"
#include "format/runtime_format.h"
#include "render/report.h"
#include "runtime/page_source.h"

namespace vt::render {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

LightingOptions lighting_options_from(const nlohmann::json& meta) {
  LightingOptions o;
  const nlohmann::json lit = meta.value("lighting", nlohmann::json::object());
  if (lit.is_object()) {
    // Shadows are what the scene's lights cast: the reference always casts them, so a bake
    // made with --no-shadows (a speed knob) fails where a shadow falls. AO is asked for: the
    // reference repeats the bake's samples and distance (seeded per texel, same rays).
    o.ao_samples = lit.value("ao_samples", 0);
    o.ao_distance = lit.value("ao_distance", 0.0);
    o.bounces = lit.value("bounces", 0);
    o.bounce_samples = lit.value("bounce_samples", 16);
    // Written only for a combined bake (the default keeps its metadata as it was).
    o.layer = lit.value("layer", "separate") == "combined" ? LightingLayer::kCombined
                                                           : LightingLayer::kSeparate;
  }
  return o;
}

}  // namespace

Expected<BakeSettings> baked_settings(const PageFileReader& reader) {
  const nlohmann::json meta = nlohmann::json::parse(reader.metadata_json(), nullptr, false);
  BakeSettings s;
  if (!meta.is_object()) return s;
  s.scene_bake = meta.value("tool", "") == "vtbake bake";
  s.supersample = meta.value("supersample", 1);
  const nlohmann::json build = meta.value("build", nlohmann::json::object());
  const std::string filter = build.is_object() ? build.value("filter", "kaiser") : "kaiser";
  VT_ASSIGN_OR_RETURN(s.filter, parse_mip_filter(filter.c_str()));
  s.lighting = lighting_options_from(meta);
  s.missing_textures = meta.value("missing_textures", "") == "warn" ? MissingTextures::kWarn
                                                                    : MissingTextures::kError;
  s.texels_per_unit = meta.value("texels_per_unit", 0.0);
  return s;
}

namespace {

// The reference is lit by the original scene's lights where the original places them, on the
// unwrapped geometry: a bake whose lights moved (or were baked from another scene) must fail,
// whatever lights its own unwrapped file carries.
void place_original_lights(const scene::Scene& original, scene::Scene& reference) {
  reference.lights = original.lights;
  for (scene::Node& n : reference.nodes) n.light = -1;
  for (const scene::PlacedLight& p : original.placed_lights()) {
    // A light node's frame: its -Z along the light's direction, at its position.
    const Vec3d z =
        normalized(Vec3d{-p.direction[0], -p.direction[1], -p.direction[2]}, Vec3d{0, 0, 1});
    const Vec3d x =
        normalized(cross(std::abs(z.y) < 0.9 ? Vec3d{0, 1, 0} : Vec3d{1, 0, 0}, z), Vec3d{1, 0, 0});
    const Vec3d y = cross(z, x);
    scene::Node n;
    n.light = p.light;
    n.local = {x.x, x.y, x.z, 0, y.x,           y.y,           y.z,           0,
               z.x, z.y, z.z, 0, p.position[0], p.position[1], p.position[2], 1};
    reference.roots.push_back(int(reference.nodes.size()));
    reference.nodes.push_back(n);
  }
}

// One file layer's reference: its working form (as the build keeps levels: linear, alpha
// premultiplied, normals unit xyz) one level at a time, and its conversion to stored texels.
struct ReferenceLayer {
  uint32_t index = 0;
  LayerSpec spec;
  uint32_t work_channels = 0;
  DownsampleRules rules;
  std::shared_ptr<const ColorConverter> to_storage;  // colour layers
  std::vector<float> level;                          // the current level, dilated
  std::vector<uint8_t> coverage;
};

// The transfer's texels of a layer in the build's working form (bake/level_source.cpp).
void to_working_form(const TransferLayer& t, ReferenceLayer& r, size_t texels) {
  const uint32_t tc = t.channels, wc = r.work_channels;
  r.level.assign(texels * wc, 0.0f);
  for (size_t i = 0; i < texels; ++i) {
    const float* s = &t.texels[i * tc];
    float* d = &r.level[i * wc];
    for (uint32_t c = 0; c < wc; ++c) d[c] = c < tc ? s[c] : (c == 3 ? 1.0f : 0.0f);
    if (!is_colour(r.spec.semantic)) continue;
    for (uint32_t c = 0; c < wc; ++c) d[c] = d[c] >= 0 ? d[c] : 0.0f;
    if (wc == 4) {
      d[3] = std::min(d[3], 1.0f);
      for (int c = 0; c < 3; ++c) d[c] *= d[3];
    }
  }
  if (r.spec.semantic == LayerSemantic::kNormal) renormalize_normals(r.level.data(), texels, 3);
}

Expected<ReferenceLayer> make_reference_layer(uint32_t index, const LayerSpec& spec,
                                              const TransferResult& transfer) {
  ReferenceLayer r;
  r.index = index;
  r.spec = spec;
  const TransferLayer* t = nullptr;
  for (const TransferLayer& l : transfer.layers)
    if (l.semantic == spec.semantic) t = &l;
  if (!t) return Error(ErrorCode::kNotFound, "the scene's materials give no such layer");
  r.work_channels = spec.semantic == LayerSemantic::kNormal ? 3 : spec.channels;
  r.rules = downsample_rules_for(spec, r.work_channels);
  if (is_colour(spec.semantic)) {
    const bool srgb = spec.color_space == ColorSpace::kSrgb;
    VT_ASSIGN_OR_RETURN(r.to_storage, ColorConverter::create("linear", srgb ? "sRGB" : "linear"));
  }
  to_working_form(*t, r, size_t(transfer.width) * transfer.height);
  VT_ASSIGN_OR_RETURN(r.coverage, transfer.coverage->to_bytes());  // a small atlas, held whole
  pull_push(r.level.data(), r.coverage.data(), transfer.width, transfer.height, r.work_channels);
  return r;
}

// A page of working texels (modified) to the layer's stored texels, as the build stores them
// (LayerPlan::store_page): 8-bit texels, or floats for float layers.
void store_reference(const ReferenceLayer& r, float* t, uint32_t side, uint8_t* out) {
  const uint32_t wc = r.work_channels;
  const size_t n = size_t(side) * side;
  if (is_colour(r.spec.semantic) && wc == 4) unpremultiply_page(t, side, wc, 3);
  if (r.spec.texel_type == TexelType::kF16) {
    if (r.to_storage) r.to_storage->apply(t, n, int(wc));
    for (size_t i = 0; i < n * wc; ++i) {
      const uint16_t h = float_to_half(t[i]);
      std::memcpy(out + 2 * i, &h, 2);
    }
    return;
  }
  if (r.spec.texel_type != TexelType::kU8) {
    if (r.to_storage) r.to_storage->apply(t, n, int(wc));
    std::memcpy(out, t, n * wc * sizeof(float));
    return;
  }
  if (r.to_storage) {
    r.to_storage->apply_to_u8(t, n, int(wc), out);
    return;
  }
  auto q = [](float v) -> uint8_t { return v > 0 ? (v >= 1 ? 255 : uint8_t(v * 255 + 0.5f)) : 0; };
  if (r.spec.semantic == LayerSemantic::kNormal) {
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 2; ++c) out[i * 2 + c] = q(t[i * 3 + c] * 0.5f + 0.5f);
    return;
  }
  for (size_t i = 0; i < n * wc; ++i) out[i] = q(t[i]);
}

// PSNR of float pages with 1.0 as the peak (HDR values count as they are).
double float_psnr(const float* a, const float* b, size_t n, int* max_abs) {
  double sse = 0, worst = 0;
  for (size_t i = 0; i < n; ++i) {
    const double d = (double(a[i]) - b[i]) * 255.0;
    sse += d * d;
    worst = std::max(worst, std::abs(d));
  }
  *max_abs = int(std::min(worst, 1e9));
  return psnr_from_mse(sse / double(std::max<size_t>(n, 1)));
}

// Largest per-channel |mean(test) - mean(ref)| of `n` texels, 8-bit steps (floats: x 255).
template <typename T>
double mean_shift(const T* ref, const T* test, size_t n, uint32_t channels) {
  const double scale = std::is_floating_point_v<T> ? 255.0 : 1.0;
  double worst = 0;
  for (uint32_t c = 0; c < channels; ++c) {
    double sum = 0;
    for (size_t i = 0; i < n; ++i) sum += double(test[i * channels + c]) - ref[i * channels + c];
    worst = std::max(worst, std::abs(sum) * scale / double(std::max<size_t>(n, 1)));
  }
  return worst;
}

// A page's PSNR over every channel (alpha and data channels count like colour).
double all_channel_psnr(const ImageError& err) {
  double mse = 0;
  for (int c = 0; c < err.channels; ++c) mse += err.mse[c] / err.channels;
  return psnr_from_mse(mse);
}

Status measure_page(const ReferenceLayer& r, const uint8_t* ref, const uint8_t* test, int ps,
                    AtlasPageError& e) {
  const size_t n = size_t(ps) * ps;
  if (r.spec.texel_type != TexelType::kU8) {
    const float* a = reinterpret_cast<const float*>(ref);
    const float* b = reinterpret_cast<const float*>(test);
    thread_local std::vector<float> ref_f, test_f;  // half pages, widened to float
    if (r.spec.texel_type == TexelType::kF16) {
      const size_t values = n * r.spec.channels;
      ref_f.resize(values), test_f.resize(values);
      for (size_t i = 0; i < values; ++i) {
        uint16_t h[2];
        std::memcpy(&h[0], ref + 2 * i, 2), std::memcpy(&h[1], test + 2 * i, 2);
        ref_f[i] = half_to_float(h[0]), test_f[i] = half_to_float(h[1]);
      }
      a = ref_f.data(), b = test_f.data();
    }
    if (is_light(r.spec.semantic)) {
      // Irradiance in lux (and the radiance of lit albedo) has no peak: judged after the tone map x
      // / (1 + x) (as codec/hdr_metrics.h's tone-mapped figure), where an error is as visible as it
      // looks.
      thread_local std::vector<float> ref_t, test_t;
      const size_t values = n * r.spec.channels;
      ref_t.assign(a, a + values), test_t.assign(b, b + values);
      for (size_t i = 0; i < values; ++i) {
        ref_t[i] = std::max(ref_t[i], 0.0f) / (1.0f + std::max(ref_t[i], 0.0f));
        test_t[i] = std::max(test_t[i], 0.0f) / (1.0f + std::max(test_t[i], 0.0f));
      }
      a = ref_t.data(), b = test_t.data();
    }
    e.psnr = float_psnr(a, b, n * r.spec.channels, &e.max_abs);
    e.mean_shift = mean_shift(a, b, n, r.spec.channels);
    return Status::Ok();
  }
  e.mean_shift = mean_shift(ref, test, n, r.spec.channels);
  VT_ASSIGN_OR_RETURN(ImageError err, compare_images(ref, test, ps, ps, r.spec.channels));
  e.psnr = all_channel_psnr(err);
  e.max_abs = err.max_abs_all;
  if (r.spec.semantic == LayerSemantic::kNormal) {
    VT_ASSIGN_OR_RETURN(AngularError a, normal_angular_error(ref, test, ps, ps, 2));
    e.mean_deg = a.mean_deg;
    e.max_deg = a.max_deg;
  }
  return Status::Ok();
}

// The PSNR a page must reach: its layer's bound, or less where the runtime format alone cannot
// reach that on the reference itself.
double page_min_psnr(const AtlasPageError& e, const AtlasLayerBounds& b) {
  if (e.runtime_floor_psnr <= 0) return b.min_psnr;
  return std::min(b.min_psnr, e.runtime_floor_psnr - b.floor_margin_db);
}

// PSNR of the reference page after the BC format alone (the floor a perfect bake scores).
Expected<double> runtime_floor_psnr(const ReferenceLayer& r, BcFormat bc, BcQuality quality,
                                    const uint8_t* ref, int ps) {
  thread_local std::vector<uint8_t> blocks, decoded;
  blocks.resize(bc_image_bytes(bc, ps, ps));
  decoded.resize(size_t(ps) * ps * r.spec.texel_bytes());
  const int channels = int(r.spec.channels);
  VT_RETURN_IF_ERROR(bc_encode_image(bc, quality, ref, ps, ps, channels, blocks.data()));
  VT_RETURN_IF_ERROR(bc_decode_image(bc, blocks.data(), ps, ps, channels, decoded.data()));
  if (r.spec.texel_type != TexelType::kU8) {  // BC6H of half texels: the float PSNR
    AtlasPageError e;
    VT_RETURN_IF_ERROR(measure_page(r, ref, decoded.data(), ps, e));
    return e.psnr;
  }
  VT_ASSIGN_OR_RETURN(ImageError err, compare_images(ref, decoded.data(), ps, ps, channels));
  return all_channel_psnr(err);
}

// How close a page is to failing: 0 well inside its bounds, 1 at a bound, above 1 failing.
double badness(const AtlasPageError& e, const AtlasLayerBounds& b, bool normal) {
  if (e.missing) return 10.0;
  const double min_psnr = page_min_psnr(e, b);
  double s = std::max((min_psnr + 15.0 - e.psnr) / 15.0, e.mean_shift / b.max_mean_shift);
  if (normal) s = std::max({s, e.mean_deg / b.max_mean_deg, e.max_deg / b.max_max_deg});
  return s;
}

bool fails(const AtlasPageError& e, const AtlasLayerBounds& b, bool normal) {
  return e.missing || e.psnr < page_min_psnr(e, b) || e.mean_shift > b.max_mean_shift ||
         (normal && (e.mean_deg > b.max_mean_deg || e.max_deg > b.max_max_deg));
}

// A level's pages as a picture: each page a square coloured green (well inside its bounds)
// through yellow to red (at its bound), failing pages red with a white cross, pages the file
// does not hold black.
Rgba8Image heat_map(const PageGeometry& g, uint32_t level, const std::vector<double>& score,
                    const std::vector<uint8_t>& failed) {
  const uint32_t px = g.pages_x(level), py = g.pages_y(level);
  const uint32_t cell = std::clamp<uint32_t>(512 / std::max(px, py), 4, 64);
  Rgba8Image img;
  img.width = px * cell;
  img.height = py * cell;
  img.texels.assign(size_t(img.width) * img.height * 4, 0);
  for (uint32_t y = 0; y < img.height; ++y) {
    for (uint32_t x = 0; x < img.width; ++x) {
      const size_t k = size_t(y / cell) * px + x / cell;
      uint8_t* p = &img.texels[(size_t(y) * img.width + x) * 4];
      p[3] = 255;
      if (score[k] < 0) continue;  // not in the file
      const uint32_t cx = x % cell, cy = y % cell;
      if (cx == 0 || cy == 0) continue;  // grid lines
      const double s = std::clamp(score[k], 0.0, 1.0);
      p[0] = uint8_t(std::min(1.0, 2 * s) * 255);
      p[1] = uint8_t(std::min(1.0, 2 - 2 * s) * 200);
      p[2] = 40;
      if (failed[k]) {
        p[0] = 230, p[1] = p[2] = 0;
        if (cx == cy || cx + cy == cell) p[0] = p[1] = p[2] = 255;
      }
    }
  }
  return img;
}

struct LayerRun {
  ReferenceLayer ref;
  AtlasLayerReport report;
  double psnr_sum = 0;
  std::vector<AtlasPageError> pages;  // every checked page, for the worst list
};

// Checks one level of one layer's pages and writes its heat map; the level stays in `run.ref`.
Status check_level(const PageSource& source, const PageFileReader& reader, uint32_t level,
                   const AtlasCheckOptions& o, LayerRun& run) {
  const PageGeometry& g = reader.geometry();
  ReferenceLayer& r = run.ref;
  const uint32_t px = g.pages_x(level), ps = g.page_size();
  const size_t n = size_t(ps) * ps, bytes = n * r.spec.texel_bytes();
  const bool normal = r.spec.semantic == LayerSemantic::kNormal;
  std::vector<AtlasPageError> errors(g.pages_in_level(level));
  std::vector<Status> status(errors.size());
  std::vector<int8_t> checked(errors.size());
  // The runtime format's floor, as the runtime gets there: stored BC blocks were encoded by
  // the baker (default quality), DCT pages are transcoded by the streamer (real-time).
  const std::optional<BcFormat> floor_bc =
      o.stored_texels ? std::nullopt : runtime_bc_format(source.upload_format(r.index));
  const BcQuality floor_quality =
      r.spec.codec == PageCodec::kBcZstd ? BcQuality::kNormal : BcQuality::kRealtime;
  parallel_for(errors.size(), o.threads, [&](size_t k) {
    const PageId id{level, uint32_t(k % px), uint32_t(k / px)};
    AtlasPageError& e = errors[k];
    e.id = id;
    e.layer = r.index;
    auto entry = reader.entry(id, r.index);
    if (!entry.ok()) {
      status[k] = entry.status();
      return;
    }
    if (entry->state == PageState::kAbsent) {
      e.missing = page_has_coverage(g, id, r.coverage.data());
      checked[k] = e.missing;
      return;
    }
    thread_local std::vector<float> work;
    thread_local std::vector<uint8_t> ref, test, upload;
    work.resize(n * r.work_channels);
    ref.resize(bytes);
    test.resize(bytes);
    cut_page_from_level(g, id, r.spec.address_mode, r.level.data(), r.work_channels, work.data());
    store_reference(r, work.data(), ps, ref.data());
    status[k] = o.stored_texels ? reader.read_texels(id, r.index, test)
                                : uploaded_texels(source, r.spec, id, r.index, upload, test.data());
    if (status[k].ok()) status[k] = measure_page(r, ref.data(), test.data(), int(ps), e);
    if (status[k].ok() && floor_bc && e.psnr < run.report.bounds.min_psnr) {
      auto floor = runtime_floor_psnr(r, *floor_bc, floor_quality, ref.data(), int(ps));
      if (floor.ok()) e.runtime_floor_psnr = *floor;
      status[k] = floor.status();
    }
    checked[k] = 1;
  });
  std::vector<double> score(errors.size(), -1.0);
  std::vector<uint8_t> failed(errors.size(), 0);
  for (size_t k = 0; k < errors.size(); ++k) {
    VT_RETURN_IF_ERROR(status[k].with_context(r.spec.name));
    if (!checked[k]) continue;
    AtlasPageError& e = errors[k];
    e.failed = fails(e, run.report.bounds, normal);
    failed[k] = e.failed;
    score[k] = e.failed ? 1.0 : badness(e, run.report.bounds, normal);
    AtlasLayerReport& lr = run.report;
    lr.pages_checked++;
    lr.pages_failed += e.failed;
    if (e.missing) {
      run.pages.push_back(e);
      continue;
    }
    lr.min_psnr = std::min(lr.min_psnr, e.psnr);
    lr.worst_mean_shift = std::max(lr.worst_mean_shift, e.mean_shift);
    run.psnr_sum += e.psnr;
    lr.worst_mean_deg = std::max(lr.worst_mean_deg, e.mean_deg);
    lr.worst_max_deg = std::max(lr.worst_max_deg, e.max_deg);
    run.pages.push_back(e);
  }
  if (!o.out_dir.empty()) {
    const std::string path =
        o.out_dir + "/atlas_" + r.spec.name + "_level" + std::to_string(level) + ".png";
    VT_RETURN_IF_ERROR(write_png(path, heat_map(g, level, score, failed)));
    run.report.heat_maps.push_back(path);
  }
  return Status::Ok();
}

// The next level of the reference, as the build makes it: filtered from the dilated level within
// each chart (under the level's coverage), then dilated under the halved coverage.
void next_level(const PageGeometry& g, uint32_t level, const DownsampleKernel& kernel,
                ReferenceLayer& r) {
  const uint32_t w = g.level_width(level), h = g.level_height(level);
  r.level =
      downsample_level(kernel, r.rules, r.level.data(), w, h, r.work_channels, r.coverage.data());
  r.coverage = downsample_coverage(r.coverage.data(), w, h);
  pull_push(r.level.data(), r.coverage.data(), g.level_width(level + 1), g.level_height(level + 1),
            r.work_channels);
}

std::string page_line(const AtlasPageError& e, bool normal) {
  char buf[160];
  if (e.missing) {
    std::snprintf(buf, sizeof buf, "(%u, %u, %u) missing", e.id.level, e.id.x, e.id.y);
  } else if (normal) {
    std::snprintf(buf, sizeof buf, "(%u, %u, %u) %.1f dB, %.2f/%.1f deg", e.id.level, e.id.x,
                  e.id.y, e.psnr, e.mean_deg, e.max_deg);
  } else {
    std::snprintf(buf, sizeof buf, "(%u, %u, %u) %.1f dB, mean shift %.1f", e.id.level, e.id.x,
                  e.id.y, e.psnr, e.mean_shift);
  }
  std::string line = buf;
  if (e.runtime_floor_psnr > 0) {
    std::snprintf(buf, sizeof buf, " (runtime format alone %.1f dB)", e.runtime_floor_psnr);
    line += buf;
  }
  return line;
}

// Sorts the layer's pages worst first, keeps the failing ones and the closest to failing, and
// names the failure.
void finish_layer(LayerRun& run, uint32_t keep, std::vector<std::string>& failures) {
  AtlasLayerReport& lr = run.report;
  const bool normal = lr.semantic == LayerSemantic::kNormal;
  std::stable_sort(run.pages.begin(), run.pages.end(), [&](const auto& a, const auto& b) {
    return badness(a, lr.bounds, normal) > badness(b, lr.bounds, normal);
  });
  const size_t n = std::max<size_t>(keep, std::min<size_t>(lr.pages_failed, 100));
  lr.worst.assign(run.pages.begin(), run.pages.begin() + std::min(n, run.pages.size()));
  const uint64_t measured = run.pages.size();
  lr.mean_psnr = measured ? run.psnr_sum / double(measured) : kPsnrIdentical;
  if (lr.pages_failed == 0) return;
  std::string line = lr.name + ": " + std::to_string(lr.pages_failed) + " of " +
                     std::to_string(lr.pages_checked) + " pages fail (";
  char bound[96];
  if (normal) {
    std::snprintf(bound, sizeof bound, ">= %.1f dB, mean <= %.1f deg, max <= %.0f deg",
                  lr.bounds.min_psnr, lr.bounds.max_mean_deg, lr.bounds.max_max_deg);
  } else {
    std::snprintf(bound, sizeof bound, ">= %.1f dB, mean shift <= %.1f", lr.bounds.min_psnr,
                  lr.bounds.max_mean_shift);
  }
  line += bound;
  line += "): ";
  for (size_t i = 0; i < std::min<size_t>(lr.pages_failed, 4); ++i)
    line += (i ? ", " : "") + page_line(lr.worst[i], normal);
  if (lr.pages_failed > 4) line += ", ...";
  failures.push_back(line);
}

}  // namespace

Status uploaded_texels(const PageSource& source, const LayerSpec& spec, const PageId& id,
                       uint32_t layer, std::vector<uint8_t>& upload, uint8_t* out) {
  upload.resize(source.upload_bytes(layer));
  VT_RETURN_IF_ERROR(source.load(id, layer, upload));
  const int ps = int(source.geometry().page_size());
  const RuntimeFormatInfo& info = *runtime_format_info(source.upload_format(layer));
  if (info.bc) return bc_decode_image(*info.bc, upload.data(), ps, ps, spec.channels, out);
  if (info.is_float) {
    // The upload widens float texels to the format's channels (RGBA16F, RGBA32F): keep the
    // layer's own.
    const size_t n = size_t(ps) * ps, tb = spec.texel_bytes();
    const size_t upload_tb = tb / std::max<uint32_t>(spec.channels, 1) * info.channels;
    for (size_t t = 0; t < n; ++t) std::memcpy(out + t * tb, upload.data() + t * upload_tb, tb);
    return Status::Ok();
  }
  const size_t n = size_t(ps) * ps;
  for (size_t t = 0; t < n; ++t)
    for (uint32_t c = 0; c < spec.channels; ++c)
      out[t * spec.channels + c] = c < info.channels ? upload[t * info.channels + c] : 0;
  return Status::Ok();
}

AtlasLayerBounds default_atlas_bounds(const LayerSpec& layer) {
  // Page PSNR bounds: format/page_error_bounds.h. Largest page mean shift on the sample scene
  // (8-bit steps): dct 1.0 / 0.40 / 0.98 / 5.1 (albedo / normal / orm / emissive; ringing
  // clipped at black around the emissive lines), bc and raw 1.5 / 0.45 / 0.85 / 0.58. Emissive
  // at half strength shifts a DCT page by 16.
  const bool bc_upload = runtime_bc_format(layer.runtime_format).has_value();
  AtlasLayerBounds b;
  if (layer.codec != PageCodec::kDct && !bc_upload) {
    b.min_psnr = 60;  // lossless all the way: only rounding
    b.max_mean_deg = 0.5;
    b.max_max_deg = 2;
    b.max_mean_shift = 1;
    return b;
  }
  const double dct = kDctPagePsnr.of(layer.semantic), bc = kBcPagePsnr.of(layer.semantic);
  b.min_psnr = layer.codec == PageCodec::kDct ? dct : bc;
  if (layer.codec == PageCodec::kDct) b.floor_margin_db += bc - dct;
  b.max_mean_deg = layer.codec == PageCodec::kDct ? 4.0 : 3.0;
  b.max_max_deg = layer.codec == PageCodec::kDct ? 50.0 : 45.0;
  b.max_mean_shift = layer.codec == PageCodec::kDct ? 8.0 : 3.0;
  return b;
}

Expected<AtlasCheckReport> check_atlas_pages(std::shared_ptr<const PageFileReader> reader,
                                             const scene::Scene& original,
                                             const scene::Scene& unwrapped,
                                             const AtlasCheckOptions& o) {
  VT_ASSIGN_OR_RETURN(const BakeSettings settings, baked_settings(*reader));
  return check_atlas_pages(std::move(reader), settings, original, unwrapped, o);
}

Expected<AtlasCheckReport> check_atlas_pages(std::shared_ptr<const PageFileReader> reader,
                                             const BakeSettings& settings,
                                             const scene::Scene& original,
                                             const scene::Scene& unwrapped,
                                             const AtlasCheckOptions& o) {
  AtlasCheckReport report;
  if (!o.enabled) {
    report.note = "disabled";
    return report;
  }
  const auto t0 = Clock::now();
  const PageGeometry& g = reader->geometry();
  if (!settings.scene_bake) {
    return Error(ErrorCode::kInvalidArgument,
                 reader->path() + ": not a scene bake (metadata has no \"tool\": \"vtbake bake\")");
  }
  if (original.materials.size() != unwrapped.materials.size()) {
    return Error(ErrorCode::kInvalidArgument,
                 "the unwrapped scene has " + std::to_string(unwrapped.materials.size()) +
                     " materials, the original " + std::to_string(original.materials.size()) +
                     ": not a bake of this scene");
  }
  // The transfer's buffers (as bake_scene counts them) and two levels of the widest layer.
  const uint64_t texels = uint64_t(g.width) * g.height;
  const uint64_t need = texels * (13 * sizeof(float) + 1 + 24) + texels * 4 * sizeof(float) * 2;
  if (need > o.memory_limit) {
    report.note = "skipped: the reference of a " + std::to_string(g.width) + "x" +
                  std::to_string(g.height) + " atlas needs about " + std::to_string(need >> 20) +
                  " MiB, over the memory limit";
    return report;
  }
  VT_ASSIGN_OR_RETURN(std::unique_ptr<PageSource> source, make_page_file_source(reader));

  scene::Scene scene = unwrapped;
  scene.materials = original.materials;
  scene.images = original.images;
  place_original_lights(original, scene);
  TransferOptions to;
  to.width = g.width;
  to.height = g.height;
  to.supersample = settings.supersample;
  to.lighting = settings.lighting;
  to.threads = o.threads;
  to.scratch_dir = o.scratch_dir;
  to.missing_textures = settings.missing_textures;
  auto transfer = transfer_materials(scene, to);
  if (!transfer.ok()) return transfer.status().with_context("atlas check: transfer");
  report.transfer_seconds = seconds_since(t0);

  const DownsampleKernel kernel = make_downsample_kernel(settings.filter);
  report.ran = true;
  for (uint32_t li = 0; li < reader->layers().size(); ++li) {
    const LayerSpec& spec = reader->layers()[li];
    LayerRun run;
    AtlasLayerReport& lr = run.report;
    lr.name = spec.name;
    lr.semantic = spec.semantic;
    lr.codec = to_string(spec.codec);
    lr.runtime_format = to_string(spec.runtime_format);
    lr.bounds = default_atlas_bounds(spec);
    lr.bounds.min_psnr += o.psnr_offset_db;
    lr.min_psnr = kPsnrIdentical;
    auto ref = make_reference_layer(li, spec, *transfer);
    if (!ref.ok()) {
      lr.note = "not checked: " + ref.status().message();
      report.layers.push_back(std::move(lr));
      continue;
    }
    run.ref = std::move(ref).value();
    for (uint32_t level = 0; level < g.level_count(); ++level) {
      VT_RETURN_IF_ERROR(check_level(*source, *reader, level, o, run));
      if (level + 1 < g.level_count()) next_level(g, level, kernel, run.ref);
    }
    finish_layer(run, o.worst_pages, report.failures);
    report.layers.push_back(std::move(lr));
  }
  report.seconds = seconds_since(t0);
  return report;
}

nlohmann::json to_json(const AtlasCheckReport& r) {
  using nlohmann::json;
  json layers = json::array();
  for (const AtlasLayerReport& l : r.layers) {
    json worst = json::array();
    for (const AtlasPageError& e : l.worst) {
      json p = {{"level", e.id.level},  {"x", e.id.x},          {"y", e.id.y},
                {"psnr", e.psnr},       {"max_abs", e.max_abs}, {"mean_shift", e.mean_shift},
                {"missing", e.missing}, {"failed", e.failed}};
      if (e.runtime_floor_psnr > 0) p["runtime_floor_psnr"] = e.runtime_floor_psnr;
      if (l.semantic == LayerSemantic::kNormal) {
        p["mean_deg"] = e.mean_deg;
        p["max_deg"] = e.max_deg;
      }
      worst.push_back(p);
    }
    json layer = {
        {"name", l.name},
        {"codec", l.codec},
        {"runtime_format", l.runtime_format},
        {"passed", l.pages_failed == 0},
        {"pages_checked", l.pages_checked},
        {"pages_failed", l.pages_failed},
        {"min_psnr", l.min_psnr},
        {"mean_psnr", l.mean_psnr},
        {"worst_mean_shift", l.worst_mean_shift},
        {"bounds", {{"min_psnr", l.bounds.min_psnr}, {"max_mean_shift", l.bounds.max_mean_shift}}},
        {"worst_pages", worst},
        {"heat_maps", l.heat_maps}};
    if (l.semantic == LayerSemantic::kNormal) {
      layer["worst_mean_deg"] = l.worst_mean_deg;
      layer["worst_max_deg"] = l.worst_max_deg;
      layer["bounds"]["max_mean_deg"] = l.bounds.max_mean_deg;
      layer["bounds"]["max_max_deg"] = l.bounds.max_max_deg;
    }
    if (!l.note.empty()) layer["note"] = l.note;
    layers.push_back(layer);
  }
  return {{"ran", r.ran},
          {"passed", r.passed()},
          {"note", r.note},
          {"failures", r.failures},
          {"transfer_seconds", r.transfer_seconds},
          {"seconds", r.seconds},
          {"layers", layers}};
}

}  // namespace vt::render
