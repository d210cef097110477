// How subcommands join the `vtbake` command: each cli/cmd_*.cpp defines one static
// CommandRegistration that adds its CLI11 subcommand and returns the function to run.
// cli/ holds no algorithm: a subcommand parses flags into a library options struct, calls the
// library, and prints the result.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

#include "common/status.h"
#include "format/page_file.h"
#include "format/page_file_inspect.h"

namespace vt::cli {

// Exit codes, documented in `vtbake --help`.
enum ExitCode : int {
  kExitOk = 0,        // the work succeeded
  kExitFailure = 1,   // the work ran and failed (verify found a bad page, validate below threshold)
  kExitBadInput = 2,  // bad usage or bad input (unreadable file, wrong flag)
};

struct GlobalOptions {
  int threads = 0;  // 0 = all cores
  bool quiet = false;
  bool json = false;
};

using CommandRunner = std::function<int(const GlobalOptions&)>;
// Adds the subcommand's options and positionals to `sub` (already created with the registered
// name and description) and returns what runs it once the command line is parsed.
using CommandFactory = std::function<CommandRunner(CLI::App& sub)>;

struct RegisteredCommand {
  std::string name;
  std::string description;
  CommandFactory factory;
};

// static const vt::cli::CommandRegistration kInfo{"info", "Describe a page file", make_info};
struct CommandRegistration {
  CommandRegistration(std::string name, std::string description, CommandFactory factory);
};
std::vector<RegisteredCommand>& registered_commands();

// Loads the commands module (libvtbake-commands.so: the bake stack and its commands) if it is
// not loaded yet; its static registrations join registered_commands(). An error names the
// module's path and the loader's reason. main() calls it for every command the executable does
// not hold; a light command calls it when it needs the module after all.
Status load_commands_module();

// Writes an extracted level as an image in any format OpenImageIO writes; set by the module
// (cli/image_writer_oiio.cpp), null until it is loaded.
using ImageWriter = Status (*)(const std::string& path, const LevelImage& image,
                               const LayerSpec& layer);
ImageWriter& module_image_writer();

}  // namespace vt::cli
