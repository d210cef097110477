// One scene bake sharded over a build farm (docs/FARM.md). Three steps, each a process that may
// run on another machine, sharing one work folder:
//  1. plan (plan_bake): load, unwrap, transfer, train the DCT tables, and run the pyramid once
//     without encoding for the task keys. Writes the task graph (plan.json: tasks, keys,
//     dependencies, estimated cost) and, with a work folder, what the shards read: level0/ (the
//     transferred layers and their coverage), levels/ (every level in working form), tables.vtpf (a
//     page file with no pages: the final header, tables included) and unwrapped.glb.
//  2. shards (run_shard): each reads the tables and every level as the plan's pyramid pass
//     wrote it (levels/; pull-push dilation needs whole levels, so only one process can make
//     them) and cuts and encodes only its own band tasks' pages into
//     parts/NAME.part: the pages, their keys and checksums, its task keys, and one checksum
//     over the whole file, written under a temporary name and renamed when complete.
//  3. merge (merge_shards): the page file from the parts and the unwrapped scene beside it,
//     byte-identical to a one-process bake of the same scene and settings.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "bake/scene_bake.h"
#include "common/status.h"

namespace vt {

// The work folder's files.
std::string work_plan_path(const std::string& work_dir);  // DIR/plan.json
// DIR/parts/shard-I-of-N.part (index 0-based) or, for a task list, DIR/parts/tasks-HASH.part.
std::string shard_part_path(const std::string& work_dir, uint32_t index, uint32_t count);
std::string tasks_part_path(const std::string& work_dir, const std::vector<uint32_t>& tasks);

struct PlanSummary {
  std::string plan_path, work_dir;
  uint64_t plan_hash = 0;
  uint32_t tasks = 0, band_tasks = 0;
  uint64_t pages = 0;             // pages with some coverage: those the shards encode
  std::vector<StageTime> stages;  // load, unwrap, transfer, plan (tables), keys, write
  double seconds = 0;
};

// Step 1. `options.build.output` is the page file the merge will write (the unwrapped scene's
// image paths are made relative to its folder, as bake_scene makes them). Writes `plan_path`
// and, when `work_dir` is not "", the shards' inputs there (every file staged and renamed into
// place together, plan.json last); parts of another plan left in DIR/parts are removed.
Expected<PlanSummary> plan_bake(const std::string& scene_path, const SceneBakeOptions& options,
                                const std::string& work_dir, const std::string& plan_path);

// The band tasks of shard `index` of `count`: every band task of the plan goes to the shard
// with the least estimated cost so far, costliest first (ties: lower task id, lower shard).
Expected<std::vector<uint32_t>> shard_tasks(const std::string& work_dir, uint32_t index,
                                            uint32_t count);

struct MergeOptions {
  std::string work_dir;
  std::string output;     // the .vtpf ("" = the plan's output)
  std::string unwrapped;  // "" = output with .glb, "-" = none
};

struct MergeSummary {
  std::string output, unwrapped;
  std::vector<std::string> parts;  // the parts whose pages were used
  uint64_t pages = 0, stored = 0, constant = 0, absent = 0, stored_bytes = 0, file_bytes = 0;
  double seconds = 0;
};

struct ShardOptions {
  std::string work_dir;
  uint32_t index = 0, count = 0;  // --shard I/N, I in [0, N)
  std::vector<uint32_t> tasks;    // --tasks LIST instead (count == 0)
  // The build settings, as the plan was made with (flags, memory limit, threads, scratch): the
  // shard's plan must have the plan's hash. Layers, metadata and keys come from the folder.
  BuildOptions build;
  // With --shard I/N: once its part is written, merge if every part of N is there
  // (merge_when_complete), so that the last shard to finish writes the page file and a farm
  // needs no merge job. `merge.work_dir` is taken from `work_dir`.
  bool merge_last = false;
  MergeOptions merge;
};

struct ShardSummary {
  std::string part;
  std::vector<uint32_t> tasks;
  uint64_t pages = 0, stored = 0, constant = 0, stored_bytes = 0;
  std::vector<StageTime> stages;  // read, plan, build, write (, merge)
  double seconds = 0;
  bool merged = false;  // merge_last: this shard merged (`merge` holds the merge's summary)
  MergeSummary merge;
};

// Step 2. Errors: no plan in the folder, a shard index out of range, settings that give another
// plan hash than the folder's, or a failed write (nothing is left under the part's name).
Expected<ShardSummary> run_shard(const ShardOptions& options);

// Step 3. Refuses (naming the part) a part of another plan, a damaged part, a task whose keys
// differ between parts; fails listing the tasks no part holds. Nothing is written on failure.
Expected<MergeSummary> merge_shards(const MergeOptions& options);

// The merge of a complete set of shards, by whichever shard gets there: under an exclusive lock
// on DIR/merge.lock, merges when every part of `count` is in DIR/parts and DIR/merged.json does
// not already record this plan's merge into the same output (with the size and modification time it
// still has), then records it there. False (nothing written) when a part is absent or the merge is
// recorded. The plan removes merged.json.
Expected<bool> merge_when_complete(const MergeOptions& options, uint32_t count,
                                   MergeSummary* summary);
std::string work_merged_path(const std::string& work_dir);  // DIR/merged.json

// Shards of `count` (0-based) whose part is absent, damaged or of another plan: the ones a farm
// must run again.
Expected<std::vector<uint32_t>> missing_shards(const std::string& work_dir, uint32_t count);

}  // namespace vt
