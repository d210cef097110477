// The scene model shared by unwrap, transfer and the validation renderer: meshes made of
// triangle primitives, glTF metallic-roughness materials, images (by file or embedded), and a
// node hierarchy that flattens into mesh instances with world matrices.
// Import: glTF 2.0 (.gltf/.glb, KHR_draco_mesh_compression), Wavefront OBJ (+MTL), PLY, Draco
// (.drc). Export: glTF 2.0 binary (.glb), and text (.gltf + .bin) in scene/gltf_export.h.
// Errors name the file and the problem.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "common/status.h"

namespace vt::scene {

using Vec2 = std::array<float, 2>;
using Vec3 = std::array<float, 3>;
using Vec4 = std::array<float, 4>;
// Column-major 4x4 (glTF's order); double so that large world offsets keep their precision.
using Mat4 = std::array<double, 16>;

constexpr Mat4 kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

enum class WrapMode { kRepeat, kClampToEdge, kMirroredRepeat };
enum class FilterMode { kLinear, kNearest };
enum class AlphaMode { kOpaque, kMask, kBlend };

// KHR_texture_transform: uv' = T(offset) * R(rotation) * S(scale) * uv. Affine, so applying it
// to each vertex's UV and interpolating equals applying it per sample: the bake and the
// validator's reference both use apply() per vertex or per sample with the same result.
struct TextureTransform {
  Vec2 offset = {0, 0};
  float rotation = 0;  // radians, as in KHR_texture_transform
  Vec2 scale = {1, 1};

  bool identity() const {
    return offset[0] == 0 && offset[1] == 0 && rotation == 0 && scale[0] == 1 && scale[1] == 1;
  }
  // The 2x3 matrix (column-major linear part, then offset): uv' = m[0..3] * uv + m[4..5].
  std::array<double, 6> matrix() const;
  std::array<double, 2> apply(double u, double v) const;
};

// One texture slot of a material. image < 0 means the slot is unused.
struct TextureRef {
  int image = -1;    // index into Scene::images
  int texcoord = 0;  // which UV set of the primitive (TEXCOORD_n) it reads, after overrides
  WrapMode wrap_s = WrapMode::kRepeat;
  WrapMode wrap_t = WrapMode::kRepeat;
  FilterMode mag_filter = FilterMode::kLinear;  // the sampler's magFilter
  TextureTransform transform;
  bool valid() const { return image >= 0; }
};

// glTF 2.0 metallic-roughness material; factors multiply the textures as in the glTF spec.
struct Material {
  std::string name;
  Vec4 base_color_factor = {1, 1, 1, 1};  // linear RGBA
  TextureRef base_color_texture;          // sRGB RGBA
  float metallic_factor = 1.0f;
  float roughness_factor = 1.0f;
  TextureRef metallic_roughness_texture;  // G = roughness, B = metallic (linear)
  TextureRef normal_texture;              // tangent space, linear
  float normal_scale = 1.0f;
  TextureRef occlusion_texture;  // R = occlusion (may be the same image as metallic-roughness)
  float occlusion_strength = 1.0f;
  Vec3 emissive_factor = {0, 0, 0};
  float emissive_strength = 1.0f;  // KHR_materials_emissive_strength: multiplies the factor
  TextureRef emissive_texture;     // sRGB RGB
  AlphaMode alpha_mode = AlphaMode::kOpaque;
  float alpha_cutoff = 0.5f;
  bool double_sided = false;
  // Its own atlas density, texels per world unit (glTF extras.vtbake_texels_per_unit); 0 = the
  // scene's. A density file overrides it.
  double texels_per_unit = 0;

  // The five texture slots, for code that treats them alike.
  std::array<TextureRef*, 5> textures() {
    return {&base_color_texture, &metallic_roughness_texture, &normal_texture, &occlusion_texture,
            &emissive_texture};
  }
};

// An image a material uses: either a file (uri, resolved relative to the scene file's folder
// into `path`) or bytes embedded in the scene (a .glb buffer view or a data: URI).
struct Image {
  std::string name;
  std::string uri;   // as written in the source; empty when embedded
  std::string path;  // file to open: uri resolved against the scene's folder; empty when embedded
  std::string mime_type;       // "image/png", "image/jpeg", ... (may be empty for files)
  std::vector<uint8_t> bytes;  // embedded data; empty for files
  bool embedded() const { return path.empty(); }
  // Neither a file nor bytes (a glTF image without uri or bufferView): a missing texture.
  bool has_no_data() const { return path.empty() && bytes.empty(); }
  // The file extension embedded bytes are read as (".png", ".jpg", ".exr", ".webp"): readers
  // pick their decoder by name. The MIME type, else the bytes' magic, else ".png".
  const char* embedded_extension() const;
};

// Indexed triangles with per-vertex attributes. Every attribute array is either empty or has
// positions.size() entries; indices.size() is a multiple of 3.
struct Primitive {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;           // optional
  std::vector<Vec4> tangents;          // optional; w = handedness (+1 / -1)
  std::vector<std::vector<Vec2>> uvs;  // UV sets: uvs[n] is TEXCOORD_n (glTF convention, v down)
  std::vector<Vec4> colors;            // optional, linear RGBA
  std::vector<uint32_t> indices;       // triangle list
  int material = -1;                   // index into Scene::materials; -1 = default material

