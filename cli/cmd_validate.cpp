// `vtbake validate SCENE BAKED.vtpf`: renders the baked scene through the virtual-texture path
// (feedback -> runtime streamer -> physical cache -> page table -> final pass) on Vulkan
// (lavapipe when no GPU) and the original scene from its own textures, from automatic views or
// a camera file (render/camera.h), and fails when they differ. The work is render::validate_bake
// (render/validate.h).
#include <cstdio>
#include <string>

#include "cli/cli_util.h"
#include "cli/command.h"
#include "cli/json_output.h"
#include "cli/scene_load_flags.h"
#include "render/report.h"
#include "render/validate.h"

namespace {

struct ValidateArgs {
  std::string size = "1280x720";  // parsed into options.width and height
  std::string up = "auto";        // parsed into options.up
  vt::render::BakeValidationOptions options;
};

void print_atlas(const vt::render::AtlasCheckReport& a) {
  if (!a.ran) {
    std::printf("  atlas check: %s\n", a.note.c_str());
    return;
  }
  std::printf("  atlas check (%.1f s, transfer %.1f s)\n", a.seconds, a.transfer_seconds);
  std::printf("  layer       codec  runtime  pages  failed  min dB  mean dB  bound dB  shift\n");
  for (const auto& l : a.layers) {
    if (!l.note.empty()) {
      std::printf("  %-10s  %s\n", l.name.c_str(), l.note.c_str());
      continue;
    }
    std::printf("  %-10s  %5s  %7s  %5llu  %6llu  %6.1f  %7.1f  %8.1f  %5.2f\n", l.name.c_str(),
                l.codec.c_str(), l.runtime_format.c_str(), (unsigned long long)l.pages_checked,
                (unsigned long long)l.pages_failed, l.min_psnr, l.mean_psnr, l.bounds.min_psnr,
                l.worst_mean_shift);
  }
  for (const std::string& f : a.failures) std::printf("  FAIL %s\n", f.c_str());
}

void print_text(const vt::render::ValidationReport& r) {
  print_atlas(r.atlas);
  if (r.views.empty()) {
    std::printf("%s\n", r.passed() ? "PASS" : "FAIL");
    return;
  }
  std::printf("validate %s (layer %u, %s cache) on %s, %ux%u\n", r.page_file.c_str(), r.layer,
              r.cache_format.c_str(), r.device.c_str(), r.width, r.height);
  std::printf("  view  PSNR dB  tile dB   SSIM    coarser  frames  result\n");
  for (const auto& v : r.views) {
    std::printf("  %4u  %7.2f  %7.2f  %.4f  %7.4f  %6u  %s\n", v.view, v.metrics.psnr_rgb,
                v.metrics.worst_tile_psnr, v.metrics.ssim, v.metrics.coarser_share,
                v.converge.frames_to_converge,
                v.failures.empty() ? "pass" : v.failures.front().c_str());
  }
  std::printf("  bounds: PSNR >= %.1f dB, worst tile >= %.1f dB; images and report in %s\n",
              r.thresholds.min_psnr, r.thresholds.min_tile_psnr, r.out_dir.c_str());
  std::printf("  contact sheet: %s\n", r.contact_sheet.c_str());
  std::printf("%s\n", r.passed() ? "PASS" : "FAIL");
}

// On stderr whatever --json and --quiet say: what a build log must show.
void print_warnings_and_failures(const vt::render::ValidationReport& r) {
  for (const std::string& w : r.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  for (const std::string& f : vt::render::failure_lines(r)) {
    std::fprintf(stderr, "vtbake validate: %s\n", f.c_str());
  }
}

int run(ValidateArgs& a, const vt::cli::GlobalOptions& global) {
  vt::render::BakeValidationOptions& o = a.options;
  if (std::sscanf(a.size.c_str(), "%ux%u", &o.width, &o.height) != 2 || o.width == 0 ||
      o.height == 0 || o.width > 8192 || o.height > 8192) {
    return vt::cli::bad_usage("validate",
                              "--size must be WxH (at most 8192x8192), got '" + a.size + "'");
  }
  auto up = vt::render::parse_up_axis(a.up);
  if (!up.ok()) return vt::cli::bad_usage("validate", "--up: " + up.status().message());
  o.up = *up;
  auto report = vt::render::validate_bake(o);
  if (!report.ok()) return vt::cli::report_error("validate", report.status());
  if (global.json) {
    nlohmann::json j = nlohmann::json::parse(vt::render::report_json(*report));
    j["input"] = o.page_file;
    j["output"] = report->out_dir;
    vt::cli::print_json("validate", report->passed() ? vt::cli::kExitOk : vt::cli::kExitFailure, j);
  } else if (!global.quiet) {
    print_text(*report);
  }
  print_warnings_and_failures(*report);
  return report->passed() ? vt::cli::kExitOk : vt::cli::kExitFailure;
}

vt::cli::CommandRunner make_validate(CLI::App& app) {
  auto args = std::make_shared<ValidateArgs>();
  vt::render::BakeValidationOptions& f = args->options;
  app.add_option(
         "scene", f.scene,
         "The original scene (.gltf, .glb, .obj, .ply, .drc, .ac, .acc, or what assimp reads)")
      ->required();
  app.add_option("page_file", f.page_file, "The baked page file (.vtpf)")->required();
  app.add_option("--unwrapped", f.unwrapped,
                 "The unwrapped scene `vtbake bake` wrote (default: PAGE_FILE with .glb)");
  auto* views = app.add_option("--views", f.views,
                               "Automatic views: an overview, then views framed on the surfaces "
                               "with the most texels and views at one baked texel per pixel")
                    ->check(CLI::Range(1, 64))
                    ->capture_default_str();
  app.add_option("--up", args->up,
                 "The scene's up axis for automatic views: auto (from the data), x, y, z, -x, -y, "
                 "-z")
      ->capture_default_str();
  app.add_option("--min-density", f.thresholds.min_density,
                 "Fail a view whose baked texels per source texel (median in view) is below this")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  auto* cameras = app.add_option("--cameras", f.cameras_file,
                                 "Camera file (JSON, format below) instead of automatic views");
  views->excludes(cameras);
  app.add_option("--size", args->size, "Render size WxH")->capture_default_str();
  app.add_option("--layer", f.layer, "Layer to validate (default: the albedo layer)");
  app.add_option("--min-psnr", f.thresholds.min_psnr,
                 "Fail when a view's PSNR is below this, dB (sample scene: 34-36 dB)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  app.add_option("--min-tile-psnr", f.thresholds.min_tile_psnr,
                 "Fail when a view's worst 16x16 tile is below this, dB (sample scene: 25-27 dB)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  app.add_option("--slots", f.slots, "Physical cache slots per side")
      ->check(CLI::Range(1, 128))
      ->capture_default_str();
  app.add_option("--max-frames", f.max_frames, "Give up converging after this many frames")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_flag("--hardware", f.prefer_hardware, "Prefer a hardware Vulkan device over lavapipe");
  auto* atlas_only = app.add_flag(
      "--atlas-only", [&f](int64_t) { f.render_views = false; },
      "Only the atlas-space page check (every page of every layer; no Vulkan)");
  app.add_option("--atlas-offset-db", f.atlas.psnr_offset_db,
                 "Added to every layer's per-page PSNR bound in the atlas check (negative loosens)")
      ->check(CLI::Range(-60.0, 60.0))
      ->capture_default_str();
  app.add_flag(
         "--no-atlas-check", [&f](int64_t) { f.atlas.enabled = false; },
         "Skip the atlas-space page check")
      ->excludes(atlas_only);
  app.add_flag(
         "--no-exact-check", [&f](int64_t) { f.exact.enabled = false; },
         "Skip the exact streaming check (virtual render against the baked levels as a texture)")
      ->excludes(atlas_only);
  vt::cli::add_scene_load_flags(app, f.load);
  app.add_option("--out", f.out_dir,
                 "Folder for the PNGs and report.json (default PAGE_FILE.validate)");
  app.footer(
      "Camera file (--cameras), in the scene's world units:\n"
      "  {\"cameras\": [{\"eye\": [0, 6, 8], \"target\": [0, 0, 0], \"up\": [0, 1, 0],\n"
      "                \"fov_y_deg\": 50, \"near\": 0.1, \"far\": 100}, ...]}\n"
      "eye and target are required; up defaults to [0, 1, 0], fov_y_deg (vertical, in (0, 180))\n"
      "to 50, near and far to 1/100 and 100 times the eye-target distance. 1-256 cameras;\n"
      "unknown keys, non-finite numbers, eye == target and up parallel to the view are errors.\n"
      "Writes per view its images, the atlas heat maps, contact_sheet.png (every image on one\n"
      "sheet, failures outlined in red) and report.json into --out; --json prints the report.\n"
      "Exit status: 0 every view and every page passes, 1 a view or a page (atlas check: each\n"
      "page of each layer against the original materials) fails its bounds or a write fails\n"
      "(stderr names the failing views with their reasons, and the layers with their worst\n"
      "pages as (level, x, y)), 2 bad input or no Vulkan device.");
  return [args](const vt::cli::GlobalOptions& global) { return run(*args, global); };
}

const vt::cli::CommandRegistration kValidate{
    "validate", "Render a bake through the virtual-texture path and compare with the original",
    make_validate};

}  // namespace
