#include "bake/unwrap_cache.h"

#include <xxhash.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <span>
#include <type_traits>
#include <vector>

#include "bake/content_key.h"
#include "bake/image_source.h"
#include "bake/unwrap/texel_density.h"
#include "format/atomic_output.h"
#include "format/zstd_frame.h"

namespace vt {
namespace {

constexpr char kMagic[8] = {'V', 'T', 'U', 'N', 'W', 'R', 'A', 'P'};
constexpr uint32_t kVersion = 2;  // 2: UnwrapStats::objects
constexpr int kZstdLevel = 1;     // fast: every bake writes it
// A packed result larger than this is not believed (a damaged size field).
constexpr uint64_t kMaxPacked = uint64_t(1) << 36;

struct Header {
  char magic[8];
  uint32_t version, reserved;
  uint64_t key, packed, stored, checksum;  // checksum: XXH3 of the packed bytes
};

// Fields appended in order; strings and arrays with their length first.
class Packer {
 public:
  template <typename T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const uint8_t*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof v);
  }
  void put(const std::string& s) {
    put(uint64_t(s.size()));
    bytes.insert(bytes.end(), s.begin(), s.end());
  }
  template <typename T>
  void put(const std::vector<T>& v) {
    put(uint64_t(v.size()));
    if constexpr (std::is_trivially_copyable_v<T>) {
      const auto* p = reinterpret_cast<const uint8_t*>(v.data());
      bytes.insert(bytes.end(), p, p + v.size() * sizeof(T));
    } else {
      for (const T& e : v) put(e);
    }
  }
  std::vector<uint8_t> bytes;
};

// The same fields read back; every length is checked against what is left, and the first
// failure sticks (ok() false).
class Unpacker {
 public:
  explicit Unpacker(std::span<const uint8_t> in) : in_(in) {}
  template <typename T>
  void get(T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (!take(sizeof v)) return;
    std::memcpy(&v, in_.data() + at_ - sizeof v, sizeof v);
  }
  void get(std::string& s) {
    const uint64_t n = length(1);
    if (!take(n)) return;
    s.assign(reinterpret_cast<const char*>(in_.data() + at_ - n), n);
  }
  template <typename T>
  void get(std::vector<T>& v) {
    const uint64_t n = length(std::is_trivially_copyable_v<T> ? sizeof(T) : 1);
    if (!ok_) return;
    v.resize(n);
    if constexpr (std::is_trivially_copyable_v<T>) {
      if (take(n * sizeof(T)))
        std::memcpy(v.data(), in_.data() + at_ - n * sizeof(T), n * sizeof(T));
    } else {
      for (T& e : v) get(e);
    }
  }
  bool ok() const { return ok_; }
  bool done() const { return ok_ && at_ == in_.size(); }

 private:
  // A length whose elements (at least `min_bytes` each) fit in what is left.
  uint64_t length(uint64_t min_bytes) {
    uint64_t n = 0;
    get(n);
    if (ok_ && n > (in_.size() - at_) / min_bytes) ok_ = false;
    return ok_ ? n : 0;
  }
  bool take(uint64_t n) {
    if (!ok_ || n > in_.size() - at_) return ok_ = false;
    at_ += n;
    return true;
  }
  std::span<const uint8_t> in_;
  size_t at_ = 0;
  bool ok_ = true;
};

// Every field of the statistics (unwrap.h UnwrapStats; a field added there is added here).
void put_stats(Packer& p, const unwrap::UnwrapStats& s) {
  p.put(s.faces), p.put(s.degenerate_faces), p.put(s.charts), p.put(s.split_rounds);
  p.put(s.charts_split), p.put(s.atlas_width), p.put(s.atlas_height), p.put(s.pages_x);
  p.put(s.pages_y), p.put(s.texels_per_unit), p.put(s.source_texels_per_unit);
  p.put(s.density_rule), p.put(s.density_file);
  p.put(uint64_t(s.materials.size()));
  for (const auto& m : s.materials)
    p.put(m.name), p.put(m.source), p.put(m.requested), p.put(m.requested_scale), p.put(m.achieved);
  p.put(uint64_t(s.objects.size()));
  for (const auto& o : s.objects) p.put(o.name), p.put(o.source), p.put(o.scale);
  p.put(s.warnings);
  p.put(s.utilisation), p.put(s.stretch_l2), p.put(s.stretch_linf), p.put(s.flipped_triangles);
  p.put(s.overlapping_triangles), p.put(s.overlapping_texels), p.put(s.unmapped_faces);
  p.put(s.seconds);
}

