// Colour configs: the built-in one (sRGB is the IEC 61966-2-1 curve, the 8-bit table and code
// boundaries give exactly what converting through OpenColorIO gives; ACES, gamma and BT.709
// spaces are real transforms) and an OpenColorIO config the test writes (file rules, aliases,
// errors), through to a build's stored texels.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "bake/build.h"
#include "bake/color.h"
#include "bake_test_util.h"
#include "format/page_file_inspect.h"
#include "tests/process_temp_dir.h"

namespace vt {
namespace {

namespace fs = std::filesystem;

double srgb_to_linear(double v) {
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

std::array<float, 3> convert(const ColorConfig& config, const std::string& from,
                             const std::string& to, std::array<float, 3> rgb) {
  auto c = config.converter(from, to);
  EXPECT_TRUE(c.ok()) << c.status().message();
  if (c.ok()) (*c)->apply(rgb.data(), 1, 3);
  return rgb;
}

// ACEScg to linear Rec.709 (Bradford D60 -> D65), as the ACES reference configs publish it.
constexpr double kAcescgToRec709[3][3] = {{1.70505099, -0.62179212, -0.08325887},
                                          {-0.13025642, 1.14080474, -0.01054832},
                                          {-0.02400336, -0.12896886, 1.15297223}};

fs::path temp_dir() {
  fs::path d = test::process_temp_dir("vt_color") /
               ::testing::UnitTest::GetInstance()->current_test_info()->name();
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// A small OCIO 2 config: reference linear Rec.709, ACEScg by its published matrix, an sRGB
// texture space under the name current configs use, a pure 2.2 power, data; a file rule sends
// "*_acescg.exr" to ACEScg.
const char* kUserConfig = R"(ocio_profile_version: 2

search_path: ""
strictparsing: true
luma: [0.2126, 0.7152, 0.0722]

roles:
  scene_linear: lin_rec709
  default: lin_rec709
  data: Raw
  color_picking: sRGB - Texture

file_rules:
  - !<Rule> {name: acescg, pattern: "*_acescg", extension: "exr", colorspace: ACEScg}
  - !<Rule> {name: Default, colorspace: default}

displays:
  sRGB:
    - !<View> {name: Raw, colorspace: Raw}
active_displays: []
active_views: []

colorspaces:
  - !<ColorSpace>
    name: lin_rec709
    isdata: false

  - !<ColorSpace>
    name: ACEScg
    aliases: [lin_ap1]
    isdata: false
    to_scene_reference: !<MatrixTransform> {matrix: [1.70505099, -0.62179212, -0.08325887, 0, -0.13025642, 1.14080474, -0.01054832, 0, -0.02400336, -0.12896886, 1.15297223, 0, 0, 0, 0, 1]}

  - !<ColorSpace>
    name: sRGB - Texture
    aliases: [srgb_tx]
    isdata: false
    to_scene_reference: !<ExponentWithLinearTransform> {gamma: 2.4, offset: 0.055}

  - !<ColorSpace>
    name: g22_rec709
    isdata: false
    to_scene_reference: !<ExponentTransform> {value: 2.2}

  - !<ColorSpace>
    name: Raw
    isdata: true
)";

std::string write_user_config(const fs::path& dir) {
  const std::string path = (dir / "studio.ocio").string();
  std::ofstream(path) << kUserConfig;
  return path;
}

TEST(Color, SrgbCurveIsTheStandardOne) {
  auto to_lin = ColorConverter::create("sRGB", "linear");
  ASSERT_TRUE(to_lin.ok()) << to_lin.status().message();
  for (int k = 0; k < 256; ++k) {
    float t[3] = {k / 255.0f, k / 255.0f, k / 255.0f};
    (*to_lin)->apply(t, 1, 3);
    EXPECT_NEAR(t[0], srgb_to_linear(k / 255.0), 2e-6) << k;
  }
  // Off the 8-bit codes (the OpenColorIO path, not the table).
  float t[3] = {0.5004f, 0.02f, 0.9f};
  (*to_lin)->apply(t, 1, 3);
  EXPECT_NEAR(t[0], srgb_to_linear(0.5004), 2e-6);
  EXPECT_NEAR(t[1], srgb_to_linear(0.02), 2e-6);
  // One sample at a time (the scene transfer): common/srgb.h's curve.
  float s[3] = {0.5004f, 0.02f, -0.1f};
  (*to_lin)->apply_rgb(s);
  EXPECT_NEAR(s[0], srgb_to_linear(0.5004), 2e-6);
  EXPECT_NEAR(s[1], srgb_to_linear(0.02), 2e-6);
  EXPECT_EQ(s[2], 0.0f);
  // Its table stays within 3e-7 of the curve everywhere (a few float roundings; the curve
  // itself above 1).
  double worst = 0;
  for (int i = 0; i <= 100000; ++i) {
    const float v = float(i) / 90000.0f;
    float rgb[3] = {v, v, v};
    (*to_lin)->apply_rgb(rgb);
    worst = std::max(worst, std::abs(double(rgb[0]) - double(srgb_to_linear(double(v)))));
  }
  EXPECT_LT(worst, 3e-7);
}

TEST(Color, RoundTripKeepsEveryCode) {
  auto to_lin = ColorConverter::create("srgb_texture", "scene_linear");
  auto to_srgb = ColorConverter::create("linear", "sRGB");
  ASSERT_TRUE(to_lin.ok() && to_srgb.ok());
  for (int k = 0; k < 256; ++k) {
    float t[4] = {k / 255.0f, k / 255.0f, k / 255.0f, k / 255.0f};
    (*to_lin)->apply(t, 1, 4);
    uint8_t out[4];
    (*to_srgb)->apply_to_u8(t, 1, 4, out);
    for (int c = 0; c < 4; ++c) ASSERT_EQ(out[c], k) << "channel " << c;
  }
}

TEST(Color, BoundariesMatchConvertingThenRounding) {
  auto to_srgb = ColorConverter::create("linear", "sRGB");
  ASSERT_TRUE(to_srgb.ok());
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.1f, 1.2f);
  for (int i = 0; i < 20000; ++i) {
    float t[3] = {u(rng), u(rng) * u(rng), std::pow(u(rng), 4.0f)};
    uint8_t fast[3];
    (*to_srgb)->apply_to_u8(t, 1, 3, fast);
    (*to_srgb)->apply(t, 1, 3);
    for (int c = 0; c < 3; ++c) {
      float v = t[c];
      uint8_t slow = !(v > 0) ? 0 : v >= 1 ? 255 : uint8_t(v * 255.0f + 0.5f);
      ASSERT_EQ(fast[c], slow) << "value " << t[c];
    }
  }
}

TEST(Color, BuiltinAcesSpacesAreTheirMatrices) {
  const ColorConfig& b = *ColorConfig::builtin();
  EXPECT_EQ(b.working_space(), "linear");
  for (int col = 0; col < 3; ++col) {
    std::array<float, 3> in{0, 0, 0};
    in[col] = 1;
    const auto out = convert(b, "ACEScg", "linear", in);
    for (int row = 0; row < 3; ++row) EXPECT_NEAR(out[row], kAcescgToRec709[row][col], 1e-5);
  }
  const auto red = convert(b, "ACEScg", "lin_rec709", {1, 0, 0});
  EXPECT_NEAR(red[0], 1.705, 1e-3);
  EXPECT_NEAR(red[1], -0.130, 1e-3);
  EXPECT_NEAR(red[2], -0.024, 1e-3);
  // AP0 to Rec.709 (Bradford), as published with the ACES reference configs.
  const auto ap0 = convert(b, "ACES2065-1", "linear", {1, 0, 0});
  EXPECT_NEAR(ap0[0], 2.52169, 1e-4);
  EXPECT_NEAR(ap0[1], -0.27648, 1e-4);
  EXPECT_NEAR(ap0[2], -0.01538, 1e-4);
  // White stays white; ACEScg and ACES2065-1 differ only by primaries.
  const auto white = convert(b, "ACES2065-1", "ACEScg", {1, 1, 1});
  for (float v : white) EXPECT_NEAR(v, 1.0, 1e-5);
  // Not per-channel: an 8-bit code goes through the matrix, not a grey table.
  auto c = b.converter("ACEScg", "linear");
  ASSERT_TRUE(c.ok());
  float t[3] = {1, 0, 0};
  (*c)->apply_rgb(t);
  EXPECT_NEAR(t[1], -0.130, 1e-3);
}

TEST(Color, BuiltinGammaAndRec709Curves) {
  const ColorConfig& b = *ColorConfig::builtin();
  EXPECT_NEAR(convert(b, "Gamma2.2", "linear", {0.5f, 0.5f, 0.5f})[0], 0.2176, 1e-4);
  EXPECT_NEAR(convert(b, "gamma 1.8", "linear", {0.5f, 0.5f, 0.5f})[0], std::pow(0.5, 1.8), 1e-5);
  // A gAMA the config has no space for is the same power over linear Rec.709.
  EXPECT_NEAR(convert(b, "Gamma2.6", "linear", {0.5f, 0.5f, 0.5f})[0], std::pow(0.5, 2.6), 1e-5);
  EXPECT_NEAR(convert(b, "linear", "Gamma2.6", {0.25f, 0.25f, 0.25f})[0], std::pow(0.25, 1 / 2.6),
              1e-5);
  // BT.709 OETF: V = 1.099 L^0.45 - 0.099 above the knee, 4.5 L below.
  EXPECT_NEAR(convert(b, "linear", "Rec709", {0.5f, 0.5f, 0.5f})[0],
              1.099 * std::pow(0.5, 0.45) - 0.099, 2e-4);
  EXPECT_NEAR(convert(b, "linear", "Rec709", {0.01f, 0.01f, 0.01f})[0], 0.045, 2e-4);
}

TEST(Color, BuiltinNamesAliasesAndRoles) {
  const ColorConfig& b = *ColorConfig::builtin();
  EXPECT_EQ(*b.resolve("scene_linear"), "linear");
  EXPECT_EQ(*b.resolve("Linear"), "linear");
  EXPECT_EQ(*b.resolve("lin_rec709"), "linear");
  EXPECT_EQ(*b.resolve("srgb_texture"), "sRGB");
  EXPECT_EQ(*b.resolve("data"), "raw");
  EXPECT_EQ(*b.resolve("Raw"), "raw");
  EXPECT_EQ(*b.resolve("ACES - ACEScg"), "ACEScg");
  EXPECT_EQ(*b.resolve("GAMMA2.2"), "Gamma2.2");
  EXPECT_TRUE(b.is_data("Non-Color"));
  EXPECT_FALSE(b.is_data("sRGB"));
  EXPECT_EQ(b.space_from_file_rules("a_acescg.exr"), "");
  EXPECT_EQ(b.texture_space("", "", false), "sRGB");
  EXPECT_EQ(b.texture_space("", "", true), "linear");
  EXPECT_EQ(b.texture_space("", "Gamma2.2", false), "Gamma2.2");
  auto raw = ColorConverter::create("raw", "sRGB");
  ASSERT_TRUE(raw.ok());
  EXPECT_TRUE((*raw)->is_identity());
  // The config serialises, and OpenColorIO reads it back with the same spaces.
  const fs::path dir = temp_dir();
  std::ofstream(dir / "builtin.ocio") << b.yaml();
  auto back = ColorConfig::load((dir / "builtin.ocio").string());
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ((*back)->color_spaces(), b.color_spaces());
  EXPECT_NEAR(convert(**back, "ACEScg", "linear", {1, 0, 0})[0], 1.705, 1e-3);
}

TEST(Color, UnknownSpaceIsAClearError) {
  auto c = ColorConverter::create("ProPhoto RGB", "linear");
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().code(), ErrorCode::kNotFound);
  EXPECT_NE(c.status().message().find("'ProPhoto RGB'"), std::string::npos);
  EXPECT_NE(c.status().message().find("ACEScg"), std::string::npos) << c.status().message();
}

TEST(Color, UserConfigFileRulesAliasesAndErrors) {
  const fs::path dir = temp_dir();
  auto loaded = ColorConfig::load(write_user_config(dir));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  const ColorConfig& u = **loaded;
  EXPECT_FALSE(u.is_builtin());
  EXPECT_EQ(u.working_space(), "lin_rec709");
  EXPECT_EQ(u.space_from_file_rules("/textures/wall_acescg.exr"), "ACEScg");
  EXPECT_EQ(u.space_from_file_rules("/textures/wall.exr"), "");  // the default rule only
  EXPECT_EQ(u.space_from_file_rules("/textures/wall_acescg.png"), "");
  EXPECT_EQ(u.texture_space("/t/wall_acescg.exr", "Linear", true), "ACEScg");
  EXPECT_EQ(u.texture_space("/t/wall.png", "sRGB", false), "sRGB");
  // Names found through the config, or through the names other tools give the same space.
  EXPECT_EQ(*u.resolve("srgb_tx"), "sRGB - Texture");
  EXPECT_EQ(*u.resolve("sRGB"), "sRGB - Texture");
  EXPECT_EQ(*u.resolve("linear"), "lin_rec709");
  EXPECT_EQ(*u.resolve("lin_ap1"), "ACEScg");
  EXPECT_EQ(*u.resolve("Gamma2.2"), "g22_rec709");
  EXPECT_EQ(*u.resolve("data"), "Raw");

  const auto red = convert(u, "ACEScg", u.working_space(), {1, 0, 0});
  EXPECT_NEAR(red[0], 1.705, 1e-3);
  EXPECT_NEAR(red[1], -0.130, 1e-3);
  EXPECT_NEAR(red[2], -0.024, 1e-3);
  EXPECT_NEAR(convert(u, "Gamma2.2", "scene_linear", {0.5f, 0.5f, 0.5f})[0], 0.2176, 1e-4);
  EXPECT_NEAR(convert(u, "sRGB", "linear", {0.5f, 0.5f, 0.5f})[0], srgb_to_linear(0.5), 2e-6);

  auto unknown = u.converter("ProPhoto RGB", "linear");
  ASSERT_FALSE(unknown.ok());
  const std::string& m = unknown.status().message();
  EXPECT_NE(m.find("'ProPhoto RGB'"), std::string::npos) << m;
  EXPECT_NE(m.find("studio.ocio"), std::string::npos) << m;
  EXPECT_NE(m.find("lin_rec709, ACEScg, sRGB - Texture, g22_rec709, Raw"), std::string::npos) << m;
}

TEST(Color, BadConfigsNameTheFileAndTheProblem) {
  const fs::path dir = temp_dir();
  auto missing = ColorConfig::load((dir / "none.ocio").string());
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("none.ocio"), std::string::npos);

