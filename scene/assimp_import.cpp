// Every other scene format assimp reads (FBX, COLLADA, 3DS, Blender, X, LightWave, STL, ...)
// mapped onto the scene model: one primitive per assimp mesh, the node hierarchy kept (a node
// with several meshes gets one scene mesh holding them all), materials onto glTF
// metallic-roughness, embedded textures kept as image bytes (uncompressed ones as PNG). Only the
// bake side links assimp.
#include <assimp/DefaultIOSystem.h>
#include <assimp/GltfMaterial.h>
#include <assimp/MemoryIOWrapper.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/version.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string_view>

#include "scene/image_load.h"
#include "scene/import_budget.h"
#include "scene/scene_io_util.h"

namespace vt::scene::detail {
namespace {

Mat4 to_mat4(const aiMatrix4x4& m) {
  // assimp is row-major with translation in the last column: transpose into glTF's order.
  return {m.a1, m.b1, m.c1, m.d1, m.a2, m.b2, m.c2, m.d2,
          m.a3, m.b3, m.c3, m.d3, m.a4, m.b4, m.c4, m.d4};
}

WrapMode wrap_mode(aiTextureMapMode m) {
  switch (m) {
    case aiTextureMapMode_Clamp:
    case aiTextureMapMode_Decal:
      return WrapMode::kClampToEdge;
    case aiTextureMapMode_Mirror:
      return WrapMode::kMirroredRepeat;
    default:
      return WrapMode::kRepeat;
  }
}

std::string mime_from_hint(const char* hint) {
  std::string h(hint);
  std::transform(h.begin(), h.end(), h.begin(), [](unsigned char c) { return std::tolower(c); });
  if (h == "jpg" || h == "jpeg") return "image/jpeg";
  if (h == "png") return "image/png";
  if (h == "exr") return "image/x-exr";
  if (h == "webp") return "image/webp";
  if (h == "tga") return "image/x-tga";
  if (h == "bmp") return "image/bmp";
  if (h == "dds") return "image/vnd-ms.dds";
  return h.empty() ? std::string() : "image/" + h;
}

// Quake 2 models (MD2) whose last section ends at the end of the file: assimp 5.2 counts a
// section ending there as outside the file (`>=` where `>` is meant: "Invalid MD2 header: Some
// offsets are outside the file"), so every MD2 without GL commands after its frames was refused
// (UFO: Alien Invasion's 859 models nearly all). True when the header's sections all lie in the
// file and one of those assimp checks ends exactly at its end.
bool md2_ends_at_its_last_section(const std::vector<uint8_t>& bytes) {
  if (bytes.size() < 68 || std::memcmp(bytes.data(), "IDP2", 4) != 0) return false;
  const auto field = [&](int i) { return uint64_t(read_u32(&bytes[4 + 4 * i])); };
  // skins, texture coordinates, triangles, frames (assimp's sizes; a frame is 40 bytes + 4 a
  // vertex), GL commands.
  const uint64_t ends[5] = {field(10) + field(4) * 64, field(11) + field(6) * 4,
                            field(12) + field(7) * 12, field(13) + field(9) * (40 + 4 * field(5)),
                            field(14) + field(8) * 4};
  const uint64_t size = bytes.size();
  return std::all_of(std::begin(ends), std::end(ends), [&](uint64_t e) { return e <= size; }) &&
         field(15) <= size && std::any_of(ends, ends + 4, [&](uint64_t e) { return e == size; });
}

// Files handed to assimp as its readers need them:
// - files that start with a UTF-16 byte-order mark, as UTF-8: its XML readers (COLLADA;
//   Irrlicht's .irr scenes, which Irrlicht writes in UTF-16) and its ASE reader take the bytes
//   as UTF-8, and failed ("malformed XML", "No meshes remaining");
// - MD2 models whose last section ends the file, with one zero byte after it (above);
// - Doom 3 MD5 meshes without their `MD5Version 10` line, with it: the Cube 2 engine does not
//   ask for it (Red Eclipse's zapper), assimp refused them ("MD5Version tag has not been found");
//   and every MD5 mesh with zero bytes after it: assimp's parser steps past the text's end by a
//   byte or more where a token ends the file (a 17-byte crafted file read past its buffer).
class FilesAsAssimpReadsThem : public Assimp::DefaultIOSystem {
 public:
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    Assimp::IOStream* stream = DefaultIOSystem::Open(file, mode);
    uint8_t mark[4] = {};
    if (!stream || mode[0] != 'r' || stream->FileSize() < 4 || stream->Read(mark, 1, 4) != 4) {
      if (stream) stream->Seek(0, aiOrigin_SET);
      return stream;
    }
    stream->Seek(0, aiOrigin_SET);
    const bool utf16 = (mark[0] == 0xff && mark[1] == 0xfe) || (mark[0] == 0xfe && mark[1] == 0xff);
    const bool md2 = std::memcmp(mark, "IDP2", 4) == 0;
    const bool md5 = lower_extension(file) == "md5mesh";
    if (!utf16 && !md2 && !md5) return stream;
    std::vector<uint8_t> bytes(stream->FileSize());
    bytes.resize(stream->Read(bytes.data(), 1, bytes.size()));
    stream->Seek(0, aiOrigin_SET);
    constexpr std::string_view kMd5Version = "MD5Version";
    std::string served;
    if (utf16) {
      std::string note;
      Expected<std::string> text = decode_text(bytes, file, &note);
      if (!text.ok()) return stream;  // odd-length UTF-16: assimp's own error says what it finds
      served = std::move(*text);
    } else if (md2) {
      if (!md2_ends_at_its_last_section(bytes)) return stream;
      served.assign(bytes.begin(), bytes.end());
      served.push_back('\0');
    } else {
      const bool versioned = std::search(bytes.begin(), bytes.end(), kMd5Version.begin(),
                                         kMd5Version.end()) != bytes.end();
      served = (versioned ? "" : "MD5Version 10\n") + std::string(bytes.begin(), bytes.end()) +
               std::string(16, '\0');
    }
    Close(stream);
    auto* copy = new uint8_t[served.size()];
    std::memcpy(copy, served.data(), served.size());
    return new Assimp::MemoryIOStream(copy, served.size(), /*own=*/true);
  }
};

// The diffuse texture assimp's MD2 importer writes when the model names no skin.
constexpr char kAssimpNoSkin[] = "$texture_dummy.bmp";

}  // namespace

