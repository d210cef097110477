// glTF 2.0 nodes, their transforms, the node graph's rules (a forest: no cycle, no node with
// two parents) and the displayed scene's roots.
#include <algorithm>

#include "scene/gltf_import_steps.h"

namespace vt::scene::detail {

namespace {

Mat4 node_matrix(const JsonFields& n) {
  std::vector<double> matrix = n.numbers("matrix", 16);
  std::vector<double> t = n.numbers("translation", 3), s = n.numbers("scale", 3),
                      q = n.numbers("rotation", 4);
  if (!matrix.empty()) {
    Mat4 m;
    std::copy(matrix.begin(), matrix.end(), m.begin());
    return m;
  }
  if (t.empty()) t = {0, 0, 0};
  if (s.empty()) s = {1, 1, 1};
  if (q.empty()) q = {0, 0, 0, 1};
  double x = q[0], y = q[1], z = q[2], w = q[3];
  double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),
                 2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                 2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y)};
  Mat4 m = kIdentity;
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row) m[c * 4 + row] = r[c * 3 + row] * s[c];
  for (int i = 0; i < 3; ++i) m[12 + i] = t[i];
  return m;
}

// Each node's parent (-1 for none); fails on a self-reference or a second parent.
std::vector<int> parents(const Gltf& g, const std::vector<Node>& nodes, FieldErrors* errors) {
  std::vector<int> parent(nodes.size(), -1);
  auto name = [&](int i) { return entry_name(g, "nodes", static_cast<size_t>(i)); };
  for (size_t p = 0; p < nodes.size() && !errors->failed(); ++p)
    for (int c : nodes[p].children) {
      std::string where = "nodes[" + std::to_string(p) + "].children";
      if (c == static_cast<int>(p))
        errors->fail(ErrorCode::kCorrupt, where, name(c) + " lists itself as a child");
      else if (parent[c] == static_cast<int>(p))
        errors->fail(ErrorCode::kCorrupt, where, name(c) + " is listed twice");
      else if (parent[c] >= 0)
        errors->fail(ErrorCode::kCorrupt, where,
                     name(c) + " has two parents, " + name(parent[c]) + " and " +
                         name(static_cast<int>(p)) + " (the node graph must be a forest)");
      if (errors->failed()) break;
      parent[c] = static_cast<int>(p);
    }
  return parent;
}

// With one parent per node, a cycle is a chain of parents that comes back to itself.
void check_no_cycle(const Gltf& g, const std::vector<int>& parent, FieldErrors* errors) {
  enum : char { kUnseen, kOnPath, kDone };
  std::vector<char> state(parent.size(), kUnseen);
  for (size_t start = 0; start < parent.size(); ++start) {
    std::vector<int> path;
    int n = static_cast<int>(start);
    for (; n >= 0 && state[n] == kUnseen; n = parent[n]) {
      state[n] = kOnPath;
      path.push_back(n);
    }
    if (n >= 0 && state[n] == kOnPath) {
      // path runs child -> parent; print the cycle parent -> child, as "children" reads.
      std::string cycle = entry_name(g, "nodes", n);
      for (auto it = path.rbegin(); it != path.rend() && *it != n; ++it)
        cycle += " -> " + entry_name(g, "nodes", *it);
      cycle += " -> " + entry_name(g, "nodes", n);
      errors->fail(ErrorCode::kCorrupt, "nodes", "the node graph has a cycle: " + cycle);
      return;
    }
    for (int p : path) state[p] = kDone;
  }
}

}  // namespace

Status load_nodes(const JsonFields& root, Scene* scene) {
  FieldErrors* errors = root.errors();
  const Gltf& g = errors->gltf();
  for (const JsonFields& n : root.objects("nodes")) {
    Node node;
    node.name = n.string("name");
    node.local = node_matrix(n);
    node.mesh = n.index("mesh", "meshes");
    node.children = n.indices("children", "nodes");
    node.texels_per_unit = density_extra(n);
    n.index("skin", "skins");
    n.index("camera", "cameras");
    scene->nodes.push_back(std::move(node));
  }
  VT_RETURN_IF_ERROR(errors->status());
  std::vector<int> parent = parents(g, scene->nodes, errors);
  if (!errors->failed()) check_no_cycle(g, parent, errors);
  VT_RETURN_IF_ERROR(errors->status());

  std::vector<JsonFields> scenes = root.objects("scenes");
  for (const JsonFields& s : scenes) s.indices("nodes", "nodes");
  int which = root.has("scene") ? root.index("scene", "scenes") : 0;
  if (which >= 0 && which < static_cast<int>(scenes.size())) {
    JsonFields shown = scenes[which];
    scene->roots = shown.indices("nodes", "nodes");
    std::vector<char> listed(scene->nodes.size(), 0);
    for (int r : scene->roots) {
      if (parent[r] >= 0)
        shown.fail("nodes", entry_name(g, "nodes", r) + " is not a root node (" +
                                entry_name(g, "nodes", parent[r]) + " lists it as a child)");
      else if (listed[r])
        shown.fail("nodes", entry_name(g, "nodes", r) + " is listed twice");
      listed[r] = 1;
    }
  } else if (!errors->failed()) {
    // No scene: every node that is nobody's child is a root.
    for (size_t i = 0; i < parent.size(); ++i)
      if (parent[i] < 0) scene->roots.push_back(static_cast<int>(i));
  }
  return errors->status();
}

}  // namespace vt::scene::detail
