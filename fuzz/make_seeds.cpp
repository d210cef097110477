// Writes the fuzz targets' seed corpora: `vt_fuzz_seeds DIR` fills DIR/<target>/ with small valid
// inputs made by the project's own writers (a page file per codec and one with every codec,
// absent and constant pages; DCT tables and pages; a glTF and a GLB from the glTF exporter; OBJ
// with MTL; PLY in each encoding), so the corpora are never committed and follow the formats.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "format/layer_codec.h"
#include "format/page_file.h"
#include "fuzz/fuzz_dct.h"
#include "fuzz/fuzz_obj.h"
#include "scene/gltf_export.h"
#include "scene/scene.h"
#include "scene/scene_io_util.h"
#include "tests/scene/iqm_file.h"
#include "tests/scene/pcx_files.h"

namespace vt::fuzz {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "vt_fuzz_seeds: %s\n", what.c_str());
  std::exit(1);
}

void write(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  if (!out) fail(path.string() + ": cannot write");
}

std::string read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

LayerSpec layer(const char* name, uint8_t channels, TexelType type, PageCodec codec,
                RuntimeFormat runtime, uint32_t page_size) {
  LayerSpec l;
  l.name = name;
  l.channels = channels;
  l.texel_type = type;
  l.codec = codec;
  l.runtime_format = runtime;
  if (codec == PageCodec::kDct) {
    DctSettings settings;
    settings.channels = channels;
    settings.layout = channels >= 3 ? DctPlaneLayout::kYCoCg420 : DctPlaneLayout::kPlanes;
    auto tables = dct_make_tables(settings, int(page_size), int(page_size));
    if (!tables.ok()) fail(tables.status().message());
    l.codec_tables = dct_serialize_tables(**tables);
  }
  return l;
}

// 24 x 24 texels in 16-texel pages (payload 8, border 4): three levels, 14 pages per layer. Page
// k of a layer is stored, constant or absent by k % 5, so every index state appears.
void write_page_file(const fs::path& path, std::vector<LayerSpec> layers) {
  PageFileDesc desc;
  desc.geometry = {24, 24, 8, 4};
  desc.layers = std::move(layers);
  desc.metadata_json = R"({"tool":"vt_fuzz_seeds"})";
  const uint32_t ps = desc.geometry.page_size();
  auto writer = PageFileWriter::create(path.string(), desc);
  if (!writer.ok()) fail(writer.status().message());
  int k = 0;
  for (uint32_t level = 0; level < desc.geometry.level_count(); ++level)
    for (uint32_t y = 0; y < desc.geometry.pages_y(level); ++y)
      for (uint32_t x = 0; x < desc.geometry.pages_x(level); ++x, ++k)
        for (uint32_t l = 0; l < desc.layers.size(); ++l) {
          auto codec = LayerCodec::create(desc.layers[l], ps);
          if (!codec.ok()) fail(codec.status().message());
          std::vector<uint8_t> texels(codec->page_bytes());
          for (size_t i = 0; i < texels.size(); ++i) texels[i] = uint8_t(i * 7 + k * 31 + (i >> 6));
          Status s;
          if (k % 5 == 3) {
            s = (*writer)->add_constant_page({level, x, y}, l,
                                             std::span(texels.data(), codec->texel_bytes()));
          } else if (k % 5 != 4) {
            std::vector<uint8_t> coded;
            s = codec->encode(texels.data(), {}, coded);
            if (s.ok()) s = (*writer)->add_page({level, x, y}, l, coded);
          }
          if (!s.ok()) fail(s.message());
        }
  if (Status s = (*writer)->finish(); !s.ok()) fail(s.message());
}

void page_file_seeds(const fs::path& dir) {
  const uint32_t ps = 16;
  const LayerSpec raw =
      layer("albedo", 4, TexelType::kU8, PageCodec::kRaw, RuntimeFormat::kRgba8, ps);
  const LayerSpec raw_zstd =
      layer("lighting", 4, TexelType::kF16, PageCodec::kRawZstd, RuntimeFormat::kRgba16f, ps);
  const LayerSpec dct =
      layer("albedo", 3, TexelType::kU8, PageCodec::kDct, RuntimeFormat::kBc1, ps);
  const LayerSpec dct1 = layer("orm", 1, TexelType::kU8, PageCodec::kDct, RuntimeFormat::kBc4, ps);
  const LayerSpec bc =
      layer("normal", 2, TexelType::kU8, PageCodec::kBcZstd, RuntimeFormat::kBc5, ps);
  write_page_file(dir / "raw.vtpf", {raw});
  write_page_file(dir / "raw_zstd.vtpf", {raw_zstd});
  write_page_file(dir / "dct.vtpf", {dct, dct1});
  write_page_file(dir / "bc_zstd.vtpf", {bc});
  LayerSpec r = raw, z = raw_zstd, d = dct, b = bc;
  r.name = "custom", z.name = "emissive", d.name = "base", b.name = "normal";
  write_page_file(dir / "every_codec.vtpf", {d, b, z, r});
}

