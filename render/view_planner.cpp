#include "render/view_planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <numbers>
#include <numeric>

namespace vt::render {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// A view leans this far off the framed surface's normal: enough perspective to see relief and
// anisotropic filtering, far from grazing.
constexpr double kSurfaceTiltDeg = 25.0;
constexpr double kTexelTiltDeg = 12.0;
// Charts join a cluster whose normal is within this angle and whose seed lies within this share
// of the scene's diagonal.
constexpr double kClusterConeDeg = 35.0;
constexpr double kClusterReach = 0.25;
// Clusters with less of the atlas than this are not worth a view of their own.
constexpr double kMinClusterShare = 0.005;
// Thinnest extent below this share of the middle one: a flat scene (a board, a terrain tile).
constexpr double kFlatRatio = 0.2;

Vec3d d3(Vec3f v) {
  return {v.x, v.y, v.z};
}
Vec3f f3(Vec3d v) {
  return {float(v.x), float(v.y), float(v.z)};
}
Vec3d unit(Vec3d v, Vec3d fallback) {
  return normalized(v, fallback);
}

Vec3d axis_vector(UpAxis a) {
  switch (a) {
    case UpAxis::kPosX:
      return {1, 0, 0};
    case UpAxis::kNegX:
      return {-1, 0, 0};
    case UpAxis::kNegY:
      return {0, -1, 0};
    case UpAxis::kPosZ:
      return {0, 0, 1};
    case UpAxis::kNegZ:
      return {0, 0, -1};
    default:
      return {0, 1, 0};
  }
}

// Two horizontal axes for `up`, fixed by up alone.
void horizontal_frame(Vec3d up, Vec3d* h1, Vec3d* h2) {
  // For +Y up: h1 = +X, h2 = +Z, the orbit the old views used.
  *h1 = std::abs(up.y) < 0.9 ? unit(cross(Vec3d{0, 1, 0}, up), {1, 0, 0})
                             : unit(cross(up, Vec3d{0, 0, 1}), {1, 0, 0});
  *h2 = cross(*h1, up);
}

struct Cluster {
  double atlas = 0, area = 0;
  Vec3d normal_sum, centroid_sum;
  Vec3d seed;      // centroid of its first (largest) chart
  Vec3d normal;    // unit mean normal
  Vec3d centroid;  // area-weighted
  double radius = 0;
};

struct ChartSums {
  double atlas = 0, area = 0;
  Vec3d normal_sum, centroid_sum;
};

// Charts grouped greedily, largest first, by normal and place; clusters ordered by atlas texels.
std::vector<Cluster> cluster_charts(const ViewSurfaces& s, std::vector<int>* cluster_of_chart) {
  std::vector<ChartSums> charts(s.chart_count);
  for (const SurfaceTriangle& t : s.triangles) {
    ChartSums& c = charts[t.chart];
    const Vec3d centre = (d3(t.p[0]) + d3(t.p[1]) + d3(t.p[2])) / 3.0;
    c.atlas += t.atlas_texels;
    c.area += t.world_area;
    c.normal_sum = c.normal_sum + d3(t.normal) * double(t.world_area);
    c.centroid_sum = c.centroid_sum + centre * double(t.world_area);
  }
  std::vector<uint32_t> order(charts.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return charts[a].atlas > charts[b].atlas; });
  const double reach = kClusterReach * length(d3(s.hi) - d3(s.lo));
  const double cone = std::cos(kClusterConeDeg * kDeg);
  std::vector<Cluster> clusters;
  cluster_of_chart->assign(charts.size(), -1);
  for (uint32_t ci : order) {
    const ChartSums& c = charts[ci];
    if (!(c.area > 0)) continue;
    const Vec3d n = unit(c.normal_sum, {0, 0, 0});
    const Vec3d centre = c.centroid_sum / c.area;
    int found = -1;
    for (size_t k = 0; k < clusters.size() && found < 0; ++k) {
      const Cluster& cl = clusters[k];
      if (dot(n, unit(cl.normal_sum, {0, 0, 0})) >= cone && length(centre - cl.seed) <= reach)
        found = int(k);
    }
    if (found < 0) {
      found = int(clusters.size());
      clusters.push_back({});
      clusters.back().seed = centre;
    }
    Cluster& cl = clusters[found];
    cl.atlas += c.atlas, cl.area += c.area;
    cl.normal_sum = cl.normal_sum + c.normal_sum;
    cl.centroid_sum = cl.centroid_sum + c.centroid_sum;
    (*cluster_of_chart)[ci] = found;
  }
  for (Cluster& cl : clusters) {
    cl.normal = unit(cl.normal_sum, {0, 0, 1});
    cl.centroid = cl.centroid_sum / cl.area;
  }
  for (const SurfaceTriangle& t : s.triangles) {
    const int k = (*cluster_of_chart)[t.chart];
    if (k < 0) continue;
    for (const Vec3f& q : t.p)
      clusters[k].radius = std::max(clusters[k].radius, length(d3(q) - clusters[k].centroid));
  }
  // Keep the chart -> cluster map valid across the reordering.
  std::vector<uint32_t> rank(clusters.size());
  std::iota(rank.begin(), rank.end(), 0u);
  std::stable_sort(rank.begin(), rank.end(),
                   [&](uint32_t a, uint32_t b) { return clusters[a].atlas > clusters[b].atlas; });
  std::vector<int> new_index(clusters.size());
  std::vector<Cluster> sorted;
  for (uint32_t r = 0; r < rank.size(); ++r) {
    new_index[rank[r]] = int(r);
    sorted.push_back(clusters[rank[r]]);
  }
  for (int& k : *cluster_of_chart)
    if (k >= 0) k = new_index[k];
  return sorted;
}