Expected<Image> embedded_texels_png(const aiTexture& t, const std::string& name,
                                    const aiColor3D* colour_key) {
  if (t.mWidth > 65536 || t.mHeight > 65536 || !t.pcData)
    return Error(ErrorCode::kCorrupt, std::to_string(t.mWidth) + "x" + std::to_string(t.mHeight) +
                                          " texels: not an image");
  // assimp gives Half-Life's key (its palette's last entry) in 0-255, other keys in 0-1.
  const auto key_byte = [](float c) { return int(std::lround(c > 1.0f ? c : c * 255.0f)); };
  const int key[3] = {colour_key ? key_byte(colour_key->r) : -1,
                      colour_key ? key_byte(colour_key->g) : -1,
                      colour_key ? key_byte(colour_key->b) : -1};
  const auto alpha = [&](const aiTexel& x) {
    return x.r == key[0] && x.g == key[1] && x.b == key[2] ? uint8_t(0) : x.a;
  };
  const size_t count = size_t(t.mWidth) * t.mHeight;
  const bool opaque =
      std::all_of(t.pcData, t.pcData + count, [&](const aiTexel& x) { return alpha(x) == 255; });
  const int channels = opaque ? 3 : 4;
  std::vector<uint8_t> texels(count * channels);
  for (size_t i = 0; i < count; ++i) {
    const aiTexel& x = t.pcData[i];
    uint8_t* d = &texels[i * channels];
    d[0] = x.r, d[1] = x.g, d[2] = x.b;
    if (!opaque) d[3] = alpha(x);
  }
  const OIIO::ImageSpec spec(int(t.mWidth), int(t.mHeight), channels, OIIO::TypeDesc::UINT8);
  return embedded_png(name, spec, OIIO::TypeDesc::UINT8, texels.data());
}

namespace {

// What the file had that was dropped before assimp's validation, for the warnings.
struct Dropped {
  unsigned animations = 0, lights = 0, empty_meshes = 0;
};

class AssimpScene {
 public:
  AssimpScene(const std::string& path, const aiScene& ai, const Dropped& dropped)
      : path_(path), ai_(ai), dropped_(dropped) {
    scene_.source_path = path;
    folder_ = parent_folder(path);
  }

  Expected<Scene> convert() {
    for (unsigned i = 0; i < ai_.mNumMaterials; ++i)
      scene_.materials.push_back(material(*ai_.mMaterials[i]));
    VT_RETURN_IF_ERROR(add_node(*ai_.mRootNode, -1));
    scene_.roots.push_back(0);
    fit_uv_sets();
    untexture_surfaces_without_uvs(&scene_);
    if (skipped_faces_ > 0)
      warn(std::to_string(skipped_faces_) + " point and line primitives skipped (no surface)");
    if (dropped_.animations > 0)
      warn(std::to_string(dropped_.animations) + " animations ignored (baked in the rest pose)");
    if (dropped_.empty_meshes > 0)
      warn(std::to_string(dropped_.empty_meshes) +
           " meshes without vertices or faces skipped (nothing to bake in them)");
    if (boned_meshes_ > 0)
      warn(std::to_string(boned_meshes_) + " skinned meshes baked in their bind pose");
    if (dropped_.lights > 0)
      warn(std::to_string(dropped_.lights) +
           " lights ignored (only glTF KHR_lights_punctual lights are baked)");
    return std::move(scene_);
  }

 private:
  void warn(const std::string& what) { scene_.warnings.push_back(path_ + ": " + what); }

  // assimp's UV source index (COLLADA's set numbers, for one) can name a set the meshes that
  // use the material do not have: such a slot reads set 0, with a warning.
  void fit_uv_sets() {
    std::vector<size_t> fewest(scene_.materials.size(), SIZE_MAX);
    for (const Mesh& m : scene_.meshes)
      for (const Primitive& p : m.primitives)
        if (p.material >= 0 && size_t(p.material) < fewest.size())
          fewest[p.material] = std::min(fewest[p.material], p.uvs.size());
    for (size_t i = 0; i < scene_.materials.size(); ++i) {
      Material& mat = scene_.materials[i];
      for (TextureRef* r : mat.textures()) {
        if (!r->valid() || fewest[i] == SIZE_MAX || fewest[i] == 0 ||
            size_t(r->texcoord) < fewest[i])
          continue;
        warn("material '" + mat.name + "': a texture names UV set " + std::to_string(r->texcoord) +
             ", which its meshes lack; set 0 is used");
        r->texcoord = 0;
      }
    }
  }

