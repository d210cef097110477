// vtbake-bench KIND [options] [INPUTS...]: the benchmark kinds of bench/registry.h as a program
// of their own, so that the shipping `vtbake` links neither them nor their anchors (libjpeg).
// This file only maps flags onto a kind's options and prints its report.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "bench/registry.h"

namespace {

// vtbake's exit codes: 0 done, 1 the work failed, 2 bad usage or bad input.
int exit_code_for(const vt::Status& status) {
  switch (status.code()) {
    case vt::ErrorCode::kInvalidArgument:
    case vt::ErrorCode::kNotFound:
    case vt::ErrorCode::kCorrupt:
    case vt::ErrorCode::kUnsupported:
      return 2;
    default:
      return 1;
  }
}

struct KindArgs {
  std::vector<std::string> inputs;
  std::map<std::string, std::string> values;
};

int run_kind(const vt::bench::BenchKind& kind, const KindArgs& args, bool quiet, bool json) {
  vt::bench::BenchRequest request;
  request.inputs = args.inputs;
  request.values = args.values;
  if (!quiet) {
    request.progress = [&kind](const std::string& line) {
      std::fprintf(stderr, "vtbake-bench %s: %s\n", kind.name.c_str(), line.c_str());
    };
  }
  auto report = kind.run(request);
  if (!report.ok()) {
    std::fprintf(stderr, "vtbake-bench %s: %s\n", kind.name.c_str(),
                 report.status().message().c_str());
    return exit_code_for(report.status());
  }
  std::fputs(json ? report->json.c_str() : report->text.c_str(), stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"vtbake-bench: speed and accuracy of vtbake's codecs against their anchors"};
  app.footer("Exit status: 0 done; 1 the benchmark ran and failed; 2 bad usage or bad input.");
  app.require_subcommand(1);
  app.fallthrough();  // global flags may follow the kind: `vtbake-bench codec --json a.png`
  bool quiet = false, json = false;
  app.add_flag("-q,--quiet", quiet, "No progress output");
  app.add_flag("--json", json, "Machine-readable output on stdout");

  const auto& kinds = vt::bench::bench_kinds();
  std::vector<KindArgs> args(kinds.size());
  for (size_t k = 0; k < kinds.size(); ++k) {
    CLI::App* sub = app.add_subcommand(kinds[k].name, kinds[k].description);
    for (const auto& option : kinds[k].options) {
      std::string& value = args[k].values[option.name];
      value = option.default_value;
      sub->add_option("--" + option.name, value, option.help)->capture_default_str();
    }
    sub->add_option("inputs", args[k].inputs, kinds[k].inputs_help);
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  for (size_t k = 0; k < kinds.size(); ++k) {
    if (app.got_subcommand(kinds[k].name)) return run_kind(kinds[k], args[k], quiet, json);
  }
  return 2;
}