// Möller-Trumbore: does the segment from `a` to just short of `b` cross triangle t?
bool segment_hits(Vec3d a, Vec3d b, const SurfaceTriangle& t) {
  const Vec3d dir = b - a;
  const Vec3d e1 = d3(t.p[1]) - d3(t.p[0]), e2 = d3(t.p[2]) - d3(t.p[0]);
  const Vec3d pv = cross(dir, e2);
  const double det = dot(e1, pv);
  if (std::abs(det) < 1e-18) return false;
  const Vec3d tv = a - d3(t.p[0]);
  const double u = dot(tv, pv) / det;
  if (u < 0 || u > 1) return false;
  const Vec3d qv = cross(tv, e1);
  const double v = dot(dir, qv) / det;
  if (v < 0 || u + v > 1) return false;
  const double s = dot(e2, qv) / det;
  return s > 1e-4 && s < 0.995;  // the target's own surface is not an occluder
}

// Whether a surface outside cluster `framed` lies between the eye and the target (the framed
// cluster's own curvature does not count: its centroid may lie behind its surface).
bool occluded(const ViewSurfaces& s, const std::vector<int>& cluster_of_chart, int framed,
              Vec3d eye, Vec3d target) {
  for (const SurfaceTriangle& t : s.triangles)
    if (cluster_of_chart[t.chart] != framed && segment_hits(eye, target, t)) return true;
  return false;
}

// `n` leaned by `deg` towards `toward` (made perpendicular to n first), rotated by `spin` about n.
Vec3d lean(Vec3d n, Vec3d toward, double deg, double spin) {
  Vec3d t = toward - n * dot(n, toward);
  if (length(t) < 1e-6) {
    Vec3d h1, h2;
    horizontal_frame(n, &h1, &h2);
    t = h1;
  }
  t = unit(t, {1, 0, 0});
  const Vec3d b = cross(n, t);
  const Vec3d side = t * std::cos(spin) + b * std::sin(spin);
  return unit(n * std::cos(deg * kDeg) + side * std::sin(deg * kDeg), n);
}