  // The image for a texture path: an embedded texture ("*N" or a name assimp holds) or a file
  // beside the scene; one Scene::Image per distinct path.
  // With `colour_key`, uncompressed texels of that colour become transparent.
  int image_for(const std::string& raw, const aiColor3D* colour_key) {
    const std::string cache_key = colour_key ? raw + "\n(colour-keyed)" : raw;
    auto it = images_.find(cache_key);
    if (it != images_.end()) return it->second;
    Image image;
    if (const aiTexture* t = ai_.GetEmbeddedTexture(raw.c_str())) {
      image.name = t->mFilename.length ? t->mFilename.C_Str() : raw;
      if (t->mHeight == 0) {
        const auto* bytes = reinterpret_cast<const uint8_t*>(t->pcData);
        image.bytes.assign(bytes, bytes + t->mWidth);
        image.mime_type = mime_from_hint(t->achFormatHint);
      } else {
        // Texels (Half-Life and Quake models' palette skins, which assimp expands): a PNG.
        Expected<Image> png = embedded_texels_png(*t, image.name, colour_key);
        if (!png.ok()) {
          warn("embedded texture '" + raw + "': " + png.status().message() + "; slot left empty");
          return images_[cache_key] = -1;
        }
        image = std::move(*png);
      }
    } else {
      image.name = raw;
      image.uri = raw;
      std::string note;
      image.path = resolve_written_path(folder_, raw, &note);
      if (!note.empty()) warn("texture " + note);
    }
    scene_.images.push_back(std::move(image));
    return images_[cache_key] = int(scene_.images.size() - 1);
  }

  TextureRef texture(const aiMaterial& m, aiTextureType type,
                     const aiColor3D* colour_key = nullptr) {
    TextureRef ref;
    if (m.GetTextureCount(type) == 0) return ref;
    aiString file;
    aiTextureMapping mapping = aiTextureMapping_UV;
    unsigned uv_index = 0;
    aiTextureMapMode modes[2] = {aiTextureMapMode_Wrap, aiTextureMapMode_Wrap};
    if (m.GetTexture(type, 0, &file, &mapping, &uv_index, nullptr, nullptr, modes) != AI_SUCCESS)
      return ref;
    // assimp's IQM importer turns a mesh's material string into a texture path, empty when the
    // game assigns skins in its own config (Sauerbraten's iqm.cfg).
    if (file.length == 0) {
      const std::string name = m.GetName().C_Str();
      warn((name.empty() ? std::string("an unnamed material") : "material '" + name + "'") +
           ": a texture with no file name is ignored");
      return ref;
    }
    std::string written = file.C_Str();
    if (written == kAssimpNoSkin) {
      // What assimp's MD2 importer names when the model names no skin: the game gives it one,
      // by convention the model's own name beside it (Irrlicht's sydney.md2 and sydney.bmp).
      const std::filesystem::path model(path_);
      std::string note;  // the guess's own note: it is a guess either way
      const std::string guess =
          resolve_written_path(folder_, model.stem().string() + ".png", &note);
      if (!std::filesystem::is_regular_file(guess) || guess.rfind(folder_, 0) != 0) {
        warn("the model names no skin (assimp's placeholder '" + written +
             "'): its surfaces bake from the material's colour; an image named like the model "
             "beside it (" +
             model.stem().string() + ".png, .bmp, .tga, ...) would be used");
        return ref;
      }
      written = guess.substr(folder_.size());
      warn("the model names no skin: '" + written + "' beside it, of the model's name, is used");
    }
    if (mapping != aiTextureMapping_UV) {
      warn("material '" + std::string(m.GetName().C_Str()) +
           "': a texture with non-UV (projected) mapping is ignored");
      return ref;
    }
    ref.image = image_for(written, colour_key);
    if (ref.image < 0) return {};
    ref.texcoord = int(uv_index);
    ref.wrap_s = wrap_mode(modes[0]);
    ref.wrap_t = wrap_mode(modes[1]);
    aiUVTransform tr;
    if (m.Get(AI_MATKEY_UVTRANSFORM(type, 0), tr) == AI_SUCCESS) {
      ref.transform.offset = {tr.mTranslation.x, tr.mTranslation.y};
      ref.transform.scale = {tr.mScaling.x, tr.mScaling.y};
      ref.transform.rotation = tr.mRotation;
    }
    return ref;
  }

