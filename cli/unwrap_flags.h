// The flags of vt::unwrap::UnwrapOptions, registered once for every command that unwraps
// (`unwrap`, `bake`), so each flag has one spelling, one range and one help text. They write
// straight into the options struct; its values when the flags are added are the defaults.
#pragma once

#include <CLI/CLI.hpp>

#include "bake/unwrap/unwrap.h"

namespace vt::cli {

// --texels-per-unit and --size (excluding each other), --max-size, --density, --padding, --method,
// --share-instances,
// --max-stretch, --split-rounds, --chart-angle. The page payload and threads are the command's.
void add_unwrap_flags(CLI::App& app, unwrap::UnwrapOptions& options);

}  // namespace vt::cli
