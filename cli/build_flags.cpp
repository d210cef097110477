// The build flags (see build_flags.h).
#include "cli/build_flags.h"

#include <cmath>
#include <cstdlib>

#include "bake/color.h"
#include "cli/cli_util.h"
#include "cli/layer_error_text.h"
#include "format/page_error_bounds.h"

namespace vt::cli {
namespace {

// A library parse error as CLI11's, so that a bad value fails at parse time like a range check.
void throw_if_error(const char* flag, const Status& status) {
  if (status.ok()) return;
  const std::string& message = status.message();
  if (message.rfind(flag, 0) == 0) throw CLI::ValidationError(message);
  throw CLI::ValidationError(flag, message);
}

// The default DCT floors by layer, for --help (format/page_error_bounds.h).
std::string default_floors_text() {
  const auto db = [](LayerSemantic s) {
    return std::to_string(int(std::lround(kDctPagePsnr.of(s) + kDctFloorMarginDb)));
  };
  return "albedo " + db(LayerSemantic::kAlbedo) + ", normal " + db(LayerSemantic::kNormal) +
         ", orm " + db(LayerSemantic::kOrm) + ", emissive " + db(LayerSemantic::kEmissive) +
         ", others " + db(LayerSemantic::kCustom) + " (" + std::to_string(int(kDctFloorMarginDb)) +
         " dB over the page bound validate holds the layer to)";
}

}  // namespace

void add_build_flags(CLI::App& app, BuildOptions& o) {
  app.add_option("-o,--output", o.output, "Output page file (.vtpf)")->required();
  app.add_option_function<std::string>(
      "--codec",
      [&o](const std::string& text) { throw_if_error("--codec", parse_codec(text, &o.codec)); },
      "dct[:QUALITY][:adaptive] (default, quality 75; adaptive: smaller pages, slower "
      "decoding), bc[:high|fast] or raw (lossless)");
  app.add_option_function<std::vector<std::string>>(
      "--min-psnr",
      [&o](const std::vector<std::string>& texts) {
        for (const std::string& t : texts)
          throw_if_error("--min-psnr", parse_min_psnr(t, &o.codec));
      },
      "DCT error floor: no page below DB (PSNR over its channels, stored codec); DB for every "
      "layer or LAYER=DB, repeatable; 0: none. Default: " +
          default_floors_text());
  app.add_option_function<std::string>(
      "--float-texels",
      [&o](const std::string& name) {
        auto kind = parse_float_texels(name);
        throw_if_error("--float-texels", kind.status());
        o.codec.float_texels = *kind;
      },
      "Float sources (EXR, HDR) of colour and data layers: auto (default: float with --codec "
      "raw, else 8 bits in the codec, values outside [0, 1] clipped with a warning), half (half "
      "float, raw + zstd, or BC6H blocks with --codec bc; BC6H at run time, see --half-runtime) "
      "or float (32-bit, RGBA32F)");
  app.add_option_function<std::string>(
      "--half-runtime",
      [&o](const std::string& name) {
        auto kind = parse_half_runtime(name);
        throw_if_error("--half-runtime", kind.status());
        o.codec.half_runtime = *kind;
      },
      "Runtime format of half-float layers of 1-3 channels: bc6h (default; signed for custom "
      "layers, encoded at load unless --codec bc stored the blocks) or rgba16f; 4-channel half "
      "layers are always rgba16f");
  app.add_flag_callback(
      "--no-page-modes", [&o] { o.codec.dct_page_modes = false; },
      "DCT: every page in the tables' own mode (no per-page 4:4:4, finer or lossless choice)");
  app.add_option("--payload", o.payload, "Payload texels per page side")->capture_default_str();
  app.add_option("--border", o.border, "Border texels per page side")->capture_default_str();
  app.add_option_function<std::string>(
         "--filter",
         [&o](const std::string& name) {
           auto filter = parse_mip_filter(name.c_str());
           throw_if_error("--filter", filter.status());
           o.filter = *filter;
         },
         "Mip filter: kaiser, box or lanczos3")
      ->default_str(to_string(o.filter));
  app.add_option("--alpha-coverage", o.alpha_coverage_reference,
                 "Keep the fraction of texels with alpha >= this value (e.g. 0.5) at every level")
      ->check(CLI::Range(0.0f, 1.0f));
  app.add_option_function<std::string>(
      "--fix-nonfinite",
      [&o](const std::string& name) {
        auto policy = parse_non_finite_policy(name);
        throw_if_error("--fix-nonfinite", policy.status());
        o.non_finite = *policy;
      },
      "NaN/Inf/negative colour values: black (default), clamp or error");
  app.add_option_function<std::string>(
         "--memory-limit",
         [&o](const std::string& text) {
           throw_if_error("--memory-limit", parse_byte_size(text, &o.memory_limit));
         },
         "Memory budget, e.g. 512M, 2G")
      ->default_str(format_byte_size(o.memory_limit));
  app.add_option("--scratch-dir", o.scratch_dir,
                 "Where levels larger than memory go (default: beside the output)");
  app.add_flag("--compress-scratch", o.compress_scratch,
               "Compress the levels in scratch files (zstd-1, lossless: the same output) even "
               "where they fit the scratch disk raw: about 3x less disk for 1.4-1.8x the build "
               "time (by default only when they would not fit)");
  app.add_flag("--update", o.update,
               "Update the output: copy every page of the existing file whose key (settings, "
               "codec tables, the page's input texels) is unchanged, encode the rest; its DCT "
               "tables stay pinned. Nothing is written when no input or setting changed");
  app.add_option("--tables-from", o.tables_from,
                 "Take the DCT tables of the layers from this page file instead of training "
                 "(a clean build equal to an --update of that file)")
      ->check(CLI::ExistingFile);
  app.add_flag("--retrain-tables", o.retrain_tables,
               "With --update: train new DCT tables (every page of a DCT layer is re-encoded)");
  app.add_option_function<std::string>(
         "--colorconfig",
         [&o](const std::string& path) {
           auto config = ColorConfig::load(path);
           const char* env = std::getenv("OCIO");  // CLI11 reads $OCIO when the flag is absent
           throw_if_error(env && path == env ? "$OCIO" : "--colorconfig", config.status());
           o.color_config = *config;
         },
         "OpenColorIO config (.ocio) for the colour textures: their spaces by name, alias, role "
         "or the config's file rules; its scene_linear role is the working space (default: "
         "$OCIO, else the built-in config: linear, sRGB, Rec709, Gamma1.8/2.2/2.4, ACEScg, "
         "ACES2065-1, raw)")
      ->envname("OCIO");
}

}  // namespace vt::cli
