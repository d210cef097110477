// unwrap_scene, as five stages (the functions at the end of this file, called in order):
// collect surfaces (one per primitive and instance, welded), segment them into charts,
// parameterise until valid (parameterize.cpp; charts are checked and split until every one is
// an injective map), choose the texel density and pack (pack.cpp), write the atlas UVs back as
// a new UV set. The atlas check (atlas_check.cpp) then measures the result.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <compare>
#include <cstring>
#include <functional>
#include <limits>
#include <numeric>
#include <queue>
#include <thread>
#include <unordered_map>

#include "bake/unwrap/atlas_raster.h"
#include "bake/unwrap/unwrap.h"
#include "bake/unwrap/unwrap_internal.h"
#include "common/parallel.h"
#include "scene/material_rules.h"
#include "scene/tangent_frame.h"

namespace vt::unwrap {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

using detail::bounds_of;

// Twice the signed area of the triangle abc.
double cross2(Vec2d a, Vec2d b, Vec2d c) {
  return cross(b - a, c - a);
}

// One primitive of one instance (or of one mesh with share_instances), in world space.
struct Surface {
  int source_mesh = 0;             // in the input scene
  int material = -1, node = -1;    // the primitive's material and the instance's node
  int out_mesh = 0, out_prim = 0;  // in the output scene
  std::vector<Vec3d> pos;          // welded vertices, world space minus `origin`
  std::vector<uint32_t> weld;      // source vertex -> welded vertex
  std::vector<uint32_t> tri;       // welded corners, 3 per face
  std::vector<int32_t> adj;        // per corner e: face across edge (e, e+1), or -1
  std::vector<Vec3d> normal;       // unit face normals
  std::vector<double> area;        // face areas
  std::vector<char> degenerate;
};

struct Chart {
  uint32_t surface = 0;
  std::vector<uint32_t> faces;
  bool degenerate = false;
  int round = 0;  // stretch split rounds this chart descends from
  // Filled by parameterisation:
  std::vector<uint32_t> corner_local;  // per face corner: local vertex
  std::vector<Vec3d> local_pos;
  std::vector<Vec2d> uv;
  double area3d = 0, area_uv = 0, l2 = 1;
};

// ---- surfaces -------------------------------------------------------------------------

void weld(const scene::Primitive& p, Surface* s, const scene::Mat4& world) {
  size_t n = p.positions.size();
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  // Vertices weld when position and every UV set match bit for bit: different UVs are an
  // original seam, which always cuts.
  auto less = [&](uint32_t a, uint32_t b) {
    int c = std::memcmp(p.positions[a].data(), p.positions[b].data(), sizeof(scene::Vec3));
    if (c != 0) return c < 0;
    for (const auto& set : p.uvs) {
      c = std::memcmp(set[a].data(), set[b].data(), sizeof(scene::Vec2));
      if (c != 0) return c < 0;
    }
    return a < b;
  };
  auto equal = [&](uint32_t a, uint32_t b) {
    if (std::memcmp(p.positions[a].data(), p.positions[b].data(), sizeof(scene::Vec3)))
      return false;
    for (const auto& set : p.uvs)
      if (std::memcmp(set[a].data(), set[b].data(), sizeof(scene::Vec2))) return false;
    return true;
  };
  std::sort(order.begin(), order.end(), less);
  s->weld.assign(n, 0);
  std::vector<uint32_t> rep;
  for (size_t i = 0; i < n; ++i) {
    if (i == 0 || !equal(order[i - 1], order[i])) rep.push_back(order[i]);
    s->weld[order[i]] = static_cast<uint32_t>(rep.size() - 1);
  }
  // Renumber welded vertices in source order for determinism independent of sort details.
  std::vector<uint32_t> first(rep.size(), UINT32_MAX), remap(rep.size());
  for (size_t i = 0; i < n; ++i) first[s->weld[i]] = std::min<uint32_t>(first[s->weld[i]], i);
  std::vector<uint32_t> ids(rep.size());
  std::iota(ids.begin(), ids.end(), 0u);
  std::sort(ids.begin(), ids.end(), [&](uint32_t a, uint32_t b) { return first[a] < first[b]; });
  for (size_t k = 0; k < ids.size(); ++k) remap[ids[k]] = static_cast<uint32_t>(k);
  for (auto& w : s->weld) w = remap[w];
  std::vector<Vec3d> world_pos(rep.size());
  for (size_t k = 0; k < rep.size(); ++k) {
    const auto q = scene::transform_point(world, p.positions[rep[k]]);
    world_pos[remap[k]] = {q[0], q[1], q[2]};
  }
  // Work relative to the surface's bounding-box centre so large offsets cost no precision.
  const auto [lo, hi] = bounds_of(world_pos);
  const Vec3d centre = (lo + hi) / 2.0;
  s->pos.resize(world_pos.size());
  for (size_t k = 0; k < world_pos.size(); ++k) s->pos[k] = world_pos[k] - centre;
  s->tri.resize(p.indices.size());
  for (size_t i = 0; i < p.indices.size(); ++i) s->tri[i] = s->weld[p.indices[i]];
}

// Links the corners of `s` still open (adj -1) across edges that exactly two of them use in
// opposite directions, the edges named by `corners`' vertex indices.
void pair_edges(const std::vector<uint32_t>& corners, Surface& s) {
  struct Edge {
    uint64_t key;
    uint32_t corner;
    bool forward;
  };
  std::vector<Edge> edges;
  edges.reserve(corners.size());
  for (size_t f = 0; f < corners.size() / 3; ++f) {
    if (s.degenerate[f]) continue;
    for (int e = 0; e < 3; ++e) {
      if (s.adj[3 * f + e] >= 0) continue;
      uint32_t a = corners[3 * f + e], b = corners[3 * f + (e + 1) % 3];
      uint64_t key = (static_cast<uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
      edges.push_back({key, static_cast<uint32_t>(3 * f + e), a < b});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) {
    return x.key != y.key ? x.key < y.key : x.corner < y.corner;
  });
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].key == edges[i].key) ++j;
    if (j - i == 2 && edges[i].forward != edges[i + 1].forward) {
      s.adj[edges[i].corner] = static_cast<int32_t>(edges[i + 1].corner / 3);
      s.adj[edges[i + 1].corner] = static_cast<int32_t>(edges[i].corner / 3);
    }
    i = j;
  }
}

void build_topology(const std::vector<uint32_t>& source_indices, Surface* s) {
  size_t faces = s->tri.size() / 3;
  s->normal.resize(faces);
  s->area.resize(faces);
  s->degenerate.assign(faces, 0);
  for (size_t f = 0; f < faces; ++f) {
    const Vec3d& a = s->pos[s->tri[3 * f]];
    const Vec3d& b = s->pos[s->tri[3 * f + 1]];
    const Vec3d& c = s->pos[s->tri[3 * f + 2]];
    Vec3d n = cross(b - a, c - a);
    double len = length(n);
    double longest = std::max({dot(b - a, b - a), dot(c - b, c - b), dot(a - c, a - c)});
    s->area[f] = len / 2;
    bool same = s->tri[3 * f] == s->tri[3 * f + 1] || s->tri[3 * f + 1] == s->tri[3 * f + 2] ||
                s->tri[3 * f] == s->tri[3 * f + 2];
    if (same || !(len > 1e-10 * longest) || !std::isfinite(len)) {
      s->degenerate[f] = 1;
      s->normal[f] = {0, 0, 0};
    } else {
      s->normal[f] = n / len;
    }
  }
  // Faces are neighbours across an edge used by exactly two faces in opposite directions
  // (consistent winding), first in the source's own vertex indices, then, for the edges left
  // open, in welded vertices (which rejoin vertices a format split by normal or by face).
  // Non-manifold and inconsistently wound edges cut. The source's indices come first because
  // welding makes coincident copies of a surface (Sweet Home 3D's lily: every petal two to four
  // times over) one non-manifold sheet, where every edge would cut: a chart a triangle.
  s->adj.assign(s->tri.size(), -1);
  pair_edges(source_indices, *s);
  pair_edges(s->tri, *s);
}