void get_stats(Unpacker& u, unwrap::UnwrapStats& s) {
  u.get(s.faces), u.get(s.degenerate_faces), u.get(s.charts), u.get(s.split_rounds);
  u.get(s.charts_split), u.get(s.atlas_width), u.get(s.atlas_height), u.get(s.pages_x);
  u.get(s.pages_y), u.get(s.texels_per_unit), u.get(s.source_texels_per_unit);
  u.get(s.density_rule), u.get(s.density_file);
  uint64_t n = 0;
  u.get(n);
  if (!u.ok() || n > (uint64_t(1) << 24)) return;
  s.materials.resize(n);
  for (auto& m : s.materials)
    u.get(m.name), u.get(m.source), u.get(m.requested), u.get(m.requested_scale), u.get(m.achieved);
  u.get(n);
  if (!u.ok() || n > (uint64_t(1) << 24)) return;
  s.objects.resize(n);
  for (auto& o : s.objects) u.get(o.name), u.get(o.source), u.get(o.scale);
  u.get(s.warnings);
  u.get(s.utilisation), u.get(s.stretch_l2), u.get(s.stretch_linf), u.get(s.flipped_triangles);
  u.get(s.overlapping_triangles), u.get(s.overlapping_texels), u.get(s.unmapped_faces);
  u.get(s.seconds);
}

void put_primitive(Packer& p, const scene::Primitive& prim) {
  p.put(prim.positions), p.put(prim.normals), p.put(prim.tangents), p.put(prim.uvs);
  p.put(prim.colors), p.put(prim.indices), p.put(prim.material);
}

void get_primitive(Unpacker& u, scene::Primitive& prim) {
  u.get(prim.positions), u.get(prim.normals), u.get(prim.tangents), u.get(prim.uvs);
  u.get(prim.colors), u.get(prim.indices), u.get(prim.material);
}

// A stored result fits the scene it is rebuilt on: as many nodes, mesh and material indices in
// range, every index below its primitive's vertex count, every vertex array as long as the
// positions.
bool fits(const unwrap::UnwrapResult& r, const scene::Scene& scene) {
  const auto& meshes = r.scene.meshes;
  for (const scene::Node& n : r.scene.nodes)
    if (n.mesh < -1 || n.mesh >= int64_t(meshes.size())) return false;
  for (const scene::Mesh& m : meshes)
    for (const scene::Primitive& p : m.primitives) {
      const size_t v = p.positions.size();
      if (p.material < -1 || p.material >= int64_t(scene.materials.size())) return false;
      if ((!p.normals.empty() && p.normals.size() != v) ||
          (!p.tangents.empty() && p.tangents.size() != v) ||
          (!p.colors.empty() && p.colors.size() != v) || p.indices.size() % 3 != 0)
        return false;
      for (const auto& set : p.uvs)
        if (set.size() != v) return false;
      for (uint32_t i : p.indices)
        if (i >= v) return false;
    }
  return true;
}

}  // namespace

uint64_t unwrap_cache_key(const scene::Scene& scene, const unwrap::UnwrapOptions& o) {
  KeyStream k;
  k.add(std::string("unwrap cache 1 " VTBAKE_VERSION)), k.add(code_identity());
  k.add(o.texels_per_unit), k.add(o.size_pages), k.add(o.page_payload), k.add(o.padding);
  k.add(o.method), k.add(o.share_instances), k.add(o.max_chart_angle_deg);
  k.add(o.max_chart_stretch), k.add(o.max_split_rounds), k.add(o.max_atlas_texels);
  k.add(o.max_size_pages), k.add(o.min_size_pages);
  k.add(uint64_t(scene.meshes.size()));
  for (const scene::Mesh& mesh : scene.meshes) {
    k.add(mesh.name), k.add(uint64_t(mesh.primitives.size()));
    for (const scene::Primitive& p : mesh.primitives) add_primitive(k, p);
  }
  k.add(uint64_t(scene.materials.size()));
  for (const scene::Material& m : scene.materials) add_material(k, m);
  // An image as the unwrap reads it: its size from the header (the sources' density) and the
  // label its warnings name; its texels never.
  k.add(uint64_t(scene.images.size()));
  for (const scene::Image& image : scene.images) {
    k.add(image.name), k.add(image.uri), k.add(image.path), k.add(image.mime_type);
    auto size = unwrap::image_size(image);
    k.add(uint8_t(size.ok()));
    k.add(size.ok() ? *size : std::array<int, 2>{0, 0});
    if (!size.ok()) k.add(size.status().message());
  }
  k.add(uint64_t(scene.nodes.size()));
  for (const scene::Node& n : scene.nodes)
    k.add(n.name), k.add(n.local), k.add(n.mesh), k.add(n.children), k.add(n.texels_per_unit);
  k.add(scene.roots);
  // The density file the unwrap reads: its path (the report names it) and content.
  const std::string density = unwrap::density_file_to_read(scene, o.density_file);
  std::error_code ec;
  const bool has_density = !density.empty() && std::filesystem::exists(density, ec);
  k.add(density), k.add(uint8_t(has_density));
  if (has_density) {
    auto h = hash_file(density);
    k.add(uint8_t(h.ok())), k.add(h.ok() ? *h : uint64_t(0));
  }
  return k.digest();
}

