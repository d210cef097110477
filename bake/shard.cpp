// A scene bake sharded over a build farm (see shard.h and docs/FARM.md).
#include "bake/shard.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>
#define XXH_STATIC_LINKING_ONLY  // XXH3_state_t as a member
#include <xxhash.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string_view>

#include "bake/build_plan.h"
#include "bake/build_tasks.h"
#include "bake/level_source.h"
#include "bake/level_store.h"
#include "bake/unwrap/unwrap.h"
#include "bake/update.h"
#include "common/utf8.h"
#include "format/atomic_output.h"

#ifndef VTBAKE_VERSION
#define VTBAKE_VERSION "unknown"
#endif

namespace vt {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

constexpr const char* kPlanSchema = "vtbake-plan/1";
// How a saved level stores its rows (plan.json "format"; LevelStore::save).
constexpr const char* kRawLevel = "raw";
constexpr const char* kCompressedLevel = "zstd-chunks";
constexpr char kPartMagic[8] = {'V', 'T', 'P', 'A', 'R', 'T', '0', '1'};
enum PartTag : uint8_t { kEnd = 0, kPage = 1, kTask = 2, kKey = 3 };

// Keys go into JSON as 16 hex digits: JSON readers lose integers past 2^53.
std::string hex(uint64_t v) {
  char s[17];
  std::snprintf(s, sizeof s, "%016llx", (unsigned long long)v);
  return s;
}
uint64_t unhex(const nlohmann::json& j) {
  return j.is_string() ? std::strtoull(j.get<std::string>().c_str(), nullptr, 16) : 0;
}

Status io_error(const std::string& path, const std::string& what) {
  return Error(ErrorCode::kIo, path + ": " + what + ": " + std::strerror(errno));
}

// Level 0 of a layer as the plan wrote it: raw little-endian floats, row-major, read as a saved
// level (LevelStore::open_saved checks its size).
class RawFileSource final : public ImageSource {
 public:
  static Expected<std::shared_ptr<RawFileSource>> open(const std::string& path, ImageInfo info) {
    VT_ASSIGN_OR_RETURN(
        std::shared_ptr<LevelStore> file,
        LevelStore::open_saved(path, info.width, info.height, info.channels, false));
    return std::shared_ptr<RawFileSource>(
        new RawFileSource(std::move(file), path, std::move(info)));
  }
  const ImageInfo& info() const override { return info_; }
  // The plan wrote the file with the hash of its bytes, which is the default content hash
  // (XXH3 of the rows in order): taken from the plan instead of reading the whole level again.
  void set_content_hash(uint64_t hash) { hash_ = hash; }
  Expected<uint64_t> content_hash() override {
    if (hash_) return *hash_;
    return ImageSource::content_hash();
  }
  Status read_rows(uint32_t y0, uint32_t y1, float* out) override {
    return file_->read(y0, y1, out);
  }
  std::string origin() const override { return path_; }

 private:
  RawFileSource(std::shared_ptr<LevelStore> file, std::string path, ImageInfo info)
      : file_(std::move(file)), path_(std::move(path)), info_(std::move(info)) {}
  std::shared_ptr<LevelStore> file_;
  std::string path_;
  ImageInfo info_;
  std::optional<uint64_t> hash_;
};

// Level 0 of a layer the plan wrote only in working form: its identity (shape, the plan's
// content hash) without texels; the shard reads the working form instead (given_levels).
class PlannedSource final : public ImageSource {
 public:
  PlannedSource(ImageInfo info, uint64_t hash, std::string what)
      : info_(std::move(info)), hash_(hash), what_(std::move(what)) {}
  const ImageInfo& info() const override { return info_; }
  Expected<uint64_t> content_hash() override { return hash_; }
  Status read_rows(uint32_t, uint32_t, float*) override {
    return Error(ErrorCode::kInternal,
                 what_ + ": the plan wrote this layer's level 0 in working form only");
  }
  std::string origin() const override { return what_; }

 private:
  ImageInfo info_;
  uint64_t hash_;
  std::string what_;
};

// A level in its working form as the plan saved it (converted, dilated), read by rows, with
// the mask the shard derives for it.
class FileLevel final : public LevelSource {
 public:
  FileLevel(std::shared_ptr<LevelStore> file, std::shared_ptr<const CoverageMask> cov)
      : file_(std::move(file)), coverage_(std::move(cov)) {}
  uint32_t width() const override { return file_->width(); }
  uint32_t height() const override { return file_->height(); }
  uint32_t channels() const override { return file_->channels(); }
  Status read(uint32_t y0, uint32_t y1, float* out) override { return file_->read(y0, y1, out); }
  const CoverageMask* coverage() const override { return coverage_.get(); }

 private:
  std::shared_ptr<LevelStore> file_;
  std::shared_ptr<const CoverageMask> coverage_;
};

// A file written through a staged name: bytes appended with a running XXH3 of all of them.
class HashedFile {
 public:
  Status open(const std::string& path) {
    path_ = path;
    f_ = std::fopen(path.c_str(), "wb");
    if (!f_) return io_error(path, "cannot write");
    XXH3_64bits_reset(&state_);
    return Status::Ok();
  }
  ~HashedFile() {
    if (f_) std::fclose(f_);
  }
  void put(const void* data, size_t n) {
    if (!ok_ || n == 0) return;
    ok_ = std::fwrite(data, 1, n, f_) == n;
    XXH3_64bits_update(&state_, data, n);
  }
  template <class T>
  void put(T v) {
    put(&v, sizeof v);
  }
  uint64_t digest() { return XXH3_64bits_digest(&state_); }
  Status close() {
    const bool closed = std::fclose(f_) == 0;
    f_ = nullptr;
    if (!ok_ || !closed) return io_error(path_, "write failed");
    return Status::Ok();
  }

