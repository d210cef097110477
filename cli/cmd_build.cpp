// `vtbake build IMAGE... -o FILE.vtpf`: images (any size, any format OpenImageIO reads) into a
// page file: mip pyramid, bordered pages, per-layer codec. Flags map onto vt::BuildOptions.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "bake/build.h"
#include "bake/build_summary_json.h"
#include "bake/color.h"
#include "cli/build_flags.h"
#include "cli/cli_util.h"
#include "cli/command.h"
#include "cli/json_output.h"
#include "cli/layer_error_text.h"
#include "common/utf8.h"
#include "format/atomic_output.h"
#include "samples/procedural.h"

namespace {

using vt::cli::kExitOk;

struct BuildArgs {
  std::vector<std::string> images;
  std::vector<std::string> layers;  // SEMANTIC=PATH or NAME=PATH
  std::string colorspace;
  vt::BuildOptions options;
};

bool parse_semantic(const std::string& s, vt::LayerSemantic* sem) {
  static const std::pair<const char*, vt::LayerSemantic> kNames[] = {
      {"albedo", vt::LayerSemantic::kAlbedo},
      {"normal", vt::LayerSemantic::kNormal},
      {"orm", vt::LayerSemantic::kOrm},
      {"emissive", vt::LayerSemantic::kEmissive},
      {"custom", vt::LayerSemantic::kCustom}};
  for (auto& [name, value] : kNames) {
    if (s == name) {
      *sem = value;
      return true;
    }
  }
  return false;
}

int bad(const std::string& msg) {
  return vt::cli::bad_usage("build", msg);
}

// Stage, pages, rate and ETA.
void show_progress(vt::cli::ProgressLine& line, const vt::BuildProgress& p) {
  if (!line.due(p.pages_done >= p.pages_total)) return;
  const double t = line.elapsed_seconds();
  const double rate = t > 0 ? double(p.pages_done) / t : 0;
  const double eta = rate > 0 ? double(p.pages_total - p.pages_done) / rate : 0;
  line.print("%-15s layer %u level %2u  %llu/%llu pages  %.0f pages/s  ETA %.0f s  ", p.stage,
             p.layer, p.level, (unsigned long long)p.pages_done, (unsigned long long)p.pages_total,
             rate, eta);
}

void print_text(const vt::BuildOptions& o, const vt::BuildSummary& s, double wall) {
  std::printf(
      "%s: %u x %u texels, %zu levels, %llu pages (%llu stored, %llu constant, %llu "
      "absent), %.1f MiB in %.2f s\n",
      o.output.c_str(), s.geometry.width, s.geometry.height, s.levels.size(),
      (unsigned long long)s.pages, (unsigned long long)s.stored, (unsigned long long)s.constant,
      (unsigned long long)s.absent, double(s.file_bytes) / (1 << 20), wall);
  for (const vt::LayerSummary& l : s.layers) {
    std::printf("  layer \"%s\": %u x %s, %s -> %s, ", l.name.c_str(), l.spec.channels,
                vt::to_string(l.spec.texel_type), vt::to_string(l.spec.codec),
                vt::to_string(l.spec.runtime_format));
    if (s.update.unchanged) {
      std::printf("unchanged");
    } else if (l.hdr.samples > 0) {
      std::printf("stored %s", vt::cli::hdr_error_text(l.hdr).c_str());
    } else if (std::isfinite(l.psnr_db)) {
      std::printf("PSNR %.2f dB, max error %u", l.psnr_db, l.max_error);
    } else {
      std::printf("lossless");
    }
    std::printf("%s\n", vt::cli::runtime_error_text(l).c_str());
    if (l.alpha_dropped) std::printf("  alpha dropped: opaque\n");
    if (l.non_finite.any()) {
      std::printf(
          "  warning: %llu non-finite and %llu negative values, first at texel (%u, %u) "
          "channel %u; fixed as --fix-nonfinite says\n",
          (unsigned long long)l.non_finite.non_finite, (unsigned long long)l.non_finite.negative,
          l.non_finite.first_x, l.non_finite.first_y, l.non_finite.first_channel);
    }
  }
  if (s.update.requested || s.update.tables_pinned)
    std::printf("  %s\n", vt::update_text(s.update).c_str());
  std::printf("  stages:");
  for (const vt::StageTime& t : s.stages) std::printf(" %s %.2f s", t.name.c_str(), t.seconds);
  std::printf("\n");
}

int run_build(BuildArgs& f, const vt::cli::GlobalOptions& global) {
  vt::BuildOptions& o = f.options;
  o.threads = global.threads;
  // Positional images: the first is the albedo, the others custom layers named by file.
  std::vector<std::pair<std::string, std::string>> inputs;  // layer name, path
  for (size_t i = 0; i < f.images.size(); ++i) {
    // A layer name is UTF-8 (the file format's rule): a file name in another encoding gives its
    // Latin-1 reading.
    inputs.emplace_back(
        i == 0 ? "albedo" : vt::as_utf8(std::filesystem::path(f.images[i]).stem().string()),
        f.images[i]);
  }
  for (const std::string& spec : f.layers) {
    auto eq = spec.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size()) {
      return bad("--layer expects NAME=PATH, got '" + spec + "'");
    }
    if (!vt::valid_utf8(spec.substr(0, eq)))
      return bad("--layer: the name '" + spec.substr(0, eq) + "' is not UTF-8");
    inputs.emplace_back(spec.substr(0, eq), spec.substr(eq + 1));
  }
  if (inputs.empty()) return bad("no input image (give IMAGE or --layer NAME=PATH)");
  for (auto& [name, path] : inputs) {
    vt::LayerInput in;
    // procedural:WIDTHxHEIGHT is the generated sample pattern (benchmarks of any size, no file).
    uint32_t pw = 0, ph = 0;
    if (path.rfind("procedural:", 0) == 0) {
      if (vt::Status s = vt::cli::parse_procedural_size(path, &pw, &ph); !s.ok())
        return vt::cli::report_error("build", s);
      auto pattern =
          name == "normal" ? vt::ProceduralPattern::kNormal : vt::ProceduralPattern::kAlbedo;
      in.source = std::make_shared<vt::ProceduralImageSource>(pattern, pw, ph, 3, 1);
    } else {
      if (!vt::is_udim_pattern(path)) {
        if (vt::Status s = vt::check_input_file(path); !s.ok())
          return vt::cli::report_error("build", s);
      }
      auto src = vt::is_udim_pattern(path) ? vt::open_udim_image(path) : vt::open_image_file(path);
      if (!src.ok()) return vt::cli::report_error("build", src.status());
      in.source = std::shared_ptr<vt::ImageSource>(std::move(src).value());
    }
    vt::LayerSemantic sem;
    if (parse_semantic(name, &sem)) {
      in.semantic = sem;
    } else {
      in.semantic = vt::LayerSemantic::kCustom;
      in.name = name;
    }
    // --colorspace, else what a user config's file rules say; "" = the file's metadata.
    in.color_space = !f.colorspace.empty() || !o.color_config
                         ? f.colorspace
                         : o.color_config->space_from_file_rules(path);
    o.layers.push_back(std::move(in));
  }

