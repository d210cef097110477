// Cube 2 engine games (Sauerbraten, Tesseract, Red Eclipse) name a model's textures in a config
// beside it, not in the model, whose own material strings are names ("door", "Material.001")
// or the artist's paths (see scene_io_util.h, apply_cube2_config).
#include <algorithm>
#include <cctype>
#include <filesystem>
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

// What one config gives the model: skins for every mesh (`*`), and how many lines name meshes.
struct Skins {
  std::string config, folder;  // the config, and the folder its paths are relative to
  std::string diffuse, normal;
  size_t named_meshes = 0;
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
    if (w.size() < 3 || (w[0] != kind + "skin" && w[0] != kind + "bumpmap")) continue;
    if (w[1] != "*") {
      ++skins.named_meshes;
      continue;
    }
    (w[0] == kind + "skin" ? skins.diffuse : skins.normal) = without_modifiers(w[2]);
  }
  if (!loads_model || (skins.diffuse.empty() && skins.normal.empty())) return std::nullopt;
  return skins;
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
  const auto image_for = [&](const std::string& written) {
    std::string found_note;
    Image image;
    image.name = written;
    image.uri = written;
    image.path = resolve_written_path(skins->folder, written, &found_note);
    scene.images.push_back(std::move(image));
    TextureRef ref;
    ref.image = int(scene.images.size() - 1);
    return ref;
  };
  const TextureRef diffuse = skins->diffuse.empty() ? TextureRef{} : image_for(skins->diffuse);
  const TextureRef normal = skins->normal.empty() ? TextureRef{} : image_for(skins->normal);
  for (Material& m : scene.materials) {
    if (diffuse.valid()) m.base_color_texture = diffuse;
    if (normal.valid()) m.normal_texture = normal;
  }
  scene.warnings.push_back(
      model_path + ": textures from the game's model config " + skins->config + ": " +
      (diffuse.valid() ? "skin '" + skins->diffuse + "'" : "") +
      (diffuse.valid() && normal.valid() ? ", " : "") +
      (normal.valid() ? "normal map '" + skins->normal + "'" : "") + " for every mesh" +
      (skins->named_meshes
           ? " (" + std::to_string(skins->named_meshes) +
                 (skins->named_meshes == 1 ? " line" : " lines") + " for named meshes not applied)"
           : ""));
}

}  // namespace vt::scene::detail