 private:
  std::string path_;
  std::FILE* f_ = nullptr;
  bool ok_ = true;
  XXH3_state_t state_;
};

Status write_text(const std::string& path, const std::string& text) {
  HashedFile f;
  VT_RETURN_IF_ERROR(f.open(path));
  f.put(text.data(), text.size());
  return f.close();
}

// The mask as one byte per texel (level0/coverage.u8), written in bands.
Status write_coverage(const CoverageMask& c, const std::string& path) {
  HashedFile f;
  VT_RETURN_IF_ERROR(f.open(path));
  std::vector<uint8_t> rows;
  for (uint32_t y = 0; y < c.height(); y += c.band_rows()) {
    VT_RETURN_IF_ERROR(c.read_rows(y, std::min(c.height(), y + c.band_rows()), rows));
    f.put(rows.data(), rows.size());
  }
  return f.close();
}

// Writes `height` rows of `row` floats, read a band of about 4 MiB at a time by `read(y0, y1,
// out)`, to `path`; returns the XXH3 of the bytes written (the rows in order, as
// ImageSource::content_hash hashes them).
template <class Read>
Expected<uint64_t> write_rows(const std::string& path, size_t row, uint32_t height, Read read) {
  HashedFile f;
  VT_RETURN_IF_ERROR(f.open(path));
  const uint32_t band = uint32_t(
      std::clamp<size_t>((size_t(4) << 20) / std::max<size_t>(row, 1), 1, std::max(1u, height)));
  std::vector<float> rows(row * band);
  for (uint32_t y = 0; y < height; y += band) {
    const uint32_t y1 = std::min(height, y + band);
    VT_RETURN_IF_ERROR(read(y, y1, rows.data()));
    f.put(rows.data(), size_t(y1 - y) * row * sizeof(float));
  }
  const uint64_t digest = f.digest();
  VT_RETURN_IF_ERROR(f.close());
  return digest;
}

Expected<uint64_t> write_source(ImageSource& source, const std::string& path) {
  const ImageInfo& info = source.info();
  return write_rows(
      path, size_t(info.width) * info.channels, info.height,
      [&](uint32_t y0, uint32_t y1, float* out) { return source.read_rows(y0, y1, out); });
}

// How a level is saved for the shards (plan.json "format"): a store's compressed scratch file
// as its chunks, anything else as raw floats.
const char* level_format(LevelSource& level) {
  const LevelStore* store = level.held_store();
  return store && store->compressed() ? kCompressedLevel : kRawLevel;
}
std::string level_file_name(const char* format, const std::string& stem) {
  return stem + (std::string_view(format) == kCompressedLevel ? ".f32.zc" : ".f32");
}

// A level for the shards at `path`, in level_format's form: a level store saves itself (a
// scratch file is linked, not copied); other levels are written as raw rows.
Status save_level(LevelSource& level, const std::string& path) {
  if (LevelStore* store = level.held_store()) return store->save(path);
  return write_rows(path, level.row_floats(), level.height(),
                    [&](uint32_t y0, uint32_t y1, float* out) { return level.read(y0, y1, out); })
      .status();
}

Expected<nlohmann::json> read_json(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return Error(ErrorCode::kNotFound,
                 path +
                     ": no plan here (run `vtbake bake SCENE --work DIR --plan DIR/plan.json` "
                     "first)");
  }
  std::stringstream text;
  text << in.rdbuf();
  auto j = nlohmann::json::parse(text.str(), nullptr, false);
  if (j.is_discarded() || !j.is_object() || j.value("schema", "") != kPlanSchema) {
    return Error(ErrorCode::kCorrupt, path + ": not a vtbake plan (" + kPlanSchema + ")");
  }
  return j;
}

// A work folder's plan as the shards and the merge read it.
struct WorkPlan {
  std::string dir;
  nlohmann::json json;
  uint64_t hash = 0;
  std::vector<BuildTask> tasks;
  std::vector<uint64_t> keys;
  std::vector<double> cost;
};

Expected<WorkPlan> load_plan(const std::string& work_dir) {
  WorkPlan w;
  w.dir = work_dir;
  VT_ASSIGN_OR_RETURN(w.json, read_json(work_plan_path(work_dir)));
  w.hash = unhex(w.json["plan_hash"]);
  for (const auto& t : w.json["tasks"]) {
    BuildTask task;
    task.kind = t.value("kind", "") == "level" ? BuildTask::Kind::kLevel : BuildTask::Kind::kBand;
    task.layer = t.value("layer", 0u), task.level = t.value("level", 0u);
    task.row = t.value("row", 0u);
    task.deps = t.value("deps", std::vector<uint32_t>{});
    w.tasks.push_back(task);
    w.keys.push_back(unhex(t["key"]));
    w.cost.push_back(t.value("cost", 0.0));
  }
  return w;
}

nlohmann::json task_json(const std::vector<BuildTask>& tasks, const BuildSummary& keys,
                         const BuildPlan& plan) {
  nlohmann::json out = nlohmann::json::array();
  for (size_t i = 0; i < tasks.size(); ++i) {
    const BuildTask& t = tasks[i];
    const bool band = t.kind == BuildTask::Kind::kBand;
    // Estimated cost: pages to encode, in page encodes (kLevel tasks run in every shard).
    out.push_back({{"id", i},
                   {"kind", band ? "band" : "level"},
                   {"layer", t.layer},
                   {"layer_name", plan.layers[t.layer].spec.name},
                   {"level", t.level},
                   {"row", t.row},
                   {"deps", t.deps},
                   {"key", hex(keys.task_keys[i])},
                   {"pages", band ? keys.task_pages[i] : 0},
                   {"cost", band ? double(keys.task_pages[i]) : 0.0},
                   {"pyramid_seconds", keys.task_seconds[i]}});
  }
  return out;
}

// Pages go nowhere: the plan's pass computes keys only.
class NullSink final : public PageSink {
 public:
  Status add_page(const PageId&, uint32_t, std::span<const uint8_t>) override {
    return Status::Ok();
  }
  Status add_constant_page(const PageId&, uint32_t, std::span<const uint8_t>) override {
    return Status::Ok();
  }
};

std::string default_glb(const std::string& output) {
  fs::path p(output);
  p.replace_extension(".glb");
  return p.string();
}

std::string absolute(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::absolute(path, ec);
  return (ec ? fs::path(path) : p).lexically_normal().string();
}

// Moves `from` onto `to` (another folder, perhaps another file system).
Status move_file(const std::string& from, const std::string& to) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (!ec) return Status::Ok();
  fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);
  if (ec) return Error(ErrorCode::kIo, to + ": cannot copy " + from + ": " + ec.message());
  fs::remove(from, ec);
  return Status::Ok();
}

// Removes parts of another plan from DIR/parts (a plan made again into the same folder).
void remove_stale_parts(const std::string& work_dir, uint64_t plan_hash);

}  // namespace

std::string work_plan_path(const std::string& work_dir) {
  return (fs::path(work_dir) / "plan.json").string();
}
std::string shard_part_path(const std::string& work_dir, uint32_t index, uint32_t count) {
  return (fs::path(work_dir) / "parts" /
          ("shard-" + std::to_string(index) + "-of-" + std::to_string(count) + ".part"))
      .string();
}
std::string tasks_part_path(const std::string& work_dir, const std::vector<uint32_t>& tasks) {
  const uint64_t h = XXH3_64bits(tasks.data(), tasks.size() * sizeof(uint32_t));
  return (fs::path(work_dir) / "parts" / ("tasks-" + hex(h) + ".part")).string();
}