  std::ofstream(dir / "garbage.ocio") << "ocio_profile_version: 2\ncolorspaces: [: {\n";
  auto garbage = ColorConfig::load((dir / "garbage.ocio").string());
  ASSERT_FALSE(garbage.ok());
  EXPECT_NE(garbage.status().message().find("garbage.ocio"), std::string::npos);

  std::string no_role = kUserConfig;
  no_role.replace(no_role.find("  scene_linear: lin_rec709\n"),
                  std::strlen("  scene_linear: lin_rec709\n"), "");
  std::ofstream(dir / "norole.ocio") << no_role;
  auto role = ColorConfig::load((dir / "norole.ocio").string());
  ASSERT_FALSE(role.ok());
  EXPECT_NE(role.status().message().find("norole.ocio"), std::string::npos);
  EXPECT_NE(role.status().message().find("scene_linear"), std::string::npos)
      << role.status().message();
}

// Stored float texels of level 0, layer 0 (raw codec).
std::vector<float> level0_floats(const std::string& path) {
  auto reader = PageFileReader::open(path);
  EXPECT_TRUE(reader.ok()) << reader.status().message();
  if (!reader.ok()) return {};
  auto level = extract_level(**reader, 0, 0);
  EXPECT_TRUE(level.ok()) << level.status().message();
  if (!level.ok()) return {};
  EXPECT_EQ(level->texel_type, TexelType::kF32);
  std::vector<float> out(level->texels.size() / sizeof(float));
  std::memcpy(out.data(), level->texels.data(), out.size() * sizeof(float));
  return out;
}

