// `vtbake info FILE`: geometry, layers, per-level page counts and bytes, compression ratio.
// With --json, the object documented in docs/FORMAT.md ("vtbake info --json").
#include <cstdio>
#include <nlohmann/json.hpp>

#include "cli/cli_util.h"
#include "cli/command.h"
#include "cli/json_output.h"
#include "format/page_file.h"
#include "format/page_file_inspect.h"

namespace {

nlohmann::json info_json(const vt::PageFileReader& r, const vt::PageFileStats& stats) {
  const vt::PageGeometry& g = r.geometry();
  nlohmann::json j;
  j["input"] = r.path();
  j["version"] = r.version();
  j["width"] = g.width;
  j["height"] = g.height;
  j["payload"] = g.payload;
  j["border"] = g.border;
  j["page_size"] = g.page_size();
  j["level_count"] = g.level_count();
  j["layers"] = nlohmann::json::array();
  for (size_t i = 0; i < r.layers().size(); ++i) {
    const vt::LayerSpec& l = r.layers()[i];
    j["layers"].push_back({{"index", i},
                           {"semantic", vt::to_string(l.semantic)},
                           {"name", l.name},
                           {"channels", l.channels},
                           {"texel_type", vt::to_string(l.texel_type)},
                           {"codec", vt::to_string(l.codec)},
                           {"runtime_format", vt::to_string(l.runtime_format)},
                           {"color_space", vt::to_string(l.color_space)},
                           {"address_mode", vt::to_string(l.address_mode)},
                           {"codec_tables_bytes", l.codec_tables.size()}});
  }
  j["levels"] = nlohmann::json::array();
  for (const vt::LevelStats& s : stats.levels)
    j["levels"].push_back({{"level", s.level},
                           {"width", g.level_width(s.level)},
                           {"height", g.level_height(s.level)},
                           {"pages_x", s.pages_x},
                           {"pages_y", s.pages_y},
                           {"stored", s.stored_pages},
                           {"constant", s.constant_pages},
                           {"absent", s.absent_pages},
                           {"bytes", s.bytes},
                           {"pages_raw", s.raw_bytes}});
  uint64_t stored = 0, constant = 0, absent = 0;
  for (const vt::LevelStats& s : stats.levels)
    stored += s.stored_pages, constant += s.constant_pages, absent += s.absent_pages;
  j["pages"] = {{"total", stored + constant + absent},
                {"stored", stored},
                {"constant", constant},
                {"absent", absent}};
  j["bytes"] = {{"file", r.file_size()},
                {"stored", stats.stored_bytes},
                {"pages_raw", stats.raw_bytes},
                {"pages_ratio", stats.compression_ratio}};
  // Metadata is JSON by contract; a file whose metadata does not parse still gets described.
  auto meta = nlohmann::json::parse(r.metadata_json(), nullptr, /*allow_exceptions=*/false);
  j["metadata"] = meta.is_discarded() ? nlohmann::json(r.metadata_json()) : meta;
  return j;
}

void print_text(const vt::PageFileReader& r, const vt::PageFileStats& stats) {
  const vt::PageGeometry& g = r.geometry();
  std::printf("%s: page file version %u, %llu bytes\n", r.path().c_str(), r.version(),
              (unsigned long long)r.file_size());
  std::printf("geometry: %u x %u texels, %u levels, pages of %u texels (payload %u + border %u)\n",
              g.width, g.height, g.level_count(), g.page_size(), g.payload, g.border);
  std::printf("layers:\n");
  for (size_t i = 0; i < r.layers().size(); ++i) {
    const vt::LayerSpec& l = r.layers()[i];
    std::printf("  %zu \"%s\": %s, %u x %s, codec %s, runtime %s, %s, %s\n", i, l.name.c_str(),
                vt::to_string(l.semantic), l.channels, vt::to_string(l.texel_type),
                vt::to_string(l.codec), vt::to_string(l.runtime_format),
                vt::to_string(l.color_space), vt::to_string(l.address_mode));
  }
  std::printf("levels (pages summed over layers):\n");
  std::printf("  %5s %11s %11s %8s %8s %8s %12s\n", "level", "texels", "pages", "stored",
              "constant", "absent", "bytes");
  for (const vt::LevelStats& s : stats.levels) {
    char texels[32], pages[32];
    std::snprintf(texels, sizeof texels, "%ux%u", g.level_width(s.level), g.level_height(s.level));
    std::snprintf(pages, sizeof pages, "%ux%u", s.pages_x, s.pages_y);
    std::printf("  %5u %11s %11s %8llu %8llu %8llu %12llu\n", s.level, texels, pages,
                (unsigned long long)s.stored_pages, (unsigned long long)s.constant_pages,
                (unsigned long long)s.absent_pages, (unsigned long long)s.bytes);
  }
  std::printf("stored %llu bytes for %llu raw bytes: compression ratio %.2f\n",
              (unsigned long long)stats.stored_bytes, (unsigned long long)stats.raw_bytes,
              stats.compression_ratio);
}

vt::cli::CommandRunner make_info(CLI::App& sub) {
  auto path = std::make_shared<std::string>();
  sub.add_option("file", *path, "Page file (.vtpf)")->required();
  return [path](const vt::cli::GlobalOptions& global) {
    auto reader = vt::PageFileReader::open(*path);
    if (!reader.ok()) return vt::cli::report_error("info", reader.status());
    const vt::PageFileStats stats = vt::page_file_stats(**reader);
    if (global.json)
      vt::cli::print_json("info", vt::cli::kExitOk, info_json(**reader, stats));
    else
      print_text(**reader, stats);
    return int(vt::cli::kExitOk);
  };
}

const vt::cli::CommandRegistration kInfo{
    "info", "Describe a page file: geometry, layers, pages and bytes per level", make_info};

}  // namespace