Expected<PlanSummary> plan_bake(const std::string& scene_path, const SceneBakeOptions& opts,
                                const std::string& work_dir, const std::string& plan_path) {
  auto start = Clock::now();
  PlanSummary sum;
  sum.plan_path = plan_path;
  sum.work_dir = work_dir;
  SceneBakeOptions options = opts;
  options.build.update = false;  // a farm bake is a clean bake (tables: --tables-from or trained)
  const std::string output = options.build.output;
  const std::string glb = options.unwrapped.empty()  ? default_glb(output)
                          : options.unwrapped == "-" ? ""
                                                     : options.unwrapped;
  // Every output is staged before the work, so that a bad path fails first.
  OutputSet outputs;
  std::vector<std::string> staged_layers;
  std::string staged_coverage, staged_tables, staged_glb;
  const std::string dir = work_dir.empty() ? "" : absolute(work_dir);
  // The plan records these paths as JSON text, which is UTF-8, and the shards open them again.
  for (const std::string& path : {scene_path, output, glb, dir}) {
    if (!valid_utf8(path)) {
      return Error(ErrorCode::kInvalidArgument,
                   path +
                       ": a farm plan records its paths as JSON text, which must be UTF-8, and "
                       "this one is not (rename it, or bake in one process)");
    }
  }
  if (!dir.empty()) {
    std::error_code ec;
    fs::create_directories(fs::path(dir) / "level0", ec);
    fs::create_directories(fs::path(dir) / "levels", ec);
    fs::create_directories(fs::path(dir) / "parts", ec);
    if (ec) return Error(ErrorCode::kIo, dir + ": cannot create the work folder: " + ec.message());
  }

  auto t0 = Clock::now();
  auto loaded = scene::load_scene(scene_path, options.load);
  if (!loaded.ok()) return loaded.status();
  VT_RETURN_IF_ERROR(scene::validate_geometry(*loaded));
  sum.stages.push_back({"load", seconds_since(t0)});
  auto prepared = prepare_scene_bake(*loaded, options);
  if (!prepared.ok()) return prepared.status().with_context(scene_path);
  for (const StageTime& st : prepared->summary.stages) sum.stages.push_back(st);

  // Level 0 as the transfer gave it (before drop_opaque_alpha, which each shard runs again:
  // the plan hash is of the sources as the build sees them). A layer that carries the coverage
  // mask gets its level 0 in working form below, which is all its shards read of it: for those
  // only the content hash is recorded, not the texels (a whole level of writes saved).
  t0 = Clock::now();
  BuildOptions bo = prepared->build;
  const bool coverage = !bo.layers.empty() && bo.layers[0].coverage;
  nlohmann::json layers = nlohmann::json::array();
  std::vector<uint64_t> layer_hashes;
  std::vector<bool> raw_written;
  for (size_t i = 0; i < bo.layers.size(); ++i) {
    const LayerInput& in = bo.layers[i];
    const ImageInfo& info = in.source->info();
    const std::string name = in.name.empty() ? to_string(in.semantic) : in.name;
    const bool raw = !coverage || in.coverage != bo.layers[0].coverage;
    const std::string file = raw ? "level0/" + name + ".f32" : "";
    if (!dir.empty()) {
      // A layer kept only in working form is hashed after plan_build, which hashes the rows as
      // it converts them (at 64K, asking first read a 51 GB level 0 once more: 86.5 s).
      uint64_t hash = 0;
      if (raw) {
        VT_ASSIGN_OR_RETURN(std::string staged, outputs.stage(dir + "/" + file));
        VT_ASSIGN_OR_RETURN(hash, write_source(*in.source, staged));
      }
      layer_hashes.push_back(hash);
    }
    raw_written.push_back(raw);
    layers.push_back({{"name", name},
                      {"semantic", int(in.semantic)},
                      {"file", file},
                      {"width", info.width},
                      {"height", info.height},
                      {"channels", info.channels},
                      {"is_float", info.is_float},
                      {"alpha_channel", info.alpha_channel},
                      {"info_color_space", info.color_space},
                      {"color_space", in.color_space}});
  }
  if (!dir.empty() && coverage) {
    VT_ASSIGN_OR_RETURN(std::string staged, outputs.stage(dir + "/level0/coverage.u8"));
    VT_RETURN_IF_ERROR(write_coverage(*bo.layers[0].coverage, staged));
  }
  sum.stages.push_back({"write level 0", seconds_since(t0)});

  // The plan (tables trained once, here) and a pass over the pyramid for the task keys.
  t0 = Clock::now();
  VT_RETURN_IF_ERROR(drop_opaque_alpha(bo));
  VT_ASSIGN_OR_RETURN(BuildPlan plan, plan_build(bo));
  sum.stages.push_back({"plan", seconds_since(t0)});
  for (size_t i = 0; i < plan.layers.size(); ++i) {
    layers[i]["input_key"] = hex(plan.layers[i].input_key);  // for the merged update record
    // What a shard would otherwise read the whole of level 0 for: its hash and the alpha scan.
    // The hash is of the source before drop_opaque_alpha (each shard drops it again).
    if (i < layer_hashes.size()) {
      if (!raw_written[i]) {
        VT_ASSIGN_OR_RETURN(layer_hashes[i], prepared->build.layers[i].source->content_hash());
      }
      layers[i]["content_hash"] = hex(layer_hashes[i]);
      layers[i]["alpha_dropped"] = bo.layers[i].alpha_dropped;
    }
  }
  // Level 0 in its working form (converted, dilated) for the shards, which would otherwise each
  // redo it: for the layers whose held level 0 carries the input's coverage mask. Saved on a
  // thread of its own while the key pass below runs (which only reads level 0): a level held in
  // memory is copied out (2.9 s at 5,760², where the key pass leaves part of a core idle); one
  // in a scratch file is linked at once.
  std::vector<std::pair<size_t, std::string>> working;  // layer, staged path
  for (size_t i = 0; i < plan.layers.size() && !dir.empty(); ++i) {
    LevelSource& level0 = *plan.layers[i].level0;
    if (!coverage || level0.coverage() != bo.layers[i].coverage.get()) {
      if (!raw_written[i]) {
        return Error(ErrorCode::kInternal, "plan: layer " + plan.layers[i].spec.name +
                                               " has neither level 0 as transferred nor its "
                                               "working form in the work folder");
      }
      continue;
    }
    const char* format = level_format(level0);
    const std::string file =
        level_file_name(format, "level0/" + plan.layers[i].spec.name + ".work");
    VT_ASSIGN_OR_RETURN(std::string staged, outputs.stage(dir + "/" + file));
    working.emplace_back(i, std::move(staged));
    layers[i]["work_file"] = file;
    layers[i]["work_format"] = format;
    layers[i]["work_channels"] = level0.channels();
  }
  double t_working = 0;
  std::future<Status> saving = std::async(std::launch::async, [&]() -> Status {
    const auto t = Clock::now();
    for (const auto& [layer, staged] : working)
      VT_RETURN_IF_ERROR(save_level(*plan.layers[layer].level0, staged));
    t_working = seconds_since(t);
    return Status::Ok();
  });
  t0 = Clock::now();
  const std::vector<BuildTask> tasks = make_build_tasks(plan);
  plan.options.task_subset = std::make_shared<const std::vector<uint8_t>>(tasks.size(), 0);
  // The coarser levels as this pass makes them, so that no shard redoes the pyramid (each would
  // read and filter the whole atlas, however few pages it encodes).
  double t_levels = 0;
  if (!dir.empty()) {
    plan.options.level_done = [&](size_t li, uint32_t level, LevelSource& texels,
                                  float alpha_scale) -> Status {
      const auto t = Clock::now();
      const char* format = level_format(texels);
      const std::string file = level_file_name(
          format, "levels/" + plan.layers[li].spec.name + "." + std::to_string(level));
      VT_ASSIGN_OR_RETURN(std::string staged, outputs.stage(dir + "/" + file));
      VT_RETURN_IF_ERROR(save_level(texels, staged));
      nlohmann::json& l = layers[li];
      if (!l.contains("levels")) l["levels"] = nlohmann::json::array();
      l["levels"].push_back({{"file", file}, {"format", format}, {"alpha_scale", alpha_scale}});
      l["levels_coverage"] = texels.coverage() != nullptr;
      l["work_channels"] = texels.channels();
      t_levels += seconds_since(t);
      return Status::Ok();
    };
  }
  NullSink none;
  Expected<BuildSummary> keyed = build_pages(plan, none);
  const double t_keys = seconds_since(t0) - t_levels;
  VT_RETURN_IF_ERROR(saving.get());  // joined before anything it uses goes out of scope
  VT_ASSIGN_OR_RETURN(BuildSummary keys, std::move(keyed));
  sum.stages.push_back({"write working level 0", t_working});  // alongside the keys
  sum.stages.push_back({"keys", t_keys});
  sum.stages.push_back({"write levels", t_levels});

  t0 = Clock::now();
  if (!dir.empty()) {
    // The final header (tables included) as a page file without pages.
    VT_ASSIGN_OR_RETURN(staged_tables, outputs.stage(dir + "/tables.vtpf"));
    VT_ASSIGN_OR_RETURN(auto writer, PageFileWriter::create(staged_tables, plan.desc));
    VT_RETURN_IF_ERROR(writer->finish().with_context(dir + "/tables.vtpf"));
    if (!glb.empty()) {
      // Written beside its final target so that its image paths are relative to that folder.
      VT_ASSIGN_OR_RETURN(staged_glb, outputs.stage(dir + "/unwrapped.glb"));
      VT_ASSIGN_OR_RETURN(StagingFile beside, create_staging_file(glb));
      ::close(beside.fd);
      Status saved = unwrap::save_unwrapped_glb(prepared->unwrapped, beside.path);
      if (saved.ok()) saved = move_file(beside.path, staged_glb);
      std::error_code ec;
      fs::remove(beside.path, ec);
      VT_RETURN_IF_ERROR(saved.with_context(glb));
    }
  }
  nlohmann::json j = {
      {"schema", kPlanSchema},
      {"tool", VTBAKE_VERSION},
      {"plan_hash", hex(plan.hash)},
      {"settings_key", hex(plan.settings_key)},
      {"input_key", hex(bo.input_key)},
      {"scene", loaded->source_path.empty() ? "" : absolute(loaded->source_path)},
      {"output", absolute(output)},
      {"unwrapped", glb.empty() ? "" : absolute(glb)},
      {"metadata", bo.metadata_json},
      {"geometry",
       {{"width", plan.desc.geometry.width},
        {"height", plan.desc.geometry.height},
        {"payload", plan.desc.geometry.payload},
        {"border", plan.desc.geometry.border},
        {"levels", plan.desc.geometry.level_count()}}},
      {"layers", layers},
      {"coverage", coverage ? "level0/coverage.u8" : ""},
      {"tasks", task_json(tasks, keys, plan)},
  };
  for (const BuildTask& t : tasks) {
    ++sum.tasks;
    if (t.kind == BuildTask::Kind::kBand) ++sum.band_tasks;
  }
  for (uint32_t p : keys.task_pages) sum.pages += p;
  if (!dir.empty()) {
    VT_ASSIGN_OR_RETURN(std::string staged, outputs.stage(dir + "/plan.json"));
    VT_RETURN_IF_ERROR(write_text(staged, j.dump(1) + "\n"));
  }
  if (!plan_path.empty() && (dir.empty() || absolute(plan_path) != dir + "/plan.json")) {
    VT_ASSIGN_OR_RETURN(std::string staged, outputs.stage(plan_path));
    VT_RETURN_IF_ERROR(write_text(staged, j.dump(1) + "\n"));
  }
  VT_RETURN_IF_ERROR(outputs.commit());
  if (!dir.empty()) {
    remove_stale_parts(dir, plan.hash);
    std::error_code ec;
    fs::remove(work_merged_path(dir), ec);  // no merge of this plan yet
  }
  sum.stages.push_back({"write", seconds_since(t0)});
  sum.plan_hash = plan.hash;
  sum.seconds = seconds_since(start);
  return sum;
}

