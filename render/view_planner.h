// Automatic views for `vtbake validate`: the scene's up axis from the data (or given), an
// overview, views framed on the surfaces that hold the most baked texels, and views at the
// atlas's own density (one baked texel per pixel at the view's centre), none edge-on to the
// surface it frames. Deterministic: a pure function of the surfaces and the options.
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "common/status.h"
#include "render/camera.h"
#include "render/view_surfaces.h"

namespace vt::render {

enum class UpAxis : uint8_t { kAuto, kPosX, kNegX, kPosY, kNegY, kPosZ, kNegZ };

// "auto", "x", "+x", "-x", "y", ... "-z" (case-insensitive); errors list the accepted words.
Expected<UpAxis> parse_up_axis(std::string_view text);
const char* to_string(UpAxis up);

struct ViewPlanOptions {
  uint32_t views = 6;         // 1 = the overview alone
  UpAxis up = UpAxis::kAuto;  // kAuto: found from the surfaces (ViewPlan::up_rule says how)
  uint32_t width = 1280;      // render size in pixels: texel views are sized by its height
  uint32_t height = 720;
  float fov_y = 0.9f;  // vertical field of view, radians
  // Largest angle between a view's direction and the normal of the surface it frames (for the
  // overview: the up axis of a flat scene); the planned views stay well inside it.
  double max_angle_deg = 60.0;
};

enum class ViewKind : uint8_t {
  kOverview,  // the whole scene, from above the horizon
  kSurface,   // one cluster of surfaces framed whole, along its mean normal
  kTexel,     // a point of a cluster at one baked texel per pixel
  kOrbit,     // more views around the scene when the clusters run out
};
const char* to_string(ViewKind kind);

struct PlannedView {
  ViewKind kind = ViewKind::kOverview;
  CameraSpec spec;  // what the camera is (eye, target, up, fov, near, far)
  Camera camera;
  double angle_deg = 0;         // between the view direction and the framed surface's normal
  int cluster = -1;             // the framed cluster (kSurface, kTexel), -1 = none
  double cluster_share = 0;     // the cluster's share of the atlas's texels
  double pixels_per_texel = 0;  // kTexel: at the target, face-on (1 by construction)
  bool occluded = false;        // every candidate eye had a surface between it and the target
  // One line for reports: "surface 0 (42% of the texels), 25 deg from its normal".
  std::string description;
};

struct ViewPlan {
  Vec3f up;
  // How the up axis was chosen: "given", "flat scene: the axis of least extent", "ground faces
  // up: normals", "default: glTF +Y".
  std::string up_rule;
  uint32_t clusters = 0;  // clusters of charts found
  std::vector<PlannedView> views;
  double seconds = 0;  // planner time
};

// The up axis alone (as plan_views finds it), with its rule.
Vec3f find_up_axis(const ViewSurfaces& surfaces, UpAxis given, std::string* rule);

// Plans options.views views (at least 1). kInvalidArgument for views == 0, a non-positive
// size or fov, or a camera that cannot be made (degenerate bounds).
Expected<ViewPlan> plan_views(const ViewSurfaces& surfaces, const ViewPlanOptions& options);

// {"up", "up_rule", "clusters", "seconds", "views": [{"kind", "description", "eye", "target",
// "up", "fov_y_deg", "angle_deg", "cluster", "cluster_share", "occluded"}]}; null for no views.
nlohmann::json to_json(const ViewPlan& plan);

}  // namespace vt::render
