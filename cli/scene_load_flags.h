// The flags of vt::scene::SceneLoadOptions, registered once for every command that loads a
// scene (`bake`, `unwrap`, `validate`), so each has one spelling and one help text.
#pragma once

#include <CLI/CLI.hpp>

#include "scene/scene.h"

namespace vt::cli {

// --allow-outside-paths.
void add_scene_load_flags(CLI::App& app, scene::SceneLoadOptions& options);

}  // namespace vt::cli