namespace {

std::vector<std::vector<uint32_t>> assign_shards(const WorkPlan& w, uint32_t count) {
  std::vector<uint32_t> band;
  for (uint32_t i = 0; i < w.tasks.size(); ++i)
    if (w.tasks[i].kind == BuildTask::Kind::kBand) band.push_back(i);
  std::stable_sort(band.begin(), band.end(),
                   [&](uint32_t a, uint32_t b) { return w.cost[a] > w.cost[b]; });
  std::vector<std::vector<uint32_t>> shards(count);
  std::vector<double> load(count, 0.0);
  for (uint32_t t : band) {
    const size_t s = size_t(std::min_element(load.begin(), load.end()) - load.begin());
    shards[s].push_back(t);
    load[s] += w.cost[t] + 1e-3;  // empty tasks spread too
  }
  for (auto& s : shards) std::sort(s.begin(), s.end());
  return shards;
}

}  // namespace

Expected<std::vector<uint32_t>> shard_tasks(const std::string& work_dir, uint32_t index,
                                            uint32_t count) {
  if (count == 0 || index >= count) {
    return Error(ErrorCode::kInvalidArgument, "shard " + std::to_string(index) + "/" +
                                                  std::to_string(count) +
                                                  ": expected I/N with 0 <= I < N");
  }
  VT_ASSIGN_OR_RETURN(const WorkPlan w, load_plan(work_dir));
  return assign_shards(w, count)[index];
}

namespace {

// The pages of a shard's tasks, streamed into its part as they come.
class PartSink final : public PageSink {
 public:
  PartSink(HashedFile& f, const PageGeometry& g, const std::vector<BuildTask>& tasks)
      : f_(f), g_(g) {
    for (uint32_t i = 0; i < tasks.size(); ++i)
      if (tasks[i].kind == BuildTask::Kind::kBand)
        task_of_[{tasks[i].layer, tasks[i].level, tasks[i].row}] = i;
  }
  Status add_page(const PageId& id, uint32_t layer, std::span<const uint8_t> data) override {
    return put(id, layer, PageState::kStored, data);
  }
  Status add_constant_page(const PageId& id, uint32_t layer,
                           std::span<const uint8_t> texel) override {
    return put(id, layer, PageState::kConstant, texel);
  }
  ShardSummary counts;

