// load_scene dispatch and the file helpers the importers share.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "common/utf8.h"
#include "scene/gltf_document.h"
#include "scene/image_load.h"
#include "scene/scene.h"
#include "scene/scene_io_util.h"

namespace vt::scene {
namespace detail {

Status check_regular_file(const std::string& path) {
  // Never open what is not a regular file: a FIFO blocks the open, a device never ends.
  std::error_code ec;
  auto status = std::filesystem::status(path, ec);
  if (!ec && status.type() != std::filesystem::file_type::regular)
    return Error(ErrorCode::kInvalidArgument, path + ": not a regular file to read");
  return Status::Ok();
}

namespace {

Expected<std::string> utf16_to_utf8(const uint8_t* data, size_t size, bool big_endian,
                                    const std::string& path) {
  if (size % 2 != 0)
    return Error(ErrorCode::kCorrupt, path + ": UTF-16 text with an odd number of bytes");
  auto unit = [&](size_t i) {
    return big_endian ? uint32_t(data[i] << 8 | data[i + 1]) : uint32_t(data[i + 1] << 8 | data[i]);
  };
  std::string out;
  out.reserve(size / 2);
  for (size_t i = 0; i < size; i += 2) {
    uint32_t cp = unit(i);
    if (cp >= 0xd800 && cp < 0xdc00 && i + 3 < size) {
      uint32_t low = unit(i + 2);
      if (low >= 0xdc00 && low < 0xe000) {
        cp = 0x10000 + ((cp - 0xd800) << 10) + (low - 0xdc00);
        i += 2;
      }
    }
    if (cp >= 0xd800 && cp < 0xe000) cp = 0xfffd;  // an unpaired surrogate
    append_utf8(cp, &out);
  }
  return out;
}

}  // namespace

Expected<std::string> decode_text(const std::vector<uint8_t>& bytes, const std::string& path,
                                  std::string* note) {
  note->clear();
  const uint8_t* d = bytes.data();
  size_t n = bytes.size();
  if (n >= 3 && d[0] == 0xef && d[1] == 0xbb && d[2] == 0xbf) return std::string(d + 3, d + n);
  if (n >= 2 && d[0] == 0xff && d[1] == 0xfe) return utf16_to_utf8(d + 2, n - 2, false, path);
  if (n >= 2 && d[0] == 0xfe && d[1] == 0xff) return utf16_to_utf8(d + 2, n - 2, true, path);
  // No BOM: ASCII text written as UTF-16 has a zero in every other byte.
  if (n >= 2 && d[0] != 0 && d[1] == 0) return utf16_to_utf8(d, n, false, path);
  if (n >= 2 && d[0] == 0 && d[1] != 0) return utf16_to_utf8(d, n, true, path);
  std::string text(d, d + n);
  if (valid_utf8(text)) return text;
  *note = "not UTF-8: read as Latin-1";
  return latin1_to_utf8(text);
}

Expected<std::vector<uint8_t>> read_file(const std::string& path) {
  VT_RETURN_IF_ERROR(check_regular_file(path));
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) return Error(ErrorCode::kNotFound, path + ": cannot open file");
  if (std::fseek(f.get(), 0, SEEK_END) != 0) return Error(ErrorCode::kIo, path + ": cannot seek");
  long size = std::ftell(f.get());
  if (size < 0) return Error(ErrorCode::kIo, path + ": cannot tell size");
  std::fseek(f.get(), 0, SEEK_SET);
  std::vector<uint8_t> bytes(static_cast<size_t>(size));
  if (size > 0 && std::fread(bytes.data(), 1, bytes.size(), f.get()) != bytes.size())
    return Error(ErrorCode::kIo, path + ": short read");
  return bytes;
}

std::string lower_extension(const std::string& path) {
  size_t slash = path.find_last_of("/\\");
  size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

std::string parent_folder(const std::string& path) {
  size_t slash = path.find_last_of("/\\");
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

void untexture_surfaces_without_uvs(Scene* scene) {
  std::map<std::pair<int, size_t>, int> copies;  // (material, UV sets) -> its copy
  for (Mesh& mesh : scene->meshes) {
    for (Primitive& p : mesh.primitives) {
      if (p.material < 0 || size_t(p.material) >= scene->materials.size()) continue;
      Material copy = scene->materials[size_t(p.material)];
      bool dropped = false;
      for (TextureRef* r : copy.textures()) {
        if (r->valid() && size_t(r->texcoord) >= p.uvs.size()) {
          *r = TextureRef{};
          dropped = true;
        }
      }
      if (!dropped) continue;
      auto [it, fresh] = copies.emplace(std::make_pair(p.material, p.uvs.size()), 0);
      if (fresh) {
        scene->warnings.push_back(scene->source_path + ": mesh '" + mesh.name +
                                  "' has no UV set for the textures of material '" + copy.name +
                                  "': its surfaces bake from the material's factors");
        scene->materials.push_back(std::move(copy));
        it->second = int(scene->materials.size() - 1);
      }
      p.material = it->second;
    }
  }
}

std::string percent_encode_path(const std::string& path) {
  static const char kHex[] = "0123456789ABCDEF";
  std::string out;
  for (const char c : path) {
    const auto b = static_cast<unsigned char>(c);
    const bool unreserved = (b >= 'a' && b <= 'z') || (b >= 'A' && b <= 'Z') ||
                            (b >= '0' && b <= '9') || c == '-' || c == '.' || c == '_' ||
                            c == '~' || c == '/';
    if (unreserved) {
      out.push_back(c);
    } else {
      out += {'%', kHex[b >> 4], kHex[b & 15]};
    }
  }
  return out;
}

std::string percent_decode(const std::string& uri) {
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit((unsigned char)uri[i + 1]) &&
        std::isxdigit((unsigned char)uri[i + 2])) {
      out.push_back(static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16)));
      i += 2;
    } else {
      out.push_back(uri[i]);
    }
  }
  return out;
}