  nlohmann::json meta;
  meta["tool"] = "vtbake " VTBAKE_VERSION;
  o.metadata_json = meta.dump();
  // Paths relative to the output, outside the plan hash: any spelling gives the same bytes.
  nlohmann::json provenance;
  provenance["sources"] = nlohmann::json::array();
  for (auto& [name, path] : inputs) {
    const std::string where =
        path.rfind("procedural:", 0) == 0 ? path : vt::path_for_metadata(path, o.output);
    provenance["sources"].push_back({{"layer", name}, {"path", where}});
  }
  o.provenance_json = provenance.dump();

  vt::cli::ProgressLine line(global.quiet);
  o.progress = [&line](const vt::BuildProgress& p) { show_progress(line, p); };
  auto start = std::chrono::steady_clock::now();
  auto summary = vt::build_page_file(o);
  line.done();
  double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!summary.ok()) return vt::cli::report_error("build", summary.status());
  for (const std::string& w : summary->warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  if (global.json) {
    nlohmann::json j = vt::to_json(*summary);
    j["output"] = o.output;
    j["seconds"]["total"] = wall;
    vt::cli::print_json("build", kExitOk, j);
  } else if (!global.quiet) {
    print_text(o, *summary, wall);
  }
  return kExitOk;
}

vt::cli::CommandRunner make_build(CLI::App& sub) {
  auto f = std::make_shared<BuildArgs>();
  sub.add_option("images", f->images,
                 "Input images (the first becomes the albedo layer); procedural:WxH for the "
                 "generated pattern; tex.<UDIM>.png for a UDIM grid of tiles (missing ones black)");
  sub.add_option("--layer", f->layers,
                 "A layer NAME=PATH; NAME albedo, normal, orm, emissive or any custom name");
  sub.add_option("--colorspace", f->colorspace,
                 "Colour space of the colour layers' inputs: a name, alias or role of the colour "
                 "config (sRGB, linear, ACEScg, Gamma2.2, raw ...); default: the config's file "
                 "rules, else the file's metadata, else sRGB (8/16-bit) or linear (float)");
  vt::BuildOptions& o = f->options;
  sub.add_option_function<std::string>(
         "--address",
         [&o](const std::string& name) {
           o.address = name == "wrap" ? vt::AddressMode::kWrap : vt::AddressMode::kClamp;
         },
         "Edge rule for borders: clamp or wrap")
      ->check(CLI::IsMember({"clamp", "wrap"}))
      ->default_str(vt::to_string(o.address));
  vt::cli::add_build_flags(sub, o);
  return [f](const vt::cli::GlobalOptions& global) { return run_build(*f, global); };
}

const vt::cli::CommandRegistration kBuild{"build", "Build a page file from images", make_build};

}  // namespace