 private:
  Status put(const PageId& id, uint32_t layer, PageState state, std::span<const uint8_t> b) {
    const auto it = task_of_.find({layer, id.level, id.y});
    if (it == task_of_.end()) return Error(ErrorCode::kInternal, "page outside the plan's tasks");
    f_.put(uint8_t(kPage));
    f_.put(uint8_t(state));
    f_.put(uint16_t(layer));
    f_.put(it->second);
    f_.put(id.level), f_.put(id.x), f_.put(id.y);
    f_.put(uint32_t(b.size()));
    f_.put(uint64_t(XXH3_64bits(b.data(), b.size())));
    f_.put(b.data(), b.size());
    ++counts.pages;
    if (state == PageState::kStored) ++counts.stored, counts.stored_bytes += b.size();
    if (state == PageState::kConstant) ++counts.constant;
    (void)g_;
    return Status::Ok();
  }
  HashedFile& f_;
  const PageGeometry& g_;
  std::map<std::tuple<uint32_t, uint32_t, uint32_t>, uint32_t> task_of_;
};

// Reads level0/coverage.u8 (one byte per texel of the atlas) in bands into a mask, in memory or
// a scratch file as `options` allow.
Expected<std::shared_ptr<const CoverageMask>> read_coverage(const std::string& path, uint32_t w,
                                                            uint32_t h,
                                                            const BuildOptions& options) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return io_error(path, "cannot open");
  if (uint64_t(in.tellg()) != uint64_t(w) * h)
    return Error(ErrorCode::kCorrupt, path + ": not the atlas's size");
  in.seekg(0);
  VT_ASSIGN_OR_RETURN(
      std::shared_ptr<CoverageMask> mask,
      CoverageMask::create(w, h, CoverageMask::fits_memory(w, h, options.memory_limit),
                           scratch_dir_for(options)));
  std::vector<uint8_t> rows;
  for (uint32_t y = 0; y < h; y += mask->band_rows()) {
    const uint32_t n = std::min(h - y, mask->band_rows());
    rows.resize(size_t(n) * w);
    if (!in.read(reinterpret_cast<char*>(rows.data()), std::streamsize(rows.size())))
      return io_error(path, "read failed");
    VT_RETURN_IF_ERROR(mask->write_rows(y, n, rows.data()));
  }
  return std::shared_ptr<const CoverageMask>(std::move(mask));
}

Expected<std::vector<LayerInput>> work_layers(const WorkPlan& w, const BuildOptions& options) {
  std::shared_ptr<const CoverageMask> coverage;
  const std::string cov = w.json.value("coverage", "");
  if (!cov.empty() && !w.json["layers"].empty()) {
    const auto& l = w.json["layers"][0];
    VT_ASSIGN_OR_RETURN(coverage, read_coverage(w.dir + "/" + cov, l.value("width", 0u),
                                                l.value("height", 0u), options));
  }
  std::vector<LayerInput> layers;
  for (const auto& l : w.json["layers"]) {
    ImageInfo info;
    info.width = l.value("width", 0u), info.height = l.value("height", 0u);
    info.channels = l.value("channels", 0u);
    info.is_float = l.value("is_float", false);
    info.alpha_channel = l.value("alpha_channel", -1);
    info.color_space = l.value("info_color_space", "");
    if (coverage && (coverage->width() != info.width || coverage->height() != info.height)) {
      return Error(ErrorCode::kCorrupt, w.dir + "/" + cov + ": not the atlas's size");
    }
    LayerInput in;
    in.semantic = LayerSemantic(l.value("semantic", 0));
    in.color_space = l.value("color_space", "");
    in.coverage = coverage;
    const uint32_t channels = info.channels;
    if (const std::string file = l.value("file", ""); !file.empty()) {
      VT_ASSIGN_OR_RETURN(std::shared_ptr<RawFileSource> raw,
                          RawFileSource::open(w.dir + "/" + file, std::move(info)));
      if (l.contains("content_hash")) raw->set_content_hash(unhex(l["content_hash"]));
      in.source = std::move(raw);
    } else if (l.contains("content_hash") && !l.value("work_file", "").empty()) {
      in.source = std::make_shared<PlannedSource>(std::move(info), unhex(l["content_hash"]),
                                                  w.dir + "/" + l.value("work_file", ""));
    } else {
      return Error(ErrorCode::kCorrupt, work_plan_path(w.dir) + ": layer " + l.value("name", "") +
                                            " has no level 0 file");
    }
    if (l.value("alpha_dropped", false)) {
      in.source = std::make_shared<DropChannelSource>(in.source, channels - 1);
      in.alpha_dropped = true;
    }
    layers.push_back(std::move(in));
  }
  return layers;
}

// The levels in their working form as the plan wrote them: level 0 (converted and dilated) of
// the layers that carry a coverage mask, and every coarser level of every layer; the masks of
// the coarser levels are derived here as the pyramid derives them.
Expected<std::function<Expected<BuildOptions::GivenLevel>(size_t, uint32_t)>> given_levels(
    const WorkPlan& w, const BuildOptions& options) {
  const nlohmann::json& layers = w.json["layers"];
  std::vector<std::vector<BuildOptions::GivenLevel>> given(layers.size());
  std::vector<std::shared_ptr<const CoverageMask>> masks;
  for (size_t i = 0; i < layers.size() && i < options.layers.size(); ++i) {
    const auto& l = layers[i];
    const uint32_t w0 = l.value("width", 0u), h0 = l.value("height", 0u);
    const uint32_t channels = l.value("work_channels", 0u);
    auto open = [&](const std::string& file, const std::string& format, uint32_t width,
                    uint32_t height, std::shared_ptr<const CoverageMask> mask,
                    float alpha_scale) -> Expected<BuildOptions::GivenLevel> {
      const std::string path = w.dir + "/" + file;
      if (format != kRawLevel && format != kCompressedLevel) {
        return Error(ErrorCode::kCorrupt, work_plan_path(w.dir) + ": " + file +
                                              " has the unknown form \"" + format + "\"");
      }
      VT_ASSIGN_OR_RETURN(
          std::shared_ptr<LevelStore> texels,
          LevelStore::open_saved(path, width, height, channels, format == kCompressedLevel));
      return BuildOptions::GivenLevel{
          std::make_shared<FileLevel>(std::move(texels), std::move(mask)), alpha_scale};
    };
    given[i].resize(1);
    if (const std::string file = l.value("work_file", ""); !file.empty()) {
      VT_ASSIGN_OR_RETURN(given[i][0], open(file, l.value("work_format", kRawLevel), w0, h0,
                                            options.layers[i].coverage, 1.0f));
    }
    const auto& levels = l.value("levels", nlohmann::json::array());
    const bool covered = l.value("levels_coverage", false) && options.layers[i].coverage;
    if (covered && masks.empty()) masks.push_back(options.layers[i].coverage);
    const PageGeometry g{w0, h0};  // level sizes follow from the atlas's alone
    for (size_t k = 0; k < levels.size(); ++k) {
      const uint32_t width = g.level_width(uint32_t(k + 1)),
                     height = g.level_height(uint32_t(k + 1));
      if (covered && masks.size() <= k + 1) {
        VT_ASSIGN_OR_RETURN(
            std::shared_ptr<CoverageMask> half,
            masks[k]->downsample(CoverageMask::fits_memory(width, height, options.memory_limit),
                                 scratch_dir_for(options)));
        masks.push_back(std::move(half));
      }
      given[i].push_back({});
      VT_ASSIGN_OR_RETURN(
          given[i].back(),
          open(levels[k].value("file", ""), levels[k].value("format", kRawLevel), width, height,
               covered ? masks[k + 1] : nullptr, levels[k].value("alpha_scale", 1.0f)));
    }
  }
  return std::function<Expected<BuildOptions::GivenLevel>(size_t, uint32_t)>(
      [given = std::move(given)](size_t i, uint32_t level) -> Expected<BuildOptions::GivenLevel> {
        if (i < given.size() && level < given[i].size()) return given[i][level];
        return BuildOptions::GivenLevel{};
      });
}

}  // namespace