static int base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+' || c == '-') return 62;
  if (c == '/' || c == '_') return 63;
  return -1;
}

Expected<std::vector<uint8_t>> decode_data_uri(const std::string& uri, std::string* mime) {
  size_t comma = uri.find(',');
  if (uri.rfind("data:", 0) != 0 || comma == std::string::npos)
    return Error(ErrorCode::kCorrupt, "malformed data URI");
  std::string header = uri.substr(5, comma - 5);
  bool base64 = header.size() >= 7 && header.substr(header.size() - 7) == ";base64";
  if (mime) *mime = header.substr(0, header.find(';'));
  std::vector<uint8_t> out;
  if (!base64) {
    std::string text = percent_decode(uri.substr(comma + 1));
    return std::vector<uint8_t>(text.begin(), text.end());
  }
  out.reserve((uri.size() - comma) * 3 / 4);
  uint32_t acc = 0;
  int bits = 0;
  for (size_t i = comma + 1; i < uri.size(); ++i) {
    char c = uri[i];
    if (c == '=' || c == '\n' || c == '\r' || c == ' ') continue;
    int v = base64_value(c);
    if (v < 0) return Error(ErrorCode::kCorrupt, "invalid base64 character in data URI");
    acc = (acc << 6) | static_cast<uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<uint8_t>((acc >> bits) & 0xff));
    }
  }
  return out;
}

std::string base64_encode(const uint8_t* data, size_t size) {
  static const char* kTable = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  for (size_t i = 0; i < size; i += 3) {
    uint32_t v = static_cast<uint32_t>(data[i]) << 16;
    if (i + 1 < size) v |= static_cast<uint32_t>(data[i + 1]) << 8;
    if (i + 2 < size) v |= data[i + 2];
    out.push_back(kTable[(v >> 18) & 63]);
    out.push_back(kTable[(v >> 12) & 63]);
    out.push_back(i + 1 < size ? kTable[(v >> 6) & 63] : '=');
    out.push_back(i + 2 < size ? kTable[v & 63] : '=');
  }
  return out;
}

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

