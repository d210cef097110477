// `vtbake verify FILE`: checks the header, the index and every stored page's checksum.
// Exit 0: intact; 1: at least one bad page; else the exit-code rule (cli/cli_util.h).
#include <cstdio>
#include <nlohmann/json.hpp>

#include "cli/cli_util.h"
#include "cli/command.h"
#include "cli/json_output.h"
#include "format/page_file.h"
#include "format/page_file_inspect.h"

namespace {

vt::cli::CommandRunner make_verify(CLI::App& sub) {
  auto path = std::make_shared<std::string>();
  sub.add_option("file", *path, "Page file (.vtpf)")->required();
  return [path](const vt::cli::GlobalOptions& global) {
    // Opening checks the header, index and metadata checksums and every offset and size.
    auto reader = vt::PageFileReader::open(*path);
    if (!reader.ok()) return vt::cli::report_error("verify", reader.status());
    const vt::VerifyReport report = vt::verify_pages(**reader, global.threads);
    const bool ok = report.bad_pages.empty();
    if (global.json) {
      nlohmann::json bad = nlohmann::json::array();
      for (const vt::BadPage& b : report.bad_pages)
        bad.push_back({{"level", b.id.level},
                       {"x", b.id.x},
                       {"y", b.id.y},
                       {"layer", b.layer},
                       {"error", b.status.message()}});
      vt::cli::print_json(
          "verify", ok ? vt::cli::kExitOk : vt::cli::kExitFailure,
          {{"input", *path},
           {"pages", {{"checked", report.pages_checked}, {"bad", report.bad_pages.size()}}},
           {"bad_pages", bad}});
    } else {
      for (const vt::BadPage& b : report.bad_pages)
        std::fprintf(stderr, "vtbake verify: %s\n", b.status.message().c_str());
      if (!global.quiet || !ok)
        std::printf("%s: %s (%llu stored pages checked, %zu bad)\n", path->c_str(),
                    ok ? "ok" : "CORRUPT", (unsigned long long)report.pages_checked,
                    report.bad_pages.size());
    }
    return int(ok ? vt::cli::kExitOk : vt::cli::kExitFailure);
  };
}

const vt::cli::CommandRegistration kVerify{
    "verify", "Check every checksum of a page file (exit 1 on a bad page)", make_verify};

}  // namespace
