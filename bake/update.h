// Update mode: what a previous page file of a build tells the next one. Every file a build
// writes records, in the "update" object of its metadata, the plan hash (settings, tool
// version, every source's content), a settings key, the tool version, the caller's input key
// (a scene bake's key of the scene and its textures) and every page's task key: the hash of
// the layer's task seed (settings and codec tables) and the page's bordered working texels,
// which decide its stored bytes. A build in update mode (BuildOptions::update)
// copies the stored bytes of every page whose key is unchanged and encodes the rest; the file
// is byte-identical to a clean build that takes its DCT tables from the previous file
// (BuildOptions::tables_from).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/status.h"
#include "format/page_file.h"

namespace vt {

// Pinned DCT tables are retrained when they code the training sample of the new pages this
// much larger than tables trained on it (measured in docs/BENCHMARKS.md, issue 16).
constexpr double kRetrainFitBound = 1.10;

struct UpdateSummary {
  bool requested = false;  // BuildOptions::update was set
  bool unchanged = false;  // the plan equals the previous file's: nothing was written
  uint64_t reused = 0;     // pages (stored or constant) copied from the previous file
  uint64_t reencoded = 0;  // pages encoded
  uint64_t dropped = 0;    // pages the previous file had that are absent now
  // Why no page could be reused ("" = an incremental update): "no previous file", "settings
  // changed", "tool version changed (A -> B)", "tables retrained (...)", ...
  std::string full_rebuild;
  bool tables_pinned = false;     // DCT tables taken from a file rather than trained
  bool tables_retrained = false;  // pinned tables dropped for a poor fit or --retrain-tables
  // Pinned / fresh bytes of the training sample's new pages (those the previous file lacks),
  // when measured; fit_pages: how many pages that was, over all layers.
  double tables_fit = 0;
  uint64_t fit_pages = 0;
};

// One line for a summary: "update: 12 pages reused, 3 re-encoded, 0 dropped" and, when it
// happened, "; full rebuild: settings changed" or "; unchanged, output untouched".
std::string update_text(const UpdateSummary& u);

// What a build records about itself in the page file's metadata.
struct UpdateRecord {
  std::string tool;
  uint64_t plan_hash = 0;
  uint64_t settings_key = 0;
  uint64_t input_key = 0;  // BuildOptions::input_key
  // page_keys[layer][i]: the task key of page i (levels fine to coarse, rows top to bottom,
  // then x) of layer `layer`; 0 = absent.
  std::vector<std::string> layer_names;
  std::vector<std::vector<uint64_t>> page_keys;
  // Per layer: the key of its input (source content and coverage; LayerPlan::input_key), 0 =
  // not recorded (files before it).
  std::vector<uint64_t> layer_inputs;
};

// Page i of the key tables: levels fine to coarse, rows top to bottom, then x.
uint64_t page_key_index(const PageGeometry& g, const PageId& id);

// `metadata_json` (an object) with the members of `extra` (an object) added.
std::string merge_metadata(const std::string& metadata_json, const std::string& extra);

// `metadata_json` (an object) with the record as its "update" member.
std::string with_update_record(const std::string& metadata_json, const UpdateRecord& record);

// A previous output opened for an update.
class PreviousBuild {
 public:
  // Opens `path` and reads its update record. kNotFound when there is no file; a file without
  // a record (written by an older vtbake) opens with has_record() false.
  static Expected<std::unique_ptr<PreviousBuild>> open(const std::string& path);

  const PageFileReader& reader() const { return *reader_; }
  bool has_record() const { return has_record_; }
  const UpdateRecord& record() const { return record_; }
  // The layer of the previous file named `name`, or -1.
  int layer_index(const std::string& name) const;
  // The recorded task key of a page of the previous file's layer `layer` (0 = absent or
  // outside its grid).
  uint64_t key(int layer, const PageId& id) const;
  // The recorded input key of layer `layer` (0 = not recorded).
  uint64_t layer_input(int layer) const;
  // DCT tables of the layer named `name` ("" when it has none).
  std::vector<uint8_t> tables(const std::string& name) const;

 private:
  std::unique_ptr<PageFileReader> reader_;
  UpdateRecord record_;
  bool has_record_ = false;
};

// The DCT tables of every layer of `path`, by layer name, for BuildOptions::tables_from.
struct PinnedTables {
  std::vector<std::string> names;
  std::vector<std::vector<uint8_t>> tables;
  const std::vector<uint8_t>* find(const std::string& name) const;
};
Expected<PinnedTables> read_pinned_tables(const std::string& path);

// A source path as the metadata records it: relative to the output's folder (both made
// absolute and normalised first), so that any spelling of the same file gives the same bytes.
std::string path_for_metadata(const std::string& path, const std::string& output);

// Pages of the previous file's layer `layer` that are present there and absent (key 0) in
// `new_keys` (the new build's keys of the same layer), for UpdateSummary::dropped.
uint64_t count_dropped(const PreviousBuild& previous, int layer, const PageGeometry& g,
                       const std::vector<uint64_t>& new_keys);

}  // namespace vt
