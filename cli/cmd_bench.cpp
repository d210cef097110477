// `vtbake bench KIND [options] [INPUTS...]`: one sub-subcommand per kind in the bench registry
// (bench/registry.h); this file only maps flags onto the kind's options and prints its report.
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench/registry.h"
#include "cli/cli_util.h"
#include "cli/command.h"

namespace {

struct KindArgs {
  std::vector<std::string> inputs;
  std::map<std::string, std::string> values;
};

vt::cli::CommandRunner make_bench(CLI::App& app) {
  app.require_subcommand(1);
  auto args = std::make_shared<std::map<std::string, KindArgs>>();
  for (const vt::bench::BenchKind& kind : vt::bench::bench_kinds()) {
    CLI::App* sub = app.add_subcommand(kind.name, kind.description);
    KindArgs& a = (*args)[kind.name];
    for (const auto& option : kind.options) {
      a.values[option.name] = option.default_value;
      sub->add_option("--" + option.name, a.values[option.name], option.help)
          ->capture_default_str();
    }
    sub->add_option("inputs", a.inputs, kind.inputs_help);
  }
  return [&app, args](const vt::cli::GlobalOptions& global) -> int {
    for (CLI::App* sub : app.get_subcommands()) {
      for (const vt::bench::BenchKind& kind : vt::bench::bench_kinds()) {
        if (kind.name != sub->get_name()) continue;
        const KindArgs& a = (*args)[kind.name];
        vt::bench::BenchRequest request;
        request.inputs = a.inputs;
        request.values = a.values;
        if (!global.quiet) {
          request.progress = [&kind](const std::string& line) {
            std::fprintf(stderr, "bench %s: %s\n", kind.name.c_str(), line.c_str());
          };
        }
        auto report = kind.run(request);
        if (!report.ok()) {
          return vt::cli::report_error(("bench " + kind.name).c_str(), report.status());
        }
        std::fputs(global.json ? report->json.c_str() : report->text.c_str(), stdout);
        return vt::cli::kExitOk;
      }
    }
    return vt::cli::kExitBadInput;
  };
}

const vt::cli::CommandRegistration kBench{"bench", "Measure speed and accuracy (kinds: codec)",
                                          make_bench};

}  // namespace