bool exists(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

// `relative` ('/'-separated) below `folder`, matching each component case-insensitively where
// the exact name is absent (a trailing '/' keeps one on the result). Empty when some component
// has no match.
std::string match_ignoring_case(const std::string& folder, const std::string& relative) {
  std::string at = folder;
  size_t start = 0;
  while (start <= relative.size()) {
    size_t slash = relative.find('/', start);
    std::string part = relative.substr(start, slash == std::string::npos ? slash : slash - start);
    start = slash == std::string::npos ? relative.size() + 1 : slash + 1;
    if (part.empty() || part == ".") continue;
    std::error_code ec;
    if (std::filesystem::exists(at + part, ec)) {
      at += part;
    } else {
      std::string match;
      for (const auto& entry : std::filesystem::directory_iterator(at.empty() ? "." : at, ec)) {
        std::string name = entry.path().filename().string();
        if (lower(name) == lower(part) && (match.empty() || name < match)) match = name;
      }
      if (match.empty()) return "";
      at += match;
    }
    if (start <= relative.size()) at += '/';
  }
  return at;
}

// The file `relative` below `folder` as match_ignoring_case finds it; empty when it is not there.
std::string find_ignoring_case(const std::string& folder, const std::string& relative) {
  const std::string at = match_ignoring_case(folder, relative);
  return !at.empty() && exists(at) ? at : "";
}

// An image in `folder` with the stem of `name` ('/'-separated, below `folder`) and another
// image extension, letter case ignored: Quake 3 models name a texture by a shader name without
// one (or as .tga where the file is a .jpg), and the engine tries its loaders' extensions in
// turn. Their order decides between several. Empty when none is there.
std::string find_other_extension(const std::string& folder, const std::string& name) {
  static const char* const kImageExtensions[] = {".tga", ".jpg",  ".jpeg", ".png", ".bmp", ".dds",
                                                 ".tif", ".tiff", ".exr",  ".hdr", ".webp"};
  const std::filesystem::path written(name);
  const std::string dir = written.has_parent_path()
                              ? match_ignoring_case(folder, written.parent_path().string() + "/")
                              : folder;
  if (dir.empty() && written.has_parent_path()) return "";
  const std::string stem = lower(written.stem().string());
  // The best (extension rank, file name): the name decides between letter cases, whatever
  // order the folder lists them in.
  std::pair<ptrdiff_t, std::string> best{std::size(kImageExtensions), ""};
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir.empty() ? "." : dir, ec)) {
    const std::filesystem::path& p = entry.path();
    if (lower(p.stem().string()) != stem || !exists(p.string())) continue;
    const ptrdiff_t rank = std::find(std::begin(kImageExtensions), std::end(kImageExtensions),
                                     lower(p.extension().string())) -
                           std::begin(kImageExtensions);
    best = std::min(best, {rank, p.filename().string()});
  }
  return best.second.empty() ? "" : dir + best.second;
}

// The folders where tools keep a scene's images: beside it (FlightGear's Models/*/Textures/, an
// exporter's textures/), then beside its folder (a game's models/ and textures/, as Minetest's
// mods keep them); letter case ignored, each group in name order.
std::vector<std::string> texture_folders(const std::string& folder) {
  static const char* const kNames[] = {"images", "maps", "tex", "texture", "textures"};
  std::vector<std::string> out;
  for (const std::string& base : {folder, folder + "../"}) {
    std::vector<std::string> found;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(base.empty() ? "." : base, ec)) {
      const std::string name = entry.path().filename().string();
      if (entry.is_directory(ec) &&
          std::find(std::begin(kNames), std::end(kNames), lower(name)) != std::end(kNames))
        found.push_back(base + name + "/");
    }
    std::sort(found.begin(), found.end());
    out.insert(out.end(), found.begin(), found.end());
  }
  return out;
}

}  // namespace