Expected<ShardSummary> run_shard(const ShardOptions& options) {
  auto start = Clock::now();
  ShardSummary sum;
  auto t0 = Clock::now();
  VT_ASSIGN_OR_RETURN(const WorkPlan w, load_plan(options.work_dir));
  if (w.json.value("tool", "") != VTBAKE_VERSION) {
    return Error(ErrorCode::kInvalidArgument, work_plan_path(w.dir) + ": made by vtbake " +
                                                  w.json.value("tool", "") +
                                                  ", this is " VTBAKE_VERSION " (plan again)");
  }
  std::vector<uint32_t> mine = options.tasks;
  std::string part;
  if (options.merge_last && options.count == 0) {
    return Error(ErrorCode::kInvalidArgument, "merging after a shard needs --shard I/N");
  }
  if (options.count > 0) {
    if (options.index >= options.count) {
      return Error(ErrorCode::kInvalidArgument, "--shard " + std::to_string(options.index) + "/" +
                                                    std::to_string(options.count) +
                                                    ": expected I/N with 0 <= I < N");
    }
    mine = assign_shards(w, options.count)[options.index];
    part = shard_part_path(w.dir, options.index, options.count);
  } else {
    std::sort(mine.begin(), mine.end());
    mine.erase(std::unique(mine.begin(), mine.end()), mine.end());
    for (uint32_t t : mine)
      if (t >= w.tasks.size() || w.tasks[t].kind != BuildTask::Kind::kBand) {
        return Error(
            ErrorCode::kInvalidArgument,
            "--tasks: " + std::to_string(t) + " is not a band task of " + work_plan_path(w.dir));
      }
    part = tasks_part_path(w.dir, mine);
  }
  sum.part = part;
  sum.tasks = mine;
  // Staged now: a killed shard leaves only PART.tmp-*, which the merge does not read.
  OutputSet outputs;
  VT_ASSIGN_OR_RETURN(const std::string staged, outputs.stage(part));

  BuildOptions bo = options.build;
  VT_ASSIGN_OR_RETURN(bo.layers, work_layers(w, bo));
  bo.output = part;
  bo.address = AddressMode::kClamp;
  bo.metadata_json = w.json.value("metadata", "{}");
  bo.input_key = unhex(w.json["input_key"]);
  bo.update = false;
  bo.tables_from = w.dir + "/tables.vtpf";
  VT_ASSIGN_OR_RETURN(bo.level_from, given_levels(w, bo));
  sum.stages.push_back({"read", seconds_since(t0)});
  t0 = Clock::now();
  // The plan's opaque-alpha decisions where it recorded them (plans before 2026-12-04: scan).
  bool decided = true;
  for (const auto& l : w.json["layers"]) decided &= l.contains("alpha_dropped");
  if (!decided) VT_RETURN_IF_ERROR(drop_opaque_alpha(bo));
  VT_ASSIGN_OR_RETURN(BuildPlan plan, plan_build(bo));
  if (plan.hash != w.hash) {
    return Error(ErrorCode::kInvalidArgument,
                 work_plan_path(w.dir) + ": this shard's plan is " + hex(plan.hash) +
                     ", the folder's is " + hex(w.hash) +
                     ": give every shard the settings the plan was made with");
  }
  const std::vector<BuildTask> tasks = make_build_tasks(plan);
  if (tasks.size() != w.tasks.size()) {
    return Error(ErrorCode::kInternal, "shard: the plan's task graph differs from the folder's");
  }
  auto subset = std::make_shared<std::vector<uint8_t>>(tasks.size(), 0);
  for (uint32_t t : mine) (*subset)[t] = 1;
  plan.options.task_subset = subset;
  sum.stages.push_back({"plan", seconds_since(t0)});

  t0 = Clock::now();
  HashedFile f;
  VT_RETURN_IF_ERROR(f.open(staged));
  f.put(kPartMagic, sizeof kPartMagic);
  f.put(uint64_t(plan.hash));
  const std::string label = fs::path(part).filename().string();
  f.put(uint32_t(label.size()));
  f.put(label.data(), label.size());
  PartSink sink(f, plan.desc.geometry, tasks);
  VT_ASSIGN_OR_RETURN(BuildSummary built, build_pages(plan, sink));
  sum.stages.push_back({"build", seconds_since(t0)});
  t0 = Clock::now();
  for (uint32_t t : mine) {
    if (built.task_keys[t] != w.keys[t]) {
      return Error(ErrorCode::kInternal, "shard: task " + std::to_string(t) + " has key " +
                                             hex(built.task_keys[t]) + ", the plan says " +
                                             hex(w.keys[t]));
    }
    f.put(uint8_t(kTask));
    f.put(t);
    f.put(uint64_t(built.task_keys[t]));
    f.put(double(built.task_seconds[t]));
    f.put(uint32_t(built.task_pages[t]));
  }
  for (uint32_t li = 0; li < built.page_keys.size(); ++li)
    for (uint32_t i = 0; i < built.page_keys[li].size(); ++i)
      if (const uint64_t k = built.page_keys[li][i]) {
        f.put(uint8_t(kKey));
        f.put(uint16_t(li));
        f.put(i);
        f.put(k);
      }
  f.put(uint8_t(kEnd));
  const uint64_t digest = f.digest();
  f.put(digest);
  VT_RETURN_IF_ERROR(f.close());
  VT_RETURN_IF_ERROR(outputs.commit());
  sum.stages.push_back({"write", seconds_since(t0)});
  if (options.merge_last) {
    // After the commit: of shards finishing together, at least the last to commit sees every
    // part.
    t0 = Clock::now();
    MergeOptions mo = options.merge;
    mo.work_dir = w.dir;
    auto merged = merge_when_complete(mo, options.count, &sum.merge);
    if (!merged.ok()) {
      return merged.status().with_context("the shard's part is written; merging " + w.dir);
    }
    sum.merged = *merged;
    sum.stages.push_back({"merge", seconds_since(t0)});
  }
  sum.pages = sink.counts.pages, sum.stored = sink.counts.stored;
  sum.constant = sink.counts.constant, sum.stored_bytes = sink.counts.stored_bytes;
  sum.seconds = seconds_since(start);
  return sum;
}