  Material material(const aiMaterial& m) {
    Material mat;
    mat.name = m.GetName().C_Str();
    aiColor4D c;
    if (m.Get(AI_MATKEY_BASE_COLOR, c) == AI_SUCCESS ||
        m.Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS)
      mat.base_color_factor = {c.r, c.g, c.b, c.a};
    float opacity = 1;
    if (m.Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS && opacity <= 0) {
      // In COLLADA that is 3ds Max's exporter writing <transparency> inverted
      // (Collada/earthCylindrical.DAE), not a surface meant to be unseen. Elsewhere it is what
      // the author wrote (AC3D's "trans 1": FlightGear's light halos and pick boxes).
      if (lower_extension(path_) == "dae") {
        warn("material '" + mat.name +
             "': opacity 0 (the material would be invisible) read as opaque; the exporter "
             "likely wrote transparency inverted");
        opacity = 1;
      } else {
        warn("material '" + mat.name + "': opacity 0: its surfaces bake fully transparent");
      }
    }
    if (opacity < 1) {
      mat.base_color_factor[3] *= opacity;
      mat.alpha_mode = AlphaMode::kBlend;
    }
    // Half-Life's masked textures (grates, foliage): palette entry 255 is cut out. assimp says
    // so with the texture flag UseAlpha and the entry's colour as the transparent colour; its
    // texels are all opaque.
    int flags = 0;
    aiColor3D key;
    const bool keyed = m.Get(AI_MATKEY_TEXFLAGS(aiTextureType_DIFFUSE, 0), flags) == AI_SUCCESS &&
                       (flags & aiTextureFlags_UseAlpha) &&
                       m.Get(AI_MATKEY_COLOR_TRANSPARENT, key) == AI_SUCCESS;
    const aiColor3D* colour_key = keyed ? &key : nullptr;
    mat.base_color_texture = texture(m, aiTextureType_BASE_COLOR, colour_key);
    if (!mat.base_color_texture.valid())
      mat.base_color_texture = texture(m, aiTextureType_DIFFUSE, colour_key);
    if (keyed && mat.base_color_texture.valid() && mat.alpha_mode == AlphaMode::kOpaque)
      mat.alpha_mode = AlphaMode::kMask;
    mat.normal_texture = texture(m, aiTextureType_NORMALS);
    if (!mat.normal_texture.valid() && m.GetTextureCount(aiTextureType_HEIGHT) > 0)
      warn("material '" + mat.name + "': a height (bump) map is ignored (only normal maps bake)");
    aiColor3D e;
    if (m.Get(AI_MATKEY_COLOR_EMISSIVE, e) == AI_SUCCESS) mat.emissive_factor = {e.r, e.g, e.b};
    float strength;
    if (m.Get(AI_MATKEY_EMISSIVE_INTENSITY, strength) == AI_SUCCESS && strength > 0)
      mat.emissive_strength = strength;
    mat.emissive_texture = texture(m, aiTextureType_EMISSIVE);
    if (mat.emissive_texture.valid() && mat.emissive_factor == Vec3{0, 0, 0})
      mat.emissive_factor = {1, 1, 1};
    // assimp's own scale for formats without PBR: a plain material is rough and not metallic.
    mat.metallic_factor = 0, mat.roughness_factor = 1;
    m.Get(AI_MATKEY_METALLIC_FACTOR, mat.metallic_factor);
    m.Get(AI_MATKEY_ROUGHNESS_FACTOR, mat.roughness_factor);
    mat.occlusion_texture = texture(m, aiTextureType_AMBIENT_OCCLUSION);
    if (!mat.occlusion_texture.valid()) mat.occlusion_texture = texture(m, aiTextureType_LIGHTMAP);
    if (m.GetTextureCount(aiTextureType_METALNESS) +
            m.GetTextureCount(aiTextureType_DIFFUSE_ROUGHNESS) >
        0)
      warn("material '" + mat.name +
           "': separate metalness/roughness maps are ignored (factors used)");
    if (m.GetTextureCount(aiTextureType_OPACITY) > 0)
      warn("material '" + mat.name + "': a separate opacity map is ignored");
    int two_sided = 0;
    if (m.Get(AI_MATKEY_TWOSIDED, two_sided) == AI_SUCCESS) mat.double_sided = two_sided != 0;
    return mat;
  }

  Primitive primitive(const aiMesh& mesh) {
    Primitive p;
    p.material = int(mesh.mMaterialIndex);
    p.positions.resize(mesh.mNumVertices);
    for (unsigned v = 0; v < mesh.mNumVertices; ++v)
      p.positions[v] = {mesh.mVertices[v].x, mesh.mVertices[v].y, mesh.mVertices[v].z};
    if (mesh.mNormals) {
      p.normals.resize(mesh.mNumVertices);
      for (unsigned v = 0; v < mesh.mNumVertices; ++v)
        p.normals[v] = {mesh.mNormals[v].x, mesh.mNormals[v].y, mesh.mNormals[v].z};
    }
    for (unsigned s = 0; s < AI_MAX_NUMBER_OF_TEXTURECOORDS && mesh.mTextureCoords[s]; ++s) {
      auto& uv = p.uvs.emplace_back(mesh.mNumVertices);
      // assimp's UVs have v up; the scene model follows glTF (v down).
      for (unsigned v = 0; v < mesh.mNumVertices; ++v)
        uv[v] = {mesh.mTextureCoords[s][v].x, 1.0f - mesh.mTextureCoords[s][v].y};
    }
    if (mesh.mColors[0]) {
      p.colors.resize(mesh.mNumVertices);
      for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
        const aiColor4D& c = mesh.mColors[0][v];
        p.colors[v] = {c.r, c.g, c.b, c.a};
      }
    }
    p.indices.reserve(size_t(mesh.mNumFaces) * 3);
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) {
        ++skipped_faces_;
        continue;
      }
      p.indices.insert(p.indices.end(), face.mIndices, face.mIndices + 3);
    }
    if (mesh.mNumBones > 0) ++boned_meshes_;
    return p;
  }

  // The scene mesh for a node's list of assimp meshes (shared by nodes with the same list).
  int mesh_for(const aiNode& node) {
    std::vector<unsigned> key(node.mMeshes, node.mMeshes + node.mNumMeshes);
    auto it = meshes_.find(key);
    if (it != meshes_.end()) return it->second;
    Mesh mesh;
    mesh.name = node.mName.C_Str();
    for (unsigned i : key) {
      if (i >= ai_.mNumMeshes) continue;
      Primitive p = primitive(*ai_.mMeshes[i]);
      if (!p.indices.empty()) mesh.primitives.push_back(std::move(p));
    }
    scene_.meshes.push_back(std::move(mesh));
    return meshes_[key] = int(scene_.meshes.size() - 1);
  }

  Status add_node(const aiNode& ai_node, int parent) {
    // assimp hands a tree, but a hostile file may still nest without end.
    if (++depth_ > 4096) return Error(ErrorCode::kCorrupt, path_ + ": node hierarchy too deep");
    int index = int(scene_.nodes.size());
    Node node;
    node.name = ai_node.mName.C_Str();
    node.local = to_mat4(ai_node.mTransformation);
    scene_.nodes.push_back(node);
    if (parent >= 0) scene_.nodes[parent].children.push_back(index);
    if (ai_node.mNumMeshes > 0) {
      int mesh = mesh_for(ai_node);
      scene_.nodes[index].mesh = mesh;
    }
    for (unsigned c = 0; c < ai_node.mNumChildren; ++c)
      VT_RETURN_IF_ERROR(add_node(*ai_node.mChildren[c], index));
    --depth_;
    return Status::Ok();
  }

  std::string path_, folder_;
  const aiScene& ai_;
  Dropped dropped_;
  Scene scene_;
  std::map<std::string, int> images_;
  std::map<std::vector<unsigned>, int> meshes_;
  uint64_t skipped_faces_ = 0;
  int boned_meshes_ = 0;
  int depth_ = 0;
};

}  // namespace

