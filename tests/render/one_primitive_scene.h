// Test helper: a scene of one primitive in one node, its material reading one image file.
#pragma once

#include <filesystem>
#include <string>
#include <utility>

#include "scene/scene.h"

namespace vt::render {

inline scene::Scene one_primitive_scene(scene::Primitive p, const scene::Material& m,
                                        const std::string& png) {
  scene::Scene sc;
  sc.source_path = "test.gltf";
  p.material = 0;
  scene::Mesh mesh;
  mesh.name = "mesh";
  mesh.primitives.push_back(std::move(p));
  sc.meshes.push_back(std::move(mesh));
  sc.materials.push_back(m);
  scene::Image image;
  image.uri = std::filesystem::path(png).filename().string();
  image.path = png;
  sc.images.push_back(image);
  scene::Node node;
  node.mesh = 0;
  sc.nodes.push_back(node);
  sc.roots = {0};
  return sc;
}

}  // namespace vt::render
