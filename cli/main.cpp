// vtbake: offline virtual-texture baking. Each subcommand lives in its own cli/cmd_*.cpp.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <map>
#include <string_view>

#include "cli/command.h"
#include "cli/json_output.h"

namespace vt::cli {

std::vector<RegisteredCommand>& registered_commands() {
  static std::vector<RegisteredCommand> commands;
  return commands;
}

CommandRegistration::CommandRegistration(std::string name, std::string description,
                                         CommandFactory factory) {
  registered_commands().push_back({std::move(name), std::move(description), std::move(factory)});
}

}  // namespace vt::cli

int main(int argc, char** argv) {
  using namespace vt::cli;
  CLI::App app{
      "vtbake " VTBAKE_VERSION
      " - offline virtual-texture baking: scenes and images into tiled page files (.vtpf)"};
  app.footer(
      "Exit status: 0 the work succeeded; 1 the work ran and failed (a write, a memory limit, a "
      "bad page, a threshold missed); 2 bad usage or bad input (docs/JSON.md).\n"
      "Outputs (-o): written under a temporary name beside the target and renamed into place "
      "when complete; a symlink at the path is written through (its target is replaced in the "
      "target's folder, the link stays); a directory, device, FIFO or socket there is refused "
      "(exit 2). `bake` replaces its .vtpf and .glb together. Inputs must be regular files.");
  app.require_subcommand(1);
  app.fallthrough();  // global flags may follow the subcommand: `vtbake info --json f.vtpf`
  app.set_version_flag("--version", VTBAKE_VERSION);

  GlobalOptions global;
  app.add_option("--threads", global.threads, "Worker threads (0 = all cores)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("-q,--quiet", global.quiet, "No progress output");
  app.add_flag("--json", global.json, "Machine-readable output on stdout");

  // Sorted so that --help lists subcommands in a stable order whatever the link order.
  auto& commands = registered_commands();
  std::sort(commands.begin(), commands.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  std::map<CLI::App*, CommandRunner> runners;
  for (auto& command : commands) {
    CLI::App* sub = app.add_subcommand(command.name, command.description);
    runners[sub] = command.factory(*sub);
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e) == 0 ? kExitOk : kExitBadInput;
    // --json was not parsed, but a pipeline that asked for it still gets its error object.
    if (code != kExitOk && std::any_of(argv + 1, argv + argc, [](const char* a) {
          return std::string_view(a) == "--json";
        })) {
      const auto named = std::find_if(argv + 1, argv + argc, [&](const char* a) {
        return std::any_of(commands.begin(), commands.end(),
                           [&](const auto& c) { return c.name == a; });
      });
      print_json_error(named == argv + argc ? "vtbake" : *named, code,
                       {{"code", "usage"}, {"message", e.what()}});
    }
    return code;
  }
  set_json_output(global.json);

  for (CLI::App* sub : app.get_subcommands()) {
    auto it = runners.find(sub);
    if (it == runners.end()) continue;
    try {
      return it->second(global);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "vtbake %s: internal error: %s\n", sub->get_name().c_str(), e.what());
      if (global.json)
        print_json_error(sub->get_name().c_str(), kExitFailure,
                         {{"code", "internal"}, {"message", e.what()}});
      return kExitFailure;
    }
  }
  return kExitBadInput;
}
