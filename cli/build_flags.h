// The flags of vt::BuildOptions, registered once for every command that runs a build (`build`,
// `bake`), so each flag has one spelling, one range and one help text. They write straight into
// the options struct; its values when the flags are added are the defaults --help shows.
#pragma once

#include <CLI/CLI.hpp>

#include "bake/build.h"

namespace vt::cli {

// -o/--output (required), --codec, --payload, --border, --filter, --alpha-coverage,
// --fix-nonfinite, --memory-limit, --scratch-dir, --update, --tables-from, --retrain-tables,
// --colorconfig (else $OCIO). A bad value is a parse error that names the flag (exit status 2).
// The layers, the address mode and the metadata are the command's.
void add_build_flags(CLI::App& app, BuildOptions& options);

}  // namespace vt::cli