// ---- segmentation ---------------------------------------------------------------------

void segment(const Surface& s, uint32_t surface_index, double max_angle_deg,
             std::vector<Chart>* charts) {
  size_t faces = s.tri.size() / 3;
  const double cos_max = std::cos(max_angle_deg * M_PI / 180.0);
  std::vector<int32_t> chart_of(faces, -1);
  std::vector<Vec3d> centroid(faces);
  for (size_t f = 0; f < faces; ++f) {
    const Vec3d& a = s.pos[s.tri[3 * f]];
    const Vec3d& b = s.pos[s.tri[3 * f + 1]];
    const Vec3d& c = s.pos[s.tri[3 * f + 2]];
    centroid[f] = (a + b + c) / 3.0;
  }
  using Item = std::pair<double, uint32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
  for (size_t seed = 0; seed < faces; ++seed) {
    if (chart_of[seed] >= 0) continue;
    Chart chart;
    chart.surface = surface_index;
    int32_t id = static_cast<int32_t>(charts->size());
    chart_of[seed] = id;
    chart.faces.push_back(static_cast<uint32_t>(seed));
    if (s.degenerate[seed]) {
      chart.degenerate = true;
      charts->push_back(std::move(chart));
      continue;
    }
    Vec3d nsum = s.normal[seed] * s.area[seed];
    double area = s.area[seed];
    Vec3d seed_c = centroid[seed];
    auto push_neighbours = [&](uint32_t f) {
      Vec3d n = nsum;
      double len = length(n);
      if (len > 0) n = n / len;
      double radius = std::sqrt(area / M_PI) + 1e-300;
      for (int e = 0; e < 3; ++e) {
        int32_t g = s.adj[3 * f + e];
        if (g < 0 || chart_of[g] >= 0) continue;
        double cost = (1.0 - dot(s.normal[g], n)) + 0.05 * length(centroid[g] - seed_c) / radius;
        heap.push({cost, static_cast<uint32_t>(g)});
      }
    };
    push_neighbours(static_cast<uint32_t>(seed));
    while (!heap.empty()) {
      uint32_t f = heap.top().second;
      heap.pop();
      if (chart_of[f] >= 0) continue;
      Vec3d n = nsum;
      double len = length(n);
      if (len > 0) n = n / len;
      if (dot(s.normal[f], n) < cos_max || dot(s.normal[f], s.normal[seed]) < cos_max) continue;
      chart_of[f] = id;
      chart.faces.push_back(f);
      nsum = nsum + s.normal[f] * s.area[f];
      area += s.area[f];
      push_neighbours(f);
    }
    charts->push_back(std::move(chart));
  }
}

// Splits a chart into two connected halves grown from two far-apart faces.
std::pair<Chart, Chart> split_chart(const Surface& s, const Chart& chart) {
  std::vector<uint32_t> local(chart.faces.size());
  std::vector<int32_t> index_of;  // face -> position in chart, via sorted lookup
  std::vector<std::pair<uint32_t, uint32_t>> sorted(chart.faces.size());
  for (size_t i = 0; i < chart.faces.size(); ++i)
    sorted[i] = {chart.faces[i], static_cast<uint32_t>(i)};
  std::sort(sorted.begin(), sorted.end());
  auto find = [&](int32_t f) -> int32_t {
    auto it = std::lower_bound(sorted.begin(), sorted.end(),
                               std::make_pair(static_cast<uint32_t>(f), 0u));
    return (it != sorted.end() && it->first == static_cast<uint32_t>(f))
               ? static_cast<int32_t>(it->second)
               : -1;
  };
  size_t n = chart.faces.size();
  std::vector<std::array<int32_t, 3>> nb(n);
  for (size_t i = 0; i < n; ++i)
    for (int e = 0; e < 3; ++e) {
      int32_t g = s.adj[3 * chart.faces[i] + e];
      nb[i][e] = g < 0 ? -1 : find(g);
    }
  auto bfs = [&](std::vector<uint32_t> sources, std::vector<int32_t>* label) {
    std::vector<uint32_t> queue = sources;
    label->assign(n, -1);
    for (size_t k = 0; k < sources.size(); ++k) (*label)[sources[k]] = static_cast<int32_t>(k);
    uint32_t last = sources.back();
    for (size_t head = 0; head < queue.size(); ++head) {
      uint32_t i = queue[head];
      last = i;
      for (int32_t j : nb[i])
        if (j >= 0 && (*label)[j] < 0) {
          (*label)[j] = (*label)[i];
          queue.push_back(static_cast<uint32_t>(j));
        }
    }
    return last;
  };
  std::vector<int32_t> label;
  uint32_t a = bfs({0}, &label);
  uint32_t b = bfs({a}, &label);
  if (a == b) b = (a + 1) % n;
  bfs({a, b}, &label);
  std::pair<Chart, Chart> halves;
  halves.first.surface = halves.second.surface = chart.surface;
  halves.first.round = halves.second.round = chart.round;
  for (size_t i = 0; i < n; ++i) {
    // Faces the BFS did not reach (cannot happen for a connected chart) go to the first half.
    (label[i] == 1 ? halves.second : halves.first).faces.push_back(chart.faces[i]);
  }
  if (halves.second.faces.empty()) {  // keep both halves non-empty
    halves.second.faces.push_back(halves.first.faces.back());
    halves.first.faces.pop_back();
  }
  return halves;
}

// ---- parameterisation and checks --------------------------------------------------------

enum class ChartVerdict { kOk, kSplit, kStretch };

// Local vertices: corners joined across the chart's internal edges (non-manifold vertices
// thereby split into one vertex per fan).
void build_local(const Surface& s, Chart* c) {
  size_t n = c->faces.size();
  std::vector<std::pair<uint32_t, uint32_t>> sorted(n);
  for (size_t i = 0; i < n; ++i) sorted[i] = {c->faces[i], static_cast<uint32_t>(i)};
  std::sort(sorted.begin(), sorted.end());
  std::vector<uint32_t> parent(3 * n);
  std::iota(parent.begin(), parent.end(), 0u);
  std::function<uint32_t(uint32_t)> root = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  auto unite = [&](uint32_t x, uint32_t y) {
    x = root(x), y = root(y);
    if (x != y) parent[std::max(x, y)] = std::min(x, y);
  };
  for (size_t i = 0; i < n; ++i) {
    uint32_t f = c->faces[i];
    for (int e = 0; e < 3; ++e) {
      int32_t g = s.adj[3 * f + e];
      if (g < 0) continue;
      auto it = std::lower_bound(sorted.begin(), sorted.end(),
                                 std::make_pair(static_cast<uint32_t>(g), 0u));
      if (it == sorted.end() || it->first != static_cast<uint32_t>(g)) continue;
      uint32_t j = it->second;
      uint32_t a = s.tri[3 * f + e], b = s.tri[3 * f + (e + 1) % 3];
      for (int k = 0; k < 3; ++k) {
        uint32_t v = s.tri[3 * g + k];
        if (v == a) unite(3 * i + e, 3 * j + k);
        if (v == b) unite(3 * i + (e + 1) % 3, 3 * j + k);
      }
    }
  }
  c->corner_local.assign(3 * n, 0);
  c->local_pos.clear();
  std::vector<uint32_t> id(3 * n, UINT32_MAX);
  for (size_t k = 0; k < 3 * n; ++k) {
    uint32_t r = root(static_cast<uint32_t>(k));
    if (id[r] == UINT32_MAX) {
      id[r] = static_cast<uint32_t>(c->local_pos.size());
      c->local_pos.push_back(s.pos[s.tri[3 * c->faces[k / 3] + k % 3]]);
    }
    c->corner_local[k] = id[r];
  }
}

