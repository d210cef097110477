// The steps of load_gltf beyond buffers and primitives: version and extension rules, the
// checks of the fields the geometry readers use, materials, and the node graph. Each reports
// errors as "FILE: WHERE: problem" and appends warnings ("FILE: feature: what was done
// instead") for what it ignores or approximates. Internal to vt_scene.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "scene/gltf_fields.h"

namespace vt::scene::detail {

using Warnings = std::vector<std::string>;
// Extension name -> how many materials use it.
using ExtensionUses = std::map<std::string, int>;

// glTF 1.0 (by asset.version or by its object-valued top-level maps) and versions after 2.x
// are kUnsupported; a missing asset.version is a warning.
Status check_version(const Gltf& g, Warnings* warnings);

// extensionsRequired: kUnsupported naming the first extension vtbake cannot honour.
Status check_required_extensions(const JsonFields& root);

// One warning per used extension that vtbake ignores or approximates, saying what it does
// instead (material_uses adds the extensions the materials carry and their counts).
void warn_about_extensions(const JsonFields& root, const ExtensionUses& material_uses,
                           Warnings* warnings);

// Types and index ranges of buffers, bufferViews, accessors and meshes (the fields the
// accessor and primitive readers use); warns about morph targets and skins.
void check_mesh_fields(const JsonFields& root, Warnings* warnings);

// Materials with every textureInfo resolved (sampler, texCoord, KHR_texture_transform),
// KHR_materials_emissive_strength, and the specular-glossiness and KHR_technique_webgl
// (common-profile values) fallbacks.
std::vector<Material> load_materials(const JsonFields& root, ExtensionUses* uses,
                                     Warnings* warnings);

// extras.vtbake_texels_per_unit of a material or node: a positive number (else an error), 0
// when absent. Extras that are not an object are application data of others: ignored.
double density_extra(const JsonFields& object);

// Nodes and the displayed scene's roots; the graph must be a forest.
Status load_nodes(const JsonFields& root, Scene* scene);

// KHR_lights_punctual lights (checked with check_light) and the nodes that place them; after
// load_nodes.
Status load_lights(const JsonFields& root, Scene* scene);

}  // namespace vt::scene::detail
