// OBJ and MTL as exporters write them, on small files (and tiny PNGs) each test writes into a
// folder of its own: paths (backslashes, quotes, spaces, Windows drives, letter case), map
// options, the d/Tr rule, bump versus normal maps, PBR keys, vertex colours, missing MTLs and
// materials, UTF-16 text.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <optional>

#include "common/srgb.h"
#include "scene/scene.h"
#include "tests/scene/alloc_probe.h"

namespace vt::test {
namespace {

namespace fs = std::filesystem;

// A fresh folder for one test (ends with '/').
std::string folder(const std::string& name) {
  fs::path p = fs::path(::testing::TempDir()) / ("vt_obj_" + name);
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string() + "/";
}

void write_file(const std::string& path, const std::string& bytes) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path, std::ios::binary) << bytes;
}

uint32_t crc32(const std::string& s) {
  uint32_t c = 0xffffffffu;
  for (unsigned char b : s) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1)));
  }
  return ~c;
}

std::string be32(uint32_t v) {
  return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
}

std::string png_chunk(const std::string& type, const std::string& data) {
  return be32(uint32_t(data.size())) + type + data + be32(crc32(type + data));
}

// A PNG of `channels` 1 (grey) or 3 (RGB), every texel `texel`, zlib with one stored block.
std::string tiny_png(int w, int h, int channels, const std::vector<uint8_t>& texel) {
  std::string raw;
  for (int y = 0; y < h; ++y) {
    raw.push_back(0);  // filter: none
    for (int x = 0; x < w; ++x) raw.append(texel.begin(), texel.end());
  }
  uint32_t a = 1, b = 0;
  for (unsigned char ch : raw) {
    a = (a + ch) % 65521;
    b = (b + a) % 65521;
  }
  uint16_t len = uint16_t(raw.size());
  std::string z = {char(0x78),
                   char(0x01),
                   char(0x01),
                   char(len & 0xff),
                   char(len >> 8),
                   char(~len & 0xff),
                   char((~len >> 8) & 0xff)};
  z += raw + be32(b << 16 | a);
  std::string ihdr = be32(w) + be32(h) + std::string{8, char(channels == 1 ? 0 : 2), 0, 0, 0};
  return "\x89PNG\r\n\x1a\n" + png_chunk("IHDR", ihdr) + png_chunk("IDAT", z) +
         png_chunk("IEND", "");
}

// A unit quad's vertices and UVs, and its face.
const std::string kQuadVertices =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
const std::string kQuad = kQuadVertices + "f 1/1 2/2 3/3 4/4\n";

// Loads `obj` (written as a.obj next to `mtl`, written as a.mtl when not empty).
scene::Scene load(const std::string& dir, const std::string& mtl, const std::string& obj) {
  if (!mtl.empty()) write_file(dir + "a.mtl", mtl);
  write_file(dir + "a.obj", obj);
  auto s = scene::load_scene(dir + "a.obj");
  EXPECT_TRUE(s.ok()) << s.status().message();
  return s.ok() ? *s : scene::Scene{};
}

scene::Scene load_material(const std::string& dir, const std::string& mtl) {
  return load(dir, mtl, "mtllib a.mtl\n" + kQuadVertices + "usemtl m\nf 1/1 2/2 3/3 4/4\n");
}

// How many warnings contain every one of `parts`.
int warnings_with(const scene::Scene& s, std::initializer_list<std::string> parts) {
  int n = 0;
  for (const auto& w : s.warnings) {
    bool all = true;
    for (const auto& p : parts) all = all && w.find(p) != std::string::npos;
    n += all;
  }
  return n;
}

const std::string& image_path(const scene::Scene& s, const scene::TextureRef& t) {
  static const std::string none = "(no image)";
  return t.valid() ? s.images[t.image].path : none;
}