bool segments_cross(const Vec2d& a, const Vec2d& b, const Vec2d& c, const Vec2d& d) {
  double o1 = cross2(a, b, c), o2 = cross2(a, b, d), o3 = cross2(c, d, a), o4 = cross2(c, d, b);
  if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0)))
    return true;
  auto on = [](const Vec2d& p, const Vec2d& q, const Vec2d& r, double o) {  // r on segment pq
    return o == 0 && std::min(p.x, q.x) <= r.x && r.x <= std::max(p.x, q.x) &&
           std::min(p.y, q.y) <= r.y && r.y <= std::max(p.y, q.y);
  };
  return on(a, b, c, o1) || on(a, b, d, o2) || on(c, d, a, o3) || on(c, d, b, o4);
}

// True when the chart's boundary crosses itself (the only way a flip-free disk map overlaps).
bool boundary_self_intersects(const Chart& c) {
  std::vector<std::pair<uint64_t, uint32_t>> directed;
  size_t n = c.faces.size();
  for (size_t i = 0; i < n; ++i)
    for (int e = 0; e < 3; ++e)
      directed.push_back({(static_cast<uint64_t>(c.corner_local[3 * i + e]) << 32) |
                              c.corner_local[3 * i + (e + 1) % 3],
                          0});
  std::sort(directed.begin(), directed.end());
  std::vector<std::array<uint32_t, 2>> seg;
  for (const auto& d : directed) {
    uint32_t a = static_cast<uint32_t>(d.first >> 32), b = static_cast<uint32_t>(d.first);
    uint64_t rev = (static_cast<uint64_t>(b) << 32) | a;
    if (!std::binary_search(directed.begin(), directed.end(), std::make_pair(rev, 0u)))
      seg.push_back({a, b});
  }
  if (seg.size() < 3) return false;
  const auto [lo, hi] = bounds_of(c.uv);
  int g = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(seg.size()))));
  double cw = std::max(hi.x - lo.x, 1e-300) / g, ch = std::max(hi.y - lo.y, 1e-300) / g;
  std::vector<std::vector<uint32_t>> cells(static_cast<size_t>(g) * g);
  auto cell = [&](double v, double l, double w) {
    return std::clamp(static_cast<int>((v - l) / w), 0, g - 1);
  };
  for (size_t k = 0; k < seg.size(); ++k) {
    const Vec2d& a = c.uv[seg[k][0]];
    const Vec2d& b = c.uv[seg[k][1]];
    int x0 = cell(std::min(a.x, b.x), lo.x, cw), x1 = cell(std::max(a.x, b.x), lo.x, cw);
    int y0 = cell(std::min(a.y, b.y), lo.y, ch), y1 = cell(std::max(a.y, b.y), lo.y, ch);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x)
        cells[static_cast<size_t>(y) * g + x].push_back(static_cast<uint32_t>(k));
  }
  for (const auto& list : cells)
    for (size_t i = 0; i < list.size(); ++i)
      for (size_t j = i + 1; j < list.size(); ++j) {
        const auto& s1 = seg[list[i]];
        const auto& s2 = seg[list[j]];
        if (s1[0] == s2[0] || s1[0] == s2[1] || s1[1] == s2[0] || s1[1] == s2[1]) continue;
        if (segments_cross(c.uv[s1[0]], c.uv[s1[1]], c.uv[s2[0]], c.uv[s2[1]])) return true;
      }
  return false;
}

// Sander et al. stretch of one triangle: returns {L2^2, Linf} for 3D q and 2D p.
std::pair<double, double> triangle_stretch(const Vec3d& q1, const Vec3d& q2, const Vec3d& q3,
                                           const Vec2d& p1, const Vec2d& p2, const Vec2d& p3) {
  double a2 = cross2(p1, p2, p3);  // twice the signed UV area
  if (!(std::abs(a2) > 0))
    return {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  Vec3d ss = (q1 * (p2.y - p3.y) + q2 * (p3.y - p1.y) + q3 * (p1.y - p2.y)) / a2;
  Vec3d st = (q1 * (p3.x - p2.x) + q2 * (p1.x - p3.x) + q3 * (p2.x - p1.x)) / a2;
  double a = dot(ss, ss), b = dot(ss, st), c = dot(st, st);
  double root = std::sqrt((a - c) * (a - c) + 4 * b * b);
  return {(a + c) / 2, std::sqrt(std::max(0.0, (a + c + root) / 2))};
}

ChartVerdict parameterize(const Surface& s, Chart* c, const UnwrapOptions& opt) {
  build_local(s, c);
  size_t n = c->faces.size();
  c->area3d = 0;
  for (uint32_t f : c->faces) c->area3d += s.area[f];
  if (c->degenerate) {
    // Zero-area face: a tiny triangle of its own, so it still owns (part of) a texel.
    c->uv.assign(c->local_pos.size(), {0, 0});
    c->uv[c->corner_local[1]] = {1, 0};
    c->uv[c->corner_local[2]] = {0, 1};
    c->area_uv = 0.5;
    c->l2 = 1;
    return ChartVerdict::kOk;
  }
  if (n == 1) {
    // One face: an exact isometric placement, longest edge first for accuracy.
    const Vec3d* q[3] = {&c->local_pos[c->corner_local[0]], &c->local_pos[c->corner_local[1]],
                         &c->local_pos[c->corner_local[2]]};
    int e = 0;
    double best = -1;
    for (int k = 0; k < 3; ++k) {
      double l = length(*q[(k + 1) % 3] - *q[k]);
      if (l > best) best = l, e = k;
    }
    Vec3d ab = *q[(e + 1) % 3] - *q[e], ac = *q[(e + 2) % 3] - *q[e];
    double len = length(ab);
    double x = dot(ac, ab) / len, y = length(cross(ab, ac)) / len;
    c->uv.assign(3, {0, 0});
    c->uv[c->corner_local[e]] = {0, 0};
    c->uv[c->corner_local[(e + 1) % 3]] = {len, 0};
    c->uv[c->corner_local[(e + 2) % 3]] = {x, y};
  } else {
    // Normalise the chart to unit size for the solver; scale back afterwards.
    const auto [lo, hi] = bounds_of(c->local_pos);
    double scale = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    if (!(scale > 0)) return ChartVerdict::kSplit;
    std::vector<Vec3d> unit(c->local_pos.size());
    for (size_t v = 0; v < unit.size(); ++v) unit[v] = (c->local_pos[v] - lo) / scale;
    std::vector<std::array<uint32_t, 3>> faces(n);
    for (size_t i = 0; i < n; ++i)
      faces[i] = {c->corner_local[3 * i], c->corner_local[3 * i + 1], c->corner_local[3 * i + 2]};
    auto status = detail::parameterize_chart(unit, faces, opt.method, &c->uv);
    if (status != detail::ParamStatus::kOk) return ChartVerdict::kSplit;
    for (Vec2d& p : c->uv) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) return ChartVerdict::kSplit;
      p.x *= scale, p.y *= scale;
    }
  }
  // Orientation: the chart's total signed area is made positive (never mirrored later), and
  // then every face must be positive too.
  double total = 0;
  for (size_t i = 0; i < n; ++i)
    total += cross2(c->uv[c->corner_local[3 * i]], c->uv[c->corner_local[3 * i + 1]],
                    c->uv[c->corner_local[3 * i + 2]]);
  if (total < 0)
    for (Vec2d& p : c->uv) p.x = -p.x;
  const auto [lo, hi] = bounds_of(c->uv);
  double extent2 = std::max(hi.x - lo.x, hi.y - lo.y);
  extent2 *= extent2;
  c->area_uv = 0;
  double l2sum = 0;
  for (size_t i = 0; i < n; ++i) {
    const Vec2d& a = c->uv[c->corner_local[3 * i]];
    const Vec2d& b = c->uv[c->corner_local[3 * i + 1]];
    const Vec2d& d = c->uv[c->corner_local[3 * i + 2]];
    double a2 = cross2(a, b, d);
    // Strictly positive with margin: the map must survive rounding to float atlas UVs.
    if (!(a2 > 1e-12 * extent2)) return n > 1 ? ChartVerdict::kSplit : ChartVerdict::kOk;
    c->area_uv += a2 / 2;
    auto [l2sq, linf] = triangle_stretch(c->local_pos[c->corner_local[3 * i]],
                                         c->local_pos[c->corner_local[3 * i + 1]],
                                         c->local_pos[c->corner_local[3 * i + 2]], a, b, d);
    (void)linf;
    l2sum += l2sq * s.area[c->faces[i]];
  }
  if (n > 1 && boundary_self_intersects(*c)) return ChartVerdict::kSplit;
  c->l2 = c->area3d > 0 ? std::sqrt(l2sum / c->area3d) * std::sqrt(c->area_uv / c->area3d) : 1.0;
  if (!std::isfinite(c->l2)) return ChartVerdict::kSplit;
  if (n > 1 && c->l2 > opt.max_chart_stretch) return ChartVerdict::kStretch;
  return ChartVerdict::kOk;
}

