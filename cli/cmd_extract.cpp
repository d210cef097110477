// `vtbake extract FILE --level L [--layer N] -o out.exr|png`: one level's payload reassembled
// into an image of exactly the level's size. Absent pages are filled from their nearest present
// ancestor, upsampled nearest (docs/FORMAT.md, "Extracting a level"). The texels are written
// as stored: a colour layer's alpha is unassociated (PNG's convention), and a 2- or 4-channel
// data layer (normal XY, custom) has no alpha at all, so nothing is divided by a last channel.
// OpenEXR alone stores colour premultiplied: a colour layer with alpha goes in multiplied.
#include <cstdio>
#include <filesystem>

#include "cli/cli_util.h"
#include "cli/command.h"
#include "cli/json_output.h"
#include "cli/level_png.h"
#include "format/page_file.h"
#include "format/page_file_inspect.h"

namespace {

struct ExtractOptions {
  std::string path;
  uint32_t level = 0;
  uint32_t layer = 0;
  std::string output;
};

vt::cli::CommandRunner make_extract(CLI::App& sub) {
  auto opt = std::make_shared<ExtractOptions>();
  sub.add_option("file", opt->path, "Page file (.vtpf)")->required();
  sub.add_option("--level", opt->level, "Mip level to extract (0 = finest)")->required();
  sub.add_option("--layer", opt->layer, "Layer index (see `vtbake info`)")->capture_default_str();
  sub.add_option("-o,--output", opt->output, "Output image (.exr, .png, ...)")->required();
  return [opt](const vt::cli::GlobalOptions& global) {
    auto reader = vt::PageFileReader::open(opt->path);
    if (!reader.ok()) return vt::cli::report_error("extract", reader.status());
    auto image = vt::extract_level(**reader, opt->level, opt->layer);
    if (!image.ok()) return vt::cli::report_error("extract", image.status());
    // 8-bit PNG needs no image library; every other format is OpenImageIO's, in the module.
    const vt::LayerSpec& layer = (*reader)->layers()[opt->layer];
    const std::string ext = std::filesystem::path(opt->output).extension().string();
    vt::Status written = vt::Status::Ok();
    if ((ext == ".png" || ext == ".PNG") && vt::level_png_supported(*image)) {
      written = vt::write_level_png(opt->output, *image, layer);
    } else if (vt::Status loaded = vt::cli::load_commands_module(); !loaded.ok()) {
      written = loaded;
    } else {
      written = vt::cli::module_image_writer()(opt->output, *image, layer);
    }
    if (!written.ok()) return vt::cli::report_error("extract", written);
    if (global.json) {
      std::error_code ec;
      const auto bytes = std::filesystem::file_size(opt->output, ec);
      vt::cli::print_json("extract", vt::cli::kExitOk,
                          {{"input", opt->path},
                           {"output", opt->output},
                           {"level", opt->level},
                           {"layer", opt->layer},
                           {"width", image->width},
                           {"height", image->height},
                           {"channels", image->channels},
                           {"pages",
                            {{"filled_from_ancestor", image->filled_from_ancestor},
                             {"filled_with_zero", image->filled_with_zero}}},
                           {"bytes", {{"file", ec ? 0 : bytes}}}});
    } else if (!global.quiet)
      std::printf(
          "%s: level %u layer %u, %u x %u texels, %u channels (%llu absent pages filled "
          "from a coarser level, %llu left zero)\n",
          opt->output.c_str(), opt->level, opt->layer, image->width, image->height, image->channels,
          (unsigned long long)image->filled_from_ancestor,
          (unsigned long long)image->filled_with_zero);
    return int(vt::cli::kExitOk);
  };
}

const vt::cli::CommandRegistration kExtract{
    "extract", "Reassemble one level of a page file into an image (EXR, PNG, ...)", make_extract};

}  // namespace
