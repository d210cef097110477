// Helpers shared by the scene importers and the exporter (internal to vt_scene).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/status.h"
#include "scene/scene.h"

namespace vt::scene::detail {

Expected<std::vector<uint8_t>> read_file(const std::string& path);
std::string lower_extension(const std::string& path);
std::string parent_folder(const std::string& path);  // "" or ends with '/'
// Decodes a data: URI ("data:<mime>;base64,<payload>"); mime receives the media type.
Expected<std::vector<uint8_t>> decode_data_uri(const std::string& uri, std::string* mime);
std::string base64_encode(const uint8_t* data, size_t size);
std::string percent_decode(const std::string& uri);

// The file an exporter meant by `written` (relative to `folder`, "" or ending in '/'):
// backslashes read as '/', a leading "./" dropped; when that file does not exist, a
// case-insensitive match in the same folders, then the base name next to `folder` (an absolute
// or Windows path from the exporter's machine). `note` receives what was substituted (empty
// when the file was found as written). When nothing matches, the path as written resolved
// against `folder` is returned (the caller reports it missing).
std::string resolve_written_path(const std::string& folder, const std::string& written,
                                 std::string* note);

Expected<Scene> load_gltf(const std::string& path);
Expected<Scene> load_obj(const std::string& path);
Expected<Scene> load_ply(const std::string& path);
Expected<Scene> load_drc(const std::string& path);
// Any other format assimp reads (FBX, COLLADA, 3DS, ...; glTF 1.0).
Expected<Scene> load_assimp(const std::string& path);
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