TEST(ObjMtl, PathsAsExportersWriteThem) {
  std::string dir = folder("paths");
  std::string png = tiny_png(2, 2, 3, {200, 100, 50});
  write_file(dir + "tex/wall.png", png);
  write_file(dir + "my tex.png", png);
  write_file(dir + "Rock.PNG", png);
  write_file(dir + "desk.png", png);
  scene::Scene s = load(dir,
                        "newmtl back slash\nmap_Kd .\\tex\\wall.png\n"
                        "newmtl quoted\nmap_Kd -clamp on \"my tex.png\"\n"
                        "newmtl spaces\nmap_Kd -o 0 0 my tex.png\n"
                        "newmtl case\nmap_Kd rock.png\n"
                        "newmtl drive\nmap_Kd C:\\Users\\art\\Desktop\\desk.png\n"
                        "newmtl missing\nmap_Kd textures\\gone.png\n",
                        "mtllib a.mtl\n" + kQuad);
  ASSERT_EQ(s.materials.size(), 6u);
  EXPECT_EQ(s.materials[0].name, "back slash");
  EXPECT_EQ(image_path(s, s.materials[0].base_color_texture), dir + "tex/wall.png");
  EXPECT_EQ(image_path(s, s.materials[1].base_color_texture), dir + "my tex.png");
  EXPECT_EQ(s.materials[1].base_color_texture.wrap_s, scene::WrapMode::kClampToEdge);
  EXPECT_EQ(s.materials[1].base_color_texture.wrap_t, scene::WrapMode::kClampToEdge);
  // One image per file, whoever names it.
  EXPECT_EQ(s.materials[2].base_color_texture.image, s.materials[1].base_color_texture.image);
  EXPECT_EQ(image_path(s, s.materials[3].base_color_texture), dir + "Rock.PNG");
  EXPECT_EQ(warnings_with(s, {"a.mtl", "material 'case'", "rock.png", "Rock.PNG", "case"}), 1);
  EXPECT_EQ(image_path(s, s.materials[4].base_color_texture), dir + "desk.png");
  EXPECT_EQ(
      warnings_with(s, {"material 'drive'", "C:\\Users\\art\\Desktop\\desk.png", dir + "desk.png"}),
      1);
  // A file that is nowhere keeps its path for the transfer to report.
  EXPECT_EQ(image_path(s, s.materials[5].base_color_texture), dir + "textures/gone.png");
  EXPECT_EQ(s.images[s.materials[5].base_color_texture.image].uri, "textures\\gone.png");
  EXPECT_EQ(s.warnings.size(), 2u);
}

TEST(ObjMtl, SeveralLibrariesAndLibraryNamesWithSpaces) {
  std::string dir = folder("libs");
  write_file(dir + "one.mtl", "newmtl first\nKd 1 0 0\n");
  write_file(dir + "two.mtl", "newmtl second\nKd 0 1 0\n");
  write_file(dir + "my materials.mtl", "newmtl Hard Shiny Plastic White \nKd 0 0 1\n");
  scene::Scene s = load(dir, "",
                        "mtllib one.mtl two.mtl\nmtllib my materials.mtl\n" + kQuadVertices +
                            "usemtl second\nf 1/1 2/2 3/3\n" +
                            "usemtl Hard Shiny Plastic White\nf 1/1 3/3 4/4\n");
  ASSERT_EQ(s.materials.size(), 3u);
  EXPECT_EQ(s.materials[2].name, "Hard Shiny Plastic White");
  const auto& prims = s.meshes[0].primitives;
  ASSERT_EQ(prims.size(), 2u);
  EXPECT_EQ(prims[0].material, 1);
  EXPECT_EQ(prims[1].material, 2);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
}

TEST(ObjMtl, MapOptionsBeforeTheFileName) {
  std::string dir = folder("options");
  write_file(dir + "a.png", tiny_png(2, 2, 3, {200, 100, 50}));
  write_file(dir + "n.png", tiny_png(2, 2, 3, {128, 128, 255}));
  scene::Scene s = load_material(
      dir,
      "newmtl m\nmap_Kd -blendu off -blendv on -boost 2 -texres 512 -cc off -imfchan r "
      "-o 0.25 0.5 -s 2 4 1 a.png\n"
      "map_Bump -bm 0.5 -mm 0 1 n.png\n"
      "newmtl changed\nmap_Kd -mm 0.1 0.9 -t 0.5 0 0 a.png\nmap_Ks a.png\nmap_Ns a.png\n");
  ASSERT_EQ(s.materials.size(), 2u);
  const auto& t = s.materials[0].base_color_texture;
  EXPECT_EQ(image_path(s, t), dir + "a.png");
  EXPECT_FLOAT_EQ(t.transform.scale[0], 2.0f);
  EXPECT_FLOAT_EQ(t.transform.scale[1], 4.0f);
  EXPECT_FLOAT_EQ(t.transform.offset[0], 0.25f);
  // MTL's v is up: v' = 4 v + 0.5 there is v' = 4 v + (1 - 4 - 0.5) in glTF's v-down.
  EXPECT_FLOAT_EQ(t.transform.offset[1], -3.5f);
  EXPECT_EQ(t.wrap_s, scene::WrapMode::kRepeat);
  EXPECT_EQ(image_path(s, s.materials[0].normal_texture), dir + "n.png");
  EXPECT_FLOAT_EQ(s.materials[0].normal_scale, 0.5f);
  EXPECT_TRUE(s.materials[1].base_color_texture.transform.identity());
  // One line for the material, naming what it loses.
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0], dir + "a.mtl: material 'changed': ignored (not baked): -mm on " +
                               "map_Kd, -t on map_Kd, map_Ks, map_Ns");
}

