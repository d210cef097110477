// `vtbake bake SCENE -o OUT.vtpf`: the main job. Unwraps the scene, transfers its materials into
// the atlas, builds the page file and writes the unwrapped scene beside it. Flags map onto
// vt::SceneBakeOptions; the work is bake_scene() (bake/scene_bake.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake/build_summary_json.h"
#include "bake/scene_bake.h"
#include "bake/shard.h"
#include "cli/build_flags.h"
#include "cli/cli_util.h"
#include "cli/command.h"
#include "cli/json_output.h"
#include "cli/layer_error_text.h"
#include "cli/scene_load_flags.h"
#include "cli/unwrap_flags.h"
#include "format/atomic_output.h"

namespace {

struct BakeArgs {
  std::string scene;
  std::vector<std::string> scenes;  // positionals; several = a batch
  // Batches: one output per scene under out_dir, scenes also from a list file.
  std::string out_dir, list;
  bool keep_going = false;
  bool keep_folders = false;  // outputs at the scenes' relative paths under out_dir
  vt::SceneBakeOptions options;
  // Sharding over a build farm (bake/shard.h, docs/FARM.md).
  std::string plan, work, shard;
  std::vector<uint32_t> tasks;
  bool merge_last = false;
};

// "I/N" -> (I, N) with 0 <= I < N.
bool parse_shard(const std::string& text, uint32_t& index, uint32_t& count) {
  unsigned i = 0, n = 0;
  char end = 0;
  if (std::sscanf(text.c_str(), "%u/%u%c", &i, &n, &end) != 2 || n == 0 || i >= n) return false;
  index = i, count = n;
  return true;
}

// `--plan` (and `--work` without a shard): step 1 of a farm bake.
int run_plan(const BakeArgs& a, const vt::cli::GlobalOptions& global) {
  auto s = vt::plan_bake(a.scene, a.options, a.work, a.plan);
  if (!s.ok()) return vt::cli::report_error("bake", s.status());
  if (global.json) {
    nlohmann::json stages = nlohmann::json::object();
    for (const auto& st : s->stages) stages[st.name] = st.seconds;
    stages["total"] = s->seconds;
    vt::cli::print_json("bake", vt::cli::kExitOk,
                        {{"input", a.scene},
                         {"output", s->plan_path},
                         {"work", s->work_dir},
                         {"plan_hash", s->plan_hash},
                         {"tasks", s->tasks},
                         {"band_tasks", s->band_tasks},
                         {"pages", {{"total", s->pages}}},
                         {"seconds", stages}});
    return vt::cli::kExitOk;
  }
  std::printf("planned %s: %u tasks (%u band tasks), %llu pages to encode%s%s\n",
              s->plan_path.empty() ? a.work.c_str() : s->plan_path.c_str(), s->tasks, s->band_tasks,
              (unsigned long long)s->pages, a.work.empty() ? "" : "; work folder ", a.work.c_str());
  std::printf("  time      ");
  for (const auto& st : s->stages) std::printf(" %s %.2f s,", st.name.c_str(), st.seconds);
  std::printf(" total %.2f s\n", s->seconds);
  return vt::cli::kExitOk;
}

// `--work DIR --shard I/N` or `--tasks LIST`: step 2.
int run_shard(const BakeArgs& a, const vt::cli::GlobalOptions& global) {
  vt::ShardOptions so;
  so.work_dir = a.work;
  so.build = a.options.build;
  if (!a.shard.empty() && !parse_shard(a.shard, so.index, so.count)) {
    return vt::cli::bad_usage("bake", "--shard " + a.shard + ": expected I/N with 0 <= I < N");
  }
  so.tasks = a.tasks;
  so.merge_last = a.merge_last;
  so.merge.output = a.options.build.output;
  so.merge.unwrapped = a.options.unwrapped;
  auto s = vt::run_shard(so);
  if (!s.ok()) return vt::cli::report_error("bake", s.status());
  if (global.json) {
    nlohmann::json stages = nlohmann::json::object();
    for (const auto& st : s->stages) stages[st.name] = st.seconds;
    stages["total"] = s->seconds;
    nlohmann::json report = {
        {"input", a.work},
        {"output", s->part},
        {"tasks", s->tasks},
        {"pages", {{"total", s->pages}, {"stored", s->stored}, {"constant", s->constant}}},
        {"bytes", {{"stored", s->stored_bytes}}},
        {"seconds", stages}};
    // --merge-last: the page file this shard merged, or null (parts missing, or merged).
    if (a.merge_last) {
      report["merged"] = s->merged ? nlohmann::json(s->merge.output) : nlohmann::json(nullptr);
    }
    vt::cli::print_json("bake", vt::cli::kExitOk, report);
    return vt::cli::kExitOk;
  }
  std::printf("shard %s: %zu tasks, %llu pages (%llu stored, %llu constant), %.2f s\n",
              s->part.c_str(), s->tasks.size(), (unsigned long long)s->pages,
              (unsigned long long)s->stored, (unsigned long long)s->constant, s->seconds);
  if (s->merged) {
    std::printf("merged %s from %zu parts (%llu bytes)\n", s->merge.output.c_str(),
                s->merge.parts.size(), (unsigned long long)s->merge.file_bytes);
  }
  return vt::cli::kExitOk;
}

void print_summary(const vt::SceneBakeSummary& s) {
  const auto& g = s.build.geometry;
  std::printf("baked %s (unwrapped scene: %s)\n", s.output.c_str(),
              s.unwrapped.empty() ? "not written" : s.unwrapped.c_str());
  std::printf("  atlas      %u x %u texels, %lld charts, %.3g texels/unit, utilisation %.3f\n",
              g.width, g.height, (long long)s.unwrap.charts, s.unwrap.texels_per_unit,
              s.unwrap.utilisation);
  if (const auto& objects = s.unwrap.objects; !objects.empty()) {
    std::printf("  density    %zu object(s) denser than the scene's sources at their own:",
                objects.size());
    for (size_t i = 0; i < objects.size() && i < 3; ++i)
      std::printf("%s '%s' %.2fx", i ? "," : "", objects[i].name.c_str(), objects[i].scale);
    std::printf("%s\n", objects.size() > 3 ? ", ..." : "");
  }
  std::printf("  transfer   %llu triangles, %llu covered texels (%llu edge-only, %llu contested)\n",
              (unsigned long long)s.triangles, (unsigned long long)s.transfer.covered_texels,
              (unsigned long long)s.transfer.edge_only_texels,
              (unsigned long long)s.transfer.contested_texels);
  if (const vt::LightingStats& l = s.transfer.lighting; l.samples > 0) {
    std::printf(
        "  lighting   %llu samples, %llu shadow rays, %llu AO rays, structure %.1f MiB "
        "built in %.2f s\n",
        (unsigned long long)l.samples, (unsigned long long)l.shadow_rays,
        (unsigned long long)l.ao_rays, double(l.bvh_bytes) / (1 << 20), l.build_seconds);
  }
  std::printf("  layers    ");
  for (const auto& l : s.build.layers) {
    std::printf(" %s(%u ch, %s", l.name.c_str(), unsigned(l.spec.channels),
                vt::to_string(l.spec.codec));
    if (std::isfinite(l.psnr_db)) std::printf(", %.1f dB", l.psnr_db);
    if (l.hdr.samples > 0) std::printf(", stored %s", vt::cli::hdr_error_text(l.hdr).c_str());
    std::printf("%s)", vt::cli::runtime_error_text(l).c_str());
  }
  std::printf("\n");
  std::printf("  pages      %llu in %u levels: %llu stored, %llu constant, %llu absent\n",
              (unsigned long long)s.build.pages, g.level_count(),
              (unsigned long long)s.build.stored, (unsigned long long)s.build.constant,
              (unsigned long long)s.build.absent);
  std::printf("  bytes      %llu in the file, %llu raw texels, ratio %.1f:1\n",
              (unsigned long long)s.build.file_bytes,
              (unsigned long long)vt::raw_texel_bytes(s.build), vt::compression_ratio(s.build));
  if (s.build.update.requested || s.build.update.tables_pinned)
    std::printf("  %s\n", vt::update_text(s.build.update).c_str());
  std::printf("  time      ");
  for (const auto& st : s.stages) std::printf(" %s %.2f s,", st.name.c_str(), st.seconds);
  std::printf(" total %.2f s\n", s.seconds);
  // Peak RSS so far at the end of each stage: the first is the unwrap's own memory.
  std::printf("  memory    ");
  for (const auto& [stage, bytes] : s.peak_rss)
    std::printf(" %s %.0f MiB,", stage.c_str(), double(bytes) / (1 << 20));
  std::printf(" peak resident set at the end of each stage\n");
}

// A scene of a batch: its path, and the path as the command line or the list gave it.
struct BatchScene {
  std::string path, as_given;
};

// An absolute path below `folder` as given relative to it (what --keep-folders keeps: a list
// made with `find "$PWD" ...` names its scenes absolutely); any other path unchanged.
std::string relative_if_below(const std::filesystem::path& p, const std::filesystem::path& folder) {
  if (!p.is_absolute()) return p.string();
  std::error_code error;
  const std::filesystem::path base = std::filesystem::absolute(folder, error).lexically_normal();
  if (error) return p.string();
  const std::filesystem::path relative = p.lexically_normal().lexically_relative(base);
  return relative.empty() || *relative.begin() == ".." ? p.string() : relative.string();
}

// The scenes of a batch: the positionals, then --list FILE's lines (blank lines and lines
// starting with '#' skipped; relative paths from the list file's folder).
vt::Expected<std::vector<BatchScene>> batch_scenes(const BakeArgs& a) {
  std::vector<BatchScene> scenes;
  for (const std::string& s : a.scenes) scenes.push_back({s, relative_if_below(s, ".")});
  if (!a.list.empty()) {
    if (vt::Status s = vt::check_input_file(a.list); !s.ok()) return s.with_context("--list");
    std::ifstream in(a.list);
    const std::filesystem::path base = std::filesystem::path(a.list).parent_path();
    for (std::string line; std::getline(in, line);) {
      while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
      const size_t start = line.find_first_not_of(' ');
      if (start == std::string::npos || line[start] == '#') continue;
      std::filesystem::path p(line.substr(start));
      scenes.push_back({p.is_absolute() || base.empty() ? p.string() : (base / p).string(),
                        relative_if_below(p, base.empty() ? "." : base)});
    }
  }
  return scenes;
}

// A batch scene's page file: DIR/STEM.vtpf, or with --keep-folders DIR/PATH.vtpf for the path as
// given (relative, or absolute below the list's or the current folder; without '..': a game's
// models/*/head.md3 each get their own).
vt::Expected<std::string> batch_output(const BakeArgs& a, const BatchScene& scene) {
  const std::filesystem::path dir(a.out_dir);
  if (!a.keep_folders) return (dir / std::filesystem::path(scene.path).stem()).string() + ".vtpf";
  const std::filesystem::path relative = std::filesystem::path(scene.as_given).lexically_normal();
  if (relative.is_absolute() || !relative.has_filename() || *relative.begin() == "..") {
    return vt::Error(vt::ErrorCode::kInvalidArgument,
                     scene.path + ": --keep-folders needs a path below the list's folder (or " +
                         "the current one), not '" + scene.as_given + "'");
  }
  return (dir / relative).replace_extension(".vtpf").string();
}

// `vtbake bake A B ... --out-dir D` / `--list FILE`: every argument and input checked first,
// then one bake per scene into D/STEM.vtpf (+ .glb), a line per scene on stderr, a summary
// table (or one JSON line per scene with --json) on stdout.
int run_batch(BakeArgs& a, const vt::cli::GlobalOptions& global) {
  if (a.out_dir.empty()) return vt::cli::bad_usage("bake", "several scenes need --out-dir DIR");
  if (!a.options.build.output.empty())
    return vt::cli::bad_usage("bake", "-o names one output; a batch writes under --out-dir");
  if (!a.plan.empty() || !a.work.empty() || !a.shard.empty() || !a.tasks.empty())
    return vt::cli::bad_usage("bake", "--plan, --work, --shard and --tasks take one scene");
  auto scenes = batch_scenes(a);
  if (!scenes.ok()) return vt::cli::report_error("bake", scenes.status());
  if (scenes->empty()) return vt::cli::bad_usage("bake", "--list " + a.list + ": no scenes");
  struct Item {
    std::string scene, output;
    vt::Status status;
    vt::SceneBakeSummary summary;
    bool done = false;
  };
  std::vector<Item> items;
  std::map<std::string, std::string> outputs;  // output -> scene: two scenes on one refused
  bool bad_input = false;
  for (const BatchScene& scene : *scenes) {
    Item it;
    it.scene = scene.path;
    auto output = batch_output(a, scene);
    it.output = output.ok() ? *output : "";
    it.status = output.ok() ? vt::check_input_file(scene.path) : output.status();
    if (auto [at, fresh] = outputs.emplace(it.output, scene.path); !fresh && it.status.ok()) {
      it.status =
          vt::Error(vt::ErrorCode::kInvalidArgument,
                    scene.path + ": would write " + it.output + " as " + at->second + " does" +
                        (a.keep_folders ? "" : " (--keep-folders keeps them apart)"));
    }
    if (!it.status.ok()) {
      std::fprintf(stderr, "vtbake bake: %s\n", it.status.message().c_str());
      bad_input = true;
    }
    items.push_back(std::move(it));
  }
  if (bad_input && !a.keep_going) {
    const char* message = "nothing baked (--keep-going bakes the other scenes)";
    std::fprintf(stderr, "vtbake bake: %s\n", message);
    if (global.json) {
      nlohmann::json bad = nlohmann::json::array();
      for (const Item& it : items)
        if (!it.status.ok())
          bad.push_back({{"input", it.scene}, {"error", vt::cli::error_json(it.status)}});
      vt::cli::print_json(
          "bake", vt::cli::kExitBadInput,
          {{"error", {{"code", "invalid_argument"}, {"message", message}}}, {"scenes", bad}});
    }
    return vt::cli::kExitBadInput;
  }
  for (const Item& it : items) {
    if (!it.status.ok()) continue;
    const std::string folder = std::filesystem::path(it.output).parent_path().string();
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    if (ec) {
      return vt::cli::report_error(
          "bake", vt::Error(vt::ErrorCode::kIo, folder + ": cannot create: " + ec.message()));
    }
  }
  size_t failed = 0, baked = 0;
  for (size_t i = 0; i < items.size(); ++i) {
    Item& it = items[i];
    if (it.status.ok()) {
      vt::SceneBakeOptions o = a.options;
      o.build.output = it.output;
      if (o.unwrapped != "-") o.unwrapped = "";  // beside each output
      if (o.cache != "-") o.cache = "";
      if (!global.quiet)
        std::fprintf(stderr, "bake %zu/%zu %s -> %s\n", i + 1, items.size(), it.scene.c_str(),
                     it.output.c_str());
      auto s = vt::bake_scene(it.scene, o);
      it.done = true;
      if (s.ok()) {
        it.summary = std::move(s).value();
        ++baked;
        for (const std::string& w : it.summary.warnings)
          // Most warnings name the scene already (the importers'); the others get its name.
          std::fprintf(stderr, "warning: %s%s\n",
                       w.rfind(it.scene, 0) == 0 ? "" : (it.scene + ": ").c_str(), w.c_str());
      } else {
        it.status = s.status();
        std::fprintf(stderr, "vtbake bake: %s\n", it.status.message().c_str());
      }
    }
    if (!it.status.ok()) ++failed;
    if (global.json) {
      nlohmann::json j = it.status.ok() ? vt::to_json(it.summary) : nlohmann::json::object();
      j["input"] = it.scene;
      j["output"] = it.output;
      if (!it.status.ok()) j["error"] = vt::cli::error_json(it.status);
      vt::cli::print_json("bake", it.status.ok() ? 0 : vt::cli::exit_code_for(it.status), j);
    }
    if (!it.status.ok() && !a.keep_going) break;
  }
  if (!global.json) {
    std::printf("%-40s %-8s %8s %12s %9s\n", "scene", "status", "pages", "bytes", "seconds");
    for (const Item& it : items) {
      const char* status = it.status.ok() ? (it.done ? "ok" : "skipped") : "failed";
      if (it.status.ok() && it.done) {
        std::printf("%-40s %-8s %8llu %12llu %9.2f\n", it.scene.c_str(), status,
                    (unsigned long long)it.summary.build.pages,
                    (unsigned long long)it.summary.build.file_bytes, it.summary.seconds);
      } else {
        std::printf("%-40s %-8s %8s %12s %9s\n", it.scene.c_str(), status, "-", "-", "-");
      }
    }
    std::printf("%zu of %zu scenes baked\n", baked, items.size());
  }
  if (failed == 0) return vt::cli::kExitOk;
  const bool ran_and_failed = std::any_of(
      items.begin(), items.end(), [](const Item& it) { return it.done && !it.status.ok(); });
  return ran_and_failed ? vt::cli::kExitFailure : vt::cli::kExitBadInput;
}

vt::cli::CommandRunner make_bake(CLI::App& app) {
  auto args = std::make_shared<BakeArgs>();
  vt::SceneBakeOptions& o = args->options;
  app.add_option(
      "scene", args->scenes,
      "Scene(s) to bake (.gltf, .glb, .obj, .ply, .drc, .ac, .acc, or what assimp reads: .fbx, "
      ".dae, .3ds, .md3, ...); several = a batch (--out-dir)");
  CLI::Option* out_dir = app.add_option(
      "--out-dir", args->out_dir,
      "Batch: write each scene's page file (and .glb) as DIR/STEM.vtpf; parent folders "
      "are created");
  app.add_option("--list", args->list,
                 "Batch: also bake the scenes listed in FILE, one path a line (relative to FILE's "
                 "folder; '#' lines skipped)");
  app.add_flag("--keep-going", args->keep_going,
               "Batch: bake the other scenes when one fails (exit 1 if any failed)");
  app.add_flag("--keep-folders", args->keep_folders,
               "Batch: write DIR/PATH.vtpf for each scene's path below the list's folder or the "
               "current one (as given, or the part below when given absolute; no '..') instead "
               "of DIR/STEM.vtpf, so scenes of one name in different folders stay apart")
      ->needs(out_dir);
  app.add_option("--unwrapped", o.unwrapped,
                 "Where to write the unwrapped scene (.glb; default OUT.glb; '-' = not written)");
  app.add_option("--cache", o.cache,
                 "Folder of the caches that --update reads (default OUT.cache; '-' = none): the "
                 "unwrap's, written by every bake, and the transfer's bands, written by --update "
                 "(a first one too) or when this is given");
  app.add_option("--supersample", o.supersample, "Transfer samples per texel: 1, 4 or 16")
      ->check(CLI::IsMember({1, 4, 16}));
  app.add_option_function<std::string>(
         "--missing-textures",
         [&o](const std::string& v) {
           auto policy = vt::parse_missing_textures(v);
           if (!policy.ok())
             throw CLI::ValidationError("--missing-textures", policy.status().message());
           o.missing_textures = *policy;
         },
         "A texture that cannot be read: error (default: fail naming the material, slot and "
         "path) or warn (bake the slot from its factor alone and list the miss)")
      ->default_str("error");
  app.add_option("--ao-samples", o.lighting.ao_samples,
                 "Ambient occlusion rays per texel sample, cosine-weighted, into the lighting "
                 "layer's 4th channel (0 = none; baked only when the scene has lights)")
      ->check(CLI::Range(0, 65536))
      ->default_val(0);
  app.add_option("--ao-distance", o.lighting.ao_distance,
                 "How far an AO ray looks, in world units (0 = the scene's bounding-box diagonal)")
      ->check(CLI::NonNegativeNumber)
      ->default_val(0);
  app.add_option("--bounces", o.lighting.bounces,
                 "Diffuse bounces of light into the lighting layer: 0 (direct only) or 1 (each "
                 "texel also gathers light reflected once by the surfaces around it)")
      ->check(CLI::Range(0, 1))
      ->default_val(0);
  app.add_option("--bounce-samples", o.lighting.bounce_samples,
                 "Cosine-weighted rays per texel sample for --bounces 1")
      ->check(CLI::Range(1, 65536))
      ->default_val(16);
  app.add_option_function<std::string>(
         "--lighting",
         [&o](const std::string& v) {
           auto layer = vt::parse_lighting_layer(v);
           if (!layer.ok()) throw CLI::ValidationError("--lighting", layer.status().message());
           o.lighting.layer = *layer;
         },
         "What a lit scene's light becomes: separate (default: irradiance in its own HDR "
         "'lighting' layer) or combined (a 'lit_albedo' HDR layer instead: base colour x "
         "irradiance / pi, for engines that want one texture; no --ao-samples)")
      ->default_str("separate");
  app.add_flag(
      "--no-shadows", [&o](int64_t) { o.lighting.shadows = false; },
      "Lighting without shadow rays: every light reaches every texel facing it");
  vt::cli::add_scene_load_flags(app, o.load);
  vt::cli::add_unwrap_flags(app, o.unwrap);
  vt::cli::add_build_flags(app, o.build);
  app.get_option("--output")->required(false);  // checked below: a batch has --out-dir instead
  auto* plan =
      app.add_option("--plan", args->plan,
                     "Build farm, step 1: write the task graph (tasks, keys, dependencies, "
                     "cost) to this JSON file instead of baking; with --work, also the "
                     "shards' inputs into DIR (docs/FARM.md)");
  app.add_option("--work", args->work,
                 "Build farm: the shared work folder of a sharded bake (with --plan, --shard or "
                 "--tasks)");
  auto* shard = app.add_option("--shard", args->shard,
                               "Build farm, step 2: encode shard I of N (0 <= I < N) of the plan "
                               "in --work into DIR/parts; then `vtbake merge DIR`")
                    ->needs("--work");
  app.add_option("--tasks", args->tasks, "Build farm, step 2: encode these band tasks of the plan")
      ->delimiter(',')
      ->needs("--work")
      ->excludes(shard)
      ->excludes(plan);
  shard->excludes(plan);
  app.add_flag("--merge-last", args->merge_last,
               "Build farm: with --shard I/N, merge into -o once every part of N is in DIR "
               "(the last shard to finish merges; DIR/merged.json records it), so a farm needs "
               "no merge job")
      ->needs(shard);
  return [args](const vt::cli::GlobalOptions& global) -> int {
    vt::SceneBakeOptions& o = args->options;
    o.build.threads = global.threads;
    if (args->scenes.empty() && args->list.empty())
      return vt::cli::bad_usage("bake", "no scene given");
    if (args->scenes.size() != 1 || !args->out_dir.empty() || !args->list.empty())
      return run_batch(*args, global);
    args->scene = args->scenes[0];
    if (o.build.output.empty()) return vt::cli::bad_usage("bake", "-o OUT.vtpf is required");
    if (!args->shard.empty() || !args->tasks.empty()) return run_shard(*args, global);
    // Stage, its fraction, elapsed time; redrawn at once when the stage changes.
    vt::cli::ProgressLine progress(global.quiet);
    std::string stage;
    o.progress = [&](const vt::SceneBakeProgress& p) {
      if (!progress.due(stage != p.stage || p.fraction >= 1.0)) return;
      stage = p.stage;
      progress.print("%-12s %5.1f%%  %6.1f s   ", p.stage, 100.0 * p.fraction,
                     progress.elapsed_seconds());
    };
    if (vt::Status in = vt::check_input_file(args->scene); !in.ok())
      return vt::cli::report_error("bake", in);
    if (!args->plan.empty() || !args->work.empty()) {
      if (args->work.empty() == false && args->plan.empty())
        args->plan = vt::work_plan_path(args->work);
      return run_plan(*args, global);
    }
    auto summary = vt::bake_scene(args->scene, o);
    progress.done();
    if (!summary.ok()) return vt::cli::report_error("bake", summary.status());
    for (const std::string& w : summary->warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    if (global.json) {
      nlohmann::json j = vt::to_json(*summary);
      j["input"] = args->scene;
      vt::cli::print_json("bake", vt::cli::kExitOk, j);
    } else {
      print_summary(*summary);
    }
    return vt::cli::kExitOk;
  };
}

const vt::cli::CommandRegistration kBake{
    "bake", "Bake a scene's materials into a page file (unwrap, transfer, pyramid, pages)",
    make_bake};

}  // namespace