// A Doom 3 MD5 mesh's indices, before assimp reads them: its reader takes every `tri`, `vert`
// and `weight` index as given (an index past the count grows the array to it: 2^32 - 1 ran it
// out of memory), leaves a face the file does not list without indices (it then read through a
// null pointer), and follows a face's second and third vertex, a vertex's weights and a
// weight's joint unchecked; it copies a word (a shader) or a joint's quoted name into a
// 1,024-byte string unchecked, and a lone `"` as a word of -1 bytes. Each mesh block's counts,
// and every index against its count and the file's joints, are checked; a face must be listed;
// words are shorter than 1,000 characters and a joint names itself in quotes. Numbers are read
// as assimp reads them (leading digits).
Expected<std::vector<std::string>> md5_mesh_names(const std::string& path) {
  std::vector<std::string> names;
  Expected<std::vector<uint8_t>> bytes = read_file(path);
  if (!bytes.ok()) return names;
  const std::string text(bytes->begin(), bytes->end());
  // Leading decimal digits of `w` (0 without any), saturated far above any count.
  auto number = [](const std::string& w) {
    uint64_t v = 0;
    for (size_t i = 0;
         i < w.size() && std::isdigit(static_cast<unsigned char>(w[i])) && v < (1ull << 40); ++i)
      v = v * 10 + uint64_t(w[i] - '0');
    return v;
  };
  auto refuse = [&](size_t line, const std::string& what) {
    return Error(ErrorCode::kCorrupt, path + ": MD5 line " + std::to_string(line) + ": " + what);
  };
  const uint64_t most = text.size();  // every entry takes a line of its own
  uint64_t joints = 0;
  bool in_joints = false, in_mesh = false;
  uint64_t verts = 0, tris = 0, weights = 0;
  uint64_t weights_named = 0;  // the current mesh's vertices' weights end here (numweights follows)
  size_t weights_line = 0;
  std::vector<bool> listed;  // the current mesh's faces given
  std::string name;          // the current mesh's, from its `// meshes: NAME` comment
  size_t line_no = 0, at = 0;
  while (at < text.size()) {
    // assimp ends a line at a zero byte, a form feed or a carriage return as well.
    size_t end = text.find_first_of(std::string_view("\n\r\f\0", 4), at);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(at, end - at);
    line_no += at == 0 || text[at - 1] == '\n';
    at = end + 1;
    std::vector<std::string> w;
    for (size_t i = 0; i < line.size();) {
      while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      const size_t s = i;
      while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      if (i > s) w.push_back(line.substr(s, i - s));
    }
    if (w.empty()) continue;
    if (w[0].rfind("//", 0) == 0) {
      const size_t tag = line.find("// meshes:");
      if (in_mesh && tag != std::string::npos && line.find_first_not_of(" \t") == tag) {
        name = line.substr(tag + 10);
        name.erase(0, name.find_first_not_of(" \t"));
        name.erase(name.find_last_not_of(" \t") + 1);
      }
      continue;
    }
    for (const std::string& word : w)
      if (word.size() >= 1000 || word == "\"")
        return refuse(line_no, word.size() >= 1000
                                   ? "a word of " + std::to_string(word.size()) + " characters"
                                   : "a lone quotation mark");
    if (in_joints) {
      if (w[0] == "}") {
        in_joints = false;
      } else {
        const size_t open = line.find('"'), close = line.find('"', open + 1);
        if (open == std::string::npos || close == std::string::npos || close - open > 1000)
          return refuse(line_no, "a joint without its name in quotation marks");
        ++joints;
      }
      continue;
    }
    if (!in_mesh) {
      if (w[0] == "joints") in_joints = true;
      if (w[0] == "mesh")
        in_mesh = true, verts = tris = weights = weights_named = 0, listed.clear(), name.clear();
      continue;
    }
    if (w[0] == "}") {
      const auto missing = std::find(listed.begin(), listed.end(), false);
      if (missing != listed.end())
        return refuse(line_no, "tri " + std::to_string(missing - listed.begin()) + " of " +
                                   std::to_string(tris) + " is not given");
      if (weights_named > weights)
        return refuse(weights_line,
                      "a vertex names weights past numweights " + std::to_string(weights));
      if (verts > 0 && tris > 0) names.push_back(name);  // assimp skips the others
      in_mesh = false;
    } else if (w[0] == "numverts" || w[0] == "numtris" || w[0] == "numweights") {
      const uint64_t n = w.size() > 1 ? number(w[1]) : 0;
      if (n > most)
        return refuse(line_no, w[0] + " " + std::to_string(n) + " is more than the file holds");
      (w[0] == "numverts" ? verts : w[0] == "numtris" ? tris : weights) = n;
      if (w[0] == "numtris") listed.assign(size_t(n), false);
    } else if (w[0] == "tri") {
      const uint64_t i = w.size() > 1 ? number(w[1]) : 0;
      if (i >= tris)
        return refuse(line_no,
                      "tri " + std::to_string(i) + " past numtris " + std::to_string(tris));
      listed[size_t(i)] = true;
      for (size_t k = 2; k < 5; ++k)
        if ((w.size() > k ? number(w[k]) : 0) >= verts)
          return refuse(line_no, "tri " + std::to_string(i) + " names a vertex past numverts " +
                                     std::to_string(verts));
    } else if (w[0] == "vert") {
      const uint64_t i = w.size() > 1 ? number(w[1]) : 0;
      const auto close = std::find(w.begin(), w.end(), ")");
      const uint64_t first = close != w.end() && close + 1 != w.end() ? number(*(close + 1)) : 0;
      const uint64_t count = close != w.end() && close + 2 < w.end() ? number(*(close + 2)) : 0;
      if (i >= verts)
        return refuse(line_no,
                      "vert " + std::to_string(i) + " past numverts " + std::to_string(verts));
      if (first + count > weights_named) weights_named = first + count, weights_line = line_no;
    } else if (w[0] == "weight") {
      const uint64_t i = w.size() > 1 ? number(w[1]) : 0;
      if (i >= weights)
        return refuse(
            line_no, "weight " + std::to_string(i) + " past numweights " + std::to_string(weights));
      if ((w.size() > 2 ? number(w[2]) : 0) >= joints)
        return refuse(line_no, "weight " + std::to_string(i) + " names a joint past the file's " +
                                   std::to_string(joints));
    }
  }
  return names;
}

