// `vtbake extract FILE --level L [--layer N] -o out.exr|png`: one level's payload reassembled
// into an image of exactly the level's size. Absent pages are filled from their nearest present
// ancestor, upsampled nearest (docs/FORMAT.md, "Extracting a level"). The texels are written
// as stored: a colour layer's alpha is unassociated (PNG's convention), and a 2- or 4-channel
// data layer (normal XY, custom) has no alpha at all, so nothing is divided by a last channel.
#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <filesystem>

#include "cli/cli_util.h"
#include "cli/command.h"
#include "cli/json_output.h"
#include "format/atomic_output.h"
#include "format/page_file.h"
#include "format/page_file_inspect.h"

namespace {

struct ExtractOptions {
  std::string path;
  uint32_t level = 0;
  uint32_t layer = 0;
  std::string output;
};

OIIO::TypeDesc oiio_type(vt::TexelType type) {
  switch (type) {
    case vt::TexelType::kU8:
      return OIIO::TypeDesc::UINT8;
    case vt::TexelType::kF16:
      return OIIO::TypeDesc::HALF;
    case vt::TexelType::kF32:
      return OIIO::TypeDesc::FLOAT;
  }
  return OIIO::TypeDesc::UINT8;
}

// The image spec that makes OpenImageIO write the layer's texels unchanged.
OIIO::ImageSpec output_spec(const vt::LevelImage& image, const vt::LayerSpec& layer) {
  OIIO::ImageSpec spec(int(image.width), int(image.height), int(image.channels),
                       oiio_type(image.texel_type));
  const bool colour = layer.semantic == vt::LayerSemantic::kAlbedo ||
                      layer.semantic == vt::LayerSemantic::kEmissive;
  const bool alpha = colour && (image.channels == 2 || image.channels == 4);
  spec.alpha_channel = alpha ? int(image.channels) - 1 : -1;
  if (!alpha && image.channels == 4) spec.channelnames[3] = "W";  // data, not an alpha
  // The page file never premultiplies: without this, the PNG writer divides colour by the last
  // channel of every 2- and 4-channel image, taking it for associated alpha.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  return spec;
}

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
    // The writer is chosen by the final name; the texels go to a staging file beside it
    // (never through a FIFO or onto a device, never truncated under the final name).
    auto out = OIIO::ImageOutput::create(opt->output);
    if (!out) {
      return vt::cli::bad_usage(
          "extract", opt->output + ": cannot write this kind of image: " + OIIO::geterror());
    }
    const OIIO::TypeDesc type = oiio_type(image->texel_type);
    const OIIO::ImageSpec spec = output_spec(*image, (*reader)->layers()[opt->layer]);
    vt::Status written = vt::write_output(opt->output, [&](const std::string& temp) -> vt::Status {
      if (!out->open(temp, spec) || !out->write_image(type, image->texels.data()) ||
          !out->close()) {
        return vt::Error(vt::ErrorCode::kIo, opt->output + ": " + out->geterror());
      }
      return vt::Status::Ok();
    });
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
