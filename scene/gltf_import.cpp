// glTF 2.0 import (.gltf with external or data: buffers, .glb): the container, the document's
// version and extension rules, images, and the order of the steps. Every offset, size, index
// and type from the file is checked before use.
#include <cstring>
#include <nlohmann/json.hpp>

#include "scene/gltf_import_steps.h"
#include "scene/scene_io_util.h"

namespace vt::scene::detail {
namespace {

using json = nlohmann::json;

// nlohmann's message without its "[json.exception.parse_error.101] " prefix.
std::string json_message(const json::exception& e) {
  std::string what = e.what();
  size_t end = what.rfind("] ", 64);
  return what.rfind("[json.exception.", 0) == 0 && end != std::string::npos ? what.substr(end + 2)
                                                                            : what;
}

// Parses the JSON chunk of a .glb (into g->doc) and keeps its first BIN chunk.
Status parse_glb(const std::vector<uint8_t>& bytes, Gltf* g, std::vector<uint8_t>* bin) {
  if (bytes.size() < 12) return g->fail("truncated .glb header");
  uint32_t version = read_u32(&bytes[4]);
  if (version == 1)
    return Error(ErrorCode::kUnsupported,
                 g->path +
                     ": glTF 1.0 binary is not supported (convert it to glTF 2.0, e.g. with "
                     "`assimp export FILE out.glb -f glb2` from Debian's assimp-utils)");
  if (version != 2)
    return Error(ErrorCode::kUnsupported, g->path + ": .glb container version " +
                                              std::to_string(version) +
                                              " is not supported (vtbake reads version 2)");
  if (bytes.size() < 20) return g->fail("truncated .glb header");
  size_t total = std::min<size_t>(read_u32(&bytes[8]), bytes.size());
  size_t pos = 12;
  bool have_json = false;
  while (pos + 8 <= total) {
    size_t len = read_u32(&bytes[pos]);
    uint32_t type = read_u32(&bytes[pos + 4]);
    pos += 8;
    if (len > total - pos) return g->fail(".glb chunk runs past the end of the file");
    if (type == 0x4E4F534A && !have_json) {
      g->doc = json::parse(bytes.begin() + pos, bytes.begin() + pos + len);
      have_json = true;
    } else if (type == 0x004E4942 && bin->empty()) {
      bin->assign(bytes.begin() + pos, bytes.begin() + pos + len);
    }
    pos += (len + 3) & ~size_t{3};
  }
  if (!have_json) return g->fail(".glb has no JSON chunk");
  return Status::Ok();
}

Status load_images(const Gltf& g, const JsonFields& root, Scene* scene) {
  std::string folder = parent_folder(g.path);
  for (const JsonFields& im : root.objects("images")) {
    Image image;
    image.name = im.string("name");
    image.mime_type = im.string("mimeType");
    std::string uri = im.string("uri");
    int view = im.index("bufferView", "bufferViews");
    VT_RETURN_IF_ERROR(root.errors()->status());
    if (im.has("uri") && im.has("bufferView"))
      return g.fail(im.where() + ": an image has both a uri and a bufferView");
    if (!im.has("uri") && !im.has("bufferView")) {
      // No data at all: gltfpack writes this for an image it could not read. Kept as an
      // embedded image without bytes: the textures that name it are missing textures (refused,
      // or baked from their factors under --missing-textures warn), named by material slot.
      scene->warnings.push_back(g.path + ": " + im.where() +
                                ": neither uri nor bufferView (the image's data was left out)");
    } else if (uri.rfind("data:", 0) == 0) {
      auto data = decode_data_uri(uri, &image.mime_type);
      if (!data.ok()) return data.status().with_context(g.path + ": " + im.where());
      image.bytes = std::move(data).value();
    } else if (im.has("uri")) {
      image.uri = uri;
      image.path = folder + percent_decode(uri);
    } else {
      const uint8_t* data;
      size_t size;
      VT_RETURN_IF_ERROR(view_bytes(g, static_cast<size_t>(view), &data, &size, nullptr));
      image.bytes.assign(data, data + size);
    }
    scene->images.push_back(std::move(image));
  }
  return Status::Ok();
}

Status load_meshes(const Gltf& g, Scene* scene) {
  const json& meshes = g.doc.value("meshes", json::array());
  for (size_t mi = 0; mi < meshes.size(); ++mi) {
    Mesh mesh;
    mesh.name = meshes[mi].value("name", std::string());
    const json& prims = meshes[mi].value("primitives", json::array());
    for (size_t pi = 0; pi < prims.size(); ++pi) {
      std::string where = "mesh " + std::to_string(mi) + " primitive " + std::to_string(pi);
      auto prim = load_primitive(g, prims[pi], where);
      if (!prim.ok()) return prim.status();
      mesh.primitives.push_back(std::move(prim).value());
    }
    scene->meshes.push_back(std::move(mesh));
  }
  return Status::Ok();
}

// Everything after the container: the steps in the order their inputs need.
Expected<Scene> load_document(Gltf& g, std::vector<uint8_t>* glb_bin) {
  if (!g.doc.is_object()) return g.fail("not a glTF JSON object");
  Scene scene;
  scene.source_path = g.path;
  Warnings& warnings = scene.warnings;
  VT_RETURN_IF_ERROR(check_version(g, &warnings));
  FieldErrors errors(g);
  JsonFields root(&errors, g.doc, "");
  VT_RETURN_IF_ERROR(check_required_extensions(root));
  // The JSON-only steps first: a bad document is refused before any buffer is read.
  check_mesh_fields(root, &warnings);
  ExtensionUses uses;
  scene.materials = load_materials(root, &uses, &warnings);
  VT_RETURN_IF_ERROR(errors.status());
  VT_RETURN_IF_ERROR(load_nodes(root, &scene));
  VT_RETURN_IF_ERROR(load_lights(root, &scene));
  warn_about_extensions(root, uses, &warnings);
  VT_RETURN_IF_ERROR(errors.status());
  VT_RETURN_IF_ERROR(load_buffers(&g, glb_bin));
  VT_RETURN_IF_ERROR(load_images(g, root, &scene));
  VT_RETURN_IF_ERROR(load_meshes(g, &scene));
  return scene;
}

}  // namespace

Expected<Scene> load_gltf(const std::string& path, const SceneLoadOptions& options) {
  VT_ASSIGN_OR_RETURN(auto bytes, read_file(path));
  Gltf g;
  g.path = path;
  g.options = options;
  std::vector<uint8_t> bin;
  bool glb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  try {
    if (glb)
      VT_RETURN_IF_ERROR(parse_glb(bytes, &g, &bin));
    else
      g.doc = json::parse(bytes.begin(), bytes.end());
  } catch (const json::exception& e) {
    return g.fail("malformed JSON: " + json_message(e));
  }
  try {
    return load_document(g, glb ? &bin : nullptr);
  } catch (const json::exception& e) {
    // The checks above cover the fields the importer reads; this is the net under them.
    return g.fail("unexpected glTF JSON: " + json_message(e));
  }
}

}  // namespace vt::scene::detail
