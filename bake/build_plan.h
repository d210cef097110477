// The first step of a build: everything decided before the first page is encoded. plan_build is
// a function of the options and the sources' texels alone: the final file description (DCT
// tables trained up front on a spread sample of the layers' own level-0 pages), each layer's
// conversion and encoder, where each level lives (memory or scratch file), and a hash that
// names the plan (settings, tool version, source content). The writer is created from
// plan.desc and only ever takes pages.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bake/build.h"
#include "bake/color.h"
#include "bake/page_encoder.h"
#include "bake/pyramid.h"
#include "bake/update.h"

namespace vt {

class LevelSource;

// A page's task key: hash(its layer's task seed, the page, the alpha scale of its level, its
// bordered working texels); the page's stored bytes are a function of these alone (never 0,
// which marks an absent page). The build keys every page so (update.h); the plan keys its
// training sample so in update mode.
uint64_t page_task_key(uint64_t task_seed, const PageId& id, float alpha_scale,
                       const std::vector<float>& texels);

// How one layer goes from its source to stored texels.
struct LayerPlan {
  LayerSpec spec;  // as written: codec, runtime format, trained tables
  uint32_t source_channels = 0;
  uint32_t work_channels = 0;  // channels of the level images (normals: xyz)
  int alpha = -1;              // alpha channel in the level images, or -1
  bool normal = false;
  bool decode_unorm_normal = false;  // source normals are n * 0.5 + 0.5
  bool colour = false;               // albedo or emissive: linear light, premultiplied alpha
  std::shared_ptr<const ColorConverter> to_linear;
  std::shared_ptr<const ColorConverter> to_storage;
  DownsampleRules rules;
  std::shared_ptr<const PageEncoder> encoder;  // made once, with the final tables
  // Level 0 in its working form (linear, premultiplied, normals decoded). Streams from the
  // source, or for layers with a coverage mask is held whole and dilated (pull-push).
  std::shared_ptr<LevelSource> level0;
  // level_in_memory[l]: level l is held in memory (else in a scratch file). Level 0 streams
  // unless the layer has coverage.
  std::vector<bool> level_in_memory;
  // Where this layer's task keys start: the settings and the layer's spec, tables included.
  uint64_t task_seed = 0;
  // The key of the layer's input: its source's content and its coverage (recorded per layer).
  uint64_t input_key = 0;
  // Update mode: the previous file's layer `previous_layer` had this input, spec and tables, so
  // its pages are this layer's (copied; level0 is then null: nothing is read, dilated, trained
  // or encoded).
  bool copy_previous = false;
  int previous_layer = -1;

  // Linear working texels of a side x side page (modified) to the layer's stored bytes: colour
  // unpremultiplied, and under zero alpha bled from the texels around. Returns true when the
  // storage clipped some value (8 bits: outside [0, 1]; half: beyond +-kHalfMax); for 8-bit
  // layers `reference`, when not null, then receives what the stored bytes would be unclipped
  // (side * side * spec.channels values in 8-bit code units, unrounded): the values the page's
  // error is measured against. Half layers always fill it (when not null) with the float values
  // before rounding to half (side * side * spec.channels): half storage is not lossless, and its
  // error is measured against them.
  bool store_page(float* texels, uint32_t side, float alpha_scale, uint8_t* out,
                  float* reference = nullptr) const;
};

struct BuildPlan {
  BuildOptions options;  // as given (after drop_opaque_alpha)
  PageFileDesc desc;     // the file's final header
  std::vector<LayerPlan> layers;
  int threads = 1;
  DownsampleKernel kernel;
  uint32_t margin = 0;  // rows a band reads past its pages: max(border, filter reach)
  std::string scratch_dir;
  bool compress_scratch = false;  // BuildOptions::compress_scratch, or the levels' scratch needs it
  uint64_t hash = 0;          // the plan's identity: settings, tool version, every source's content
  uint64_t settings_key = 0;  // the settings alone (tool version included)
  // Update mode: the previous output when its pages can be reused (same tool, settings and
  // size), and what the plan decided about it. With `unchanged` the plan stops before opening
  // the sources' level 0 and training: the previous file is the output.
  std::shared_ptr<const PreviousBuild> previous;
  UpdateSummary update;
  bool unchanged = false;
  // The least memory this build needs whatever the limit (level 0's working set, the libraries).
  uint64_t memory_floor = 0;
  std::vector<std::string> warnings;  // copied to BuildSummary::warnings
};

// Where scratch files go: BuildOptions::scratch_dir, else the output's folder.
std::string scratch_dir_for(const BuildOptions& options);
// The memory a level's pull-push dilation may use before its pull levels go to scratch files.
inline uint64_t dilation_budget(const BuildOptions& options) {
  return options.memory_limit / 4;
}

// Checks the options, reads each DCT layer's training sample and works out the plan. Errors
// name the layer at fault.
Expected<BuildPlan> plan_build(const BuildOptions& options);

}  // namespace vt
