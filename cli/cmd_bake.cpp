// `vtbake bake SCENE -o OUT.vtpf`: the main job. Unwraps the scene, transfers its materials into
// the atlas, builds the page file and writes the unwrapped scene beside it. Flags map onto
// vt::SceneBakeOptions; the work is bake_scene() (bake/scene_bake.h).
#include <cmath>
#include <cstdio>
#include <string>

#include "bake/scene_bake.h"
#include "cli/cli_util.h"
#include "cli/command.h"

namespace {

using vt::cli::kExitBadInput;
using vt::cli::kExitFailure;
using vt::cli::kExitOk;

struct BakeFlags {
  std::string scene;
  std::string output;
  std::string unwrapped;
  double texels_per_unit = 0;
  int size_pages = 0;
  int padding = 4;
  std::string method = "lscm";
  int supersample = 1;
  std::string codec = "dct";
  bool share_instances = false;
  std::string memory_limit = "8G";
};

int bad(const std::string& msg) {
  return vt::cli::bad_usage("bake", msg);
}

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
    std::printf(")");
  }
  std::printf("\n");
  std::printf("  pages      %llu in %u levels: %llu stored, %llu constant, %llu absent\n",
              (unsigned long long)s.build.pages, g.level_count(),
              (unsigned long long)s.build.stored, (unsigned long long)s.build.constant,
              (unsigned long long)s.build.absent);
  std::printf("  bytes      %llu in the file, %llu raw texels, ratio %.1f:1\n",
              (unsigned long long)s.build.file_bytes, (unsigned long long)s.raw_bytes, s.ratio);
  std::printf("  time      ");
  for (const auto& st : s.stages) std::printf(" %s %.2f s,", st.name.c_str(), st.seconds);
  std::printf(" total %.2f s\n", s.seconds);
}

vt::cli::CommandRunner make_bake(CLI::App& app) {
  auto f = std::make_shared<BakeFlags>();
  app.add_option("scene", f->scene, "Scene to bake (.gltf, .glb, .obj, .ply, .drc)")->required();
  app.add_option("-o,--output", f->output, "Page file to write (.vtpf)")->required();
  app.add_option("--unwrapped", f->unwrapped,
                 "Where to write the unwrapped scene (.glb; default OUT.glb; '-' = not written)");
  auto* tpu = app.add_option("--texels-per-unit", f->texels_per_unit, "World texel density")
                  ->check(CLI::PositiveNumber);
  auto* size = app.add_option("--size", f->size_pages, "Atlas side in pages (default 16)")
                   ->check(CLI::Range(1, 1024));
  tpu->excludes(size);
  app.add_option("--padding", f->padding, "Empty texels between charts")->check(CLI::Range(0, 64));
  app.add_option("--method", f->method, "Parameterisation: lscm or arap")
      ->check(CLI::IsMember({"lscm", "arap"}));
  app.add_option("--supersample", f->supersample, "Transfer samples per texel: 1, 4 or 16")
      ->check(CLI::IsMember({1, 4, 16}));
  app.add_option("--codec", f->codec,
                 "Page codec: dct[:QUALITY][:adaptive], bc[:high|fast] or raw");
  app.add_flag("--share-instances", f->share_instances,
               "Instances of one mesh share texels (default: each gets its own)");
  app.add_option("--memory-limit", f->memory_limit, "Memory budget, e.g. 512M, 8G (default 8G)");
  return [f](const vt::cli::GlobalOptions& global) -> int {
    vt::SceneBakeOptions o;
    o.output = f->output;
    o.unwrapped = f->unwrapped;
    o.unwrap.texels_per_unit = f->texels_per_unit;
    if (f->size_pages > 0) o.unwrap.size_pages = f->size_pages;
    o.unwrap.padding = f->padding;
    o.unwrap.method = f->method == "arap" ? vt::unwrap::Method::kArap : vt::unwrap::Method::kLscm;
    o.unwrap.share_instances = f->share_instances;
    o.supersample = f->supersample;
    if (vt::Status st = vt::cli::parse_codec(f->codec, &o.codec); !st.ok())
      return bad(st.message());
    if (vt::Status st = vt::cli::parse_byte_size(f->memory_limit, &o.memory_limit); !st.ok())
      return bad("--memory-limit: " + st.message());
    o.threads = global.threads;
    // Stage, its fraction, elapsed time; redrawn at once when the stage changes.
    vt::cli::ProgressLine progress(global.quiet);
    std::string stage;
    o.progress = [&](const vt::SceneBakeProgress& p) {
      if (!progress.due(stage != p.stage || p.fraction >= 1.0)) return;
      stage = p.stage;
      progress.print("%-12s %5.1f%%  %6.1f s   ", p.stage, 100.0 * p.fraction,
                     progress.elapsed_seconds());
    };
    auto summary = vt::bake_scene(f->scene, o);
    progress.done();
    if (!summary.ok()) return vt::cli::report_error("bake", summary.status());
    if (global.json) {
      std::printf("%s\n", vt::summary_json(*summary).c_str());
    } else {
      print_summary(*summary);
    }
    return kExitOk;
  };
}

const vt::cli::CommandRegistration kBake{
    "bake", "Bake a scene's materials into a page file (unwrap, transfer, pyramid, pages)",
    make_bake};

}  // namespace
