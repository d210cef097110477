// Cube 2 engine games (Sauerbraten, Tesseract, Red Eclipse) name a model's textures in a config
// beside it, not in the model, whose own material strings are names ("door", "Material.001")
// or the artist's paths (see scene_io_util.h, apply_cube2_config).
#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <map>
#include <optional>

#include "scene/scene_io_util.h"

namespace vt::scene::detail {
namespace {

// The words of one config line: spaces separate, double quotes group, `//` ends the line.
std::vector<std::string> words(const std::string& line) {
  std::vector<std::string> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i >= line.size() || line.compare(i, 2, "//") == 0) break;
    std::string w;
    if (line[i] == '"') {
      const size_t end = line.find('"', i + 1);
      w = line.substr(i + 1, end == std::string::npos ? std::string::npos : end - i - 1);
      i = end == std::string::npos ? line.size() : end + 1;
    } else {
      while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) w += line[i++];
    }
    out.push_back(std::move(w));
  }
  return out;
}

// A texture argument without its load modifiers ("<dds>skin.png", "<mad:0.5>x.png").
std::string without_modifiers(std::string name) {
  while (!name.empty() && name[0] == '<') {
    const size_t end = name.find('>');
    if (end == std::string::npos) break;
    name.erase(0, end + 1);
  }
  return name;
}

// One `KINDskin` / `KINDbumpmap` line: the mesh it names (`*`: every mesh) and its texture.
struct SkinLine {
  bool normal = false;
  std::string mesh, texture;
};

// What one config gives the model, its lines in order (a later line overrides an earlier one).
struct Skins {
  std::string config, folder;  // the config, and the folder its paths are relative to
  std::vector<SkinLine> lines;
};

// The config's skins when it configures `model`: its `KINDload` names the model (relative to
// the config), or, for a config beside the model, names nothing.
std::optional<Skins> read_config(const std::string& config, const std::string& kind,
                                 const std::filesystem::path& model, bool beside) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(config, ec)) return std::nullopt;
  Expected<std::vector<uint8_t>> bytes = read_file(config);
  if (!bytes.ok()) return std::nullopt;
  std::string note;
  Expected<std::string> text = decode_text(*bytes, config, &note);
  if (!text.ok()) return std::nullopt;
  Skins skins;
  skins.config = config;
  skins.folder = parent_folder(config);
  bool loads_model = beside;
  size_t at = 0;
  while (at < text->size()) {
    size_t end = text->find('\n', at);
    if (end == std::string::npos) end = text->size();
    const std::vector<std::string> w = words(text->substr(at, end - at));
    at = end + 1;
    if (w.size() < 2) continue;
    if (w[0] == kind + "load") {
      const std::filesystem::path loaded = std::filesystem::path(skins.folder + w[1]);
      loads_model = std::filesystem::equivalent(loaded, model, ec);
      if (!loads_model) return std::nullopt;
    }
    if (w.size() >= 3 && (w[0] == kind + "skin" || w[0] == kind + "bumpmap"))
      skins.lines.push_back({w[0] == kind + "bumpmap", w[1], without_modifiers(w[2])});
  }
  if (!loads_model || skins.lines.empty()) return std::nullopt;
  return skins;
}

// The names the engine gives a model's meshes, one per mesh assimp makes a material for, in
// file order: MD5's `// meshes: NAME` comment in each mesh block that has vertices and triangles
// (assimp skips the others), IQM's mesh names, MD3's surface names (assimp names the materials
// `MD3_[SKIN][SURFACE]`). Empty for other kinds or a file not read so.
std::vector<std::string> engine_mesh_names(const std::string& model_path, const std::string& kind,
                                           const Scene& scene) {
  std::vector<std::string> names;
  if (kind == "md3") {
    for (const Material& m : scene.materials) {
      const size_t open = m.name.rfind("][");
      if (m.name.rfind("MD3_[", 0) != 0 || open == std::string::npos || m.name.back() != ']')
        return {};
      names.push_back(m.name.substr(open + 2, m.name.size() - open - 3));
    }
    return names;
  }
  if (kind != "md5" && kind != "iqm") return names;
  // The importer's checks read them; a file they refuse never gets here.
  Expected<std::vector<std::string>> read =
      kind == "md5" ? md5_mesh_names(model_path) : iqm_mesh_names(model_path);
  return read.ok() ? std::move(read).value() : names;
}

}  // namespace