// An Inter-Quake Model's sections against its size, before assimp reads them: its reader follows
// every offset and count the header and the meshes give without a check, so a crafted file had
// it read (or allocate) far past its buffer. Checked: the text, the meshes, the vertex arrays,
// each mesh's triangles and, for the arrays assimp reads (position, texture coordinates, normal,
// colour), each mesh's vertices; a mesh's material name ends inside the text. A file assimp
// refuses anyway (magic, version, size) is left to it (no names).
namespace iqm {
// Byte offsets of the header's fields (after the 16-byte magic), the header's and a mesh
// record's size (name, material, first and count of vertices, first and count of triangles).
constexpr size_t kVersion = 16, kFileSize = 20, kNumText = 28, kOfsText = 32, kNumMeshes = 36,
                 kOfsMeshes = 40, kNumArrays = 44, kOfsArrays = 52, kOfsTriangles = 60;
constexpr size_t kHeaderSize = 124, kMeshSize = 24;
}  // namespace iqm
Expected<std::vector<std::string>> iqm_mesh_names(const std::string& path) {
  std::vector<std::string> names;
  Expected<std::vector<uint8_t>> bytes = read_file(path);
  if (!bytes.ok()) return names;
  const std::vector<uint8_t>& b = *bytes;
  auto u32 = [&b](uint64_t at) { return read_u32(&b[size_t(at)]); };
  constexpr uint64_t kArray = 20, kTriangle = 12, kMesh = iqm::kMeshSize;
  if (b.size() < iqm::kHeaderSize || std::memcmp(b.data(), "INTERQUAKEMODEL", 16) != 0 ||
      u32(iqm::kVersion) != 2 || u32(iqm::kFileSize) != b.size())
    return names;
  // `count` entries of `unit` bytes from byte `start` (a double: no overflow) inside the file.
  auto inside = [&](const std::string& what, double start, uint64_t count, uint64_t unit) {
    if (start > double(b.size()))
      return Error(ErrorCode::kCorrupt, path + ": IQM " + what + " start past the end of the file");
    return check_backed(path + ": IQM " + what, count, unit, "the file after its start",
                        b.size() - uint64_t(start));
  };
  const uint64_t num_text = u32(iqm::kNumText), ofs_text = u32(iqm::kOfsText);
  const uint64_t num_meshes = u32(iqm::kNumMeshes), ofs_meshes = u32(iqm::kOfsMeshes);
  const uint64_t num_arrays = u32(iqm::kNumArrays), ofs_arrays = u32(iqm::kOfsArrays);
  const uint64_t ofs_triangles = u32(iqm::kOfsTriangles);
  VT_RETURN_IF_ERROR(inside("text", double(ofs_text), num_text, 1));
  VT_RETURN_IF_ERROR(inside("meshes", double(ofs_meshes), num_meshes, kMesh));
  VT_RETURN_IF_ERROR(inside("vertex arrays", double(ofs_arrays), num_arrays, kArray));
  // The arrays assimp reads (float positions, texture coordinates and normals; colours), each
  // attribute once: it allocates one for every array it reads, and a second one leaked the first.
  struct Array {
    uint64_t index, offset, size, unit;
  };
  std::vector<Array> read;
  bool seen[7] = {};
  for (uint64_t a = 0; a < num_arrays; ++a) {
    const uint64_t at = ofs_arrays + a * kArray;
    const uint32_t type = u32(at), format = u32(at + 8), size = u32(at + 12);
    constexpr uint32_t kUbyte = 1, kFloat = 7, kColor = 6;
    if (!((type <= 2 && format == kFloat && size >= (type == 1 ? 2u : 3u)) ||
          (type == kColor && (format == kUbyte || format == kFloat) && size >= 3)))
      continue;
    if (seen[type])
      return Error(ErrorCode::kCorrupt, path + ": IQM vertex array " + std::to_string(a) +
                                            " repeats an earlier array's attribute");
    seen[type] = true;
    read.push_back({a, u32(at + 16), size, format == kFloat ? 4u : 1u});
  }
  for (uint64_t m = 0; m < num_meshes; ++m) {
    const uint64_t at = ofs_meshes + m * kMesh;
    const uint64_t material = u32(at + 4), first_vertex = u32(at + 8), vertices = u32(at + 12);
    const uint64_t first_triangle = u32(at + 16), triangles = u32(at + 20);
    const std::string mesh = "mesh " + std::to_string(m);
    if (material >= num_text ||
        !std::memchr(b.data() + ofs_text + material, 0, num_text - material))
      return Error(ErrorCode::kCorrupt,
                   path + ": IQM " + mesh + "'s material name is not in the text");
    VT_RETURN_IF_ERROR(inside(mesh + "'s triangles",
                              double(ofs_triangles) + double(first_triangle) * kTriangle, triangles,
                              kTriangle));
    for (const Array& r : read)
      VT_RETURN_IF_ERROR(inside(mesh + "'s vertices in array " + std::to_string(r.index),
                                double(r.offset) + double(first_vertex) * double(r.size * r.unit),
                                vertices, r.size * r.unit));
    // Its name: an offset into the text (not read by assimp: an unending one is cut; one
    // outside the text leaves the model without names).
    const uint64_t name = u32(at);
    const char* text = reinterpret_cast<const char*>(b.data() + ofs_text);
    if (name < num_text) names.emplace_back(text + name, strnlen(text + name, num_text - name));
  }
  if (names.size() != num_meshes) names.clear();
  return names;
}

