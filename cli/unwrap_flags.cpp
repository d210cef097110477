// The unwrap flags (see unwrap_flags.h).
#include "cli/unwrap_flags.h"

namespace vt::cli {

void add_unwrap_flags(CLI::App& app, unwrap::UnwrapOptions& o) {
  auto* tpu = app.add_option("--texels-per-unit", o.texels_per_unit,
                             "World texel density (default: twice the textures' density on "
                             "the surfaces, 90th percentile by area, within --max-size)")
                  ->check(CLI::PositiveNumber);
  // 16384 pages a side is the page format's 2^28 pages in level 0; the memory limit and the
  // format's 2^24 texels a side are checked before the unwrap.
  app.add_option("--size", o.size_pages,
                 "Fit the atlas to this many pages per side (density derived; default: from "
                 "the textures)")
      ->check(CLI::Range(1, 16384))
      ->excludes(tpu);
  app.add_option("--max-size", o.max_size_pages,
                 "Largest atlas side in pages when the density comes from the textures (the "
                 "scene bake's --memory-limit can lower it)")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  app.add_option("--density", o.density_file,
                 "Density file (JSON): {\"materials\": {NAME: texels per unit or "
                 "{\"scale\": K}}, \"objects\" (or \"nodes\"): {NODE: ...}, "
                 "\"texels_per_unit\" or \"size_pages\"}; default: SCENE.density.json beside "
                 "the scene when it exists, '-' = none");
  // The unwrapper's own bound.
  app.add_option("--padding", o.padding, "Empty texels between charts")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  app.add_option_function<std::string>(
         "--method",
         [&o](const std::string& name) {
           o.method = name == "arap" ? unwrap::Method::kArap : unwrap::Method::kLscm;
         },
         "Chart parameterisation: lscm (default) or arap")
      ->check(CLI::IsMember({"lscm", "arap"}));
  app.add_flag("--share-instances", o.share_instances,
               "Instances of a mesh share one chart set (default: unique texels per instance)");
  app.add_option("--max-stretch", o.max_chart_stretch,
                 "Charts with L2 stretch above this are split and redone")
      ->check(CLI::Range(1.0, 100.0))
      ->capture_default_str();
  app.add_option("--split-rounds", o.max_split_rounds, "Stretch split-and-redo rounds (0 = none)")
      ->check(CLI::Range(0, 64))
      ->capture_default_str();
  app.add_option("--chart-angle", o.max_chart_angle_deg,
                 "Largest normal deviation inside a chart, degrees")
      ->check(CLI::Range(1.0, 179.0))
      ->capture_default_str();
}

}  // namespace vt::cli