struct Context {
  const ViewSurfaces& s;
  const ViewPlanOptions& o;
  std::vector<int> cluster_of_chart;
  Vec3d up, h1, h2;
  double aspect = 1, diameter = 1;
  double atlas_total = 0;
  double half_fov_min = 0.45;  // half of the smaller of the two fields of view
};

Expected<PlannedView> make_view(const Context& c, ViewKind kind, Vec3d eye, Vec3d target,
                                double z_near) {
  PlannedView v;
  v.kind = kind;
  const Vec3d dir = unit(target - eye, {0, 0, -1});
  Vec3d cam_up = c.up;
  if (std::abs(dot(dir, cam_up)) > 0.98) cam_up = c.h2;  // looking straight down the up axis
  v.spec.eye = f3(eye);
  v.spec.target = f3(target);
  v.spec.up = f3(cam_up);
  v.spec.fov_y_deg = float(c.o.fov_y / kDeg);
  const double dist = length(target - eye);
  v.spec.z_near = float(std::max(z_near, dist * 1e-3));
  v.spec.z_far = float(dist + c.diameter * 1.5);
  VT_ASSIGN_OR_RETURN(v.camera, camera_from_spec(v.spec, float(c.aspect)));
  return v;
}

// A view of `target` from distance `dist` along `n` leaned by `tilt_deg`: the first of a few
// leaning directions (then shorter distances, when `may_approach`) from which no surface hides
// the target.
Expected<PlannedView> framed_view(const Context& c, ViewKind kind, int cluster, Vec3d target,
                                  Vec3d n, double dist, double tilt_deg, bool may_approach) {
  constexpr double kPi = std::numbers::pi;
  const double spins[] = {0, kPi / 2, -kPi / 2, kPi};
  const double scales[] = {1.0, 0.5, 0.25};
  Vec3d eye = target + lean(n, c.up, tilt_deg, 0) * dist;
  bool clear = false;
  for (double scale : scales) {
    for (double spin : spins) {
      const Vec3d e = target + lean(n, c.up, tilt_deg, spin) * (dist * scale);
      if (!occluded(c.s, c.cluster_of_chart, cluster, e, target)) {
        eye = e, clear = true;
        break;
      }
    }
    if (clear || !may_approach) break;
  }
  VT_ASSIGN_OR_RETURN(PlannedView v, make_view(c, kind, eye, target, dist * 0.02));
  v.occluded = !clear;
  v.cluster = cluster;
  v.angle_deg = std::acos(std::clamp(dot(unit(eye - target, n), n), -1.0, 1.0)) / kDeg;
  return v;
}

Vec3d centre_of(const ViewSurfaces& s) {
  return (d3(s.lo) + d3(s.hi)) * 0.5;
}

// The overview and the orbit views: the bounding sphere from above the horizon.
Expected<PlannedView> orbit_view(const Context& c, ViewKind kind, double azimuth, double elev_deg,
                                 double dist_scale) {
  const double radius = std::max(0.5 * c.diameter, 1e-3);
  const double dist = dist_scale * radius / std::sin(c.half_fov_min);
  const double e = elev_deg * kDeg;
  const Vec3d dir =
      (c.h1 * std::cos(azimuth) + c.h2 * std::sin(azimuth)) * std::cos(e) + c.up * std::sin(e);
  const Vec3d target = centre_of(c.s);
  VT_ASSIGN_OR_RETURN(PlannedView v,
                      make_view(c, kind, target + dir * dist, target, dist - radius * 1.2));
  v.angle_deg = 90.0 - elev_deg;  // from the up axis
  return v;
}

// The triangle of cluster k nearest its centroid: a point that is on the surface.
size_t anchor_triangle(const ViewSurfaces& s, const std::vector<int>& cluster_of_chart, int k,
                       Vec3d centroid) {
  size_t best = 0;
  double best_d = 1e300;
  for (size_t i = 0; i < s.triangles.size(); ++i) {
    const SurfaceTriangle& t = s.triangles[i];
    if (cluster_of_chart[t.chart] != k || !(t.atlas_texels > 0)) continue;
    const double d = length((d3(t.p[0]) + d3(t.p[1]) + d3(t.p[2])) / 3.0 - centroid);
    if (d < best_d) best_d = d, best = i;
  }
  return best;
}