namespace {

struct PartPage {
  uint32_t task, layer;
  PageId id;
  PageState state;
  size_t offset, size;  // in Part::bytes
};
struct Part {
  std::string path;
  uint64_t plan_hash = 0;
  std::vector<uint8_t> bytes;
  std::vector<PartPage> pages;
  std::map<uint32_t, uint64_t> task_keys;
  std::vector<std::tuple<uint32_t, uint32_t, uint64_t>> page_keys;  // layer, index, key
};

// Reads and checks a part: complete (its final checksum over every byte) and well formed.
Expected<Part> read_part(const std::string& path) {
  Part p;
  p.path = path;
  std::ifstream in(path, std::ios::binary);
  if (!in) return io_error(path, "cannot open");
  p.bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  const auto& b = p.bytes;
  auto bad = [&](const std::string& what) {
    return Error(ErrorCode::kCorrupt, path + ": " + what + " (run this shard again)");
  };
  if (b.size() < 8 + 8 + 4 + 9 || std::memcmp(b.data(), kPartMagic, 8) != 0)
    return bad("not a vtbake shard part");
  uint64_t digest;
  std::memcpy(&digest, b.data() + b.size() - 8, 8);
  if (b[b.size() - 9] != kEnd || XXH3_64bits(b.data(), b.size() - 8) != digest)
    return bad("checksum mismatch: truncated or damaged");
  size_t at = 8;
  const size_t end = b.size() - 9;
  auto get = [&](auto& v) {
    if (at + sizeof v > end) return false;
    std::memcpy(&v, b.data() + at, sizeof v);
    at += sizeof v;
    return true;
  };
  uint32_t label = 0;
  if (!get(p.plan_hash) || !get(label) || at + label > end) return bad("bad header");
  at += label;
  while (at < end) {
    uint8_t tag = 0;
    get(tag);
    if (tag == kPage) {
      uint8_t state = 0;
      uint16_t layer = 0;
      PartPage pg{};
      uint32_t size = 0;
      uint64_t sum = 0;
      if (!get(state) || !get(layer) || !get(pg.task) || !get(pg.id.level) || !get(pg.id.x) ||
          !get(pg.id.y) || !get(size) || !get(sum) || at + size > end)
        return bad("bad page record");
      if (XXH3_64bits(b.data() + at, size) != sum) return bad("page checksum mismatch");
      pg.layer = layer, pg.state = PageState(state), pg.offset = at, pg.size = size;
      at += size;
      p.pages.push_back(pg);
    } else if (tag == kTask) {
      uint32_t t = 0, pages = 0;
      uint64_t key = 0;
      double seconds = 0;
      if (!get(t) || !get(key) || !get(seconds) || !get(pages)) return bad("bad task record");
      p.task_keys[t] = key;
    } else if (tag == kKey) {
      uint16_t layer = 0;
      uint32_t index = 0;
      uint64_t key = 0;
      if (!get(layer) || !get(index) || !get(key)) return bad("bad key record");
      p.page_keys.emplace_back(layer, index, key);
    } else {
      return bad("unknown record");
    }
  }
  return p;
}

std::vector<std::string> list_parts(const std::string& work_dir) {
  std::vector<std::string> parts;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(fs::path(work_dir) / "parts", ec))
    if (e.is_regular_file() && e.path().extension() == ".part") parts.push_back(e.path().string());
  std::sort(parts.begin(), parts.end());
  return parts;
}

void remove_stale_parts(const std::string& work_dir, uint64_t plan_hash) {
  for (const std::string& path : list_parts(work_dir)) {
    std::ifstream in(path, std::ios::binary);
    char head[16] = {};
    in.read(head, sizeof head);
    uint64_t h = 0;
    std::memcpy(&h, head + 8, 8);
    if (!in || std::memcmp(head, kPartMagic, 8) != 0 || h != plan_hash) {
      std::error_code ec;
      fs::remove(path, ec);
    }
  }
}

}  // namespace

