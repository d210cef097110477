// `vtbake sample-scene DIR`: writes the procedural sample scene (samples/sample_scene.h) that
// `vtbake bake` bakes with no download.
#include <cstdio>

#include "cli/cli_util.h"
#include "cli/command.h"
#include "cli/json_output.h"
#include "samples/sample_scene.h"

namespace {

vt::cli::CommandRunner make_sample_scene(CLI::App& app) {
  auto dir = std::make_shared<std::string>();
  auto opt = std::make_shared<vt::SampleSceneOptions>();
  app.add_option("dir", *dir, "Folder to write scene.gltf, scene.bin and the textures into")
      ->required();
  app.add_option("--ground-cells", opt->ground_cells, "Ground grid cells per side")
      ->check(CLI::Range(1, 4096));
  app.add_option("--sphere-segments", opt->sphere_segments, "Sphere and torus segments")
      ->check(CLI::Range(4, 8192));
  app.add_option("--texture-size", opt->texture_size, "Side of every texture in texels")
      ->check(CLI::Range(16, 8192));
  app.add_flag("--lights", opt->lights,
               "Add a sun, a point and a spot light (KHR_lights_punctual, required): the bake "
               "gets a lighting layer");
  return [dir, opt](const vt::cli::GlobalOptions& global) -> int {
    vt::Status s = vt::write_sample_scene(*dir, *opt);
    if (!s.ok()) return vt::cli::report_error("sample-scene", s);
    if (global.json) {
      vt::cli::print_json("sample-scene", vt::cli::kExitOk, {{"output", *dir + "/scene.gltf"}});
    } else if (!global.quiet) {
      std::printf("wrote %s/scene.gltf\n", dir->c_str());
    }
    return vt::cli::kExitOk;
  };
}

const vt::cli::CommandRegistration kSampleScene{
    "sample-scene", "Write the procedural sample scene (glTF + textures) into a folder",
    make_sample_scene};

}  // namespace