void apply_cube2_config(const std::string& model_path, Scene& scene) {
  const std::string ext = lower_extension(model_path);
  const std::string kind = ext == "md5mesh" ? "md5" : ext;
  if (kind != "iqm" && kind != "md5" && kind != "md3" && kind != "obj" && kind != "smd") return;
  const std::string folder = parent_folder(model_path), file = kind + ".cfg";
  // Beside the model, else in a folder below it that loads it (Red Eclipse's weapons keep
  // item/md5.cfg with `md5load ../item.md5mesh`).
  std::optional<Skins> skins = read_config(folder + file, kind, model_path, true);
  if (!skins) {
    std::vector<std::string> below;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(folder.empty() ? "." : folder, ec))
      if (e.is_directory(ec)) below.push_back(e.path().string() + "/" + file);
    std::sort(below.begin(), below.end());
    for (size_t i = 0; !skins && i < below.size(); ++i)
      skins = read_config(below[i], kind, model_path, false);
  }
  if (!skins) return;
  // Lines naming a mesh apply where the engine's mesh names line up with the materials.
  std::vector<std::string> names = engine_mesh_names(model_path, kind, scene);
  if (names.size() != scene.materials.size()) names.clear();
  std::map<std::string, TextureRef> images;  // one image per texture written
  const auto image_for = [&](const std::string& written) {
    auto [it, added] = images.try_emplace(written);
    if (added) {
      std::string found_note;
      Image image;
      image.name = written;
      image.uri = written;
      image.path = resolve_written_path(skins->folder, written, &found_note);
      scene.images.push_back(std::move(image));
      it->second.image = int(scene.images.size() - 1);
    }
    return it->second;
  };
  // What each target (`*` or a mesh name) ends with, in order of first mention, for the warning.
  std::vector<std::pair<std::string, std::array<std::string, 2>>> told;
  size_t not_applied = 0;
  for (const SkinLine& line : skins->lines) {
    bool applied = false;
    for (size_t m = 0; m < scene.materials.size(); ++m) {
      if (line.mesh != "*" && (names.empty() || names[m] != line.mesh)) continue;
      (line.normal ? scene.materials[m].normal_texture : scene.materials[m].base_color_texture) =
          image_for(line.texture);
      applied = true;
    }
    if (!applied) {
      not_applied += line.mesh != "*";
      continue;
    }
    auto it = std::find_if(told.begin(), told.end(), [&](auto& t) { return t.first == line.mesh; });
    if (it == told.end()) it = told.insert(told.end(), {line.mesh, {}});
    it->second[line.normal] = line.texture;
  }
  if (told.empty()) {
    scene.warnings.push_back(model_path + ": the game's model config " + skins->config +
                             " names skins for meshes the model does not name (" +
                             std::to_string(not_applied) + " lines): not applied");
    return;
  }
  std::string what;
  for (const auto& [mesh, textures] : told) {
    if (!what.empty()) what += "; ";
    if (!textures[0].empty()) what += "skin '" + textures[0] + "'";
    if (!textures[0].empty() && !textures[1].empty()) what += ", ";
    if (!textures[1].empty()) what += "normal map '" + textures[1] + "'";
    what += mesh == "*" ? " for every mesh" : " for mesh '" + mesh + "'";
  }
  scene.warnings.push_back(
      model_path + ": textures from the game's model config " + skins->config + ": " + what +
      (not_applied ? " (" + std::to_string(not_applied) + (not_applied == 1 ? " line" : " lines") +
                         " for meshes the model does not name not applied)"
                   : ""));
}

}  // namespace vt::scene::detail
