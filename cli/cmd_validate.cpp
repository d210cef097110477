// `vtbake validate SCENE BAKED.vtpf`: renders the baked scene through the virtual-texture path
// (feedback -> runtime streamer -> physical cache -> page table -> final pass) on Vulkan
// (lavapipe when no GPU) and the original scene from its own textures, from automatic views or
// a camera file (render/camera.h), and fails when they differ. The work is render::validate_views
// (render/validate.h).
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "scene/scene.h"
#include "cli/command.h"
#include "format/page_file.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/report.h"
#include "render/scene_draws.h"
#include "render/validate.h"
#include "runtime/page_source.h"

namespace {

using vt::cli::kExitBadInput;
using vt::cli::kExitFailure;
using vt::cli::kExitOk;

struct ValidateFlags {
  std::string scene;
  std::string page_file;
  std::string unwrapped;
  std::string out;
  std::string size = "1280x720";
  std::string layer;
  std::string cameras;  // camera file; excludes --views
  int views = 6;
  double min_psnr = -1;
  double min_tile_psnr = -1;
  int slots = 32;
  int max_frames = 48;
  bool hardware = false;
};

int fail(const std::string& msg, int code) {
  std::fprintf(stderr, "vtbake validate: %s\n", msg.c_str());
  return code;
}

int code_for(const vt::Status& s) {
  return s.code() == vt::ErrorCode::kResourceLimit || s.code() == vt::ErrorCode::kInternal
             ? kExitFailure
             : kExitBadInput;
}

int run(const ValidateFlags& f, const vt::cli::GlobalOptions& global) {
  using namespace vt;
  uint32_t width = 0, height = 0;
  if (std::sscanf(f.size.c_str(), "%ux%u", &width, &height) != 2 || width == 0 || height == 0 ||
      width > 8192 || height > 8192) {
    return fail("--size must be WxH (at most 8192x8192), got '" + f.size + "'", kExitBadInput);
  }
  // Before any scene or Vulkan work: a bad camera file is a quick, clear error.
  std::vector<render::Camera> file_cameras;
  if (!f.cameras.empty()) {
    auto cams = render::load_cameras_json(f.cameras, float(width) / float(height));
    if (!cams.ok()) return fail(cams.status().message(), kExitBadInput);
    file_cameras = std::move(*cams);
  }
  const std::string unwrapped =
      f.unwrapped.empty() ? std::filesystem::path(f.page_file).replace_extension(".glb").string()
                          : f.unwrapped;
  const std::string out_dir =
      f.out.empty() ? std::filesystem::path(f.page_file).replace_extension(".validate").string()
                    : f.out;

  auto reader = PageFileReader::open(f.page_file);
  if (!reader.ok()) return fail(reader.status().message(), code_for(reader.status()));
  std::shared_ptr<const PageFileReader> shared_reader(std::move(*reader));
  auto original = scene::load_scene(f.scene);
  if (!original.ok()) return fail(original.status().message(), code_for(original.status()));
  auto baked = scene::load_scene(unwrapped);
  if (!baked.ok()) return fail(baked.status().message(), code_for(baked.status()));
  auto reference = render::reference_scene_draws(*original);
  if (!reference.ok()) return fail(reference.status().message(), code_for(reference.status()));
  auto virt = render::virtual_scene_draws(*baked);
  if (!virt.ok()) return fail(virt.status().message(), code_for(virt.status()));
  if (reference->meshes.empty() || virt->meshes.empty()) {
    return fail(f.scene + ": nothing to draw", kExitBadInput);
  }

  // Only the albedo layer has a reference (the original base colour).
  int layer = -1;
  for (size_t i = 0; i < shared_reader->layers().size(); ++i) {
    const LayerSpec& l = shared_reader->layers()[i];
    if (f.layer.empty() ? l.semantic == LayerSemantic::kAlbedo : l.name == f.layer) {
      layer = int(i);
      break;
    }
  }
  if (layer < 0) {
    return fail(f.page_file + ": no " + (f.layer.empty() ? "albedo" : "'" + f.layer + "'") +
                    " layer to validate",
                kExitBadInput);
  }
  if (shared_reader->layers()[layer].semantic != LayerSemantic::kAlbedo) {
    return fail("layer '" + f.layer + "' is not albedo: only albedo has a reference render",
                kExitBadInput);
  }

  render::VulkanOptions vo;
  vo.prefer_hardware = f.hardware;
  auto ctx = render::VulkanContext::create(vo);
  if (!ctx.ok()) return fail(ctx.status().message(), kExitBadInput);
  PageFileSourceOptions so;
  so.bc7_as_rgba8 = (*ctx)->is_lavapipe();  // lavapipe samples BC7 15-25x slower than BC1
  auto source = make_page_file_source(shared_reader, so);
  if (!source.ok()) return fail(source.status().message(), code_for(source.status()));
  std::shared_ptr<const PageSource> shared_source(std::move(*source));

  render::RenderOptions ro;
  ro.width = width;
  ro.height = height;
  auto renderer = render::Renderer::create(**ctx, ro);
  if (!renderer.ok()) return fail(renderer.status().message(), code_for(renderer.status()));
  Status s = (*renderer)->set_meshes(virt->meshes);
  if (s.ok()) s = (*renderer)->set_reference_meshes(reference->meshes);
  if (s.ok()) s = (*renderer)->set_reference_textures(reference->textures);
  if (!s.ok()) return fail(s.message(), code_for(s));

  std::vector<render::Camera> cameras =
      !file_cameras.empty() ? file_cameras
                            : render::orbit_views(reference->bounds_min, reference->bounds_max,
                                                  f.views, float(width) / float(height));
  render::ValidateOptions vopt;
  vopt.layer = uint32_t(layer);
  vopt.address_mode = shared_reader->layers()[layer].address_mode;
  vopt.streamer.slots_x = vopt.streamer.slots_y = uint32_t(f.slots);
  vopt.converge.max_frames = uint32_t(f.max_frames);
  render::Thresholds thresholds = render::scene_thresholds();
  if (f.min_psnr >= 0) thresholds.min_psnr = f.min_psnr;
  if (f.min_tile_psnr >= 0) thresholds.min_tile_psnr = f.min_tile_psnr;
  vopt.thresholds = thresholds;
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return fail(out_dir + ": cannot create: " + ec.message(), kExitBadInput);
  vopt.out_dir = out_dir;

  auto report = render::validate_views(**renderer, shared_source, cameras, vopt);
  if (!report.ok()) return fail(report.status().message(), code_for(report.status()));
  report->page_file = f.page_file;
  report->device = (*ctx)->device_name();
  const std::string json_path = out_dir + "/report.json";
  s = render::write_report_json(json_path, *report);
  if (!s.ok()) return fail(s.message(), kExitFailure);

  if (global.json) {
    std::FILE* jf = std::fopen(json_path.c_str(), "rb");
    if (jf) {
      char buf[4096];
      size_t n;
      while ((n = std::fread(buf, 1, sizeof(buf), jf)) > 0) std::fwrite(buf, 1, n, stdout);
      std::fclose(jf);
    }
  } else if (!global.quiet) {
    std::printf("validate %s (layer %d, %s cache) on %s, %ux%u\n", f.page_file.c_str(), layer,
                report->cache_format.c_str(), report->device.c_str(), width, height);
    std::printf("  view  PSNR dB  tile dB   SSIM    coarser  frames  result\n");
    for (const auto& v : report->views) {
      std::printf("  %4u  %7.2f  %7.2f  %.4f  %7.4f  %6u  %s\n", v.view, v.metrics.psnr_rgb,
                  v.metrics.worst_tile_psnr, v.metrics.ssim, v.metrics.coarser_share,
                  v.converge.frames_to_converge,
                  v.failures.empty() ? "pass" : v.failures.front().c_str());
    }
    std::printf("  bounds: PSNR >= %.1f dB, worst tile >= %.1f dB; images and report in %s\n",
                report->thresholds.min_psnr, report->thresholds.min_tile_psnr, out_dir.c_str());
    std::printf("%s\n", report->passed() ? "PASS" : "FAIL");
  }
  return report->passed() ? kExitOk : kExitFailure;
}

vt::cli::CommandRunner make_validate(CLI::App& app) {
  auto f = std::make_shared<ValidateFlags>();
  app.add_option("scene", f->scene, "The original scene (.gltf, .glb, .obj, .ply, .drc)")
      ->required();
  app.add_option("page_file", f->page_file, "The baked page file (.vtpf)")->required();
  app.add_option("--unwrapped", f->unwrapped,
                 "The unwrapped scene `vtbake bake` wrote (default: PAGE_FILE with .glb)");
  auto* views = app.add_option("--views", f->views, "Automatic camera views around the scene")
                    ->check(CLI::Range(1, 64));
  auto* cameras = app.add_option("--cameras", f->cameras,
                                 "Camera file (JSON, format below) instead of automatic views");
  views->excludes(cameras);
  app.add_option("--size", f->size, "Render size WxH");
  app.add_option("--layer", f->layer, "Layer to validate (default: the albedo layer)");
  app.add_option("--min-psnr", f->min_psnr,
                 "Fail when a view's PSNR is below this (default 30 dB, measured on the sample "
                 "scene: 34-36 dB)")
      ->check(CLI::Range(0.0, 100.0));
  app.add_option("--min-tile-psnr", f->min_tile_psnr,
                 "Fail when a view's worst 16x16 tile is below this (default 20 dB; sample "
                 "scene: 25-27 dB)")
      ->check(CLI::Range(0.0, 100.0));
  app.add_option("--slots", f->slots, "Physical cache slots per side")->check(CLI::Range(1, 128));
  app.add_option("--max-frames", f->max_frames, "Give up converging after this many frames")
      ->check(CLI::Range(1, 1000));
  app.add_flag("--hardware", f->hardware, "Prefer a hardware Vulkan device over lavapipe");
  app.add_option("--out", f->out,
                 "Folder for the PNGs and report.json (default PAGE_FILE.validate)");
  app.footer(
      "Camera file (--cameras), in the scene's world units:\n"
      "  {\"cameras\": [{\"eye\": [0, 6, 8], \"target\": [0, 0, 0], \"up\": [0, 1, 0],\n"
      "                \"fov_y_deg\": 50, \"near\": 0.1, \"far\": 100}, ...]}\n"
      "eye and target are required; up defaults to [0, 1, 0], fov_y_deg (vertical, in (0, 180))\n"
      "to 50, near and far to 1/100 and 100 times the eye-target distance. 1-256 cameras;\n"
      "unknown keys, non-finite numbers, eye == target and up parallel to the view are errors.\n"
      "Exit status: 0 every view passes, 1 a view fails its bounds, 2 bad input or no Vulkan.");
  return [f](const vt::cli::GlobalOptions& global) { return run(*f, global); };
}

const vt::cli::CommandRegistration kValidate{
    "validate", "Render a bake through the virtual-texture path and compare with the original",
    make_validate};

}  // namespace