namespace {

// An OFF file's vertex and face counts against its size, before assimp allocates for them: a
// 309-byte file declaring 353,535,235,358 vertices (assimp's own invalid/OutOfMemory.off) made
// it take 16 GB and 90 s. ASCII OFF: every vertex takes at least "0 0 0\n", every face "0\n".
Status check_off_counts(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(4096, '\0');
  head.resize(size_t(in.read(head.data(), std::streamsize(head.size())).gcount()));
  std::error_code ec;
  const uint64_t size = std::filesystem::file_size(path, ec);
  // The first words outside comments: the keyword ([ST][C][N][4][n]OFF, optional), the counts.
  std::vector<std::string> words;
  bool comment = false;
  for (size_t i = 0; i < head.size() && words.size() < 4; ++i) {
    const char c = head[i];
    if (c == '#') comment = true;
    if (c == '\n') comment = false;
    if (comment || std::isspace(static_cast<unsigned char>(c))) {
      if (!words.empty() && !words.back().empty()) words.emplace_back();
      continue;
    }
    if (words.empty()) words.emplace_back();
    words.back() += c;
  }
  const size_t first = !words.empty() && words[0].find("OFF") != std::string::npos ? 1 : 0;
  // A binary OFF, or counts that do not parse: assimp says what it finds.
  if (ec || words.size() < first + 2 || (first == 1 && words[1] == "BINARY")) return Status::Ok();
  uint64_t counts[2] = {};
  for (int k = 0; k < 2; ++k) {
    const std::string& w = words[first + k];
    if (std::from_chars(w.data(), w.data() + w.size(), counts[k]).ec != std::errc())
      return Status::Ok();
  }
  VT_RETURN_IF_ERROR(check_backed(path + ": OFF vertices", counts[0], 6, "the file", size));
  VT_RETURN_IF_ERROR(check_backed(path + ": OFF faces", counts[1], 2, "the file", size));
  VT_RETURN_IF_ERROR(check_ceiling(path + ": OFF vertices", counts[0], kMaxVertices, "vertices"));
  return check_ceiling(path + ": OFF faces", counts[1], kMaxIndices / 3, "faces");
}

// Quake 2 stores a model's texture coordinates as signed 16-bit texels (a vertex may lie left of
// or above the skin, the texture repeating there); assimp 5.2 reads them unsigned, so -4 became
// 65532 / width: UFO: Alien Invasion's hull1.md2 had u up to 256 on a 256-wide skin, triangles
// spanning the texture 256 times (baked so, and the atlas sized for it: 15,360 texels a side for
// a 1024 skin). Folds every coordinate past 32767 texels back by 65536, from the header's skin
// size (assimp's divisor; 1 when the header gives 0).
void repair_md2_texture_coordinates(const std::string& path, aiScene& scene) {
  uint8_t header[20] = {};
  std::ifstream in(path, std::ios::binary);
  if (!in.read(reinterpret_cast<char*>(header), sizeof header) ||
      std::memcmp(header, "IDP2", 4) != 0)
    return;
  const uint32_t w = read_u32(header + 8), h = read_u32(header + 12);
  const double width = w ? w : 1, height = h ? h : 1;
  for (unsigned i = 0; i < scene.mNumMeshes; ++i) {
    aiMesh& m = *scene.mMeshes[i];
    if (!m.mTextureCoords[0]) continue;
    for (unsigned v = 0; v < m.mNumVertices; ++v) {
      aiVector3D& uv = m.mTextureCoords[0][v];
      const double s = double(uv.x) * width, t = (1.0 - double(uv.y)) * height;  // assimp's map
      if (s >= 32767.5) uv.x = float((s - 65536) / width);
      if (t >= 32767.5) uv.y = float(1.0 - (t - 65536) / height);
    }
  }
}

// Deletes the meshes without vertices or faces (an STL's empty solid, an exporter's empty
// geometry) and the nodes' references to them: assimp's validation refuses a whole scene over
// one. A null entry goes too (assimp's MD3 reader leaves one for an empty surface that is not
// its last). Returns how many went.
unsigned drop_empty_meshes(aiScene& scene) {
  std::vector<int> remap(scene.mNumMeshes, -1);
  unsigned kept = 0;
  for (unsigned i = 0; i < scene.mNumMeshes; ++i) {
    aiMesh* m = scene.mMeshes[i];
    if (!m || m->mNumVertices == 0 || m->mNumFaces == 0) {
      delete m;
      continue;
    }
    remap[i] = int(kept);
    scene.mMeshes[kept++] = m;
  }
  const unsigned dropped = scene.mNumMeshes - kept;
  scene.mNumMeshes = kept;
  if (dropped == 0) return 0;
  std::vector<aiNode*> stack = {scene.mRootNode};
  while (!stack.empty()) {
    aiNode* node = stack.back();
    stack.pop_back();
    if (!node) continue;
    unsigned n = 0;
    for (unsigned k = 0; k < node->mNumMeshes; ++k)
      if (node->mMeshes[k] < remap.size() && remap[node->mMeshes[k]] >= 0)
        node->mMeshes[n++] = unsigned(remap[node->mMeshes[k]]);
    node->mNumMeshes = n;
    stack.insert(stack.end(), node->mChildren, node->mChildren + node->mNumChildren);
  }
  return dropped;
}

// Deletes an aiScene array of owned pointers (animations, lights, cameras) and empties it.
template <class T>
void drop(T**& items, unsigned& count) {
  for (unsigned i = 0; i < count; ++i) delete items[i];
  delete[] items;
  items = nullptr;
  count = 0;
}

}  // namespace