std::string resolve_written_path(const std::string& folder, const std::string& written,
                                 std::string* note) {
  note->clear();
  std::string s = written;
  for (char& ch : s)
    if (ch == '\\') ch = '/';
  while (s.rfind("./", 0) == 0) s.erase(0, 2);
  // "\..\maps\x.jpg": exporters mean the scene's folder, not the root of a drive.
  if (written.size() > 1 && written[0] == '\\' && written[1] != '\\') s.erase(0, 1);
  bool windows_absolute =
      (s.size() >= 2 && std::isalpha(static_cast<unsigned char>(s[0])) && s[1] == ':') ||
      s.rfind("//", 0) == 0;
  bool absolute = windows_absolute || (!s.empty() && s[0] == '/');
  std::string as_written = absolute ? s : folder + s;
  if (!windows_absolute && exists(as_written)) return as_written;
  if (!absolute) {
    std::string found = find_ignoring_case(folder, s);
    if (!found.empty()) {
      *note = "'" + written + "' not found; using '" + found + "' (letter case differs)";
      return found;
    }
  }
  size_t slash = s.find_last_of('/');
  std::string base = slash == std::string::npos ? s : s.substr(slash + 1);
  if (base != s && !base.empty()) {
    std::string beside = folder + base;
    if (!exists(beside)) beside = find_ignoring_case(folder, base);
    if (!beside.empty()) {
      *note = "'" + written + "' not found; using '" + beside + "' (same name, next to it)";
      return beside;
    }
  }
  const std::vector<std::string> texture_dirs =
      base.empty() ? std::vector<std::string>{} : texture_folders(folder);
  for (const std::string& dir : texture_dirs) {
    const std::string found = find_ignoring_case(dir, base);
    if (!found.empty()) {
      *note = "'" + written + "' not found; using '" + found + "' (same name, textures folder)";
      return found;
    }
  }
  std::string other = absolute ? "" : find_other_extension(folder, s);
  if (other.empty() && base != s && !base.empty()) other = find_other_extension(folder, base);
  for (size_t i = 0; other.empty() && i < texture_dirs.size(); ++i)
    other = find_other_extension(texture_dirs[i], base);
  if (!other.empty()) {
    *note = "'" + written + "' not found; using '" + other + "' (same name, another extension)";
    return other;
  }
  // UFO: Alien Invasion's MD2 skins: ".name" is the image `name` beside the model, of any
  // extension (the game's convention; Quake 2's own skins are paths).
  if (s.size() > 1 && s[0] == '.' && s[1] != '.' && s.find('/') == std::string::npos) {
    const std::string found = resolve_written_path(folder, s.substr(1), note);
    if (exists(found)) {
      *note = "'" + written + "' not found; using '" + found +
              "' (a leading dot: the name beside the model, any extension)";
      return found;
    }
    note->clear();
  }
  return windows_absolute ? folder + base : as_written;
}

std::string find_in_texture_folders(const Image& image, const std::vector<std::string>& folders) {
  const std::string base = std::filesystem::path(image.path).filename().string();
  // The path as written only when it stays below the folder: no "..", not absolute.
  const std::filesystem::path written(image.uri);
  const bool below =
      !written.is_absolute() && std::find(written.begin(), written.end(), "..") == written.end();
  for (std::string dir : folders) {
    if (!dir.empty() && dir.back() != '/') dir += '/';
    std::string found = below ? find_ignoring_case(dir, image.uri) : "";
    if (found.empty()) found = find_ignoring_case(dir, base);
    if (found.empty()) found = find_other_extension(dir, base);
    if (!found.empty()) return found;
  }
  return "";
}

std::string scene_folder_tree(const std::string& scene_path) {
  std::error_code ec;
  std::filesystem::path folder = std::filesystem::absolute(scene_path, ec).parent_path();
  folder = std::filesystem::weakly_canonical(folder, ec);
  return folder.parent_path().string();
}

