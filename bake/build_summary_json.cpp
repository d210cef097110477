// The build summary's JSON (see build_summary_json.h).
#include "bake/build_summary_json.h"

#include <cmath>
#include <nlohmann/json.hpp>

namespace vt {
namespace {

nlohmann::json level_json(uint32_t level, const LevelSummary& v) {
  return {{"level", level},         {"width", v.width},     {"height", v.height},
          {"pages_x", v.pages_x},   {"pages_y", v.pages_y}, {"stored", v.stored},
          {"constant", v.constant}, {"absent", v.absent},   {"bytes", v.stored_bytes},
          {"scratch", v.scratch}};
}

nlohmann::json finite_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

// HDR error figures (codec/hdr_metrics.h): "log2_error_mean", "log2_error_max",
// "tonemapped_psnr_db" (null when exact), "relative_error_max".
nlohmann::json hdr_json(const HdrError& e) {
  return {{"log2_error_mean", e.log_abs_mean()},
          {"log2_error_max", e.log_abs_max},
          {"tonemapped_psnr_db", finite_or_null(e.tonemapped_psnr_db())},
          {"relative_error_max", e.relative_max}};
}

// The error after the runtime format ("runtime": PSNR, max error, normal angles) and the DCT
// page modes chosen ("dct_modes": pages per mode name).
void add_runtime_json(const LayerSummary& l, nlohmann::json& j) {
  const RuntimeError& r = l.runtime;
  if (r.samples > 0) {
    j["runtime"] = {{"format", to_string(l.spec.runtime_format)},
                    {"psnr_db", finite_or_null(r.psnr_db())},
                    {"max_error", r.max_error}};
  } else if (r.hdr.samples > 0) {
    j["runtime"] = {{"format", to_string(l.spec.runtime_format)}};
  }
  if (r.hdr.samples > 0) j["runtime"]["hdr"] = hdr_json(r.hdr);
  if (r.samples > 0) {
    if (r.normals > 0)
      j["runtime"]["normal_error_deg"] = {
          {"mean", r.angle_mean_deg()}, {"p99", r.angle_p99_deg()}, {"max", r.angle_max_deg}};
  }
  if (l.spec.codec != PageCodec::kDct) return;
  nlohmann::json modes = nlohmann::json::object();
  for (int m = 0; m < kDctModeKinds; ++m)
    if (l.dct_modes[m]) modes[dct_mode_name(uint8_t(m))] = l.dct_modes[m];
  j["dct_modes"] = modes;
}

nlohmann::json layer_json(const LayerSummary& l) {
  nlohmann::json j = {{"name", l.name},
                      {"semantic", to_string(l.spec.semantic)},
                      {"channels", l.spec.channels},
                      {"texel_type", to_string(l.spec.texel_type)},
                      {"codec", to_string(l.spec.codec)},
                      {"runtime_format", to_string(l.spec.runtime_format)},
                      {"color_space", to_string(l.spec.color_space)},
                      // JSON has no infinity: a lossless layer's PSNR is null.
                      {"psnr_db", std::isfinite(l.psnr_db) ? nlohmann::json(l.psnr_db) : nullptr},
                      {"max_error", l.max_error},
                      {"alpha_dropped", l.alpha_dropped},
                      {"non_finite", l.non_finite.non_finite},
                      {"negative", l.non_finite.negative}};
  add_runtime_json(l, j);
  if (l.hdr.samples > 0) j["hdr"] = hdr_json(l.hdr);  // half storage vs the floats
  if (l.non_finite.any()) {
    j["first_bad_texel"] = {{"x", l.non_finite.first_x},
                            {"y", l.non_finite.first_y},
                            {"channel", l.non_finite.first_channel}};
  }
  // Level-0 values outside [0, 1] that 8-bit storage clipped (psnr_db and runtime count them).
  j["clipped"] = {{"texels", l.clipped.texels},
                  {"values", l.clipped.values},
                  {"min", l.clipped.min_value},
                  {"max", l.clipped.max_value}};
  return j;
}

nlohmann::json update_json(const UpdateSummary& u) {
  return {{"requested", u.requested},
          {"unchanged", u.unchanged},
          {"pages_reused", u.reused},
          {"pages_reencoded", u.reencoded},
          {"pages_dropped", u.dropped},
          {"full_rebuild",
           u.full_rebuild.empty() ? nlohmann::json(nullptr) : nlohmann::json(u.full_rebuild)},
          {"tables_pinned", u.tables_pinned},
          {"tables_retrained", u.tables_retrained},
          {"tables_fit", u.tables_fit},
          {"tables_fit_pages", u.fit_pages}};
}

}  // namespace

uint64_t raw_texel_bytes(const BuildSummary& s) {
  const PageGeometry& g = s.geometry;
  uint64_t bytes = 0;
  for (const LayerSummary& layer : s.layers) {
    for (uint32_t l = 0; l < g.level_count(); ++l) {
      bytes += uint64_t(g.level_width(l)) * g.level_height(l) * layer.spec.texel_bytes();
    }
  }
  return bytes;
}

double compression_ratio(const BuildSummary& s) {
  return s.file_bytes ? double(raw_texel_bytes(s)) / double(s.file_bytes) : 0;
}

nlohmann::json to_json(const BuildSummary& s) {
  nlohmann::json levels = nlohmann::json::array();
  for (size_t l = 0; l < s.levels.size(); ++l)
    levels.push_back(level_json(uint32_t(l), s.levels[l]));
  nlohmann::json layers = nlohmann::json::array();
  for (const LayerSummary& l : s.layers) layers.push_back(layer_json(l));
  nlohmann::json seconds = nlohmann::json::object();
  for (const StageTime& t : s.stages) seconds[t.name] = t.seconds;
  nlohmann::json j = {
      {"width", s.geometry.width},
      {"height", s.geometry.height},
      {"payload", s.geometry.payload},
      {"border", s.geometry.border},
      {"pages",
       {{"total", s.pages}, {"stored", s.stored}, {"constant", s.constant}, {"absent", s.absent}}},
      {"bytes",
       {{"file", s.file_bytes},
        {"stored", s.stored_bytes},
        {"raw", raw_texel_bytes(s)},
        {"ratio", compression_ratio(s)},
        {"scratch_peak", s.scratch_bytes},
        {"level_memory_peak", s.level_memory_bytes}}},
      {"levels", levels},
      {"layers", layers},
      {"seconds", seconds}};
  if (!s.warnings.empty()) j["warnings"] = s.warnings;
  // Only for updates and pinned tables: a clean build's report keeps its schema.
  if (s.update.requested || s.update.tables_pinned) j["update"] = update_json(s.update);
  return j;
}

}  // namespace vt
