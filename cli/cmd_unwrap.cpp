// `vtbake unwrap SCENE -o OUT.glb`: unique atlas UVs for every surface of a scene, plus the
// unwrap report (JSON) and a picture of the atlas (PNG) beside the output.
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "bake/unwrap/unwrap.h"
#include "cli/cli_util.h"
#include "cli/command.h"
#include "cli/json_output.h"
#include "cli/scene_load_flags.h"
#include "cli/unwrap_flags.h"
#include "format/atomic_output.h"
#include "scene/scene.h"

namespace {

struct Args {
  std::string input, output, report, picture;
  vt::unwrap::UnwrapOptions options;
  vt::scene::SceneLoadOptions load;
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
  sub.add_option(
         "scene", args->input,
         "Input scene: .gltf, .glb, .obj, .ply, .drc, .ac, .acc, or what assimp reads (.fbx, .dae, "
         ".3ds, .md3, ...)")
      ->required();
  sub.add_option("-o,--output", args->output, "Output .glb with the atlas UV set added")
      ->required();
  vt::cli::add_unwrap_flags(sub, args->options);
  vt::cli::add_scene_load_flags(sub, args->load);
  sub.add_option("--report", args->report, "Report JSON path (default OUT.report.json)");
  sub.add_option("--picture", args->picture, "Atlas PNG path (default OUT.atlas.png)");
  return [args](const vt::cli::GlobalOptions& global) -> int {
    using Clock = std::chrono::steady_clock;
    auto& a = *args;
    a.options.threads = global.threads;
    if (a.report.empty()) a.report = stem(a.output) + ".report.json";
    if (a.picture.empty()) a.picture = stem(a.output) + ".atlas.png";

    auto t0 = Clock::now();
    if (vt::Status in = vt::check_input_file(a.input); !in.ok())
      return vt::cli::report_error("unwrap", in);
    auto scene = vt::scene::load_scene(a.input, a.load);
    if (!scene.ok()) return vt::cli::report_error("unwrap", scene.status());
    double load_s = std::chrono::duration<double>(Clock::now() - t0).count();
    for (const std::string& w : scene->warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    if (!global.quiet)
      std::fprintf(stderr, "loaded %s: %zu meshes, %zu triangles (%.2f s)\n", a.input.c_str(),
                   scene->meshes.size(), scene->triangle_count(), load_s);
    auto result = vt::unwrap::unwrap_scene(*scene, a.options);
    if (!result.ok()) return vt::cli::report_error("unwrap", result.status().with_context(a.input));
    vt::Status st = vt::unwrap::save_unwrapped_glb(*result, a.output);
    if (!st.ok()) return vt::cli::report_error("unwrap", st);
    std::string report = vt::unwrap::report_json(result->stats);
    st = vt::write_output_bytes(a.report, report + "\n");
    if (!st.ok()) return vt::cli::report_error("unwrap", st);
    st = vt::unwrap::write_atlas_picture(*result, a.picture);
    if (!st.ok()) std::fprintf(stderr, "vtbake unwrap: warning: %s\n", st.message().c_str());
    const auto& s = result->stats;
    for (const std::string& w : s.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    bool valid = s.flipped_triangles == 0 && s.overlapping_triangles == 0 &&
                 s.overlapping_texels == 0 && s.unmapped_faces == 0;
    if (global.json) {
      nlohmann::json j = nlohmann::json::parse(report);
      j["input"] = a.input;
      j["output"] = a.output;
      j["outputs"] = {a.output, a.report, a.picture};
      vt::cli::print_json("unwrap", valid ? vt::cli::kExitOk : vt::cli::kExitFailure, j);
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
    return valid ? vt::cli::kExitOk : vt::cli::kExitFailure;
  };
}

const vt::cli::CommandRegistration kUnwrap{
    "unwrap", "Give every surface of a scene unique atlas texels", make_unwrap};

}  // namespace