// Cluster k framed whole along its mean normal.
Expected<PlannedView> surface_view(const Context& c, const Cluster& cl, int k) {
  const double dist = std::max(cl.radius, 1e-3) / std::sin(c.half_fov_min) * 1.05;
  VT_ASSIGN_OR_RETURN(PlannedView v, framed_view(c, ViewKind::kSurface, k, cl.centroid, cl.normal,
                                                 dist, kSurfaceTiltDeg, true));
  char buf[160];
  std::snprintf(buf, sizeof buf, "surface %d (%.0f%% of the texels), %.0f deg from its normal", k,
                100.0 * cl.atlas / c.atlas_total, v.angle_deg);
  v.description = buf;
  return v;
}

// A point on cluster k, nearly face-on, at one baked texel per pixel: a pixel at distance d
// spans d * 2 tan(fov / 2) / height units, a texel 1 / (its chart's texels per unit).
Expected<PlannedView> texel_view(const Context& c, const Cluster& cl, int k) {
  const ViewSurfaces& s = c.s;
  const SurfaceTriangle& t = s.triangles[anchor_triangle(s, c.cluster_of_chart, k, cl.centroid)];
  double chart_atlas = 0, chart_area = 0;
  for (const SurfaceTriangle& u : s.triangles)
    if (u.chart == t.chart) chart_atlas += u.atlas_texels, chart_area += u.world_area;
  const double texels_per_unit = std::sqrt(chart_atlas / std::max(chart_area, 1e-30));
  Vec3d n = d3(t.normal);
  if (dot(n, cl.normal) < 0) n = n * -1.0;
  const double pixel_per_unit_distance = 2.0 * std::tan(0.5 * c.o.fov_y) / c.o.height;
  const double dist = 1.0 / (pixel_per_unit_distance * std::max(texels_per_unit, 1e-30));
  const Vec3d target = (d3(t.p[0]) + d3(t.p[1]) + d3(t.p[2])) / 3.0;
  VT_ASSIGN_OR_RETURN(PlannedView v,
                      framed_view(c, ViewKind::kTexel, k, target, n, dist, kTexelTiltDeg, false));
  v.pixels_per_texel =
      1.0 / (pixel_per_unit_distance * length(d3(v.spec.eye) - target) * texels_per_unit);
  char buf[160];
  std::snprintf(buf, sizeof buf, "texels of surface %d at %.2f pixels per texel, %.0f deg", k,
                v.pixels_per_texel, v.angle_deg);
  v.description = buf;
  return v;
}

}  // namespace

Expected<UpAxis> parse_up_axis(std::string_view text) {
  std::string t(text);
  for (char& ch : t) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  static const std::pair<const char*, UpAxis> kWords[] = {
      {"auto", UpAxis::kAuto}, {"x", UpAxis::kPosX},  {"+x", UpAxis::kPosX}, {"-x", UpAxis::kNegX},
      {"y", UpAxis::kPosY},    {"+y", UpAxis::kPosY}, {"-y", UpAxis::kNegY}, {"z", UpAxis::kPosZ},
      {"+z", UpAxis::kPosZ},   {"-z", UpAxis::kNegZ}};
  for (const auto& [word, axis] : kWords)
    if (t == word) return axis;
  return Error(ErrorCode::kInvalidArgument,
               "up axis '" + std::string(text) + "': expected auto, x, y, z, -x, -y or -z");
}