// ---- scaling and rotation ---------------------------------------------------------------

// Rotates chart-local points to the smallest-area bounding box (hull edge directions), then
// moves the box's corner to the origin.
void fit_box(detail::PackChart* pc) {
  std::vector<Vec2d> pts = pc->points;
  // Lexicographic, as std::array's operator< orders.
  std::sort(pts.begin(), pts.end(), [](Vec2d a, Vec2d b) {
    const auto c = a.x <=> b.x;
    return c != 0 ? c < 0 : a.y < b.y;
  });
  pts.erase(std::unique(pts.begin(), pts.end(),
                        [](Vec2d a, Vec2d b) { return a.x == b.x && a.y == b.y; }),
            pts.end());
  std::vector<Vec2d> hull;
  if (pts.size() >= 3) {
    std::vector<Vec2d> h(2 * pts.size());
    size_t k = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
      while (k >= 2 && cross2(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
      h[k++] = pts[i];
    }
    for (size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {
      while (k >= t && cross2(h[k - 2], h[k - 1], pts[i - 1]) <= 0) --k;
      h[k++] = pts[i - 1];
    }
    h.resize(k - 1);
    hull = h;
  } else {
    hull = pts;
  }
  double best_area = std::numeric_limits<double>::infinity(), best_c = 1, best_s = 0;
  for (size_t i = 0; i < hull.size(); ++i) {
    const Vec2d& a = hull[i];
    const Vec2d& b = hull[(i + 1) % hull.size()];
    double dx = b.x - a.x, dy = b.y - a.y, len = std::hypot(dx, dy);
    if (!(len > 0)) continue;
    double cs = dx / len, sn = dy / len;
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    for (const Vec2d& p : hull) {
      double x = p.x * cs + p.y * sn, y = -p.x * sn + p.y * cs;
      lo[0] = std::min(lo[0], x), hi[0] = std::max(hi[0], x), lo[1] = std::min(lo[1], y),
      hi[1] = std::max(hi[1], y);
    }
    double area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
    if (area < best_area * (1 - 1e-9)) best_area = area, best_c = cs, best_s = sn;
  }
  for (Vec2d& p : pc->points) p = {p.x * best_c + p.y * best_s, -p.x * best_s + p.y * best_c};
  const auto [lo, hi] = bounds_of(pc->points);
  // Centre the box in whole texels with at least kMargin texel around it, more than the
  // footprint margin: no triangle then touches a texel beyond the footprint grid.
  const double kMargin = 2 * kFootprintMargin;
  double w = hi.x - lo.x, h = hi.y - lo.y;
  double gx = std::max(1.0, std::ceil(w + 2 * kMargin)),
         gy = std::max(1.0, std::ceil(h + 2 * kMargin));
  double ox = (gx - w) / 2 - lo.x, oy = (gy - h) / 2 - lo.y;
  for (Vec2d& p : pc->points) p = {p.x + ox, p.y + oy};
  pc->width = gx;
  pc->height = gy;
}

// Twice the signed area in atlas texels (x right, y down); front faces are negative.
double atlas_cross(const std::vector<scene::Vec2>& uv, const uint32_t* t, double W, double H) {
  double ax = uv[t[0]][0] * W, ay = uv[t[0]][1] * H;
  double bx = uv[t[1]][0] * W, by = uv[t[1]][1] * H;
  double cx = uv[t[2]][0] * W, cy = uv[t[2]][1] * H;
  return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

void repair_rounding(const Surface& s, const std::vector<uint32_t>& index, double W, double H,
                     std::vector<scene::Vec2>* uv) {
  size_t faces = index.size() / 3;
  std::vector<uint32_t> bad;
  for (size_t f = 0; f < faces; ++f)
    if (!s.degenerate[f] && !(atlas_cross(*uv, &index[3 * f], W, H) < 0))
      bad.push_back(static_cast<uint32_t>(f));
  if (bad.empty()) return;
  // Faces around each vertex (CSR).
  std::vector<uint32_t> start(uv->size() + 1, 0), list(index.size());
  for (uint32_t v : index) ++start[v + 1];
  for (size_t v = 0; v < uv->size(); ++v) start[v + 1] += start[v];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (size_t c = 0; c < index.size(); ++c) list[fill[index[c]]++] = static_cast<uint32_t>(c / 3);
  for (uint32_t f : bad) {
    for (int step = 0; step < 64 && !(atlas_cross(*uv, &index[3 * f], W, H) < 0); ++step) {
      int k = step % 3;
      const uint32_t* t = &index[3 * f];
      uint32_t v = t[k];
      const auto& a = (*uv)[t[(k + 1) % 3]];
      const auto& b = (*uv)[t[(k + 2) % 3]];
      // Moving v lowers the cross product along -(gradient); in (x, y) texel space the
      // gradient for the corner opposite edge a->b is (-(b.y - a.y), b.x - a.x) up to scale.
      double gx = -(b[1] - a[1]) * H, gy = (b[0] - a[0]) * W;
      scene::Vec2 old = (*uv)[v];
      std::vector<uint32_t> good;  // triangles at v that are fine now must stay fine
      for (uint32_t m = start[v]; m < start[v + 1]; ++m)
        if (list[m] != f && !s.degenerate[list[m]] &&
            atlas_cross(*uv, &index[3 * list[m]], W, H) < 0)
          good.push_back(list[m]);
      scene::Vec2 moved = old;
      for (int n = 0; n <= step / 3; ++n) {
        if (gx != 0) moved[0] = std::nextafter(moved[0], gx > 0 ? -1.0f : 2.0f);
        if (gy != 0) moved[1] = std::nextafter(moved[1], gy > 0 ? -1.0f : 2.0f);
      }
      moved[0] = std::clamp(moved[0], 0.0f, 1.0f);
      moved[1] = std::clamp(moved[1], 0.0f, 1.0f);
      (*uv)[v] = moved;
      bool others_fine = true;
      for (uint32_t g : good)
        if (!(atlas_cross(*uv, &index[3 * g], W, H) < 0)) others_fine = false;
      if (!others_fine) (*uv)[v] = old;
    }
  }
}

// ---- the stages of unwrap_scene ----------------------------------------------------------

Status check_options(const UnwrapOptions& opt) {
  if (opt.padding < 0 || opt.padding > 1024)
    return Error(ErrorCode::kInvalidArgument, "padding must be in [0, 1024]");
  if (opt.page_payload <= 0)
    return Error(ErrorCode::kInvalidArgument, "page payload must be positive");
  if (!(opt.texels_per_unit >= 0) || !std::isfinite(opt.texels_per_unit))
    return Error(ErrorCode::kInvalidArgument, "texels per unit must be a finite positive number");
  if (opt.size_pages < 0 || opt.max_size_pages < 1 || opt.min_size_pages < 1)
    return Error(ErrorCode::kInvalidArgument, "atlas sizes in pages must be positive");
  return Status::Ok();
}

// Stage 1: one welded surface per primitive and instance (per mesh with share_instances), in
// world space. Makes `out`'s meshes match the surfaces' out_mesh numbering.
Expected<std::vector<Surface>> collect_surfaces(const scene::Scene& in, const UnwrapOptions& opt,
                                                int threads, scene::Scene* out) {
  // Which meshes to unwrap, with which world matrix.
  struct Job {
    int mesh, node;
    scene::Mat4 world;
  };
  std::vector<Job> jobs;  // per output mesh
  std::vector<scene::Instance> instances = in.instances();
  if (opt.share_instances) {
    for (size_t m = 0; m < in.meshes.size(); ++m) {
      Job job{static_cast<int>(m), -1, scene::kIdentity};
      for (const auto& inst : instances)
        if (inst.mesh == static_cast<int>(m)) {
          job.world = inst.world, job.node = inst.node;
          break;
        }
      jobs.push_back(job);
    }
  } else {
    out->meshes.clear();
    for (auto& node : out->nodes) node.mesh = -1;  // nodes outside the scene keep no mesh
    for (const auto& inst : instances) {
      out->nodes[inst.node].mesh = static_cast<int>(out->meshes.size());
      out->meshes.push_back(in.meshes[inst.mesh]);
      jobs.push_back({inst.mesh, inst.node, inst.world});
    }
  }
  std::vector<Surface> surfaces;
  for (size_t j = 0; j < jobs.size(); ++j) {
    const scene::Mesh& mesh = in.meshes[jobs[j].mesh];
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      if (mesh.primitives[p].indices.empty()) continue;
      Surface s;
      s.source_mesh = jobs[j].mesh;
      s.material = mesh.primitives[p].material;
      s.node = jobs[j].node;
      s.out_mesh = static_cast<int>(j);
      s.out_prim = static_cast<int>(p);
      surfaces.push_back(std::move(s));
    }
  }
  for (const auto& s : surfaces) {
    // World matrices can still overflow a finite mesh into inf: name the instance.
    for (double v : jobs[s.out_mesh].world)
      if (!std::isfinite(v))
        return Error(ErrorCode::kInvalidArgument,
                     "mesh '" + in.meshes[s.source_mesh].name + "': non-finite node transform");
  }
  parallel_for(surfaces.size(), threads, [&](size_t i) {
    Surface& s = surfaces[i];
    weld(in.meshes[s.source_mesh].primitives[s.out_prim], &s, jobs[s.out_mesh].world);
    build_topology(in.meshes[s.source_mesh].primitives[s.out_prim].indices, &s);
  });
  for (const auto& s : surfaces)
    for (const Vec3d& p : s.pos)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        return Error(ErrorCode::kInvalidArgument, "mesh '" + in.meshes[s.source_mesh].name +
                                                      "': world position overflows double");
  return surfaces;
}

// Stage 2: charts grown on every surface, in surface order.
std::vector<Chart> segment_surfaces(const std::vector<Surface>& surfaces, const UnwrapOptions& opt,
                                    int threads) {
  std::vector<std::vector<Chart>> per(surfaces.size());
  parallel_for(surfaces.size(), threads, [&](size_t i) {
    segment(surfaces[i], static_cast<uint32_t>(i), opt.max_chart_angle_deg, &per[i]);
  });
  std::vector<Chart> charts;
  for (auto& v : per)
    for (auto& c : v) charts.push_back(std::move(c));
  return charts;
}

// Stage 3: parameterises the charts; charts that fail are split and redone until every chart
// is valid. A one-face chart always succeeds, so this terminates. Deterministic chart order.
std::vector<Chart> parameterize_until_valid(const std::vector<Surface>& surfaces,
                                            std::vector<Chart> pending, const UnwrapOptions& opt,
                                            int threads, UnwrapStats* st) {
  std::vector<Chart> done;
  while (!pending.empty()) {
    std::vector<ChartVerdict> verdict(pending.size());
    parallel_for(pending.size(), threads, [&](size_t i) {
      verdict[i] = parameterize(surfaces[pending[i].surface], &pending[i], opt);
    });
    std::vector<Chart> next;
    bool stretch_round = false;
    for (size_t i = 0; i < pending.size(); ++i) {
      Chart& c = pending[i];
      bool split = verdict[i] == ChartVerdict::kSplit ||
                   (verdict[i] == ChartVerdict::kStretch && c.round < opt.max_split_rounds);
      if (!split) {
        done.push_back(std::move(c));
        continue;
      }
      if (verdict[i] == ChartVerdict::kStretch) {
        stretch_round = true;
        ++c.round;
      }
      ++st->charts_split;
      auto halves = split_chart(surfaces[c.surface], c);
      next.push_back(std::move(halves.first));
      next.push_back(std::move(halves.second));
    }
    st->split_rounds += stretch_round;
    pending = std::move(next);
  }
  // By surface, then by first face.
  std::stable_sort(done.begin(), done.end(), [](const Chart& a, const Chart& b) {
    return a.surface != b.surface ? a.surface < b.surface : a.faces[0] < b.faces[0];
  });
  return done;
}

// Charts scaled to `tpu` texels per world unit times their weight (their own density over the
// scene's; 1 for most), rotated and boxed for packing.
std::vector<detail::PackChart> make_pack_charts(const std::vector<Chart>& charts,
                                                const std::vector<double>& weight, double tpu,
                                                int threads) {
  std::vector<detail::PackChart> pcs(charts.size());
  parallel_for(charts.size(), threads, [&](size_t i) {
    const Chart& c = charts[i];
    double k = (c.degenerate || !(c.area3d > 0) || !(c.area_uv > 0))
                   ? (c.degenerate ? 0.5 : tpu * weight[i])
                   : std::sqrt(c.area3d / c.area_uv) * tpu * weight[i];
    if (!std::isfinite(k)) k = 0.5;
    detail::PackChart& pc = pcs[i];
    pc.points.resize(c.uv.size());
    for (size_t v = 0; v < c.uv.size(); ++v) pc.points[v] = c.uv[v] * k;
    for (size_t f = 0; f < c.faces.size(); ++f)
      pc.tris.push_back(
          {c.corner_local[3 * f], c.corner_local[3 * f + 1], c.corner_local[3 * f + 2]});
    fit_box(&pc);
  });
  return pcs;
}

// The atlas width (whole pages) that the boxes of `pcs` with their gutters could fill.
int atlas_width_for(const std::vector<detail::PackChart>& pcs, const UnwrapOptions& opt) {
  double box = 0, need = 1;
  for (const auto& pc : pcs) {
    box += (std::ceil(pc.width) + opt.padding) * (std::ceil(pc.height) + opt.padding);
    need = std::max(need, std::ceil(std::min(pc.width, pc.height)) + 1);
  }
  double side = std::max(need, std::sqrt(box));
  return static_cast<int>(std::ceil(side / opt.page_payload) * opt.page_payload);
}

// A packed atlas: the charts as packed and where they went.
struct PackedAtlas {
  double texels_per_unit = 0;  // of weight 1
  int width = 0;
  bool square = false;  // fitted to a size: as high as wide
  std::string bound;    // ", capped" or ", floored" when the sources' density left the bounds
  std::vector<detail::PackChart> charts;
  detail::PackResult packed;
};

// The starting density for a square atlas `width` texels wide: an optimistic fill, bounded so
// that no chart is longer than the atlas (a chart's bounding-box diagonal at one texel per unit
// bounds every rotation's extent).
double first_density_guess(const std::vector<Chart>& charts, const std::vector<double>& weight,
                           int width) {
  double area3d = 0;
  for (size_t i = 0; i < charts.size(); ++i) area3d += charts[i].area3d * weight[i] * weight[i];
  double tpu = std::sqrt(0.7 * static_cast<double>(width) * width / std::max(area3d, 1e-300));
  if (!(area3d > 0)) tpu = 1;
  double longest = 0;
  for (size_t i = 0; i < charts.size(); ++i) {
    const Chart& c = charts[i];
    if (c.degenerate || !(c.area3d > 0) || !(c.area_uv > 0)) continue;
    const auto [lo, hi] = bounds_of(c.uv);
    longest = std::max(longest, std::hypot(hi.x - lo.x, hi.y - lo.y) *
                                    std::sqrt(c.area3d / c.area_uv) * weight[i]);
  }
  if (longest > 0) tpu = std::min(tpu, (width - 2.0) / longest);
  return tpu;
}

// At `tpu` exactly: the atlas width follows from the charts, its height from the packing.
Expected<PackedAtlas> pack_at_density(const std::vector<Chart>& charts,
                                      const std::vector<double>& weight, double tpu,
                                      const UnwrapOptions& opt, int threads) {
  PackedAtlas best;
  best.texels_per_unit = tpu;
  best.charts = make_pack_charts(charts, weight, tpu, threads);
  best.width = atlas_width_for(best.charts, opt);
  if (static_cast<int64_t>(best.width) * best.width > opt.max_atlas_texels)
    return Error(ErrorCode::kResourceLimit, "atlas of " + std::to_string(best.width) +
                                                " texels wide at " + std::to_string(tpu) +
                                                " texels per unit exceeds the atlas limit");
  best.packed = detail::pack_charts(best.charts, best.width, opt.padding, threads);
  return best;
}

// Until the search has a fit and a miss it steps x1.3 / x0.7, except from a trial whose charts
// are estimated over twice the atlas width: chart sides scale with the density, so that trial
// sizes the next one. Fixed steps alone took all 16 trials on a texture repeated many times
// (Collada/teapots.DAE: 44 s of a 48 s bake).
double next_density_step(bool fits, int estimated_width, int width) {
  if (estimated_width > 2 * width) return std::clamp(0.97 * width / estimated_width, 0.05, 0.7);
  return fits ? 1.3 : 0.7;
}

// The atlas side in pages below which `count` charts cannot fit at any density: each takes at
// least a texel, and charts keep `padding` texels apart (a square grid of one-texel charts is
// the densest arrangement).
int gutter_pages(size_t count, const UnwrapOptions& opt) {
  const double side = std::sqrt(static_cast<double>(count)) * (1.0 + opt.padding) -
                      static_cast<double>(opt.padding);
  return std::max(1, static_cast<int>(std::ceil(side / opt.page_payload)));
}

// Why `count` charts do not fit `pages` x `pages` at any density searched.
Status charts_do_not_fit(size_t count, int pages, const UnwrapOptions& opt) {
  return Error(ErrorCode::kResourceLimit,
               std::to_string(count) + " charts do not fit in " + std::to_string(pages) +
                   " pages at any density (with --padding " + std::to_string(opt.padding) +
                   " between charts they need at least " +
                   std::to_string(gutter_pages(count, opt)) +
                   "): a larger --size or --max-size, or a smaller --padding");
}

// The densest scale at which the charts fit `pages` x `pages` (bisection on the scale).
Expected<PackedAtlas> pack_to_fit(const std::vector<Chart>& charts,
                                  const std::vector<double>& weight, int pages,
                                  const UnwrapOptions& opt, int threads) {
  PackedAtlas best;
  const int width = pages * opt.page_payload;
  if (static_cast<int64_t>(width) * width > opt.max_atlas_texels)
    return Error(ErrorCode::kResourceLimit,
                 "atlas of " + std::to_string(pages) + " pages exceeds the atlas limit");
  // Gutters alone over the atlas: no density fits, and each of the 16 trials would pack.
  if (gutter_pages(charts.size(), opt) > pages) return charts_do_not_fit(charts.size(), pages, opt);
  best.width = width;
  best.square = true;
  double lo = 0, hi = 0;
  double tpu = first_density_guess(charts, weight, width);
  bool have_fit = false;
  for (int iter = 0; iter < 16; ++iter) {
    auto trial = make_pack_charts(charts, weight, tpu, threads);
    int w = atlas_width_for(trial, opt);
    bool fits = false;
    detail::PackResult pr;
    if (w <= 2 * width) {  // hopeless widths are skipped: their charts cannot fit
      pr = detail::pack_charts(trial, width, opt.padding, threads, width);
      double max_w = 0;
      for (const auto& pc : trial) max_w = std::max(max_w, std::min(pc.width, pc.height));
      fits = !pr.overflow && pr.height <= width && max_w < width;
    }
    if (fits) {
      if (!have_fit || tpu > best.texels_per_unit) {
        best.texels_per_unit = tpu, best.charts = trial, best.packed = pr, have_fit = true;
      }
      lo = tpu;
    } else {
      hi = tpu;
    }
    if (lo > 0 && hi > 0 && hi / lo < 1.02) break;
    tpu = lo > 0 && hi > 0 ? std::sqrt(lo * hi) : tpu * next_density_step(fits, w, width);
  }
  if (!have_fit) return charts_do_not_fit(charts.size(), pages, opt);
  return best;
}

// pack_to_fit at plan.pages, or where the plan lets the atlas grow, at the first size from there
// (x1.5 a step, from the gutters' bound) that the charts fit, up to max_pages.
Expected<PackedAtlas> pack_to_fit_or_grow(const std::vector<Chart>& charts,
                                          const std::vector<double>& weight,
                                          const detail::DensityPlan& plan, const UnwrapOptions& opt,
                                          int threads) {
  int pages = plan.pages;
  if (plan.may_grow)
    pages = std::max(pages, std::min(gutter_pages(charts.size(), opt), plan.max_pages));
  for (;;) {
    auto fitted = pack_to_fit(charts, weight, pages, opt, threads);
    if (fitted.ok() && pages > plan.pages) fitted->bound = ", grown to fit its charts";
    if (fitted.ok() || !plan.may_grow || pages >= plan.max_pages) return fitted;
    pages = std::min(plan.max_pages, std::max(pages + 1, pages * 3 / 2));
  }
}

// Stage 4: chooses the texel density and packs, as the density plan says: at a given density,
// fitted to a size, or at the sources' density unless the atlas side would leave the bounds
// (then fitted to the bound it crossed).
Expected<PackedAtlas> choose_density_and_pack(const std::vector<Chart>& charts,
                                              const std::vector<double>& weight,
                                              const detail::DensityPlan& plan,
                                              const UnwrapOptions& opt, int threads) {
  using Mode = detail::DensityPlan::Mode;
  if (plan.mode == Mode::kExact)
    return pack_at_density(charts, weight, plan.texels_per_unit, opt, threads);
  if (plan.mode == Mode::kFitPages) return pack_to_fit_or_grow(charts, weight, plan, opt, threads);
  const int lo = plan.min_pages * opt.page_payload, hi = plan.max_pages * opt.page_payload;
  // The width estimate alone rules out an atlas far over the cap before any packing.
  int width = atlas_width_for(make_pack_charts(charts, weight, plan.texels_per_unit, threads), opt);
  if (width <= hi) {
    auto exact = pack_at_density(charts, weight, plan.texels_per_unit, opt, threads);
    if (!exact.ok()) return exact;
    int side = std::max(exact->width, exact->packed.height);
    if (side <= hi && !exact->packed.overflow && side >= lo) return exact;
    width = side;
  }
  auto fitted =
      pack_to_fit(charts, weight, width > hi ? plan.max_pages : plan.min_pages, opt, threads);
  if (fitted.ok()) fitted->bound = width > hi ? ", capped" : ", floored";
  return fitted;
}

// Each chart's density over the scene's: its object's or material's own density, 1 for most.
// Without a scene density (a fitted size and no textures), own densities are taken relative to
// the first guess for that size.
std::vector<double> chart_weights(const std::vector<Surface>& surfaces,
                                  const std::vector<Chart>& charts, const detail::DensityPlan& plan,
                                  const UnwrapOptions& opt) {
  std::vector<double> weight(charts.size(), 1.0);
  double base = plan.texels_per_unit;
  for (size_t i = 0; i < charts.size(); ++i) {
    const Surface& s = surfaces[charts[i].surface];
    const OwnDensity own = plan.wanted(s.material, s.node);
    if (own.scale > 0) weight[i] = own.scale;
    if (!(own.texels_per_unit > 0)) continue;
    if (!(base > 0))
      base = first_density_guess(charts, std::vector<double>(charts.size(), 1.0),
                                 plan.pages * opt.page_payload);
    weight[i] = own.texels_per_unit / base;
  }
  return weight;
}

// The area-weighted density each material's charts got.
std::vector<double> material_densities(const scene::Scene& in, const std::vector<Surface>& surfaces,
                                       const std::vector<Chart>& charts,
                                       const std::vector<double>& weight, double tpu) {
  std::vector<double> sum(in.materials.size(), 0.0), area(in.materials.size(), 0.0);
  for (size_t i = 0; i < charts.size(); ++i) {
    int m = surfaces[charts[i].surface].material;
    if (m < 0 || m >= static_cast<int>(sum.size()) || charts[i].degenerate) continue;
    sum[m] += charts[i].area3d * tpu * weight[i];
    area[m] += charts[i].area3d;
  }
  for (size_t m = 0; m < sum.size(); ++m) sum[m] = area[m] > 0 ? sum[m] / area[m] : 0.0;
  return sum;
}

// Per-surface sums for the stretch statistics.
struct StretchSums {
  double l2_num = 0, area3d = 0, area_uv = 0, linf = 0;
};

// Stage 5 for one surface: every chart-local vertex becomes a vertex per source vertex it came
// from; the primitive gets the atlas UVs as a new last UV set. Fills `tris` (one per face, from
// the float UVs actually written) and the surface's stretch sums.
void write_surface_uvs(const Surface& s, const std::vector<Chart>& charts,
                       const std::vector<uint32_t>& chart_ids, const PackedAtlas& atlas, double W,
                       double H, const scene::Primitive& src, const scene::TextureRef* normal_map,
                       scene::Primitive* dst, std::vector<AtlasTriangle>* tris, StretchSums* sums) {
  size_t faces = s.tri.size() / 3;
  std::vector<uint32_t> new_index(s.tri.size());
  std::vector<scene::Vec2> atlas_uv;
  std::vector<uint32_t> source_of;
  std::vector<int32_t> face_chart(faces, -1);
  for (uint32_t ci : chart_ids) {
    const Chart& c = charts[ci];
    const auto& pc = atlas.charts[ci];
    const auto& pl = atlas.packed.placements[ci];
    std::vector<scene::Vec2> local_uv(c.uv.size());
    for (size_t v = 0; v < c.uv.size(); ++v) {
      Vec2d p = detail::place_point(pc, pl, pc.points[v]);
      local_uv[v] = {static_cast<float>(p.x / W), static_cast<float>(1.0 - p.y / H)};
    }
    std::unordered_map<uint64_t, uint32_t> made;  // (local vertex, source vertex) -> new
    for (size_t i = 0; i < c.faces.size(); ++i) {
      uint32_t f = c.faces[i];
      face_chart[f] = static_cast<int32_t>(ci);
      for (int k = 0; k < 3; ++k) {
        uint32_t local = c.corner_local[3 * i + k];
        uint32_t source = src.indices[3 * f + k];
        uint64_t key = (static_cast<uint64_t>(local) << 32) | source;
        auto [it, inserted] = made.try_emplace(key, static_cast<uint32_t>(source_of.size()));
        if (inserted) {
          source_of.push_back(source);
          atlas_uv.push_back(local_uv[local]);
        }
        new_index[3 * f + k] = it->second;
      }
    }
  }
  // Float rounding of atlas UVs can flip or flatten a triangle that is a sliver in UV. Such
  // a triangle is repaired by moving its corners a few float ulps (far below the 1/16 texel
  // chart margin) in the direction that restores its orientation, keeping every triangle
  // around the moved corner correctly oriented.
  repair_rounding(s, new_index, W, H, &atlas_uv);
  // Rebuild the primitive's vertex arrays from source_of.
  auto gather = [&](const auto& from, auto& to) {
    if (from.empty()) return;
    std::remove_reference_t<decltype(to)> v(source_of.size());
    for (size_t i = 0; i < source_of.size(); ++i) v[i] = from[source_of[i]];
    to = std::move(v);
  };
  gather(src.positions, dst->positions);
  // Without normals of its own a primitive is shaded with normals smoothed over its shared
  // vertices, by the validator's reference, the transfer and the lighting alike; split along
  // the charts they would turn flat at every chart edge (a box lit with gradients in the
  // reference, flat in the bake). The unwrapped scene carries the source's.
  const bool own_normals = src.normals.size() == src.positions.size() || src.indices.empty();
  const std::vector<scene::Vec3> smoothed =
      own_normals ? std::vector<scene::Vec3>{} : scene::compute_normals(src);
  const std::vector<scene::Vec3>& normals = own_normals ? src.normals : smoothed;
  gather(normals, dst->normals);
  // The same for the frame a normal map is decoded in: derived after the split, a vertex on a
  // chart edge would average only its own chart's faces (a face alone in a chart, or one whose
  // source UVs are degenerate, would get an arbitrary tangent) where the reference, deriving it
  // on the source, averages them all.
  const bool derive_tangents = src.tangents.size() != src.positions.size() && normal_map &&
                               scene::texture_uv_set(src, *normal_map) &&
                               normals.size() == src.positions.size();
  gather(
      derive_tangents ? scene::compute_tangents(src, normals, normal_map->texcoord) : src.tangents,
      dst->tangents);
  gather(src.colors, dst->colors);
  dst->uvs.resize(src.uvs.size());
  for (size_t n = 0; n < src.uvs.size(); ++n) gather(src.uvs[n], dst->uvs[n]);
  dst->uvs.push_back(atlas_uv);
  dst->indices = new_index;
  // Atlas triangles and stretch against world space.
  tris->resize(faces);
  for (size_t f = 0; f < faces; ++f) {
    AtlasTriangle& t = (*tris)[f];
    Vec2d p[3];
    for (int k = 0; k < 3; ++k) {
      const auto& uv = atlas_uv[new_index[3 * f + k]];
      p[k] = {static_cast<double>(uv[0]) * W, static_cast<double>(uv[1]) * H};
      t.uv[2 * k] = p[k].x;
      t.uv[2 * k + 1] = p[k].y;
    }
    t.chart = face_chart[f];
    if (s.degenerate[f]) continue;
    // y down in the atlas: flip y so front faces are positive for the stretch formula.
    Vec2d q[3] = {{p[0].x, -p[0].y}, {p[1].x, -p[1].y}, {p[2].x, -p[2].y}};
    auto [l2sq, li] = triangle_stretch(s.pos[s.tri[3 * f]], s.pos[s.tri[3 * f + 1]],
                                       s.pos[s.tri[3 * f + 2]], q[0], q[1], q[2]);
    double a_uv = std::abs(cross2(q[0], q[1], q[2])) / 2;
    sums->l2_num += l2sq * s.area[f];
    sums->area3d += s.area[f];
    sums->area_uv += a_uv;
    if (std::isfinite(li)) sums->linf = std::max(sums->linf, li);
    t.stretch_l2 = static_cast<float>(std::sqrt(l2sq) * std::sqrt(a_uv / s.area[f]));
  }
}

// Stage 5: writes the atlas UVs of every surface into `result` and the stretch statistics.
void write_atlas_uvs(const scene::Scene& in, const std::vector<Surface>& surfaces,
                     const std::vector<Chart>& charts, const PackedAtlas& atlas,
                     UnwrapResult* result, int threads) {
  UnwrapStats& st = result->stats;
  const double W = st.atlas_width, H = st.atlas_height;
  std::vector<std::vector<uint32_t>> charts_of(surfaces.size());
  for (size_t c = 0; c < charts.size(); ++c)
    charts_of[charts[c].surface].push_back(static_cast<uint32_t>(c));
  std::vector<std::vector<AtlasTriangle>> tri_out(surfaces.size());
  std::vector<StretchSums> sums(surfaces.size());
  parallel_for(surfaces.size(), threads, [&](size_t si) {
    const Surface& s = surfaces[si];
    const scene::Primitive& src = in.meshes[s.source_mesh].primitives[s.out_prim];
    const bool has_material = src.material >= 0 && size_t(src.material) < in.materials.size();
    const scene::TextureRef* normal_map =
        has_material && in.materials[src.material].normal_texture.valid()
            ? &in.materials[src.material].normal_texture
            : nullptr;
    write_surface_uvs(s, charts, charts_of[si], atlas, W, H, src, normal_map,
                      &result->scene.meshes[s.out_mesh].primitives[s.out_prim], &tri_out[si],
                      &sums[si]);
  });
  result->triangles.resize(0);
  double num = 0, a3 = 0, auv = 0, li = 0;
  for (size_t si = 0; si < surfaces.size(); ++si) {
    num += sums[si].l2_num, a3 += sums[si].area3d, auv += sums[si].area_uv,
        li = std::max(li, sums[si].linf);
    for (auto& t : tri_out[si]) result->triangles.push_back(t);
  }
  double normalise = a3 > 0 ? std::sqrt(auv / a3) : 1.0;
  st.stretch_l2 = a3 > 0 ? std::sqrt(num / a3) * normalise : 1.0;
  st.stretch_linf = li * normalise;
  for (const auto& t : result->triangles)
    for (double v : t.uv)
      if (!std::isfinite(v)) {
        ++st.unmapped_faces;
        break;
      }
}

}  // namespace

Expected<UnwrapResult> unwrap_scene(const scene::Scene& in, const UnwrapOptions& opt) {
  VT_RETURN_IF_ERROR(check_options(opt));
  VT_RETURN_IF_ERROR(scene::validate_geometry(in));
  const int threads = thread_count(opt.threads);
  UnwrapResult result;
  UnwrapStats& st = result.stats;
  result.scene = in;

  // The density plan first: a bad density file fails before any work.
  auto plan = detail::plan_density(in, opt);
  if (!plan.ok()) return plan.status();

  auto t0 = Clock::now();
  auto surfaces = collect_surfaces(in, opt, threads, &result.scene);
  if (!surfaces.ok()) return surfaces.status();
  std::vector<Chart> charts = segment_surfaces(*surfaces, opt, threads);
  for (const auto& s : *surfaces) {
    st.faces += static_cast<int64_t>(s.tri.size() / 3);
    for (char d : s.degenerate) st.degenerate_faces += d;
  }
  if (st.faces == 0) return Error(ErrorCode::kInvalidArgument, "scene has no triangles to unwrap");
  st.seconds.segment = seconds_since(t0);

  t0 = Clock::now();
  charts = parameterize_until_valid(*surfaces, std::move(charts), opt, threads, &st);
  st.charts = static_cast<int64_t>(charts.size());
  st.seconds.parameterize = seconds_since(t0);

  t0 = Clock::now();
  const std::vector<double> weight = chart_weights(*surfaces, charts, *plan, opt);
  auto atlas = choose_density_and_pack(charts, weight, *plan, opt, threads);
  if (!atlas.ok()) return atlas.status();
  const int page = opt.page_payload;
  st.texels_per_unit = atlas->texels_per_unit;
  st.density_rule = plan->rule + atlas->bound;
  detail::report_density(
      *plan, in, material_densities(in, *surfaces, charts, weight, atlas->texels_per_unit), &st);
  st.atlas_width = atlas->width;
  st.atlas_height = std::max(page, (atlas->packed.height + page - 1) / page * page);
  if (atlas->square) st.atlas_height = atlas->width;  // a fitted size is a square
  st.pages_x = st.atlas_width / page;
  st.pages_y = st.atlas_height / page;
  st.seconds.pack = seconds_since(t0);

  t0 = Clock::now();
  write_atlas_uvs(in, *surfaces, charts, *atlas, &result, threads);
  st.seconds.output = seconds_since(t0);

  t0 = Clock::now();
  AtlasCheck check = check_atlas(result.triangles, st.atlas_width, st.atlas_height);
  st.utilisation = check.utilisation;
  st.flipped_triangles = check.flipped_triangles;
  st.overlapping_triangles = check.overlapping_triangles;
  st.overlapping_texels = check.overlapping_texels;
  st.seconds.check = seconds_since(t0);
  return result;
}

}  // namespace vt::unwrap
