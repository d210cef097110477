// The main job (see scene_bake.h).
#include "bake/scene_bake.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "bake/build_summary_json.h"

namespace vt {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

std::string default_unwrapped(const std::string& output) {
  std::filesystem::path p(output);
  p.replace_extension(".glb");
  return p.string();
}

}  // namespace

std::vector<LayerInput> layer_inputs(TransferResult& transfer) {
  std::vector<LayerInput> inputs;
  for (TransferLayer& layer : transfer.layers) {
    ImageInfo info;
    info.width = transfer.width;
    info.height = transfer.height;
    info.channels = layer.channels;
    LayerInput in;
    in.semantic = layer.semantic;
    in.coverage = transfer.coverage;
    switch (layer.semantic) {
      case LayerSemantic::kNormal:
        info.is_float = true;  // unit xyz in [-1, 1], not n * 0.5 + 0.5
        break;
      case LayerSemantic::kAlbedo:
      case LayerSemantic::kEmissive:
        // Linear colour; values in [0, 1] go in as integer-like data so the build stores sRGB
        // 8-bit texels, HDR values keep float.
        info.is_float = layer.hdr;
        info.color_space = "linear";
        in.color_space = "linear";
        info.alpha_channel = layer.channels == 4 ? 3 : -1;
        break;
      default:
        info.is_float = layer.hdr;
        break;
    }
    in.source = std::make_shared<MemoryImageSource>(info, std::move(layer.texels));
    in.consume_source = true;  // the build converts the transfer's buffers in place
    layer.texels.clear();
    inputs.push_back(std::move(in));
  }
  return inputs;
}

Expected<SceneBakeSummary> bake_scene(const std::string& scene_path,
                                      const SceneBakeOptions& options) {
  auto t0 = Clock::now();
  if (options.progress) options.progress({"load", 0.0});
  auto loaded = scene::load_scene(scene_path);
  if (!loaded.ok()) return loaded.status();
  VT_RETURN_IF_ERROR(scene::validate_geometry(*loaded).with_context(scene_path));
  double load_seconds = seconds_since(t0);
  auto summary = bake_scene(*loaded, options);
  if (!summary.ok()) return summary.status().with_context(scene_path);
  summary->stages.insert(summary->stages.begin(), StageTime{"load", load_seconds});
  summary->seconds += load_seconds;
  return summary;
}

Expected<SceneBakeSummary> bake_scene(const scene::Scene& input, const SceneBakeOptions& options) {
  auto start = Clock::now();
  auto report = [&](const char* stage, double f) {
    if (options.progress) options.progress({stage, f});
  };
  const std::string& output = options.build.output;
  if (output.empty()) return Error(ErrorCode::kInvalidArgument, "no output path");
  if (input.triangle_count() == 0) {
    return Error(ErrorCode::kInvalidArgument, "the scene has no triangles to bake");
  }
  SceneBakeSummary summary;
  summary.output = output;
  summary.unwrapped = options.unwrapped.empty()  ? default_unwrapped(output)
                      : options.unwrapped == "-" ? ""
                                                 : options.unwrapped;

  // Unwrap.
  auto t0 = Clock::now();
  report("unwrap", 0.0);
  unwrap::UnwrapOptions uo = options.unwrap;
  uo.page_payload = int(options.build.payload);
  uo.threads = options.build.threads;
  auto unwrapped = unwrap::unwrap_scene(input, uo);
  if (!unwrapped.ok()) return unwrapped.status().with_context("unwrap");
  summary.unwrap = unwrapped->stats;
  summary.triangles = uint64_t(unwrapped->stats.faces);
  summary.stages.push_back({"unwrap", seconds_since(t0)});
  report("unwrap", 1.0);

  // Transfer. Its buffers: 13 floats per texel at most, plus coverage.
  t0 = Clock::now();
  const uint32_t W = uint32_t(unwrapped->stats.atlas_width),
                 H = uint32_t(unwrapped->stats.atlas_height);
  uint64_t transfer_bytes = uint64_t(W) * H * (13 * sizeof(float) + 1 + 24);
  if (transfer_bytes > options.build.memory_limit) {
    return Error(ErrorCode::kResourceLimit,
                 "transfer: an atlas of " + std::to_string(W) + "x" + std::to_string(H) +
                     " texels needs about " + std::to_string(transfer_bytes >> 20) +
                     " MiB, over the memory limit; lower --texels-per-unit or --size");
  }
  TransferOptions to;
  to.width = W, to.height = H;
  to.supersample = options.supersample;
  to.threads = options.build.threads;
  to.color_config = options.build.color_config;
  to.scratch_dir = options.build.scratch_dir.empty()
                       ? std::filesystem::path(output).parent_path().string()
                       : options.build.scratch_dir;
  to.progress = [&](double f) { report("transfer", f); };
  auto transfer = transfer_materials(unwrapped->scene, to);
  if (!transfer.ok()) return transfer.status().with_context("transfer");
  summary.transfer = transfer->stats;
  summary.stages.push_back({"transfer", seconds_since(t0)});

  // Pyramid, paging, encode.
  t0 = Clock::now();
  BuildOptions bo = options.build;
  bo.layers = layer_inputs(*transfer);
  bo.address = AddressMode::kClamp;
  nlohmann::json meta = {
      {"tool", "vtbake bake"},
      {"scene", input.source_path},
      {"supersample", options.supersample},
      {"texels_per_unit", summary.unwrap.texels_per_unit},
      {"atlas", {W, H}},
      {"unwrap_method", options.unwrap.method == unwrap::Method::kArap ? "arap" : "lscm"},
      {"padding", options.unwrap.padding},
  };
  bo.metadata_json = meta.dump();
  bo.progress = [&](const BuildProgress& p) {
    report("build", p.pages_total ? double(p.pages_done) / double(p.pages_total) : 0.0);
  };
  auto built = build_page_file(bo);
  if (!built.ok()) return built.status().with_context("build");
  summary.build = std::move(built).value();
  summary.stages.push_back({"build", seconds_since(t0)});

  // The unwrapped scene beside it.
  if (!summary.unwrapped.empty()) {
    t0 = Clock::now();
    report("write scene", 0.0);
    VT_RETURN_IF_ERROR(
        scene::save_glb(unwrapped->scene, summary.unwrapped).with_context(summary.unwrapped));
    summary.stages.push_back({"write scene", seconds_since(t0)});
  }

  summary.seconds = seconds_since(start);
  return summary;
}

nlohmann::json to_json(const SceneBakeSummary& s) {
  nlohmann::json stages = nlohmann::json::object();
  for (const StageTime& st : s.stages) stages[st.name] = st.seconds;
  const unwrap::UnwrapStats& u = s.unwrap;
  const TransferStats& t = s.transfer;
  return {
      {"output", s.output},
      {"unwrapped", s.unwrapped},
      {"triangles", s.triangles},
      {"atlas",
       {{"width", u.atlas_width},
        {"height", u.atlas_height},
        {"charts", u.charts},
        {"texels_per_unit", u.texels_per_unit},
        {"utilisation", u.utilisation},
        {"stretch_l2", u.stretch_l2}}},
      {"transfer",
       {{"covered_texels", t.covered_texels},
        {"edge_only_texels", t.edge_only_texels},
        {"contested_texels", t.contested_texels},
        {"samples", t.samples},
        {"texels_per_second", t.seconds > 0 ? double(t.covered_texels) / t.seconds : 0.0}}},
      {"build", to_json(s.build)},
      {"seconds", stages},
      {"total_seconds", s.seconds},
  };
}

}  // namespace vt