const char* to_string(UpAxis up) {
  switch (up) {
    case UpAxis::kAuto:
      return "auto";
    case UpAxis::kPosX:
      return "+x";
    case UpAxis::kNegX:
      return "-x";
    case UpAxis::kPosY:
      return "+y";
    case UpAxis::kNegY:
      return "-y";
    case UpAxis::kPosZ:
      return "+z";
    case UpAxis::kNegZ:
      return "-z";
  }
  return "?";
}

const char* to_string(ViewKind kind) {
  switch (kind) {
    case ViewKind::kOverview:
      return "overview";
    case ViewKind::kSurface:
      return "surface";
    case ViewKind::kTexel:
      return "texel";
    case ViewKind::kOrbit:
      return "orbit";
  }
  return "?";
}

Vec3f find_up_axis(const ViewSurfaces& s, UpAxis given, std::string* rule) {
  if (given != UpAxis::kAuto) {
    *rule = "given";
    return f3(axis_vector(given));
  }
  const double ext[3] = {double(s.hi.x) - s.lo.x, double(s.hi.y) - s.lo.y, double(s.hi.z) - s.lo.z};
  // Signed area facing along each axis (n.a > 0.7 counts +, < -0.7 counts -), and the total.
  double facing[3] = {0, 0, 0}, signed_sum[3] = {0, 0, 0}, total = 0;
  for (const SurfaceTriangle& t : s.triangles) {
    const double n[3] = {t.normal.x, t.normal.y, t.normal.z};
    total += t.world_area;
    for (int a = 0; a < 3; ++a) {
      signed_sum[a] += t.world_area * n[a];
      if (std::abs(n[a]) > 0.7) facing[a] += t.world_area * (n[a] > 0 ? 1 : -1);
    }
  }
  auto axis = [](int a, bool negative) {
    Vec3f v{0, 0, 0};
    (a == 0 ? v.x : a == 1 ? v.y : v.z) = negative ? -1.0f : 1.0f;
    return v;
  };
  int order[3] = {0, 1, 2};
  std::stable_sort(order, order + 3, [&](int a, int b) { return ext[a] < ext[b]; });
  if (ext[order[0]] < kFlatRatio * ext[order[1]]) {
    *rule = "flat scene: the axis of least extent";
    return axis(order[0], signed_sum[order[0]] < -0.05 * total);
  }
  // Ground, floors and roofs face up and rarely have a matching face down; glTF's +Y stands
  // unless another axis is clearly more lopsided.
  int best = 1;
  for (int a : {0, 2})
    if (std::abs(facing[a]) > 2 * std::abs(facing[1]) + 0.1 * total &&
        std::abs(facing[a]) > std::abs(facing[best]))
      best = a;
  if (best != 1 || std::abs(facing[1]) > 0.1 * total) {
    *rule = "normals: the axis most surfaces face up along";
    return axis(best, facing[best] < 0);
  }
  *rule = "default: glTF +Y (no axis stood out)";
  return axis(1, false);
}

