// vtbake: offline virtual-texture baking. Each subcommand lives in its own cli/cmd_*.cpp.
// The executable holds the light commands (info, verify, version: page-file readers, nothing
// of the bake stack); the rest are in the commands module, loaded only when the command
// line names one of them or asks for the full list (docs/ARCHITECTURE.md, "Start-up").
#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <map>
#include <string>
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

namespace {

// The subcommand the command line names: its first word that is not a global flag or a flag's
// value; empty when there is none (`vtbake --help`, `vtbake`).
std::string_view subcommand_word(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--") return i + 1 < argc ? std::string_view(argv[i + 1]) : std::string_view();
    if (arg == "--threads") {
      ++i;  // its value
      continue;
    }
    if (!arg.empty() && arg[0] == '-') continue;
    return arg;
  }
  return {};
}

// Whether the command line asks for --json: read before CLI11 has parsed it, for the errors
// found before or while parsing.
bool asks_for_json(int argc, char** argv) {
  return std::any_of(argv + 1, argv + argc,
                     [](const char* a) { return std::string_view(a) == "--json"; });
}

bool is_registered(std::string_view name) {
  for (const auto& command : registered_commands())
    if (command.name == name) return true;
  return false;
}

// The module's path: beside the executable in the build tree, else in the installed layout
// (VTBAKE_MODULE_RELDIR is lib/vtbake relative to bin/).
std::string module_path() {
  char exe[4096];
  const ssize_t n = readlink("/proc/self/exe", exe, sizeof(exe) - 1);
  std::string dir = ".";
  if (n > 0) {
    exe[n] = '\0';
    dir.assign(exe);
    dir.erase(dir.rfind('/'));
  }
  const std::string beside = dir + "/" VTBAKE_MODULE_NAME;
  if (access(beside.c_str(), F_OK) == 0) return beside;
  return dir + "/" VTBAKE_MODULE_RELDIR "/" VTBAKE_MODULE_NAME;
}

}  // namespace

// Never unloaded: the module's factories and runners live in it.
Status load_commands_module() {
  static const Status loaded = [] {
    const std::string path = module_path();
    if (dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) return Status::Ok();
    return Error(ErrorCode::kInternal,
                 "cannot load the bake commands module " + path + ": " + dlerror());
  }();
  return loaded;
}

ImageWriter& module_image_writer() {
  static ImageWriter writer = nullptr;
  return writer;
}

}  // namespace vt::cli

int main(int argc, char** argv) {
  using namespace vt::cli;
  // A light command runs without the module; anything else (a bake command, an unknown word,
  // the top-level help) needs the full list.
  if (!is_registered(subcommand_word(argc, argv))) {
    if (vt::Status loaded = load_commands_module(); !loaded.ok()) {
      std::fprintf(stderr, "vtbake: %s\n", loaded.message().c_str());
      // --json is not parsed yet; a pipeline that asked for it still gets its error object.
      if (asks_for_json(argc, argv)) print_json_error("vtbake", kExitFailure, error_json(loaded));
      return kExitFailure;
    }
  }

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
    if (code != kExitOk && asks_for_json(argc, argv)) {
      const std::string named(subcommand_word(argc, argv));
      print_json_error(is_registered(named) ? named.c_str() : "vtbake", code,
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
