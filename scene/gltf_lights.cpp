// KHR_lights_punctual: the document's lights (directional, point, spot) and the nodes that place
// them. Values are checked against the extension (scene.h check_light) and a bad one is an error
// naming the file and the light.
#include "scene/gltf_import_steps.h"

namespace vt::scene::detail {

namespace {

Light read_light(const JsonFields& l) {
  Light light;
  light.name = l.string("name");
  const std::string type = l.string("type");
  if (type == "directional")
    light.type = LightType::kDirectional;
  else if (type == "point")
    light.type = LightType::kPoint;
  else if (type == "spot")
    light.type = LightType::kSpot;
  else
    l.fail("type", type.empty() ? std::string("missing (directional, point or spot)")
                                : "'" + type + "' is not directional, point or spot");
  light.color = l.floats<3>("color", light.color);
  light.intensity = float(l.number("intensity", 1.0));
  if (l.has("range") && light.type != LightType::kDirectional)
    light.range = float(l.number("range", 0.0));
  if (light.type == LightType::kSpot) {
    JsonFields spot = l.object("spot");
    light.inner_cone_angle = float(spot.number("innerConeAngle", light.inner_cone_angle));
    light.outer_cone_angle = float(spot.number("outerConeAngle", light.outer_cone_angle));
  }
  return light;
}

}  // namespace

Status load_lights(const JsonFields& root, Scene* scene) {
  FieldErrors* errors = root.errors();
  JsonFields ext = root.object("extensions").object("KHR_lights_punctual");
  for (const JsonFields& l : ext.objects("lights")) {
    Light light = read_light(l);
    VT_RETURN_IF_ERROR(errors->status());
    const Status ok = check_light(light);
    if (!ok.ok()) errors->fail(ErrorCode::kCorrupt, l.where(), ok.message());
    VT_RETURN_IF_ERROR(errors->status());
    scene->lights.push_back(std::move(light));
  }
  const std::vector<JsonFields> nodes = root.objects("nodes");
  for (size_t i = 0; i < nodes.size() && i < scene->nodes.size(); ++i) {
    JsonFields use = nodes[i].object("extensions").object("KHR_lights_punctual");
    if (!use.has("light")) continue;
    const size_t light = use.count("light", 0);
    VT_RETURN_IF_ERROR(errors->status());
    if (light >= scene->lights.size()) {
      use.fail("light", "light " + std::to_string(light) + " does not exist (the file has " +
                            std::to_string(scene->lights.size()) + " KHR_lights_punctual lights)");
      return errors->status();
    }
    scene->nodes[i].light = int(light);
  }
  return errors->status();
}

}  // namespace vt::scene::detail
