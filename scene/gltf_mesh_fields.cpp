// The fields of buffers, bufferViews, accessors and meshes, checked before the accessor and
// primitive readers use them: types, index ranges, and the features baked in a fixed pose.
#include "scene/gltf_import_steps.h"

namespace vt::scene::detail {

namespace {

void check_buffers(const JsonFields& root) {
  for (const JsonFields& b : root.objects("buffers")) {
    b.string("uri");
    b.count("byteLength", 0);
  }
  for (const JsonFields& v : root.objects("bufferViews")) {
    if (!v.has("buffer")) v.fail("buffer", "expected a buffer index");
    v.index("buffer", "buffers");
    v.count("byteOffset", 0);
    v.count("byteLength", 0);
    v.count("byteStride", 0);
  }
  for (const JsonFields& a : root.objects("accessors")) {
    a.index("bufferView", "bufferViews");
    a.count("byteOffset", 0);
    a.count("componentType", 0);
    a.count("count", 0);
    a.string("type");
    a.boolean("normalized", false);
    a.object("sparse");
  }
}

// Returns whether the primitive has morph targets.
bool check_primitive(const JsonFields& p) {
  JsonFields attributes = p.object("attributes");
  for (const std::string& name : attributes.keys()) attributes.index(name.c_str(), "accessors");
  p.index("indices", "accessors");
  p.index("material", "materials");
  if (p.count("mode", 4) > 6) p.fail("mode", "expected a primitive mode (0 to 6)");
  JsonFields ext = p.object("extensions");
  if (ext.has("KHR_draco_mesh_compression")) {
    JsonFields draco = ext.object("KHR_draco_mesh_compression");
    if (!draco.has("bufferView")) draco.fail("bufferView", "expected a bufferView index");
    draco.index("bufferView", "bufferViews");
    if (!draco.has("attributes")) draco.fail("attributes", "expected an object");
    JsonFields ids = draco.object("attributes");
    for (const std::string& name : ids.keys()) ids.count(name.c_str(), 0);
  }
  std::vector<JsonFields> targets = p.objects("targets");
  for (const JsonFields& t : targets)
    for (const std::string& name : t.keys()) t.index(name.c_str(), "accessors");
  return !targets.empty();
}

}  // namespace

void check_mesh_fields(const JsonFields& root, Warnings* warnings) {
  check_buffers(root);
  size_t morphed = 0;
  for (const JsonFields& mesh : root.objects("meshes")) {
    mesh.string("name");
    for (const JsonFields& p : mesh.objects("primitives")) morphed += check_primitive(p);
  }
  const std::string& path = root.errors()->gltf().path;
  if (morphed > 0)
    warnings->push_back(path + ": morph targets ignored: " + std::to_string(morphed) +
                        (morphed == 1 ? " primitive" : " primitives") +
                        " baked in the base shape (bind pose), target weights not applied");
  size_t skins = root.objects("skins").size();
  if (skins > 0)
    warnings->push_back(path + ": " + std::to_string(skins) + (skins == 1 ? " skin" : " skins") +
                        " ignored: skinned meshes baked in bind pose at their nodes");
}

}  // namespace vt::scene::detail