// A build with a user config: the file rule makes an "_acescg" EXR ACEScg, converted into the
// working space; the same file under another name is taken as its metadata says (linear).
TEST(Color, BuildConvertsByTheConfigsFileRules) {
  const fs::path dir = temp_dir();
  auto config = ColorConfig::load(write_user_config(dir));
  ASSERT_TRUE(config.ok()) << config.status().message();
  const std::array<float, 3> acescg = {0.5f, 0.4f, 0.3f};
  ImageInfo info;
  info.width = 8, info.height = 8, info.channels = 3, info.is_float = true;
  std::vector<float> texels;
  for (int i = 0; i < 64; ++i) texels.insert(texels.end(), acescg.begin(), acescg.end());
  MemoryImageSource mem(info, texels);
  for (const char* name : {"wall_acescg.exr", "wall.exr"}) {
    const std::string path = (dir / name).string();
    ASSERT_TRUE(write_image_file(mem, path).ok());
    auto src = open_image_file(path);
    ASSERT_TRUE(src.ok()) << src.status().message();
    BuildOptions o;
    o.color_config = *config;
    o.layers.push_back(test::layer_input(LayerSemantic::kAlbedo,
                                         std::shared_ptr<ImageSource>(std::move(src).value())));
    o.layers[0].color_space = (*config)->space_from_file_rules(path);
    o.codec.codec = CodecKind::kRaw;
    o.payload = 8;
    o.output = path + ".vtpf";
    auto sum = build_page_file(o);
    ASSERT_TRUE(sum.ok()) << sum.status().message();
    const std::vector<float> got = level0_floats(o.output);
    ASSERT_EQ(got.size(), 64u * 3);
    const bool rule = std::string(name) == "wall_acescg.exr";
    for (int c = 0; c < 3; ++c) {
      double want = acescg[c];
      if (rule) {
        want = 0;
        for (int k = 0; k < 3; ++k) want += kAcescgToRec709[c][k] * acescg[k];
      }
      EXPECT_NEAR(got[c], want, 1e-3) << name << " channel " << c;
    }
  }
}