TEST(ObjMtl, BumpIsANormalMapUnlessItHoldsHeights) {
  std::string dir = folder("bump");
  write_file(dir + "normal.png", tiny_png(4, 4, 3, {128, 128, 255}));
  write_file(dir + "grey.png", tiny_png(4, 4, 3, {90, 90, 91}));
  write_file(dir + "height.png", tiny_png(4, 4, 1, {90}));
  scene::Scene s = load_material(dir,
                                 "newmtl m\nbump normal.png\n"
                                 "newmtl rgb_grey\nmap_bump grey.png\n"
                                 "newmtl one_channel\nmap_Bump height.png\n"
                                 "newmtl luminance\nbump -imfchan l normal.png\n"
                                 "newmtl norm\nnorm grey.png\n");
  ASSERT_EQ(s.materials.size(), 5u);
  EXPECT_EQ(image_path(s, s.materials[0].normal_texture), dir + "normal.png");
  EXPECT_FALSE(s.materials[1].normal_texture.valid());
  EXPECT_FALSE(s.materials[2].normal_texture.valid());
  EXPECT_FALSE(s.materials[3].normal_texture.valid());
  EXPECT_EQ(image_path(s, s.materials[4].normal_texture), dir + "grey.png");  // `norm` says so
  EXPECT_EQ(warnings_with(s, {"height map"}), 3);
  EXPECT_EQ(warnings_with(s, {"material 'one_channel'", "map_Bump 'height.png'"}), 1);
  EXPECT_EQ(s.images.size(), 2u);  // height maps add no image
}

TEST(ObjMtl, OpacityFromDAndTr) {
  std::string dir = folder("opacity");
  write_file(dir + "a.png", tiny_png(2, 2, 3, {1, 2, 3}));
  scene::Scene s = load_material(dir,
                                 "newmtl m\nKd 0.5 0.5 0.5\nTr 1.000000\n"
                                 "newmtl tr\nTr 0.25\n"
                                 "newmtl both\nd 0.5\nTr 0.2\n"
                                 "newmtl agree\nd 0.8\nTr 0.2\n"
                                 "newmtl map_d\nmap_Kd a.png\nmap_d -imfchan m a.png\n"
                                 "newmtl halo\nd -halo 0.5\n");
  ASSERT_EQ(s.materials.size(), 6u);
  // Tr 1 alone would hide the surface: read as MeshLab's opacity, with a warning.
  EXPECT_FLOAT_EQ(s.materials[0].base_color_factor[3], 1.0f);
  EXPECT_EQ(s.materials[0].alpha_mode, scene::AlphaMode::kOpaque);
  EXPECT_EQ(warnings_with(s, {"material 'm'", "Tr 1", "opacity"}), 1);
  EXPECT_FLOAT_EQ(s.materials[1].base_color_factor[3], 0.75f);
  EXPECT_EQ(s.materials[1].alpha_mode, scene::AlphaMode::kBlend);
  EXPECT_FLOAT_EQ(s.materials[2].base_color_factor[3], 0.5f);
  EXPECT_EQ(warnings_with(s, {"material 'both'", "disagree", "d (opacity) wins"}), 1);
  EXPECT_FLOAT_EQ(s.materials[3].base_color_factor[3], 0.8f);
  EXPECT_EQ(warnings_with(s, {"material 'agree'"}), 0);
  EXPECT_FLOAT_EQ(s.materials[4].base_color_factor[3], 1.0f);
  EXPECT_EQ(s.materials[4].alpha_mode, scene::AlphaMode::kBlend);  // alpha from map_Kd's alpha
  EXPECT_FLOAT_EQ(s.materials[5].base_color_factor[3], 0.5f);
  EXPECT_EQ(s.warnings.size(), 3u);
}

// The texels of an embedded PNG, as stored.
std::vector<uint8_t> embedded_texels(const scene::Image& im, int* w, int* h, int* channels) {
  OIIO::Filesystem::IOMemReader proxy(im.bytes.data(), im.bytes.size());
  OIIO::ImageSpec config, spec;
  config.attribute("oiio:UnassociatedAlpha", 1);  // the bytes as stored
  auto in = OIIO::ImageInput::create("png");
  const bool opened = in && in->set_ioproxy(&proxy) && in->open("packed.png", spec, config);
  EXPECT_TRUE(opened) << OIIO::geterror();
  if (!opened) return {};
  *w = in->spec().width, *h = in->spec().height, *channels = in->spec().nchannels;
  std::vector<uint8_t> px(size_t(*w) * *h * *channels);
  EXPECT_TRUE(in->read_image(0, 0, 0, *channels, OIIO::TypeDesc::UINT8, px.data()));
  return px;
}

