// `vtbake version`: the tool version and the libraries it was built with, for bug reports.
#include <cstdio>

#include "cli/command.h"
#include "cli/json_output.h"

namespace {

vt::cli::CommandRunner make_version(CLI::App&) {
  return [](const vt::cli::GlobalOptions& global) {
    if (global.json) {
      vt::cli::print_json("version", vt::cli::kExitOk, {{"version", VTBAKE_VERSION}});
    } else {
      std::printf("vtbake %s\n", VTBAKE_VERSION);
    }
    return vt::cli::kExitOk;
  };
}

const vt::cli::CommandRegistration kVersion{"version", "Print the vtbake version", make_version};

}  // namespace
