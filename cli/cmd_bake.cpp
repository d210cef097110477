// `vtbake bake SCENE -o OUT.vtpf`: the main job. Unwraps the scene, transfers its materials into
// the atlas, builds the page file and writes the unwrapped scene beside it. Flags map onto
// vt::SceneBakeOptions; the work is bake_scene() (bake/scene_bake.h).
#include <cmath>
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "bake/build_summary_json.h"
#include "bake/scene_bake.h"
#include "cli/build_flags.h"
#include "cli/cli_util.h"
#include "cli/command.h"
#include "cli/layer_error_text.h"
#include "cli/scene_load_flags.h"
#include "cli/unwrap_flags.h"
#include "format/atomic_output.h"

namespace {

struct BakeArgs {
  std::string scene;
  vt::SceneBakeOptions options;
};

void print_summary(const vt::SceneBakeSummary& s) {
  const auto& g = s.build.geometry;
  std::printf("baked %s (unwrapped scene: %s)\n", s.output.c_str(),
              s.unwrapped.empty() ? "not written" : s.unwrapped.c_str());
  std::printf("  atlas      %u x %u texels, %lld charts, %.3g texels/unit, utilisation %.3f\n",
              g.width, g.height, (long long)s.unwrap.charts, s.unwrap.texels_per_unit,
              s.unwrap.utilisation);
  std::printf("  transfer   %llu triangles, %llu covered texels (%llu edge-only, %llu contested)\n",
              (unsigned long long)s.triangles, (unsigned long long)s.transfer.covered_texels,
              (unsigned long long)s.transfer.edge_only_texels,
              (unsigned long long)s.transfer.contested_texels);
  std::printf("  layers    ");
  for (const auto& l : s.build.layers) {
    std::printf(" %s(%u ch, %s", l.name.c_str(), unsigned(l.spec.channels),
                vt::to_string(l.spec.codec));
    if (std::isfinite(l.psnr_db)) std::printf(", %.1f dB", l.psnr_db);
    std::printf("%s)", vt::cli::runtime_error_text(l).c_str());
  }
  std::printf("\n");
  std::printf("  pages      %llu in %u levels: %llu stored, %llu constant, %llu absent\n",
              (unsigned long long)s.build.pages, g.level_count(),
              (unsigned long long)s.build.stored, (unsigned long long)s.build.constant,
              (unsigned long long)s.build.absent);
  std::printf("  bytes      %llu in the file, %llu raw texels, ratio %.1f:1\n",
              (unsigned long long)s.build.file_bytes,
              (unsigned long long)vt::raw_texel_bytes(s.build), vt::compression_ratio(s.build));
  if (s.build.update.requested || s.build.update.tables_pinned)
    std::printf("  %s\n", vt::update_text(s.build.update).c_str());
  std::printf("  time      ");
  for (const auto& st : s.stages) std::printf(" %s %.2f s,", st.name.c_str(), st.seconds);
  std::printf(" total %.2f s\n", s.seconds);
  // Peak RSS so far at the end of each stage: the first is the unwrap's own memory.
  std::printf("  memory    ");
  for (const auto& [stage, bytes] : s.peak_rss)
    std::printf(" %s %.0f MiB,", stage.c_str(), double(bytes) / (1 << 20));
  std::printf(" peak resident set at the end of each stage\n");
}

vt::cli::CommandRunner make_bake(CLI::App& app) {
  auto args = std::make_shared<BakeArgs>();
  vt::SceneBakeOptions& o = args->options;
  app.add_option("scene", args->scene, "Scene to bake (.gltf, .glb, .obj, .ply, .drc)")->required();
  app.add_option("--unwrapped", o.unwrapped,
                 "Where to write the unwrapped scene (.glb; default OUT.glb; '-' = not written)");
  app.add_option("--supersample", o.supersample, "Transfer samples per texel: 1, 4 or 16")
      ->check(CLI::IsMember({1, 4, 16}));
  app.add_option_function<std::string>(
         "--missing-textures",
         [&o](const std::string& v) {
           auto policy = vt::parse_missing_textures(v);
           if (!policy.ok())
             throw CLI::ValidationError("--missing-textures", policy.status().message());
           o.missing_textures = *policy;
         },
         "A texture that cannot be read: error (default: fail naming the material, slot and "
         "path) or warn (bake the slot from its factor alone and list the miss)")
      ->default_str("error");
  vt::cli::add_scene_load_flags(app, o.load);
  vt::cli::add_unwrap_flags(app, o.unwrap);
  vt::cli::add_build_flags(app, o.build);
  return [args](const vt::cli::GlobalOptions& global) -> int {
    vt::SceneBakeOptions& o = args->options;
    o.build.threads = global.threads;
    // Stage, its fraction, elapsed time; redrawn at once when the stage changes.
    vt::cli::ProgressLine progress(global.quiet);
    std::string stage;
    o.progress = [&](const vt::SceneBakeProgress& p) {
      if (!progress.due(stage != p.stage || p.fraction >= 1.0)) return;
      stage = p.stage;
      progress.print("%-12s %5.1f%%  %6.1f s   ", p.stage, 100.0 * p.fraction,
                     progress.elapsed_seconds());
    };
    if (vt::Status in = vt::check_input_file(args->scene); !in.ok())
      return vt::cli::report_error("bake", in);
    auto summary = vt::bake_scene(args->scene, o);
    progress.done();
    if (!summary.ok()) return vt::cli::report_error("bake", summary.status());
    for (const std::string& w : summary->warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    if (global.json) {
      std::printf("%s\n", vt::to_json(*summary).dump(2).c_str());
    } else {
      print_summary(*summary);
    }
    return vt::cli::kExitOk;
  };
}

const vt::cli::CommandRegistration kBake{
    "bake", "Bake a scene's materials into a page file (unwrap, transfer, pyramid, pages)",
    make_bake};

}  // namespace