Status check_inside_scene_tree(const std::string& scene_path, const std::string& file,
                               const std::string& what, const SceneLoadOptions& options) {
  std::error_code ec;
  if (options.allow_outside_paths || !std::filesystem::exists(file, ec)) return Status::Ok();
  const std::filesystem::path real = std::filesystem::canonical(file, ec);
  if (ec) return Error(ErrorCode::kIo, scene_path + ": " + what + ": cannot resolve " + file);
  const std::filesystem::path root = scene_folder_tree(scene_path);
  auto [r, f] = std::mismatch(root.begin(), root.end(), real.begin(), real.end());
  if (r == root.end()) return Status::Ok();
  return Error(ErrorCode::kInvalidArgument,
               scene_path + ": " + what + ": '" + file + "' is " + real.string() +
                   ", outside the scene's folder tree " + root.string() +
                   " (a scene may name files in its folder, below it or in a sibling folder; "
                   "--allow-outside-paths reads it anyway)");
}

Scene single_mesh_scene(const std::string& path, std::string name, std::vector<Primitive> prims,
                        std::vector<Material> materials) {
  Scene scene;
  scene.source_path = path;
  Mesh mesh;
  mesh.name = std::move(name);
  mesh.primitives = std::move(prims);
  scene.meshes.push_back(std::move(mesh));
  scene.materials = std::move(materials);
  Node node;
  node.name = scene.meshes[0].name;
  node.mesh = 0;
  scene.nodes.push_back(node);
  scene.roots.push_back(0);
  return scene;
}

}  // namespace detail

namespace {

// glTF 1.0 (a .glb header of version 1, or a 1.0 JSON document): the own importer reads 2.0
// only, assimp reads 1.0.
bool is_gltf1(const std::string& path) {
  std::ifstream f(path, std::ios::binary | std::ios::ate);
  const uint64_t size = f ? uint64_t(f.tellg()) : 0;
  f.seekg(0);
  char head[20] = {};
  f.read(head, 20);
  if (std::memcmp(head, "glTF", 4) == 0) {
    uint32_t version, length, content_length;
    std::memcpy(&version, head + 4, 4);
    std::memcpy(&length, head + 8, 4);
    std::memcpy(&content_length, head + 12, 4);
    // assimp trusts a binary glTF 1.0's lengths (a 26-byte file made it ask for 2 GiB): only a
    // header whose lengths match the file goes there; the own importer refuses the others.
    return version == 1 && f && length == size && content_length <= size - 20;
  }
  f.clear();
  f.seekg(0);
  return detail::is_gltf1_document(nlohmann::json::parse(f, nullptr, false));
}

// "material 'Body' baseColorTexture image 2 'brick'": the first material slot using the
// image, for error messages.
std::string image_user(const Scene& scene, size_t image) {
  std::string name = "image " + std::to_string(image);
  if (!scene.images[image].name.empty()) name += " '" + scene.images[image].name + "'";
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const Material& mat = scene.materials[m];
    const std::pair<const TextureRef*, const char*> slots[] = {
        {&mat.base_color_texture, "baseColorTexture"},
        {&mat.metallic_roughness_texture, "metallicRoughnessTexture"},
        {&mat.normal_texture, "normalTexture"},
        {&mat.occlusion_texture, "occlusionTexture"},
        {&mat.emissive_texture, "emissiveTexture"}};
    for (const auto& [ref, slot] : slots)
      if (ref->image == static_cast<int>(image))
        return "material '" + (mat.name.empty() ? std::to_string(m) : mat.name) + "' " + slot +
               " " + name;
  }
  return name;
}

