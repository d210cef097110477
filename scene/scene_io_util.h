// Helpers shared by the scene importers and the exporter (internal to vt_scene).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/status.h"
#include "scene/scene.h"

struct aiColor3D;  // assimp's, for embedded_texels_png
struct aiTexture;

namespace vt::scene::detail {

// kInvalidArgument when something other than a regular file is at `path` (never opened: a
// FIFO would block); Ok when it is a file or nothing is there (opening reports that).
Status check_regular_file(const std::string& path);
// The whole file; refuses what is not a regular file.
Expected<std::vector<uint8_t>> read_file(const std::string& path);
// The file's text in UTF-8: a UTF-8 BOM is dropped, UTF-16 (a BOM, or ASCII with every other
// byte zero) is converted, and text that is not valid UTF-8 is read as Latin-1 (`note` then
// says so; empty otherwise). The error names `path` (odd-length UTF-16).
Expected<std::string> decode_text(const std::vector<uint8_t>& bytes, const std::string& path,
                                  std::string* note);
std::string lower_extension(const std::string& path);
// The little-endian 32-bit value at `p` (glTF's binary chunks and buffers, model headers), on
// any host.
inline uint32_t read_u32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}
std::string parent_folder(const std::string& path);  // "" or ends with '/'
// Decodes a data: URI ("data:<mime>;base64,<payload>"); mime receives the media type.
Expected<std::vector<uint8_t>> decode_data_uri(const std::string& uri, std::string* mime);
std::string base64_encode(const uint8_t* data, size_t size);
std::string percent_decode(const std::string& uri);
// A relative path as a URI: bytes other than unreserved characters and '/' as %XX (spaces,
// '#', '%', non-ASCII file names), so that percent_decode gives the path back.
std::string percent_encode_path(const std::string& path);

// The file an exporter meant by `written` (relative to `folder`, "" or ending in '/'):
// backslashes read as '/', a leading "./" dropped; when that file does not exist, a
// case-insensitive match in the same folders, then the base name next to `folder` (an absolute
// or Windows path from the exporter's machine), then in a textures folder beside the scene
// (textures/, tex/, images/, maps/, letter case ignored: FlightGear's Textures/), then any of
// these with another image extension (a Quake 3 shader name, a .tga converted to .jpg). `note`
// receives what was substituted (empty
// when the file was found as written). When nothing matches, the path as written resolved
// against `folder` is returned (the caller reports it missing).
std::string resolve_written_path(const std::string& folder, const std::string& written,
                                 std::string* note);

// Game model files assimp reads without checking their indices and offsets, checked before it
// does (scene/assimp_import.cpp): kCorrupt naming the file and what is wrong; else the names the
// Cube 2 engine gives the meshes assimp makes, in its order (MD5: the `// meshes: NAME` comment
// of each mesh block with vertices and triangles; IQM: the mesh table's names), empty where the
// file is not read so (unreadable, or a file assimp refuses by itself).
Expected<std::vector<std::string>> md5_mesh_names(const std::string& path);
Expected<std::vector<std::string>> iqm_mesh_names(const std::string& path);

// Cube 2 engine games (Sauerbraten, Tesseract, Red Eclipse) name a model's textures in a config
// beside it (`iqm.cfg`, `md5.cfg`, `md3.cfg`, `obj.cfg`, `smd.cfg` by the model's format):
// `iqmskin * DIFFUSE [masks]` and `iqmbumpmap * NORMAL` (load modifiers such as `<dds>`
// dropped, paths relative to the config) become every material's base colour and normal
// textures, with a warning naming them, unless the config's `iqmload` names another model.
// `iqmskin NAME ...` gives the mesh the engine calls NAME its textures (MD5: the mesh block's
// `// meshes: NAME` comment; IQM: the mesh's name; MD3: the surface's), where the importer made
// a material per mesh (assimp does for all three); other lines naming meshes are counted in the
// warning, not applied.
void apply_cube2_config(const std::string& model_path, Scene& scene);

// The folder holding the scene's folder (absolute, symlinks resolved): the tree a scene's
// files must lie in (SceneLoadOptions::allow_outside_paths).
std::string scene_folder_tree(const std::string& scene_path);
// Ok when `file` is missing, inside scene_folder_tree(scene_path) after resolving symlinks, or
// options allow outside paths; else kInvalidArgument naming the scene, `what` (the image or
// buffer) and the path.
Status check_inside_scene_tree(const std::string& scene_path, const std::string& file,
                               const std::string& what, const SceneLoadOptions& options);
// A primitive without the UV set its material's textures read (faces without `vt` under an
// OBJ `map_Kd`; gl-117's 3DS trucks, Maya cubes under a textured material) cannot sample them:
// it gets a copy of the material without those textures, so it bakes from the factors, with a
// warning, instead of the whole model being refused. The copy keeps the name (density files
// and messages use it). For the formats that do not forbid it (glTF does).
void untexture_surfaces_without_uvs(Scene* scene);
// Appends one warning per kind of degenerate geometry with counts: zero-area triangles,
// primitives with no area at all (they get no texels).
void warn_about_degenerate_geometry(Scene* scene);

Expected<Scene> load_gltf(const std::string& path, const SceneLoadOptions& options);
Expected<Scene> load_obj(const std::string& path, const SceneLoadOptions& options);
Expected<Scene> load_ply(const std::string& path);
Expected<Scene> load_drc(const std::string& path);
// AC3D (.ac, .ac3d) and ACC (.acc, TORCS's AC3D with triangle strips and texture layers).
Expected<Scene> load_ac3d(const std::string& path);
// Any other format assimp reads (FBX, COLLADA, 3DS, ...; glTF 1.0).
Expected<Scene> load_assimp(const std::string& path);
// An uncompressed assimp texture (aiTexels, BGRA, rows top first: Half-Life's and Quake's
// palette skins) as an embedded PNG, RGB when every texel is opaque; with `colour_key` (a
// Half-Life masked texture's transparent colour, 0-1 or 0-255) texels of that colour get alpha 0.
Expected<Image> embedded_texels_png(const aiTexture& t, const std::string& name,
                                    const aiColor3D* colour_key = nullptr);
bool assimp_reads(const std::string& extension);  // lower case, without the dot
// Decodes a Draco-compressed mesh into a primitive. attribute_ids maps glTF attribute names
// (POSITION, NORMAL, TEXCOORD_n, COLOR_0, TANGENT) to Draco unique ids; when empty the Draco
// attribute types are used instead (a .drc or PLY file).
struct DracoAttribute {
  std::string name;
  int unique_id;
};
Expected<Primitive> decode_draco(const uint8_t* data, size_t size,
                                 const std::vector<DracoAttribute>& attribute_ids);

// A scene with one mesh holding `primitive` under one root node.
Scene single_mesh_scene(const std::string& path, std::string name, std::vector<Primitive> prims,
                        std::vector<Material> materials = {});

}  // namespace vt::scene::detail
