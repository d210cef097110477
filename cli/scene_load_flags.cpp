// The scene loading flags (see scene_load_flags.h).
#include "cli/scene_load_flags.h"

namespace vt::cli {

void add_scene_load_flags(CLI::App& app, scene::SceneLoadOptions& o) {
  app.add_flag("--allow-outside-paths", o.allow_outside_paths,
               "Read images and buffers the scene names outside its folder tree (by default a "
               "scene may name files in its own folder, below it or in a sibling folder: at "
               "most one '..', symlinks resolved; absolute paths elsewhere are refused)");
  app.add_option("--texture-path", o.texture_folders,
                 "Folder to look in for an image the scene names that is not where it says (a "
                 "game's shared textures: TORCS's data/textures); repeat it to search several, "
                 "in order. Letter case is ignored, and another image extension is tried")
      ->check(CLI::ExistingDirectory)
      ->allow_extra_args(false);
}

}  // namespace vt::cli