TEST(ObjMtl, SeparateOpacityRoughnessAndMetallicMapsArePacked) {
  std::string dir = folder("packed");
  write_file(dir + "kd.png", tiny_png(2, 2, 3, {10, 20, 30}));
  write_file(dir + "mask.png", tiny_png(4, 4, 1, {200}));
  write_file(dir + "rough.png", tiny_png(2, 2, 1, {100}));
  write_file(dir + "metal.png", tiny_png(2, 2, 1, {50}));
  scene::Scene s = load_material(dir,
                                 "newmtl m\nmap_Kd -s 2 2 1 kd.png\nmap_d mask.png\n"
                                 "newmtl alpha_only\nKd 1 0 0\nmap_d mask.png\n"
                                 "newmtl pr_pm\nmap_Pr rough.png\nmap_Pm metal.png\n"
                                 "newmtl pm\nPr 0.5\nmap_Pm metal.png\n"
                                 "newmtl missing\nmap_Kd kd.png\nmap_d nothere.png\n");
  ASSERT_EQ(s.materials.size(), 5u);
  int w = 0, h = 0, c = 0;
  // map_Kd's colour and map_d's grey as alpha, at the larger size; map_Kd's options kept.
  const scene::Material& m = s.materials[0];
  ASSERT_TRUE(m.base_color_texture.valid());
  EXPECT_TRUE(s.images[m.base_color_texture.image].embedded());
  EXPECT_EQ(m.base_color_texture.transform.scale, (scene::Vec2{2, 2}));
  EXPECT_EQ(m.alpha_mode, scene::AlphaMode::kBlend);
  auto px = embedded_texels(s.images[m.base_color_texture.image], &w, &h, &c);
  ASSERT_EQ(w * h * c, 64);
  EXPECT_EQ(std::vector<uint8_t>(px.begin(), px.begin() + 4),
            (std::vector<uint8_t>{10, 20, 30, 200}));
  EXPECT_EQ(std::vector<uint8_t>(px.end() - 4, px.end()), (std::vector<uint8_t>{10, 20, 30, 200}));
  // map_d alone: white colour (Kd is the factor) with its alpha.
  px = embedded_texels(s.images[s.materials[1].base_color_texture.image], &w, &h, &c);
  ASSERT_EQ(c, 4);
  EXPECT_EQ(std::vector<uint8_t>(px.begin(), px.begin() + 4),
            (std::vector<uint8_t>{255, 255, 255, 200}));
  EXPECT_FLOAT_EQ(s.materials[1].base_color_factor[0], 1.0f);
  // map_Pr in G and map_Pm in B; a missing map is 1 so that its factor applies.
  const scene::Material& pr = s.materials[2];
  EXPECT_FLOAT_EQ(pr.metallic_factor, 1.0f);  // map_Pm without Pm
  px = embedded_texels(s.images[pr.metallic_roughness_texture.image], &w, &h, &c);
  ASSERT_EQ(c, 3);
  EXPECT_EQ(std::vector<uint8_t>(px.begin(), px.begin() + 3), (std::vector<uint8_t>{255, 100, 50}));
  const scene::Material& pm = s.materials[3];
  EXPECT_FLOAT_EQ(pm.roughness_factor, 0.5f);
  px = embedded_texels(s.images[pm.metallic_roughness_texture.image], &w, &h, &c);
  EXPECT_EQ(std::vector<uint8_t>(px.begin(), px.begin() + 3), (std::vector<uint8_t>{255, 255, 50}));
  // An unreadable map_d: map_Kd as it is, and a warning naming the file.
  EXPECT_EQ(image_path(s, s.materials[4].base_color_texture), dir + "kd.png");
  EXPECT_EQ(warnings_with(s, {"material 'missing'", "map_d", "nothere.png"}), 1);
  EXPECT_EQ(s.warnings.size(), 1u) << s.warnings[0];
}

