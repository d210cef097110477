// `vtbake clean DIR...`: removes the staging files that killed writers left in DIR
// (TARGET.tmp-PID@HOST-XXXXXX and .old-, format/atomic_output.h): only those whose owner is
// gone, never a live writer's, never anything else. Every writer sweeps its own target's
// leftovers already; this is for folders a farm no longer writes to.
#include <cstdio>

#include "cli/cli_util.h"
#include "cli/command.h"
#include "cli/json_output.h"
#include "format/atomic_output.h"

namespace {

vt::cli::CommandRunner make_clean(CLI::App& sub) {
  auto dirs = std::make_shared<std::vector<std::string>>();
  sub.add_option("dirs", *dirs, "Folders to clean (not recursive)")->required();
  return [dirs](const vt::cli::GlobalOptions& global) {
    std::vector<std::string> removed;
    for (const std::string& dir : *dirs) {
      auto r = vt::sweep_stale_staging_in(dir);
      if (!r.ok()) return vt::cli::report_error("clean", r.status());
      removed.insert(removed.end(), r->begin(), r->end());
    }
    if (global.json) {
      vt::cli::print_json("clean", vt::cli::kExitOk, {{"inputs", *dirs}, {"removed", removed}});
    } else if (!global.quiet) {
      for (const std::string& path : removed) std::printf("removed %s\n", path.c_str());
      std::printf("%zu stale temporary files removed\n", removed.size());
    }
    return int(vt::cli::kExitOk);
  };
}

const vt::cli::CommandRegistration kClean{
    "clean", "Remove temporary files that killed vtbake runs left in folders", make_clean};

}  // namespace