std::optional<unwrap::UnwrapResult> read_unwrap_cache(const std::string& path, uint64_t key,
                                                      const scene::Scene& scene) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return std::nullopt;
  Header h{};
  if (!f.read(reinterpret_cast<char*>(&h), sizeof h) || std::memcmp(h.magic, kMagic, 8) != 0 ||
      h.version != kVersion || h.key != key || h.packed > kMaxPacked || h.stored > kMaxPacked)
    return std::nullopt;
  std::vector<uint8_t> frame(h.stored);
  if (!f.read(reinterpret_cast<char*>(frame.data()), std::streamsize(frame.size())) ||
      f.peek() != std::char_traits<char>::eof())
    return std::nullopt;
  std::vector<uint8_t> packed(h.packed);
  if (!zstd_decompress_exact(frame, packed).ok() ||
      XXH3_64bits(packed.data(), packed.size()) != h.checksum)
    return std::nullopt;
  unwrap::UnwrapResult r;
  r.scene = scene;
  Unpacker u(packed);
  get_stats(u, r.stats);
  uint64_t meshes = 0;
  u.get(meshes);
  if (!u.ok() || meshes > packed.size()) return std::nullopt;
  r.scene.meshes.assign(meshes, {});
  for (scene::Mesh& m : r.scene.meshes) {
    uint64_t prims = 0;
    u.get(m.name), u.get(prims);
    if (!u.ok() || prims > packed.size()) return std::nullopt;
    m.primitives.resize(prims);
    for (scene::Primitive& p : m.primitives) get_primitive(u, p);
  }
  std::vector<int> node_mesh;
  u.get(node_mesh);
  if (!u.ok() || node_mesh.size() != r.scene.nodes.size()) return std::nullopt;
  for (size_t i = 0; i < node_mesh.size(); ++i) r.scene.nodes[i].mesh = node_mesh[i];
  uint64_t triangles = 0;
  u.get(triangles);
  if (!u.ok() || triangles > packed.size()) return std::nullopt;
  r.triangles.resize(triangles);
  for (unwrap::AtlasTriangle& t : r.triangles) u.get(t.uv), u.get(t.chart), u.get(t.stretch_l2);
  if (!u.done() || !fits(r, scene)) return std::nullopt;
  return r;
}

Status write_unwrap_cache(const std::string& path, uint64_t key, const scene::Scene& scene,
                          const unwrap::UnwrapResult& r) {
  if (r.scene.nodes.size() != scene.nodes.size())
    return Error(ErrorCode::kInternal, "unwrap cache: the result has other nodes than the scene");
  Packer p;
  put_stats(p, r.stats);
  p.put(uint64_t(r.scene.meshes.size()));
  for (const scene::Mesh& m : r.scene.meshes) {
    p.put(m.name), p.put(uint64_t(m.primitives.size()));
    for (const scene::Primitive& prim : m.primitives) put_primitive(p, prim);
  }
  std::vector<int> node_mesh;
  for (const scene::Node& n : r.scene.nodes) node_mesh.push_back(n.mesh);
  p.put(node_mesh);
  p.put(uint64_t(r.triangles.size()));
  for (const unwrap::AtlasTriangle& t : r.triangles)
    p.put(t.uv), p.put(t.chart), p.put(t.stretch_l2);
  std::vector<uint8_t> frame;
  VT_RETURN_IF_ERROR(zstd_compress(p.bytes, kZstdLevel, frame));
  Header h{};
  std::memcpy(h.magic, kMagic, 8);
  h.version = kVersion, h.key = key, h.packed = p.bytes.size(), h.stored = frame.size();
  h.checksum = XXH3_64bits(p.bytes.data(), p.bytes.size());
  std::string bytes(reinterpret_cast<const char*>(&h), sizeof h);
  bytes.append(reinterpret_cast<const char*>(frame.data()), frame.size());
  // Staged beside the target and renamed when complete, as every output (format/atomic_output.h).
  return write_output_bytes(path, bytes).with_context("unwrap cache");
}

}  // namespace vt
