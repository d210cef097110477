// The kinds of `vtbake-bench`: each kind (codec, ...) is one entry with its own options, run
// from bench/tool/vtbake_bench.cpp as `vtbake-bench KIND [options] [INPUTS...]`. The registry
// is an explicit list (registry.cpp) rather than static self-registration, which a static
// library would silently drop at link time. Adding a kind: a bench/<kind>_bench.cpp with a function
// returning its BenchKind, and one line in bench_kinds().
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "common/status.h"

namespace vt::bench {

struct BenchOption {
  std::string name;  // long flag without dashes: "repeats" -> --repeats
  std::string help;
  std::string default_value;  // as typed on the command line
};

struct BenchRequest {
  std::vector<std::string> inputs;            // positional arguments
  std::map<std::string, std::string> values;  // every declared option, defaulted
  // Progress lines for a human (the CLI sends them to stderr unless --quiet); may be empty.
  std::function<void(const std::string&)> progress;
};

struct BenchReport {
  std::string text;  // human-readable tables
  std::string json;  // the same figures for machines
};

struct BenchKind {
  std::string name;
  std::string description;
  std::string inputs_help;  // what the positional arguments are
  std::vector<BenchOption> options;
  std::function<Expected<BenchReport>(const BenchRequest&)> run;
};

const std::vector<BenchKind>& bench_kinds();

// Option parsing helpers for kinds: errors name the option and the bad value.
Expected<int> option_int(const BenchRequest& request, const std::string& name, int min, int max);
Expected<std::vector<int>> option_int_list(const BenchRequest& request, const std::string& name,
                                           int min, int max);

}  // namespace vt::bench