bool assimp_reads(const std::string& extension) {
  Assimp::Importer importer;
  return importer.IsExtensionSupported("." + extension);
}

Expected<Scene> load_assimp(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    return Error(ErrorCode::kNotFound, path + ": cannot open (no such file)");
  const std::string ext = lower_extension(path);
  if ((ext == "irr" || ext == "irrmesh") && aiGetVersionMajor() * 100 + aiGetVersionMinor() < 503)
    return Error(
        ErrorCode::kUnsupported,
        path + ": Irrlicht scenes and meshes (.irr, .irrmesh) are not supported with assimp " +
            std::to_string(aiGetVersionMajor()) + "." + std::to_string(aiGetVersionMinor()) +
            ", whose reader of them finds no meshes (assimp issues 4553 and 5014, fixed "
            "in 5.3); bake the meshes the scene names (.3ds, .x, .b3d, .obj) instead");
  if (ext == "off") VT_RETURN_IF_ERROR(check_off_counts(path));
  if (ext == "iqm") VT_RETURN_IF_ERROR(iqm_mesh_names(path).status());
  if (ext == "md5mesh") VT_RETURN_IF_ERROR(md5_mesh_names(path).status());
  Assimp::Importer importer;
  importer.SetIOHandler(new FilesAsAssimpReadsThem);  // the importer owns it
  // Points and lines are dropped by SortByPType; normals are made only where a mesh has none.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  // FindInvalidData would drop a UV set whose coordinates are all equal (a Quake 3 MD3 flare or
  // muzzle flash samples one texel of its texture): the material still reads it, so keep it.
  importer.SetPropertyBool(AI_CONFIG_PP_FID_IGNORE_TEXTURECOORDS, true);
  const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                         aiProcess_SortByPType | aiProcess_GenSmoothNormals |
                         aiProcess_ValidateDataStructure | aiProcess_FindInvalidData;
  // Read, drop the animations, then post-process: the bake takes the rest pose, and assimp's
  // validation refuses a whole model over an animation's key past its end (Minetest's B3D
  // characters: key 221 of a 220-frame animation).
  const aiScene* ai = importer.ReadFile(path, 0);
  const unsigned animations = ai ? ai->mNumAnimations : 0;
  // An animation-only file (Sauerbraten's and Quake's IQM/MD5 animation files beside the
  // model) fails assimp's validation with "aiScene::mNumMeshes is 0".
  if (ai && ai->mNumMeshes == 0) {
    return Error(ErrorCode::kInvalidArgument,
                 path + ": no meshes: nothing to bake" +
                     (animations > 0 ? " (the file holds " + std::to_string(animations) +
                                           " animations only: bake the model they animate)"
                                     : std::string()));
  }
  // Lights, cameras and empty meshes go too: the bake ignores them (the warnings count them),
  // and assimp's validation refused OpenGEX files over a light without a node and STL files
  // over an empty solid.
  const unsigned lights = ai ? ai->mNumLights : 0;
  unsigned empty_meshes = 0;
  if (ai) {
    aiScene* owned = const_cast<aiScene*>(ai);  // the importer's own scene, changed in place
    drop(owned->mAnimations, owned->mNumAnimations);
    drop(owned->mLights, owned->mNumLights);
    drop(owned->mCameras, owned->mNumCameras);
    empty_meshes = drop_empty_meshes(*owned);
    if (ext == "md2") repair_md2_texture_coordinates(path, *owned);
    if (owned->mNumMeshes == 0)
      return Error(ErrorCode::kInvalidArgument, path + ": no meshes: nothing to bake (its " +
                                                    std::to_string(empty_meshes) +
                                                    " meshes have no vertices or no faces)");
  }
  if (ai) ai = importer.ApplyPostProcessing(flags);
  if (!ai || !ai->mRootNode) {
    std::string why = importer.GetErrorString();
    // assimp's own words ("Validation failed: ...", "Invalid md3 file: ...") say little of whose
    // check failed without its name.
    return Error(ErrorCode::kCorrupt,
                 path + ": " + (why.empty() ? "assimp cannot read it" : "assimp: " + why));
  }
  if (ai->mFlags & AI_SCENE_FLAGS_INCOMPLETE)
    return Error(ErrorCode::kCorrupt, path + ": assimp read an incomplete scene (no meshes?)");
  return AssimpScene(path, *ai, {animations, lights, empty_meshes}).convert();
}

}  // namespace vt::scene::detail