Expected<ViewPlan> plan_views(const ViewSurfaces& s, const ViewPlanOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  if (o.views == 0 || o.width == 0 || o.height == 0 || !(o.fov_y > 0 && o.fov_y < 3.1f) ||
      s.triangles.empty())
    return Error(ErrorCode::kInvalidArgument,
                 "view planner: needs views >= 1, a render size, a fov in (0, pi) and surfaces");
  ViewPlan plan;
  plan.up = find_up_axis(s, o.up, &plan.up_rule);
  Context c{s, o};
  c.up = d3(plan.up);
  horizontal_frame(c.up, &c.h1, &c.h2);
  c.aspect = double(o.width) / o.height;
  c.diameter = std::max(length(d3(s.hi) - d3(s.lo)), 1e-6);
  c.half_fov_min = std::min(0.5 * o.fov_y, std::atan(std::tan(0.5 * o.fov_y) * c.aspect));
  // A flat scene is looked at from high above its plane: never more than 35 deg off its normal.
  std::string auto_rule;
  const Vec3d auto_up = d3(find_up_axis(s, UpAxis::kAuto, &auto_rule));
  const bool flat = auto_rule.rfind("flat", 0) == 0 && std::abs(dot(auto_up, c.up)) > 0.9;
  const double overview_elev = flat ? 55.0 : 35.0;
  VT_ASSIGN_OR_RETURN(PlannedView overview,
                      orbit_view(c, ViewKind::kOverview, 0.7, overview_elev, 1.1));
  overview.description =
      "overview from " + std::to_string(int(std::lround(overview_elev))) + " deg above the horizon";
  plan.views.push_back(overview);

  std::vector<Cluster> clusters = cluster_charts(s, &c.cluster_of_chart);
  double& atlas_total = c.atlas_total;
  for (const Cluster& cl : clusters) atlas_total += cl.atlas;
  // Clusters worth a view, largest first; undersides (box bottoms resting on the ground, a
  // ground's back) only when nothing else is left.
  std::vector<int> chosen, undersides;
  for (size_t k = 0; k < clusters.size(); ++k) {
    if (!(atlas_total > 0) || clusters[k].atlas < kMinClusterShare * atlas_total) break;
    (dot(clusters[k].normal, c.up) < -0.7 ? undersides : chosen).push_back(int(k));
  }
  if (chosen.empty()) chosen = undersides;
  plan.clusters = uint32_t(clusters.size());
  const uint32_t rest = o.views - 1;
  const size_t surfaces = std::min<size_t>((rest + 1) / 2, chosen.size());
  const size_t texels = std::min<size_t>(rest / 2, chosen.size());
  for (size_t i = 0; plan.views.size() < o.views && i < std::max(surfaces, texels); ++i) {
    const int k = chosen[i];
    const Cluster& cl = clusters[k];
    const double share = cl.atlas / atlas_total;
    if (i < surfaces) {
      VT_ASSIGN_OR_RETURN(PlannedView v, surface_view(c, cl, k));
      v.cluster_share = share;
      plan.views.push_back(v);
    }
    if (i < texels && plan.views.size() < o.views) {
      VT_ASSIGN_OR_RETURN(PlannedView v, texel_view(c, cl, k));
      v.cluster_share = share;
      plan.views.push_back(v);
    }
  }
  // More views than clusters: around the scene, never lower than the bound allows.
  const double min_elev = flat ? std::max(20.0, 95.0 - o.max_angle_deg) : 20.0;
  static const double kElev[] = {0.0, 30.0, 15.0};
  for (uint32_t i = 0; plan.views.size() < o.views; ++i) {
    const double elev = std::max(min_elev, 20.0 + kElev[i % 3]);
    VT_ASSIGN_OR_RETURN(PlannedView v, orbit_view(c, ViewKind::kOrbit, 0.7 + 2.399963 * (i + 1),
                                                  elev, i % 2 ? 0.6 : 0.9));
    v.description = "orbit view from " + std::to_string(int(std::lround(elev))) + " deg";
    plan.views.push_back(v);
  }
  plan.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return plan;
}

nlohmann::json to_json(const ViewPlan& plan) {
  if (plan.views.empty()) return nullptr;
  auto vec = [](Vec3f v) { return nlohmann::json::array({v.x, v.y, v.z}); };
  nlohmann::json views = nlohmann::json::array();
  for (const PlannedView& v : plan.views) {
    views.push_back({{"kind", to_string(v.kind)},
                     {"description", v.description},
                     {"eye", vec(v.spec.eye)},
                     {"target", vec(v.spec.target)},
                     {"up", vec(v.spec.up)},
                     {"fov_y_deg", v.spec.fov_y_deg},
                     {"angle_deg", v.angle_deg},
                     {"cluster", v.cluster},
                     {"cluster_share", v.cluster_share},
                     {"occluded", v.occluded}});
  }
  return {{"up", vec(plan.up)},
          {"up_rule", plan.up_rule},
          {"clusters", plan.clusters},
          {"seconds", plan.seconds},
          {"views", views}};
}

}  // namespace vt::render
