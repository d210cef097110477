// Hostile inputs end to end (issue 20): a scene naming a texture above its folder tree is
// refused (exit 2) unless --allow-outside-paths; NaN UVs are an error naming the vertex, never
// baked black; a corrupt PNG exits 2 naming the file with no stray libpng line in the message
// (a scene's texture: naming the material and slot too);
// --fix-nonfinite error names the file and the layer; unwrap refuses a FIFO without blocking.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "tests/cli/cli_test_util.h"

namespace vt {
namespace {

using vt::testing::run_vtbake;
namespace fs = std::filesystem;

std::string fresh_dir(const std::string& name) {
  auto dir = fs::weakly_canonical(fs::temp_directory_path()) /
             ("vtbake_hostile_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

// A 4x4 RGB PNG written through OpenImageIO.
void write_png(const std::string& path) {
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out);
  OIIO::ImageSpec spec(4, 4, 3, OIIO::TypeDesc::UINT8);
  std::vector<uint8_t> texels(4 * 4 * 3, 128);
  ASSERT_TRUE(out->open(path, spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, texels.data()));
  out->close();
}

// dir/car/car.obj, a textured quad whose map_Kd is `map` (uv_u: the first vt's u).
std::string quad(const std::string& dir, const std::string& map, const std::string& uv_u = "0") {
  fs::create_directories(dir + "/car");
  std::ofstream(dir + "/car/car.obj") << "mtllib car.mtl\n"
                                         "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                         "vt " +
                                             uv_u +
                                             " 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                             "usemtl Paint\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
  std::ofstream(dir + "/car/car.mtl") << "newmtl Paint\nmap_Kd " + map + "\n";
  return dir + "/car/car.obj";
}

TEST(CliHostileInputs, TextureAboveTheSceneTreeIsRefusedUnlessAllowed) {
  const std::string dir = fresh_dir("outside");
  fs::create_directories(dir + "/assets");
  write_png(dir + "/secret.png");
  const std::string obj = quad(dir + "/assets", "../../secret.png");
  const std::string bake = "bake " + obj + " -o " + dir + "/q.vtpf --size 1 --unwrapped - ";
  auto r = run_vtbake(bake, true);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find(obj + ": material 'Paint' baseColorTexture image 0"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("is " + dir + "/secret.png, outside the scene's folder tree " + dir +
                       "/assets (a scene may name"),
            std::string::npos)
      << r.out;
  EXPECT_FALSE(fs::exists(dir + "/q.vtpf"));
  EXPECT_EQ(run_vtbake("-q " + bake + "--allow-outside-paths", true).exit_code, 0);
  EXPECT_TRUE(fs::exists(dir + "/q.vtpf"));
  // unwrap takes the same rule and flag.
  const std::string unwrap = "unwrap " + obj + " -o " + dir + "/u.glb --size 1";
  EXPECT_EQ(run_vtbake(unwrap, true).exit_code, 2);
  EXPECT_EQ(run_vtbake("-q " + unwrap + " --allow-outside-paths", true).exit_code, 0);
  fs::remove_all(dir);
}

TEST(CliHostileInputs, NanUvIsAnErrorNamingTheVertex) {
  const std::string dir = fresh_dir("nan_uv");
  const std::string obj = quad(dir, "tex.png", "nan");
  write_png(dir + "/car/tex.png");
  auto r = run_vtbake("bake " + obj + " -o " + dir + "/q.vtpf --size 1 --unwrapped -", true);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("primitive 0: vertex 0 has a non-finite TEXCOORD_0"), std::string::npos)
      << r.out;
  fs::remove_all(dir);
}

TEST(CliHostileInputs, CorruptPngExitsTwoNamingTheFile) {
  const std::string dir = fresh_dir("png");
  const std::string png = dir + "/bad.png";
  write_png(png);
  // Flip bytes inside the compressed IDAT payload (the header chunks stay valid).
  std::string bytes;
  {
    std::ifstream in(png, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  size_t idat = bytes.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  for (size_t i = idat + 6; i < idat + 12 && i < bytes.size(); ++i) bytes[i] = char(~bytes[i]);
  std::ofstream(png, std::ios::binary) << bytes;
  auto r = run_vtbake("build " + png + " -o " + dir + "/b.vtpf", true);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("vtbake build: " + png + ": "), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("PNG library error"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("libpng"), std::string::npos) << r.out;  // libpng's own stderr line
  EXPECT_NE(r.out.find(png + ": corrupt PNG: chunk 'IDAT'"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir + "/b.vtpf"));
  fs::remove_all(dir);
}

// A scene texture damaged in two ways: a flipped IDAT byte (stale CRC) and a cut-off file.
// Either is one error naming the material, the slot and the file before the transfer starts,
// exit 2, with no libpng line; --missing-textures warn does not bake past it (the file is there).
TEST(CliHostileInputs, CorruptSceneTextureNamesMaterialSlotAndFile) {
  const std::string dir = fresh_dir("scene_png");
  const std::string obj = quad(dir, "paint.png");
  const std::string png = dir + "/car/paint.png";
  write_png(png);
  std::string clean;
  {
    std::ifstream in(png, std::ios::binary);
    clean.assign(std::istreambuf_iterator<char>(in), {});
  }
  const size_t idat = clean.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  std::string flipped = clean;
  flipped[idat + 6] = char(~flipped[idat + 6]);
  const std::string bake = "bake " + obj + " -o " + dir + "/q.vtpf --size 1 --unwrapped -";
  for (const std::string& bytes : {flipped, clean.substr(0, idat + 8)}) {
    std::ofstream(png, std::ios::binary | std::ios::trunc) << bytes;
    for (const std::string& policy : {"", " --missing-textures warn"}) {
      auto r = run_vtbake(bake + policy, true);
      EXPECT_EQ(r.exit_code, 2) << r.out;
      EXPECT_NE(r.out.find("vtbake bake: " + obj + ": material 'Paint' baseColorTexture: " + png +
                           ": corrupt PNG: "),
                std::string::npos)
          << r.out;
      EXPECT_EQ(r.out.find("libpng"), std::string::npos) << r.out;
      EXPECT_EQ(r.out.find("PNG library error"), std::string::npos) << r.out;
      EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;  // one line
      EXPECT_FALSE(fs::exists(dir + "/q.vtpf"));
    }
  }
  std::ofstream(png, std::ios::binary | std::ios::trunc) << clean;
  EXPECT_EQ(run_vtbake("-q " + bake, true).exit_code, 0);
  fs::remove_all(dir);
}

TEST(CliHostileInputs, FixNonFiniteErrorNamesTheFileAndLayer) {
  const std::string dir = fresh_dir("nonfinite");
  const std::string exr = dir + "/hdr.exr";
  {
    auto out = OIIO::ImageOutput::create(exr);
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(8, 8, 3, OIIO::TypeDesc::FLOAT);
    std::vector<float> texels(8 * 8 * 3, 0.5f);
    texels[(2 * 8 + 5) * 3 + 1] = std::numeric_limits<float>::quiet_NaN();
    ASSERT_TRUE(out->open(exr, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, texels.data()));
    out->close();
  }
  auto r = run_vtbake(
      "build --layer emissive=" + exr + " -o " + dir + "/e.vtpf --codec raw --fix-nonfinite error",
      true);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find(exr + ": layer 'emissive': non-finite value nan at texel (5, 2) channel 1"),
            std::string::npos)
      << r.out;
  fs::remove_all(dir);
}

TEST(CliHostileInputs, UnwrapRefusesAFifoWithoutBlocking) {
  const std::string dir = fresh_dir("fifo");
  const std::string fifo = dir + "/pipe.obj";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto r = run_vtbake("unwrap " + fifo + " -o " + dir + "/u.glb", true);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find(fifo + " is a FIFO, not a regular file to read"), std::string::npos)
      << r.out;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace vt