void dct_seeds(const fs::path& dir) {
  // Tables (bit 0 set) and pages for a few layouts, trained (bit 4) or not.
  const uint8_t headers[][3] = {{1, 75, 9},
                                {0, 75, 9},
                                {2 << 1, 50, 1},
                                {(6 << 1) | 16, 90, 9},
                                {(5 << 1) | 16, 30, 0},
                                {(7 << 1), 75, 18}};
  int n = 0;
  for (const auto& h : headers) {
    const dct_fuzz::Setup setup = dct_fuzz::setup_from(h);
    const DctTablesPtr tables = dct_fuzz::tables_for(setup);
    std::vector<uint8_t> body;
    if (h[0] & 1) {
      body = dct_serialize_tables(*tables);
    } else {
      std::vector<uint8_t> texels(size_t(setup.width) * setup.height * setup.settings.channels);
      for (size_t i = 0; i < texels.size(); ++i) texels[i] = uint8_t((i * 13) ^ (i >> 4));
      if (Status s = dct_encode_page(*tables, texels.data(), setup.width, setup.height, body);
          !s.ok())
        fail(s.message());
    }
    std::string bytes(reinterpret_cast<const char*>(h), 3);
    bytes.append(body.begin(), body.end());
    write(dir / ("dct_" + std::to_string(n++)), bytes);
  }
}

// Two triangles with UVs, normals and a textured material.
scene::Scene quad_scene() {
  scene::Primitive p;
  p.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  p.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  p.uvs = {{{0, 1}, {1, 1}, {1, 0}, {0, 0}}};
  p.indices = {0, 1, 2, 0, 2, 3};
  p.material = 0;
  scene::Material m;
  m.name = "painted";
  m.base_color_factor = {0.8f, 0.5f, 0.2f, 1};
  m.base_color_texture.image = 0;
  m.base_color_texture.transform.scale = {2, 2};
  scene::Image image;
  image.name = "albedo";
  image.uri = image.path = "albedo.png";
  scene::Scene s = scene::detail::single_mesh_scene("quad.gltf", "quad", {p}, {m});
  s.images.push_back(image);
  return s;
}