Expected<Scene> load_by_extension(const std::string& path, const SceneLoadOptions& options) {
  std::string ext = detail::lower_extension(path);
  if (ext == "gltf" || ext == "glb") {
    // glTF 1.0 goes through assimp; should assimp fail too, the own importer says why not.
    if (is_gltf1(path)) {
      auto scene = detail::load_assimp(path);
      if (scene.ok()) {
        scene->warnings.push_back(path + ": glTF 1.0, read through assimp");
        return scene;
      }
    }
    return detail::load_gltf(path, options);
  }
  if (ext == "obj") return detail::load_obj(path, options);
  if (ext == "ply") return detail::load_ply(path);
  if (ext == "drc") return detail::load_drc(path);
  if (ext == "ac" || ext == "acc" || ext == "ac3d") return detail::load_ac3d(path);
  if (ext == "pk3" || ext == "bsp") {
    // assimp 5.2's Q3BSP importer fails on real maps (its own test map too, assimp issue 2862;
    // OpenArena's maps alike) and overflows its heap on crafted lump sizes (issue 6711, fixed
    // after 5.2): nothing to gain from handing it a file.
    return Error(ErrorCode::kUnsupported,
                 path +
                     ": Quake 3 BSP maps are not supported (assimp's importer fails on real "
                     "maps and is unsafe on crafted ones); bake the map's models (.md3) instead");
  }
  if (detail::assimp_reads(ext)) return detail::load_assimp(path);
  return Error(
      ErrorCode::kUnsupported,
      path +
          ": unknown scene format (expected .gltf, .glb, .obj, .ply, .drc, .ac or a format "
          "assimp reads: .fbx, .dae, .3ds, .blend, ...)");
}

}  // namespace

Expected<Scene> load_scene(const std::string& path, const SceneLoadOptions& options) {
  VT_RETURN_IF_ERROR(detail::check_regular_file(path));
  VT_ASSIGN_OR_RETURN(Scene scene, load_by_extension(path, options));
  detail::apply_cube2_config(path, scene);
  // Names go into messages, JSON reports, the metadata and the unwrapped glTF: UTF-8 from here
  // on. File paths stay as the disk has them.
  for (Material& m : scene.materials) m.name = as_utf8(m.name);
  for (Image& im : scene.images) im.name = as_utf8(im.name);
  for (Mesh& m : scene.meshes) m.name = as_utf8(m.name);
  for (Light& l : scene.lights) l.name = as_utf8(l.name);
  for (Node& n : scene.nodes) n.name = as_utf8(n.name);
  for (std::string& w : scene.warnings) w = as_utf8(w);
  size_t from_texture_folders = 0;
  for (size_t i = 0; i < scene.images.size(); ++i) {
    Image& image = scene.images[i];
    if (image.embedded()) continue;
    if (!options.texture_folders.empty() && !detail::exists(image.path)) {
      std::string found = detail::find_in_texture_folders(image, options.texture_folders);
      if (!found.empty()) {
        if (from_texture_folders++ == 0)
          scene.warnings.push_back(path + ": image '" + image.name + "' read from '" + found +
                                   "' (--texture-path)");
        image.path = std::move(found);
        continue;  // the user named that folder: it may lie outside the scene's tree
      }
    }
    VT_RETURN_IF_ERROR(
        detail::check_inside_scene_tree(path, image.path, image_user(scene, i), options));
  }
  if (from_texture_folders > 1)
    scene.warnings.push_back(path + ": " + std::to_string(from_texture_folders) +
                             " images in all read from the --texture-path folders");
  // PCX images (Quake 2's skins) become embedded PNGs: OpenImageIO has no PCX reader.
  for (Image& image : scene.images) {
    if (image.embedded() || detail::lower_extension(image.path) != "pcx" ||
        !detail::exists(image.path))
      continue;
    Expected<Image> png = pcx_as_png(image.path);
    if (!png.ok()) {
      scene.warnings.push_back(png.status().message());  // the texture's read then fails
      continue;
    }
    image.bytes = std::move(png->bytes);
    image.mime_type = png->mime_type;
    image.path.clear();
  }
  detail::warn_about_degenerate_geometry(&scene);
  return scene;
}

}  // namespace vt::scene
