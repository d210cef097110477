// `vtbake unwrap SCENE -o OUT.glb`: unique atlas UVs for every surface of a scene, plus the
// unwrap report (JSON) and a picture of the atlas (PNG) beside the output.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

#include "scene/scene.h"
#include "bake/unwrap/unwrap.h"
#include "cli/command.h"

namespace {

struct Args {
  std::string input, output, report, picture;
  double texels_per_unit = 0;
  int size_pages = 0;
  std::string method = "lscm";
  vt::unwrap::UnwrapOptions options;
};

std::string stem(const std::string& path) {
  size_t dot = path.find_last_of('.');
  size_t slash = path.find_last_of('/');
  return (dot == std::string::npos || (slash != std::string::npos && dot < slash))
             ? path
             : path.substr(0, dot);
}

vt::cli::CommandRunner make_unwrap(CLI::App& sub) {
  auto args = std::make_shared<Args>();
  sub.add_option("scene", args->input, "Input scene: .gltf, .glb, .obj, .ply or .drc")->required();
  sub.add_option("-o,--output", args->output, "Output .glb with the atlas UV set added")
      ->required();
  auto* tpu = sub.add_option("--texels-per-unit", args->texels_per_unit, "World texel density")
                  ->check(CLI::PositiveNumber);
  sub.add_option("--size", args->size_pages,
                 "Target atlas side in pages (density derived), default 16")
      ->check(CLI::PositiveNumber)
      ->excludes(tpu);
  sub.add_option("--padding", args->options.padding, "Empty texels between charts (default 4)")
      ->check(CLI::Range(0, 1024));
  sub.add_option("--method", args->method, "Chart parameterisation: lscm (default) or arap")
      ->check(CLI::IsMember({"lscm", "arap"}));
  sub.add_flag("--share-instances", args->options.share_instances,
               "Instances of a mesh share one chart set (default: unique texels per instance)");
  sub.add_option("--max-stretch", args->options.max_chart_stretch,
                 "Charts with L2 stretch above this are split and redone (default 1.05)")
      ->check(CLI::Range(1.0, 100.0));
  sub.add_option("--split-rounds", args->options.max_split_rounds,
                 "Stretch split-and-redo rounds (default 4; 0 = none)")
      ->check(CLI::Range(0, 64));
  sub.add_option("--chart-angle", args->options.max_chart_angle_deg,
                 "Largest normal deviation inside a chart, degrees (default 60)")
      ->check(CLI::Range(1.0, 179.0));
  sub.add_option("--report", args->report, "Report JSON path (default OUT.report.json)");
  sub.add_option("--picture", args->picture, "Atlas PNG path (default OUT.atlas.png)");
  return [args](const vt::cli::GlobalOptions& global) {
    using Clock = std::chrono::steady_clock;
    auto& a = *args;
    a.options.texels_per_unit = a.texels_per_unit;
    if (a.texels_per_unit == 0) a.options.size_pages = a.size_pages > 0 ? a.size_pages : 16;
    a.options.method = a.method == "arap" ? vt::unwrap::Method::kArap : vt::unwrap::Method::kLscm;
    a.options.threads = global.threads;
    if (a.report.empty()) a.report = stem(a.output) + ".report.json";
    if (a.picture.empty()) a.picture = stem(a.output) + ".atlas.png";

    auto t0 = Clock::now();
    auto scene = vt::scene::load_scene(a.input);
    if (!scene.ok()) {
      std::fprintf(stderr, "vtbake unwrap: %s\n", scene.status().message().c_str());
      return vt::cli::kExitBadInput;
    }
    double load_s = std::chrono::duration<double>(Clock::now() - t0).count();
    if (!global.quiet)
      std::fprintf(stderr, "loaded %s: %zu meshes, %zu triangles (%.2f s)\n", a.input.c_str(),
                   scene->meshes.size(), scene->triangle_count(), load_s);
    auto result = vt::unwrap::unwrap_scene(*scene, a.options);
    if (!result.ok()) {
      std::fprintf(stderr, "vtbake unwrap: %s: %s\n", a.input.c_str(),
                   result.status().message().c_str());
      return result.status().code() == vt::ErrorCode::kInternal ? vt::cli::kExitFailure
                                                                : vt::cli::kExitBadInput;
    }
    vt::Status st = vt::scene::save_glb(result->scene, a.output);
    if (!st.ok()) {
      std::fprintf(stderr, "vtbake unwrap: %s\n", st.message().c_str());
      return vt::cli::kExitFailure;
    }
    std::string report = vt::unwrap::report_json(result->stats);
    std::ofstream(a.report) << report << "\n";
    st = vt::unwrap::write_atlas_picture(*result, a.picture);
    if (!st.ok()) std::fprintf(stderr, "vtbake unwrap: warning: %s\n", st.message().c_str());
    const auto& s = result->stats;
    if (global.json) {
      std::printf("%s\n", report.c_str());
    } else if (!global.quiet) {
      std::printf(
          "%s: %lld faces, %lld charts, atlas %dx%d (%dx%d pages), %.3f texels/unit\n"
          "utilisation %.3f, stretch L2 %.4f Linf %.3f, flipped %lld, overlapping triangles %lld, "
          "overlapping texels %lld\n"
          "time: segment %.2f s, parameterise %.2f s, pack %.2f s, output %.2f s, check %.2f s\n"
          "report %s, picture %s\n",
          a.output.c_str(), static_cast<long long>(s.faces), static_cast<long long>(s.charts),
          s.atlas_width, s.atlas_height, s.pages_x, s.pages_y, s.texels_per_unit, s.utilisation,
          s.stretch_l2, s.stretch_linf, static_cast<long long>(s.flipped_triangles),
          static_cast<long long>(s.overlapping_triangles),
          static_cast<long long>(s.overlapping_texels), s.seconds.segment, s.seconds.parameterize,
          s.seconds.pack, s.seconds.output, s.seconds.check, a.report.c_str(), a.picture.c_str());
    }
    bool valid = s.flipped_triangles == 0 && s.overlapping_triangles == 0 &&
                 s.overlapping_texels == 0 && s.unmapped_faces == 0;
    return valid ? vt::cli::kExitOk : vt::cli::kExitFailure;
  };
}

const vt::cli::CommandRegistration kUnwrap{
    "unwrap", "Give every surface of a scene unique atlas texels", make_unwrap};

}  // namespace
