// The normal layer alone (issue 15): both lit passes write the normal map's detail, the shading
// normal minus the interpolated vertex normal (lit_pass.h normals_frame_for; lit.glsl
// lit_normal_detail), instead of a colour: the reference from the normal map in the mesh's
// tangent frame, the virtual render from the normal layer in the atlas frame. Lit colour barely
// moves when a normal layer's green is flipped (the lights stand near the camera, and specular
// and albedo error dominate: a correct and a flipped test bake read 30.2-30.4 and 29.8-32.6 dB).
// Two measures: the angle between the two shading normals, and how much of the reference's
// detail the virtual render repeats (the detail vectors' correlation), which a flipped or
// swapped channel halves or inverts while filtering and codec error barely move it.
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "common/status.h"
#include "render/renderer.h"

namespace vt::render {

struct NormalMetrics {
  uint64_t pixels = 0;  // drawn by both renders
  double mean_deg = 0;  // angle between the two shading normals, over those pixels
  double p99_deg = 0;
  double max_deg = 0;
  // sum(d_ref . d_virt) / sqrt(sum |d_ref|^2 sum |d_virt|^2) over the pixels, d the detail
  // vectors: 1 when the virtual render repeats the reference's detail, about 0 when half of it
  // is mirrored (a flipped green), negative when inverted; 1 without detail.
  double detail_correlation = 1;
  double reference_detail_deg = 0;  // RMS angle of the reference's detail from the vertex normal
  // Whether the correlation is judged: the reference has detail of at least kMinDetailDeg RMS
  // (a normal map that is nearly flat in view has nothing to correlate).
  bool detail_judged() const { return reference_detail_deg >= kMinDetailDeg; }
  static constexpr double kMinDetailDeg = 2.0;
};

// Bounds measured on correct bakes (docs/BENCHMARKS.md, issue 15 figures).
struct NormalBounds {
  double max_mean_deg = 0;
  double min_detail_correlation = 0;
};
NormalBounds default_normal_bounds();

Expected<NormalMetrics> compare_normals(const ReferenceFrame& reference, const VirtualFrame& frame);
// One line per broken bound, each starting "normals: "; empty when the view passes.
std::vector<std::string> check_normals(const NormalMetrics& m, const NormalBounds& b);

nlohmann::json to_json(const NormalMetrics& m);

}  // namespace vt::render
