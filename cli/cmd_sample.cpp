// `vtbake sample -o DIR`: writes the bundled sample's images, made procedurally (no downloads):
// DIR/albedo.png (sRGB colour with fine detail) and DIR/normal.png (tangent-space normals);
// --ext tif|exr for other formats (benchmark inputs).
#include <cstdio>
#include <filesystem>

#include "cli/cli_util.h"
#include "cli/command.h"
#include "cli/json_output.h"
#include "samples/procedural.h"

namespace {

struct SampleFlags {
  std::string dir;
  uint32_t width = 4096;
  uint32_t height = 3072;
  std::string ext = "png";
  bool albedo_only = false;
};

int run_sample(const SampleFlags& f, const vt::cli::GlobalOptions& global) {
  std::error_code ec;
  std::filesystem::create_directories(f.dir, ec);
  if (ec) {
    return vt::cli::report_error("sample",
                                 vt::Error(vt::ErrorCode::kIo, f.dir + ": " + ec.message()));
  }
  struct Item {
    const char* file;
    vt::ProceduralPattern pattern;
  };
  std::vector<std::string> outputs;
  for (const Item& item : {Item{"albedo", vt::ProceduralPattern::kAlbedo},
                           Item{"normal", vt::ProceduralPattern::kNormal}}) {
    if (f.albedo_only && item.pattern != vt::ProceduralPattern::kAlbedo) continue;
    vt::ProceduralImageSource src(item.pattern, f.width, f.height, 3, 1);
    std::string path =
        (std::filesystem::path(f.dir) / (std::string(item.file) + "." + f.ext)).string();
    vt::Status s = vt::write_image_file(src, path);
    if (!s.ok()) return vt::cli::report_error("sample", s);
    if (!global.quiet && !global.json) {
      std::printf("%s: %u x %u\n", path.c_str(), f.width, f.height);
    }
    outputs.push_back(path);
  }
  if (global.json)
    vt::cli::print_json(
        "sample", vt::cli::kExitOk,
        {{"output", f.dir}, {"outputs", outputs}, {"width", f.width}, {"height", f.height}});
  return vt::cli::kExitOk;
}

vt::cli::CommandRunner make_sample(CLI::App& sub) {
  auto f = std::make_shared<SampleFlags>();
  sub.add_option("-o,--output", f->dir, "Directory for the sample images")->required();
  sub.add_option("--width", f->width, "Image width")
      ->check(CLI::Range(1u, 1u << 16))
      ->capture_default_str();
  sub.add_option("--height", f->height, "Image height")
      ->check(CLI::Range(1u, 1u << 16))
      ->capture_default_str();
  sub.add_flag("--albedo-only", f->albedo_only, "Write only the albedo image");
  sub.add_option("--ext", f->ext, "Image format by extension: png, tif, exr")
      ->check(CLI::IsMember({"png", "tif", "exr"}))
      ->capture_default_str();
  return [f](const vt::cli::GlobalOptions& global) { return run_sample(*f, global); };
}

const vt::cli::CommandRegistration kSample{"sample", "Write the bundled procedural sample images",
                                           make_sample};

}  // namespace