// A PNG whose gAMA chunk OpenImageIO reads as "Gamma2.2" builds, decoded as a 2.2 power.
TEST(Color, GammaTaggedPngBuilds) {
  const fs::path dir = temp_dir();
  const std::string png = (dir / "gamma.png").string();
  {
    auto out = OIIO::ImageOutput::create(png);
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(4, 4, 3, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "Gamma2.2");
    spec.attribute("oiio:Gamma", 2.2f);
    std::vector<uint8_t> px(4 * 4 * 3, 128);
    ASSERT_TRUE(out->open(png, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, px.data()));
    ASSERT_TRUE(out->close());
  }
  auto src = open_image_file(png);
  ASSERT_TRUE(src.ok()) << src.status().message();
  EXPECT_EQ((*src)->info().color_space, "Gamma2.2");  // what OpenImageIO reads from gAMA
  BuildOptions o;
  o.layers.push_back(test::layer_input(LayerSemantic::kAlbedo,
                                       std::shared_ptr<ImageSource>(std::move(src).value())));
  o.codec.codec = CodecKind::kRaw;
  o.payload = 8;
  o.output = (dir / "gamma.vtpf").string();
  auto sum = build_page_file(o);
  ASSERT_TRUE(sum.ok()) << sum.status().message();
  // Stored sRGB 8-bit: the sRGB code of (128/255)^2.2.
  const double lin = std::pow(128 / 255.0, 2.2);
  const double enc = lin <= 0.0031308 ? lin * 12.92 : 1.055 * std::pow(lin, 1 / 2.4) - 0.055;
  const uint8_t want = uint8_t(std::lround(enc * 255));
  test::expect_level0_rgb(o.output, 4, 4, [&](uint32_t, uint32_t, uint32_t) { return want; });
}

}  // namespace
}  // namespace vt