TEST(ObjMtl, MeshLabWritesTrAsOpacity) {
  std::string dir = folder("meshlab");
  scene::Scene s = load_material(dir,
                                 "#\n# Wavefront material file\n# Converted by Meshlab Group\n#\n\n"
                                 "newmtl m\nKd 0.6 0.6 0.6\nTr 1.000000\n"
                                 "newmtl half\nTr 0.25\n");
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_FLOAT_EQ(s.materials[0].base_color_factor[3], 1.0f);
  EXPECT_EQ(s.materials[0].alpha_mode, scene::AlphaMode::kOpaque);
  EXPECT_FLOAT_EQ(s.materials[1].base_color_factor[3], 0.25f);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(ObjMtl, PbrExtensionKeys) {
  std::string dir = folder("pbr");
  write_file(dir + "rough.png", tiny_png(2, 2, 1, {100}));
  write_file(dir + "glow.png", tiny_png(2, 2, 3, {255, 0, 0}));
  scene::Scene s = load_material(dir,
                                 "newmtl m\nKd 0.2 0.4 0.6\nPr 0.3\nPm 0.7\nKe 2 4 1\nNs 90\n"
                                 "newmtl textured\nmap_Pr rough.png\nmap_Ke glow.png\n");
  ASSERT_EQ(s.materials.size(), 2u);
  const auto& m = s.materials[0];
  EXPECT_FLOAT_EQ(m.base_color_factor[1], 0.4f);
  EXPECT_FLOAT_EQ(m.roughness_factor, 0.3f);
  EXPECT_FLOAT_EQ(m.metallic_factor, 0.7f);
  EXPECT_FLOAT_EQ(m.emissive_factor[0], 0.5f);
  EXPECT_FLOAT_EQ(m.emissive_factor[1], 1.0f);
  EXPECT_FLOAT_EQ(m.emissive_factor[2], 0.25f);
  EXPECT_FLOAT_EQ(m.emissive_strength, 4.0f);
  const auto& t = s.materials[1];
  EXPECT_FLOAT_EQ(t.metallic_factor, 0.0f);
  EXPECT_EQ(image_path(s, t.metallic_roughness_texture), dir + "rough.png");
  EXPECT_EQ(image_path(s, t.emissive_texture), dir + "glow.png");
  EXPECT_FLOAT_EQ(t.emissive_factor[0], 1.0f);  // map_Ke without Ke
  EXPECT_FLOAT_EQ(t.emissive_strength, 1.0f);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(ObjMtl, VertexColoursAreSrgbEncoded) {
  std::string dir = folder("colours");
  scene::Scene s = load(dir, "",
                        "v 0 0 0 1 0.5 0\nv 1 0 0 0 0 0\nv 1 1 0 0.2 0.2 0.2\nv 0 1 0\n"
                        "f 1 2 3 4\n");
  ASSERT_EQ(s.meshes[0].primitives.size(), 1u);
  const auto& p = s.meshes[0].primitives[0];
  ASSERT_EQ(p.colors.size(), 4u);
  EXPECT_FLOAT_EQ(p.colors[0][0], 1.0f);
  EXPECT_FLOAT_EQ(p.colors[0][1], srgb_to_linear(0.5f));
  EXPECT_NEAR(p.colors[0][1], 0.2140f, 1e-4);
  EXPECT_FLOAT_EQ(p.colors[0][2], 0.0f);
  EXPECT_FLOAT_EQ(p.colors[0][3], 1.0f);
  EXPECT_FLOAT_EQ(p.colors[2][1], srgb_to_linear(0.2f));
  EXPECT_EQ(p.colors[3], (scene::Vec4{1, 1, 1, 1}));  // a vertex written without a colour
  EXPECT_TRUE(s.warnings.empty());

  scene::Scene bytes = load(folder("colours255"), "",
                            "v 0 0 0 255 128 0\nv 1 0 0 0 0 0\nv 1 1 0 51 51 51\nf 1 2 3\n");
  const auto& q = bytes.meshes[0].primitives[0];
  ASSERT_EQ(q.colors.size(), 3u);
  EXPECT_FLOAT_EQ(q.colors[0][1], srgb_to_linear(128.0f / 255.0f));
  EXPECT_EQ(warnings_with(bytes, {"a.obj", "0..255"}), 1);

  scene::Scene weight = load(folder("weight"), "", "v 0 0 0 1\nv 1 0 0 1\nv 1 1 0 1\nf 1 2 3\n");
  EXPECT_TRUE(weight.meshes[0].primitives[0].colors.empty());  // v x y z w: no colour
}

TEST(ObjMtl, MissingLibraryAndMissingMaterialAreWarned) {
  std::string dir = folder("missing");
  scene::Scene s =
      load(dir, "", "mtllib nowhere.mtl\n" + kQuadVertices + "usemtl wood\nf 1/1 2/2 3/3\n");
  ASSERT_EQ(s.meshes[0].primitives.size(), 1u);
  EXPECT_EQ(s.meshes[0].primitives[0].material, -1);
  EXPECT_EQ(warnings_with(s, {"a.obj:1", "nowhere.mtl", "defaults"}), 1);
  EXPECT_EQ(warnings_with(s, {"a.obj", "usemtl 'wood'", "default"}), 1);

  // A library that is not there, beside one with the OBJ's name (as assimp reads it).
  std::string own = folder("own_name");
  scene::Scene fallback = load(own, "newmtl wood\nKd 0.5 0.25 0\n",
                               "mtllib a.mat\n" + kQuadVertices + "usemtl wood\nf 1/1 2/2 3/3\n");
  EXPECT_EQ(fallback.meshes[0].primitives[0].material, 0);
  ASSERT_EQ(fallback.warnings.size(), 1u);
  EXPECT_EQ(fallback.warnings[0],
            own + "a.obj:1: mtllib 'a.mat' not found; using '" + own + "a.mtl' (the OBJ's name)");

  // usemtl before mtllib still finds the material; an unknown name is warned once.
  scene::Scene late = load(folder("late"), "newmtl stone\nKd 0.5 0.5 0.5\n",
                           kQuadVertices +
                               "usemtl stone\nf 1/1 2/2 3/3\nusemtl glass\nf 1/1 3/3 4/4\n"
                               "usemtl glass\nf 3/3 2/2 1/1\nmtllib a.mtl\n");
  const auto& prims = late.meshes[0].primitives;
  ASSERT_EQ(prims.size(), 2u);
  EXPECT_EQ(prims[0].material, -1);  // glass: default material first
  EXPECT_EQ(prims[0].triangle_count(), 2u);
  EXPECT_EQ(prims[1].material, 0);
  ASSERT_EQ(late.warnings.size(), 1u);
  EXPECT_NE(late.warnings[0].find("usemtl 'glass': not in its MTL libraries"), std::string::npos)
      << late.warnings[0];
}

TEST(ObjMtl, FacesWithoutUvsUnderATexturedMaterialBakeFromItsFactors) {
  // Faces without `vt` under a `map_Kd` material cannot sample it: they get a copy of the
  // material without the texture (the bake refused the whole model); faces with UVs under
  // another textured material keep theirs.
  std::string dir = folder("no_vt");
  write_file(dir + "wood.png", tiny_png(1, 1, 3, {200, 100, 50}));
  scene::Scene s = load(
      dir,
      "newmtl wood\nKd 0.5 0.25 0\nmap_Kd wood.png\n"
      "newmtl stone\nmap_Kd wood.png\n",
      "mtllib a.mtl\n" + kQuadVertices + "usemtl stone\nf 1/1 2/2 3/3\nusemtl wood\nf 1 3 4\n");
  bool textured = false, bare = false;
  for (const scene::Primitive& p : s.meshes[0].primitives) {
    ASSERT_GE(p.material, 0);
    const scene::Material& m = s.materials[size_t(p.material)];
    EXPECT_EQ(m.name, p.uvs.empty() ? "wood" : "stone");
    EXPECT_EQ(m.base_color_texture.valid(), !p.uvs.empty());
    if (p.uvs.empty()) {
      EXPECT_FLOAT_EQ(m.base_color_factor[1], 0.25f);
    }
    (p.uvs.empty() ? bare : textured) = true;
  }
  EXPECT_TRUE(textured && bare);
  EXPECT_EQ(warnings_with(s, {"a.obj", "has no UV set", "material 'wood'", "factors"}), 1);
}

TEST(ObjMtl, FacesWithoutUvsAmongFacesWithThemKeepOutOfTheTexture) {
  // One material, faces with and without `vt`: the faces without would have read the texel at
  // UV (0, 0) and baked that colour over their whole surface. They become a primitive of their
  // own under the untextured copy; the faces with UVs keep the texture and their UVs.
  std::string dir = folder("mixed_vt");
  write_file(dir + "wood.png", tiny_png(1, 1, 3, {200, 100, 50}));
  scene::Scene s = load(
      dir, "newmtl wood\nKd 0.5 0.25 0\nmap_Kd wood.png\n",
      "mtllib a.mtl\n" + kQuadVertices + "usemtl wood\nf 1/1 2/2 3/3\nf 1 3 4\nf 4/4 1/1 2/2\n");
  ASSERT_EQ(s.meshes[0].primitives.size(), 2u);
  size_t textured_triangles = 0, bare_triangles = 0;
  for (const scene::Primitive& p : s.meshes[0].primitives) {
    ASSERT_GE(p.material, 0);
    const scene::Material& m = s.materials[size_t(p.material)];
    EXPECT_EQ(m.name, "wood");
    EXPECT_EQ(m.base_color_texture.valid(), !p.uvs.empty());
    (p.uvs.empty() ? bare_triangles : textured_triangles) += p.indices.size() / 3;
    if (!p.uvs.empty()) {  // this quad's vt k sits at v k: uv = (x, 1 - y) after the flip
      ASSERT_EQ(p.uvs[0].size(), p.positions.size());
      for (size_t i = 0; i < p.positions.size(); ++i) {
        EXPECT_FLOAT_EQ(p.uvs[0][i][0], p.positions[i][0]);
        EXPECT_FLOAT_EQ(p.uvs[0][i][1], 1.0f - p.positions[i][1]);
      }
    }
  }
  EXPECT_EQ(textured_triangles, 2u);
  EXPECT_EQ(bare_triangles, 1u);
  EXPECT_EQ(warnings_with(s, {"a.obj", "has no UV set", "material 'wood'", "factors"}), 1);
}

TEST(ObjMtl, FacesMayNameElementsWrittenFurtherDown) {
  // Sweet Home 3D's catalogue truck: a face names `vt` 3773 when 3772 have been written; the
  // rest follow. A positive index is absolute and resolved once the whole file is read; a
  // negative one counts back from its own line.
  std::string dir = folder("forward");
  scene::Scene s = load(dir, "",
                        "s 1\nv 0 0 0\nv 1 0 0\nvt 0 0\nvt 1 0\n"
                        "f 1/1 2/2 3/3\n"      // v 3 and vt 3 come later
                        "f -2/-2 -1/-1 3/3\n"  // the same face, partly relative
                        "v 1 1 0\nvt 1 1\nv 0 1 0\nvt 0 1\n"
                        "f 1/1 3/3 4/4\n");
  ASSERT_EQ(s.meshes.size(), 1u);
  ASSERT_EQ(s.meshes[0].primitives.size(), 1u);
  const scene::Primitive& p = s.meshes[0].primitives[0];
  ASSERT_EQ(p.indices.size(), 9u);
  ASSERT_EQ(p.uvs.size(), 1u);
  // Both first faces are v 1, 2, 3 with vt 1, 2, 3: one set of three vertices.
  ASSERT_EQ(p.positions.size(), 4u);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(p.indices[size_t(i)], p.indices[size_t(i + 3)]);
  const scene::Vec3 want[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(p.positions[i], want[i]) << i;
    EXPECT_FLOAT_EQ(p.uvs[0][i][0], want[i][0]);
    EXPECT_FLOAT_EQ(p.uvs[0][i][1], 1.0f - want[i][1]);
  }

  // An index past the whole file's elements is still refused, naming the face's line.
  write_file(dir + "b.obj",
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1//1 2//2 3//1\n");
  auto bad = scene::load_scene(dir + "b.obj");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message(),
            dir + "b.obj:6: face index 2 out of range (the file has 1 'vn' lines)");
  // And a relative index before the first element, at its own line.
  write_file(dir + "c.obj", "v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n");
  auto before = scene::load_scene(dir + "c.obj");
  ASSERT_FALSE(before.ok());
  EXPECT_EQ(before.status().message(), dir + "c.obj:3: face index '-3' out of range");
}

TEST(ObjMtl, CornersWithoutNormalsFollowTheSmoothingGroups) {
  // A unit cube of six quads, wound outwards, no `vn`: under `s off` every face is flat (4
  // corners of its own, its axis normal); under `s 1` its 8 corners are shared and point along
  // the cube's diagonals; a `vn` given is kept.
  const std::string cube =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
      "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";
  std::string dir = folder("smoothing");
  scene::Scene flat = load(dir, "", "s off\n" + cube);
  const scene::Primitive& f = flat.meshes[0].primitives[0];
  ASSERT_EQ(f.positions.size(), 24u);
  ASSERT_EQ(f.normals.size(), 24u);
  for (size_t i = 0; i < f.indices.size(); i += 3) {
    const scene::Vec3 &a = f.positions[f.indices[i]], &b = f.positions[f.indices[i + 1]],
                      &c = f.positions[f.indices[i + 2]];
    for (int k = 0; k < 3; ++k) {  // the axis the face is constant along, and its side
      if (a[k] != b[k] || b[k] != c[k]) continue;
      for (size_t j = 0; j < 3; ++j) {
        const scene::Vec3& n = f.normals[f.indices[i + j]];
        for (int e = 0; e < 3; ++e) EXPECT_FLOAT_EQ(n[e], e == k ? a[k] * 2 - 1 : 0.0f) << i;
      }
    }
  }
  scene::Scene smooth = load(dir, "", "s 1\n" + cube);
  const scene::Primitive& m = smooth.meshes[0].primitives[0];
  ASSERT_EQ(m.positions.size(), 8u);
  ASSERT_EQ(m.normals.size(), 8u);
  for (size_t v = 0; v < 8; ++v)
    for (int e = 0; e < 3; ++e)
      EXPECT_NEAR(m.normals[v][e], (m.positions[v][e] * 2 - 1) / std::sqrt(3.0f), 1e-6) << v;
  // A corner with its own `vn` keeps it; the others are made.
  scene::Scene given = load(dir, "", "vn 0 1 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2 3\n");
  const scene::Primitive& g = given.meshes[0].primitives[0];
  ASSERT_EQ(g.normals.size(), 3u);
  EXPECT_EQ(g.normals[0], (scene::Vec3{0, 1, 0}));
  EXPECT_EQ(g.normals[1], (scene::Vec3{0, 0, 1}));
  // In units of 1e-18 (cross products far below what a normal is taken from unscaled): the same
  // flat normals, not +Z for every face.
  scene::Scene tiny = load(dir, "", "s off\nv 0 0 0\nv 0 1e-18 0\nv 0 0 1e-18\nf 1 2 3\n");
  const scene::Primitive& t = tiny.meshes[0].primitives[0];
  ASSERT_EQ(t.normals.size(), 3u);
  for (const scene::Vec3& n : t.normals) EXPECT_EQ(n, (scene::Vec3{1, 0, 0}));
}

// The same triangle as UTF-8, UTF-8 with a BOM, UTF-16 LE and BE with BOMs.
TEST(ObjMtl, Utf16AndBomText) {
  const std::string text = "# t\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n";
  auto utf16 = [&](bool big) {
    std::string out = big ? "\xfe\xff" : "\xff\xfe";
    for (char ch : text) {
      out.push_back(big ? '\0' : ch);
      out.push_back(big ? ch : '\0');
    }
    return out;
  };
  std::string dir = folder("utf16");
  for (const std::string& bytes : {text, "\xef\xbb\xbf" + text, utf16(false), utf16(true)}) {
    write_file(dir + "t.obj", bytes);
    auto s = scene::load_scene(dir + "t.obj");
    ASSERT_TRUE(s.ok()) << s.status().message();
    ASSERT_EQ(s->meshes[0].primitives.size(), 1u);
    EXPECT_EQ(s->meshes[0].primitives[0].triangle_count(), 1u);
    EXPECT_FLOAT_EQ(s->meshes[0].primitives[0].positions[1][0], 1.0f);
  }
  write_file(dir + "odd.obj", utf16(false) + "v");
  auto odd = scene::load_scene(dir + "odd.obj");
  ASSERT_FALSE(odd.ok());
  EXPECT_EQ(odd.status().code(), ErrorCode::kCorrupt);
  EXPECT_NE(odd.status().message().find("odd.obj: UTF-16"), std::string::npos);
}

// Old exporters: a Latin-1 material name (0xE6 is 'æ'), numbers with a malformed tail.
TEST(ObjMtl, Latin1NamesAndMalformedNumberTails) {
  std::string dir = folder("latin1");
  scene::Scene s = load(dir, "newmtl Terraind\xe6k\nKd 0.4 0.3 0.3\n",
                        "mtllib a.mtl\nv 0 0 0\nv +1e+2 0 0\nv 0 1 3.1+e2\n"
                        "usemtl Terraind\xe6k\nf 1 2 3\n");
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].name, "Terraind\xc3\xa6k");
  EXPECT_EQ(s.meshes[0].primitives[0].material, 0);
  EXPECT_FLOAT_EQ(s.meshes[0].primitives[0].positions[1][0], 100.0f);
  EXPECT_FLOAT_EQ(s.meshes[0].primitives[0].positions[2][2], 3.1f);
  EXPECT_EQ(warnings_with(s, {"a.mtl: not UTF-8: read as Latin-1"}), 1);
  EXPECT_EQ(warnings_with(s, {"a.obj: not UTF-8: read as Latin-1"}), 1);
}

// Fuzz finding (fuzz/fuzz_obj.cpp): an mtllib naming a folder made read_file ask for 2^63 bytes
// (a folder opens and reports that size). It is refused as not a regular file; the OBJ keeps
// its default material. An OBJ path that is a folder is refused the same way.
TEST(ObjMtl, LibraryThatIsAFolderIsRefusedBeforeAllocating) {
  const std::string dir = folder("mtl_folder");
  fs::create_directories(dir + "lib.mtl");
  write_file(dir + "a.obj", "mtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  std::optional<Expected<scene::Scene>> s;
  const size_t largest =
      largest_allocation_during([&] { s.emplace(scene::load_scene(dir + "a.obj")); });
  ASSERT_TRUE(s->ok()) << s->status().message();
  EXPECT_EQ((*s)->meshes[0].primitives[0].indices, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_LT(largest, size_t{1} << 20);

  fs::create_directories(dir + "b.obj");
  auto folder_obj = scene::load_scene(dir + "b.obj");
  ASSERT_FALSE(folder_obj.ok());
  EXPECT_EQ(folder_obj.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(folder_obj.status().message(), dir + "b.obj: not a regular file to read");
}

}  // namespace
}  // namespace vt::test
