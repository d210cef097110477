// load_scene dispatch and the file helpers the importers share.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "scene/scene.h"
#include "scene/scene_io_util.h"

namespace vt::scene {
namespace detail {

Expected<std::vector<uint8_t>> read_file(const std::string& path) {
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

namespace fs = std::filesystem;

bool exists_file(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

// `rel` under `base`, matching each component without regard to case; "" when none matches.
fs::path case_insensitive_match(const fs::path& base, const fs::path& rel) {
  fs::path at = base.empty() ? fs::path(".") : base;
  for (const fs::path& part : rel) {
    if (part == "." || part.empty()) continue;
    if (part == "..") {
      at /= part;
      continue;
    }
    std::error_code ec;
    fs::path found;
    std::string want = lower(part.string());
    for (fs::directory_iterator it(at, ec), end; !ec && it != end; it.increment(ec)) {
      if (lower(it->path().filename().string()) == want) {
        found = it->path();
        break;
      }
    }
    if (found.empty()) return {};
    at = found;
  }
  return exists_file(at) ? at : fs::path();
}

}  // namespace

std::string resolve_texture_path(const std::string& folder, const std::string& written,
                                 const std::string& scene_path,
                                 std::vector<std::string>* warnings) {
  std::string w = written;
  while (!w.empty() && (w.back() == ' ' || w.back() == '\t' || w.back() == '\r')) w.pop_back();
  if (w.size() >= 2 && (w.front() == '"' || w.front() == '\'') && w.back() == w.front())
    w = w.substr(1, w.size() - 2);
  std::replace(w.begin(), w.end(), '\\', '/');
  while (w.rfind("./", 0) == 0) w = w.substr(2);
  bool drive = w.size() >= 2 && std::isalpha(static_cast<unsigned char>(w[0])) && w[1] == ':';
  bool absolute = drive || (!w.empty() && w[0] == '/');
  std::string plain = absolute ? w : folder + w;
  if (exists_file(plain)) return plain;
  auto use = [&](const fs::path& p, const char* how) {
    if (warnings)
      warnings->push_back(scene_path + ": texture '" + written + "' not found; using '" +
                          p.string() + "' (" + how + ")");
    return p.string();
  };
  fs::path base = folder.empty() ? fs::path() : fs::path(folder);
  if (!absolute) {
    fs::path m = case_insensitive_match(base, fs::path(w));
    if (!m.empty()) return use(m, "the same name in another letter case");
  }
  fs::path name = fs::path(w).filename();
  if (!name.empty() && name != fs::path(w)) {
    if (exists_file(base / name)) return use(base / name, "the file name beside the scene");
    fs::path m = case_insensitive_match(base, name);
    if (!m.empty()) return use(m, "the file name beside the scene, in another letter case");
  }
  return plain;
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

// glTF 1.0 (a .glb header of version 1, or asset.version "1.x"): the own importer reads 2.0
// only, assimp reads 1.0.
bool is_gltf1(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  char head[8] = {};
  f.read(head, 8);
  if (std::memcmp(head, "glTF", 4) == 0) {
    uint32_t version;
    std::memcpy(&version, head + 4, 4);
    return version == 1;
  }
  f.clear();
  f.seekg(0);
  nlohmann::json doc = nlohmann::json::parse(f, nullptr, false);
  if (!doc.is_object() || !doc.contains("asset") || !doc["asset"].is_object()) return false;
  const auto& v = doc["asset"].value("version", nlohmann::json());
  return v.is_string() && v.get<std::string>().rfind("1", 0) == 0;
}

}  // namespace

Expected<Scene> load_scene(const std::string& path) {
  std::string ext = detail::lower_extension(path);
  if (ext == "gltf" || ext == "glb") {
    if (!is_gltf1(path)) return detail::load_gltf(path);
    auto scene = detail::load_assimp(path);
    if (scene.ok()) scene->warnings.push_back(path + ": glTF 1.0, read through assimp");
    return scene;
  }
  if (ext == "obj") return detail::load_obj(path);
  if (ext == "ply") return detail::load_ply(path);
  if (ext == "drc") return detail::load_drc(path);
  if (detail::assimp_reads(ext)) return detail::load_assimp(path);
  return Error(ErrorCode::kUnsupported,
               path +
                   ": unknown scene format (expected .gltf, .glb, .obj, .ply, .drc or a format "
                   "assimp reads: .fbx, .dae, .3ds, .blend, ...)");
}

}  // namespace vt::scene