std::string base64_of(const std::string& bytes) {
  return scene::detail::base64_encode(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
}

void gltf_seeds(const fs::path& dir, const fs::path& scratch) {
  const scene::Scene s = quad_scene();
  if (Status st = scene::save_glb(s, (dir / "quad.glb").string()); !st.ok()) fail(st.message());
  // The text form with its buffer inlined as a data: URI, so that one input is the whole scene.
  if (Status st = scene::save_gltf(s, (scratch / "quad.gltf").string()); !st.ok())
    fail(st.message());
  std::string json = read(scratch / "quad.gltf");
  const std::string uri = "\"quad.bin\"";
  const size_t at = json.find(uri);
  if (at == std::string::npos) fail("quad.gltf does not name quad.bin");
  json.replace(
      at, uri.size(),
      "\"data:application/octet-stream;base64," + base64_of(read(scratch / "quad.bin")) + "\"");
  write(dir / "quad.gltf", json);
}

void obj_seeds(const fs::path& dir) {
  const std::string obj =
      "# quad\nmtllib m.mtl\no quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 0.5 0.5 0.5\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\ng front\nusemtl painted\ns 1\n"
      "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\nusemtl bare\nf -4 -3 -2 -1\nl 1 2\n";
  const std::string mtl =
      "newmtl painted\nKd 0.8 0.5 0.2\nKs 0.1 0.1 0.1\nNs 20\nd 1\nillum 2\n"
      "map_Kd -s 2 2 1 -o 0.5 0 0 \"albedo map.png\"\nmap_Bump -bm 0.5 normal.png\n"
      "Pr 0.4\nPm 0.1\nKe 0 0 0\nnewmtl bare\nKd 1 1 1\nTr 0.25\n";
  write(dir / "quad_mtl.obj", obj + std::string(kMtlMarker) + mtl);
  write(dir / "quad.obj", obj);
}

void ply_seeds(const fs::path& dir) {
  const std::string props =
      "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "property float s\nproperty float t\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
  write(dir / "ascii.ply",
        "ply\nformat ascii 1.0\ncomment seed\n" + props +
            "0 0 0 0 0 255 0 0\n1 0 0 1 0 0 255 0\n1 1 0 1 1 0 0 255\n0 1 0 0 1 9 9 9\n"
            "3 0 1 2\n4 0 1 2 3\n");
  for (const bool big : {false, true}) {
    std::string body;
    auto put = [&](const void* v, size_t n) {
      const char* b = static_cast<const char*>(v);
      for (size_t i = 0; i < n; ++i) body += big ? b[n - 1 - i] : b[i];
    };
    const float xyz[4][5] = {{0, 0, 0, 0, 0}, {1, 0, 0, 1, 0}, {1, 1, 0, 1, 1}, {0, 1, 0, 0, 1}};
    for (const auto& v : xyz) {
      for (float f : v) put(&f, 4);
      body += "\x80\x40\x20";
    }
    const int faces[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (const auto& f : faces) {
      body += char(3);
      for (int i : f) put(&i, 4);
    }
    write(dir / (big ? "binary_be.ply" : "binary_le.ply"),
          std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
              " 1.0\n" + props + body);
  }
}

// An ACC car part (a strip, texture layers, normals, refs with two UV pairs) under a moved and
// turned group, an AC3D polygon, a line and a light.
void ac3d_seeds(const fs::path& dir) {
  const std::string materials =
      "MATERIAL \"paint\" rgb 0.8 0.1 0.1  amb 0.2 0.2 0.2  emis 0 0 0  spec 0.5 0.5 0.5  shi 10  "
      "trans 0\nMATERIAL \"glass\" rgb 1 1 1  amb 1 1 1  emis 0.4 0.4 0.4  spec 0 0 0  shi 0  "
      "trans 0.5\n";
  write(dir / "car.acc",
        "AC3Db\n" + materials +
            "OBJECT world\nkids 2\nOBJECT group\nname \"body\"\nloc 1 0 0\n"
            "rot 0 -1 0 1 0 0 0 0 1\nkids 1\nOBJECT poly\nname \"door\"\n"
            "texture \"paint.png\" base\ntexture \"shadow.rgb\" tiled\n"
            "texture empty_texture_no_mapping skids\ntexture empty_texture_no_mapping shad\n"
            "texrep 2 1\ntexoff 0.5 0\ncrease 45\nnumvert 4\n0 0 0 0 0 1\n0 1 0 0 0 1\n"
            "1 0 0 0 0 1\n1 1 0 0 0 1\nnumsurf 1\nSURF 0x34\nmat 0\nrefs 5\n"
            "0 0 0 0 0\n1 0 1 0 1\n2 1 0 1 0\n3 1 1 1 1\n3 1 1 1 1\nkids 0\n"
            "OBJECT light\nname \"lamp\"\nloc 0 2 0\nkids 0\n");
  write(dir / "house.ac",
        "AC3Db\n" + materials +
            "OBJECT world\nkids 1\nOBJECT poly\nname \"wall\"\ndata 4\nwall\n"
            "texture \"wall.png\"\nnumvert 6\n0 0 0\n2 0 0\n2 1 0\n1 1 0\n1 2 0\n0 2 0\n"
            "numsurf 2\nSURF 0x20\nmat 1\nrefs 6\n2 1 0.5\n3 0.5 0.5\n4 0.5 1\n5 0 1\n"
            "0 0 0\n1 1 0\nSURF 0x2\nmat 0\nrefs 2\n0 0 0\n1 1 0\nkids 0\n");
}

void pcx_seeds(const fs::path& dir) {
  write(dir / "palette.pcx", test::pcx_paletted_3x2());
  write(dir / "rgb.pcx", test::pcx_rgb_3x1());
}

void iqm_seeds(const fs::path& dir) {
  write(dir / "two_meshes.iqm", test::IqmFile().bytes);
}

}  // namespace
}  // namespace vt::fuzz

int main(int argc, char** argv) {
  using namespace vt::fuzz;
  if (argc != 2) fail("usage: vt_fuzz_seeds DIR");
  const fs::path root = argv[1];
  for (const char* t : {"page_file", "dct", "gltf", "obj", "ply", "ac3d", "pcx", "iqm", "scratch"})
    fs::create_directories(root / t);
  page_file_seeds(root / "page_file");
  dct_seeds(root / "dct");
  gltf_seeds(root / "gltf", root / "scratch");
  obj_seeds(root / "obj");
  ply_seeds(root / "ply");
  ac3d_seeds(root / "ac3d");
  pcx_seeds(root / "pcx");
  iqm_seeds(root / "iqm");
  fs::remove_all(root / "scratch");
  return 0;
}