  size_t vertex_count() const { return positions.size(); }
  size_t triangle_count() const { return indices.size() / 3; }
};

struct Mesh {
  std::string name;
  std::vector<Primitive> primitives;
};

// A KHR_lights_punctual light, in the extension's units. It shines down its node's -Z axis
// (directional, spot) from its node's origin (point, spot).
enum class LightType { kDirectional, kPoint, kSpot };
struct Light {
  std::string name;
  LightType type = LightType::kPoint;
  Vec3 color = {1, 1, 1};  // linear RGB, multiplies the intensity
  // Directional: illuminance in lux (lm/m^2) on a surface facing the light. Point and spot:
  // luminous intensity in candela (lm/sr).
  float intensity = 1;
  // Point and spot: the distance at which the light reaches zero through the extension's
  // window clamp(1 - (d / range)^4, 0, 1) / d^2; infinity = unlimited (plain 1 / d^2).
  float range = std::numeric_limits<float>::infinity();
  float inner_cone_angle = 0;                        // spot: radians from the axis, full light
  float outer_cone_angle = 0.78539816339744830962f;  // spot: radians, no light beyond (pi / 4)
};

// A light where its node puts it in the world.
struct PlacedLight {
  int light = -1;  // index into Scene::lights
  int node = -1;
  std::array<double, 3> position = {0, 0, 0};    // the node's world origin
  std::array<double, 3> direction = {0, 0, -1};  // unit: where the light travels (node -Z)
};

struct Node {
  std::string name;
  Mat4 local = kIdentity;  // transform relative to the parent
  int mesh = -1;           // index into Scene::meshes, -1 = none
  int light = -1;          // index into Scene::lights, -1 = none
  std::vector<int> children;
  // Atlas density of its subtree (glTF extras.vtbake_texels_per_unit); 0 = inherited.
  double texels_per_unit = 0;
};

// One placement of a mesh in the world (a node with a mesh, after flattening the hierarchy).
struct Instance {
  int mesh = -1;
  int node = -1;
  Mat4 world = kIdentity;
};

struct Scene {
  std::string source_path;  // the file it was loaded from (for error messages)
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Image> images;
  std::vector<Node> nodes;
  std::vector<int> roots;     // nodes of the displayed scene
  std::vector<Light> lights;  // KHR_lights_punctual (placed by nodes)
  // What the importer ignored or repaired, one line each, naming the file and the feature
  // (e.g. "a.gltf: KHR_materials_sheen: sheen is not baked; the base layer is"). The CLI
  // prints them as warnings and the bake summary lists them.
  std::vector<std::string> warnings;

  // Every mesh instance in the node hierarchy below `roots`, depth first, with world matrices.
  // A node reached twice or a cycle is visited once (cycles are broken, never followed).
  std::vector<Instance> instances() const;
  // Every light a node below `roots` places, in the same order, with world position and
  // direction. Lights no displayed node names light nothing.
  std::vector<PlacedLight> placed_lights() const;
  size_t triangle_count() const;  // over meshes (not instances)
};

struct SceneLoadOptions {
  // Files the scene names (images, glTF buffers) must lie in the scene's folder tree: the
  // folder holding the scene's folder and everything below it (so "../textures/x.png" from
  // a sibling folder is fine, "../../x" and absolute paths elsewhere are not), symlinks
  // resolved. A file outside is an error naming the scene, the image and the path; true
  // reads it anyway (--allow-outside-paths). Missing files are reported as before.
  bool allow_outside_paths = false;
  // Folders to look in for an image that is not where the scene says (a game's shared texture
  // folder: TORCS's data/textures, FlightGear's Textures): in order, the name as written below
  // each, then its base name, letter case ignored, then another image extension. Images found
  // there may lie outside the scene's folder tree (--texture-path).
  std::vector<std::string> texture_folders;
};

// Loads .gltf, .glb, .obj, .ply or .drc (chosen by extension, case-insensitive). OBJ, PLY and
// DRC give one mesh under one root node. Non-finite positions are kept; callers that need
// finite geometry check it (see validate_geometry). Degenerate geometry (zero-area triangles,
// primitives with no area at all) is a warning with counts in Scene::warnings.
Expected<Scene> load_scene(const std::string& path, const SceneLoadOptions& options = {});

// Checks indices are in range and positions and UVs finite. The error names the mesh,
// primitive and vertex or triangle, e.g. "mesh 'Body' primitive 0: vertex 17 has a non-finite
// position" (a NaN UV would bake as black texels, so it is an error, never repaired).
Status validate_geometry(const Scene& scene);

// Writes the scene as glTF 2.0 binary. Embedded images are stored in the .glb; file images
// keep their uri (rewritten relative to the output's folder when possible).
Status save_glb(const Scene& scene, const std::string& path);

// Matrix helpers (column-major).
Mat4 multiply(const Mat4& a, const Mat4& b);
std::array<double, 3> transform_point(const Mat4& m, const Vec3& p);
// A normal carried by the transform (the inverse-transpose), unit length: it stays on the side
// of the surface it was on, also where m mirrors (glTF: the winding is then reversed, and a face
// normal taken from the moved triangle's edges points the other way; see mirrors()).
std::array<double, 3> transform_direction(const Mat4& m, const Vec3& d);
// Whether m's linear part has a negative determinant: it mirrors, and reverses the winding of
// the triangles it moves.
bool mirrors(const Mat4& m);
// The linear part applied to a vector and normalised (a direction carried by the transform,
// not a normal); {0, 0, 0} when the matrix collapses it.
std::array<double, 3> transform_vector(const Mat4& m, const Vec3& d);

// Checks a light's values against KHR_lights_punctual: finite, colour and intensity >= 0,
// range > 0 (or infinity), spot 0 <= inner < outer <= pi / 2. The message names the field
// ("intensity -2 is negative"); the importers add the file and the light.
Status check_light(const Light& light);

}  // namespace vt::scene