Expected<MergeSummary> merge_shards(const MergeOptions& options) {
  auto start = Clock::now();
  VT_ASSIGN_OR_RETURN(const WorkPlan w, load_plan(options.work_dir));
  MergeSummary sum;
  sum.output = options.output.empty() ? w.json.value("output", "") : options.output;
  if (sum.output.empty()) return Error(ErrorCode::kInvalidArgument, "merge: no output path");
  const std::string planned_glb = w.json.value("unwrapped", "");
  sum.unwrapped = options.unwrapped.empty()  ? default_glb(sum.output)
                  : options.unwrapped == "-" ? ""
                                             : options.unwrapped;
  if (!sum.unwrapped.empty() && planned_glb.empty()) {
    return Error(ErrorCode::kInvalidArgument,
                 work_plan_path(w.dir) + ": planned without an unwrapped scene (--unwrapped -)");
  }
  if (!sum.unwrapped.empty() &&
      fs::path(absolute(sum.unwrapped)).parent_path() != fs::path(planned_glb).parent_path()) {
    return Error(ErrorCode::kInvalidArgument,
                 sum.unwrapped + ": the unwrapped scene's image paths were made relative to " +
                     fs::path(planned_glb).parent_path().string() +
                     " (the plan's -o folder); merge there or plan with this -o");
  }
  OutputSet outputs;
  VT_ASSIGN_OR_RETURN(const std::string staged, outputs.stage(sum.output));
  std::string staged_glb;
  if (!sum.unwrapped.empty()) {
    VT_ASSIGN_OR_RETURN(staged_glb, outputs.stage(sum.unwrapped));
  }

  // Which part gives each band task: the first (by name) that holds it.
  std::vector<Part> parts;
  std::vector<int> owner(w.tasks.size(), -1);
  for (const std::string& path : list_parts(w.dir)) {
    VT_ASSIGN_OR_RETURN(Part p, read_part(path));
    if (p.plan_hash != w.hash) {
      return Error(ErrorCode::kInvalidArgument,
                   path + ": a shard of another plan (" + hex(p.plan_hash) + ", the folder's is " +
                       hex(w.hash) + "); remove it or run that shard again");
    }
    bool used = false;
    for (const auto& [t, key] : p.task_keys) {
      if (t >= w.tasks.size() || key != w.keys[t]) {
        return Error(ErrorCode::kCorrupt,
                     path + ": task " + std::to_string(t) + " does not match the plan's key");
      }
      if (owner[t] < 0) owner[t] = int(parts.size()), used = true;
    }
    if (used) {
      sum.parts.push_back(path);
      parts.push_back(std::move(p));
    }
  }
  std::string missing;
  size_t n_missing = 0;
  for (uint32_t t = 0; t < w.tasks.size(); ++t)
    if (w.tasks[t].kind == BuildTask::Kind::kBand && owner[t] < 0) {
      if (++n_missing <= 16) missing += (missing.empty() ? "" : " ") + std::to_string(t);
    }
  if (n_missing > 0) {
    return Error(ErrorCode::kNotFound,
                 w.dir + ": " + std::to_string(n_missing) + " band tasks have no shard part (" +
                     missing + (n_missing > 16 ? " ..." : "") +
                     "): run the missing shards (vtbake merge DIR --missing N lists them)");
  }

  VT_ASSIGN_OR_RETURN(auto header, PageFileReader::open(w.dir + "/tables.vtpf"));
  PageFileDesc desc;
  desc.geometry = header->geometry();
  desc.layers = header->layers();
  desc.metadata_json = header->metadata_json();
  VT_ASSIGN_OR_RETURN(auto writer, PageFileWriter::create(staged, desc));
  UpdateRecord record;
  record.tool = VTBAKE_VERSION;
  record.plan_hash = w.hash;
  record.settings_key = unhex(w.json["settings_key"]);
  record.input_key = unhex(w.json["input_key"]);
  for (size_t i = 0; i < desc.layers.size(); ++i) {
    record.layer_names.push_back(desc.layers[i].name);
    const auto& layers = w.json["layers"];
    record.layer_inputs.push_back(
        i < layers.size() && layers[i].contains("input_key") ? unhex(layers[i]["input_key"]) : 0);
  }
  record.page_keys.assign(desc.layers.size(),
                          std::vector<uint64_t>(desc.geometry.total_pages(), 0));
  for (size_t pi = 0; pi < parts.size(); ++pi) {
    const Part& p = parts[pi];
    for (const PartPage& pg : p.pages) {
      if (owner[pg.task] != int(pi)) continue;
      if (pg.layer >= desc.layers.size() || !desc.geometry.contains(pg.id))
        return Error(ErrorCode::kCorrupt, p.path + ": page outside the plan's grid");
      const std::span<const uint8_t> data(p.bytes.data() + pg.offset, pg.size);
      if (pg.state == PageState::kStored) {
        VT_RETURN_IF_ERROR(writer->add_page(pg.id, pg.layer, data).with_context(p.path));
        ++sum.stored, sum.stored_bytes += pg.size;
      } else {
        VT_RETURN_IF_ERROR(writer->add_constant_page(pg.id, pg.layer, data).with_context(p.path));
        ++sum.constant;
      }
    }
  }
  // Page keys: each from the part that gave its task.
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> row_task;  // (layer, level, row) -> task
  for (uint32_t t = 0; t < w.tasks.size(); ++t)
    if (w.tasks[t].kind == BuildTask::Kind::kBand)
      row_task[{w.tasks[t].layer, (w.tasks[t].level << 20) | w.tasks[t].row}] = t;
  const PageGeometry& g = desc.geometry;
  std::vector<uint64_t> level_start(g.level_count() + 1, 0);
  for (uint32_t l = 0; l < g.level_count(); ++l)
    level_start[l + 1] = level_start[l] + uint64_t(g.pages_x(l)) * g.pages_y(l);
  for (size_t pi = 0; pi < parts.size(); ++pi)
    for (const auto& [layer, index, key] : parts[pi].page_keys) {
      if (layer >= record.page_keys.size() || index >= g.total_pages())
        return Error(ErrorCode::kCorrupt, parts[pi].path + ": page key outside the grid");
      const uint32_t level =
          uint32_t(std::upper_bound(level_start.begin(), level_start.end(), index) -
                   level_start.begin() - 1);
      const uint32_t row = uint32_t((index - level_start[level]) / g.pages_x(level));
      const auto it = row_task.find({layer, (level << 20) | row});
      if (it != row_task.end() && owner[it->second] == int(pi))
        record.page_keys[layer][index] = key;
    }
  const std::string scene = w.json.value("scene", "");
  const std::string provenance =
      nlohmann::json{{"scene", scene.empty() ? "" : path_for_metadata(scene, sum.output)}}.dump();
  writer->set_metadata_json(
      with_update_record(merge_metadata(desc.metadata_json, provenance), record));
  VT_RETURN_IF_ERROR(writer->finish().with_context(sum.output));
  if (!staged_glb.empty()) {
    std::error_code ec;
    fs::copy_file(w.dir + "/unwrapped.glb", staged_glb, fs::copy_options::overwrite_existing, ec);
    if (ec) {
      return Error(ErrorCode::kIo,
                   sum.unwrapped + ": cannot copy " + w.dir + "/unwrapped.glb: " + ec.message());
    }
  }
  VT_RETURN_IF_ERROR(outputs.commit());
  sum.pages = g.total_pages() * desc.layers.size();
  sum.absent = sum.pages - sum.stored - sum.constant;
  std::error_code ec;
  sum.file_bytes = fs::file_size(sum.output, ec);
  sum.seconds = seconds_since(start);
  return sum;
}

namespace {

// A file as it is now: size and modification time (null when absent). A merge recorded with
// the stamp its output still has is the file on disk; one replaced since, even by a file of the
// same size, is merged again.
nlohmann::json file_stamp(const std::string& path) {
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (ec) return nullptr;
  const auto time = fs::last_write_time(path, ec);
  if (ec) return nullptr;
  return {size, int64_t(time.time_since_epoch().count())};
}

}  // namespace

std::string work_merged_path(const std::string& work_dir) {
  return (fs::path(work_dir) / "merged.json").string();
}

Expected<bool> merge_when_complete(const MergeOptions& options, uint32_t count,
                                   MergeSummary* summary) {
  VT_ASSIGN_OR_RETURN(const WorkPlan w, load_plan(options.work_dir));
  // Cheap first: a shard that finishes before the others only looks for their parts.
  auto complete = [&] {
    std::error_code ec;
    for (uint32_t i = 0; i < count; ++i)
      if (!fs::exists(shard_part_path(w.dir, i, count), ec)) return false;
    return true;
  };
  if (!complete()) return false;
  // One merge at a time: shards finishing together queue here; the first merges, the others
  // find its record. (flock: local and NFSv4 file systems honour it across nodes.)
  const std::string lock_path = (fs::path(w.dir) / "merge.lock").string();
  const int fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) return io_error(lock_path, "cannot open");
  struct Unlock {
    int fd;
    ~Unlock() { ::close(fd); }  // closing releases the lock
  } unlock{fd};
  while (::flock(fd, LOCK_EX) != 0)
    if (errno != EINTR) return io_error(lock_path, "cannot lock");
  const std::string output =
      absolute(options.output.empty() ? w.json.value("output", "") : options.output);
  {
    std::ifstream in(work_merged_path(w.dir), std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    const auto j = nlohmann::json::parse(in ? text.str() : "", nullptr, false);
    if (j.is_object() && unhex(j.value("plan_hash", nlohmann::json())) == w.hash &&
        j.value("output", "") == output &&
        j.value("file", nlohmann::json()) == file_stamp(output)) {
      return false;  // merged already, by another shard
    }
  }
  VT_ASSIGN_OR_RETURN(MergeSummary merged, merge_shards(options));
  OutputSet record;
  VT_ASSIGN_OR_RETURN(const std::string staged, record.stage(work_merged_path(w.dir)));
  const nlohmann::json done = {{"plan_hash", hex(w.hash)},
                               {"output", output},
                               {"bytes", merged.file_bytes},
                               {"file", file_stamp(output)},
                               {"parts", merged.parts}};
  VT_RETURN_IF_ERROR(write_text(staged, done.dump(1) + "\n"));
  VT_RETURN_IF_ERROR(record.commit());
  if (summary) *summary = std::move(merged);
  return true;
}

Expected<std::vector<uint32_t>> missing_shards(const std::string& work_dir, uint32_t count) {
  VT_ASSIGN_OR_RETURN(const WorkPlan w, load_plan(work_dir));
  std::vector<uint32_t> missing;
  for (uint32_t i = 0; i < count; ++i) {
    auto p = read_part(shard_part_path(w.dir, i, count));
    if (!p.ok() || p->plan_hash != w.hash) missing.push_back(i);
  }
  return missing;
}

}  // namespace vt
