// `vtbake merge DIR -o OUT.vtpf`: the last step of a sharded bake (docs/FARM.md). Assembles the
// page file from the shard parts in DIR/parts, and the unwrapped scene beside it; or, with
// --missing N, lists the shards of N whose part is absent or unusable. The work is
// merge_shards() / missing_shards() (bake/shard.h).
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "bake/shard.h"
#include "cli/cli_util.h"
#include "cli/command.h"
#include "cli/json_output.h"

namespace {

struct MergeArgs {
  vt::MergeOptions options;
  uint32_t missing = 0;
};

vt::cli::CommandRunner make_merge(CLI::App& app) {
  auto args = std::make_shared<MergeArgs>();
  app.add_option("work", args->options.work_dir, "The work folder of a sharded bake")->required();
  app.add_option("-o,--output", args->options.output,
                 "Output page file (.vtpf; default: the plan's -o)");
  app.add_option("--unwrapped", args->options.unwrapped,
                 "Where to write the unwrapped scene (.glb; default OUT.glb; '-' = not written)");
  app.add_option("--missing", args->missing,
                 "Only list (one per line, 0-based) the shards of N whose part is absent, "
                 "damaged or of another plan; write nothing")
      ->check(CLI::PositiveNumber);
  return [args](const vt::cli::GlobalOptions& global) -> int {
    if (args->missing > 0) {
      auto m = vt::missing_shards(args->options.work_dir, args->missing);
      if (!m.ok()) return vt::cli::report_error("merge", m.status());
      if (global.json) {
        vt::cli::print_json("merge", vt::cli::kExitOk,
                            {{"input", args->options.work_dir}, {"missing", *m}});
      } else {
        for (uint32_t i : *m) std::printf("%u\n", i);
      }
      return vt::cli::kExitOk;
    }
    auto s = vt::merge_shards(args->options);
    if (!s.ok()) return vt::cli::report_error("merge", s.status());
    if (global.json) {
      vt::cli::print_json("merge", vt::cli::kExitOk,
                          {{"input", args->options.work_dir},
                           {"output", s->output},
                           {"unwrapped", s->unwrapped},
                           {"parts", s->parts},
                           {"pages",
                            {{"total", s->pages},
                             {"stored", s->stored},
                             {"constant", s->constant},
                             {"absent", s->absent}}},
                           {"bytes", {{"file", s->file_bytes}, {"stored", s->stored_bytes}}},
                           {"seconds", {{"total", s->seconds}}}});
      return vt::cli::kExitOk;
    }
    std::printf("merged %s from %zu parts (unwrapped scene: %s)\n", s->output.c_str(),
                s->parts.size(), s->unwrapped.empty() ? "not written" : s->unwrapped.c_str());
    std::printf("  pages      %llu: %llu stored, %llu constant, %llu absent; %llu bytes, %.2f s\n",
                (unsigned long long)s->pages, (unsigned long long)s->stored,
                (unsigned long long)s->constant, (unsigned long long)s->absent,
                (unsigned long long)s->file_bytes, s->seconds);
    return vt::cli::kExitOk;
  };
}

const vt::cli::CommandRegistration kMerge{
    "merge", "Assemble a sharded bake's page file from its work folder (docs/FARM.md)", make_merge};

}  // namespace
