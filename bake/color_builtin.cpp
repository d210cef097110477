// The built-in colour config (see color.h). The reference space is linear Rec.709 (sRGB
// primaries, D65 white). The ACES matrices are computed from the primaries the ACES documents
// give (S-2014-004 for AP1, SMPTE ST 2065-1 for AP0) with the Bradford chromatic adaptation
// from the ACES white to D65, as the ACES reference configs do.
#include <array>

#include "bake/color_ocio.h"
#include "common/srgb.h"

namespace vt {
namespace {

using Mat3 = std::array<std::array<double, 3>, 3>;
struct Chromaticities {
  double rx, ry, gx, gy, bx, by, wx, wy;
};

constexpr Chromaticities kRec709 = {0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290};
constexpr Chromaticities kAp1 = {0.713, 0.293, 0.165, 0.830, 0.128, 0.044, 0.32168, 0.33767};
constexpr Chromaticities kAp0 = {0.7347, 0.2653, 0.0, 1.0, 0.0001, -0.0770, 0.32168, 0.33767};

Mat3 mul(const Mat3& a, const Mat3& b) {
  Mat3 m{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) m[i][j] += a[i][k] * b[k][j];
  return m;
}

std::array<double, 3> mul(const Mat3& a, const std::array<double, 3>& v) {
  std::array<double, 3> r{};
  for (int i = 0; i < 3; ++i) r[i] = a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2];
  return r;
}

Mat3 inverse(const Mat3& m) {
  Mat3 r;
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      // Cofactor of m[j][i] (the transpose of the cofactor matrix).
      const int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
      r[i][j] = (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / det;
    }
  }
  return r;
}

std::array<double, 3> xyz_of(double x, double y) {
  return {x / y, 1.0, (1.0 - x - y) / y};
}

// RGB to CIE XYZ for the primaries, white mapping to Y = 1.
Mat3 rgb_to_xyz(const Chromaticities& c) {
  const auto r = xyz_of(c.rx, c.ry), g = xyz_of(c.gx, c.gy), b = xyz_of(c.bx, c.by);
  const Mat3 p = {{{r[0], g[0], b[0]}, {r[1], g[1], b[1]}, {r[2], g[2], b[2]}}};
  const auto s = mul(inverse(p), xyz_of(c.wx, c.wy));
  Mat3 m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m[i][j] = p[i][j] * s[j];
  return m;
}

// Bradford chromatic adaptation of XYZ from one white to another.
Mat3 bradford(const Chromaticities& from, const Chromaticities& to) {
  const Mat3 b = {
      {{0.8951, 0.2664, -0.1614}, {-0.7502, 1.7135, 0.0367}, {0.0389, -0.0685, 1.0296}}};
  const auto cs = mul(b, xyz_of(from.wx, from.wy)), cd = mul(b, xyz_of(to.wx, to.wy));
  const Mat3 scale = {{{cd[0] / cs[0], 0, 0}, {0, cd[1] / cs[1], 0}, {0, 0, cd[2] / cs[2]}}};
  return mul(inverse(b), mul(scale, b));
}

OCIO::MatrixTransformRcPtr to_rec709(const Chromaticities& c) {
  const Mat3 m = mul(inverse(rgb_to_xyz(kRec709)), mul(bradford(c, kRec709), rgb_to_xyz(c)));
  const double m44[16] = {m[0][0], m[0][1], m[0][2], 0, m[1][0], m[1][1], m[1][2], 0,
                          m[2][0], m[2][1], m[2][2], 0, 0,       0,       0,       1};
  auto t = OCIO::MatrixTransform::Create();
  t->setMatrix(m44);
  return t;
}

OCIO::ColorSpaceRcPtr space(const char* name, const char* description,
                            std::initializer_list<const char*> aliases) {
  auto cs = OCIO::ColorSpace::Create();
  cs->setName(name);
  cs->setFamily("vtbake");
  cs->setDescription(description);
  for (const char* a : aliases) cs->addAlias(a);
  return cs;
}

// Encoded value = linear^(1/gamma): to the reference, a plain power.
OCIO::ColorSpaceRcPtr gamma_space(const char* name, double gamma,
                                  std::initializer_list<const char*> aliases) {
  auto cs = space(name, "a pure power over linear Rec.709 (PNG gAMA)", aliases);
  auto t = OCIO::ExponentTransform::Create();
  t->setValue({gamma, gamma, gamma, 1.0});
  cs->setTransform(t, OCIO::COLORSPACE_DIR_TO_REFERENCE);
  return cs;
}

// A power with a linear segment near black (moncurve): sRGB and the BT.709 OETF.
OCIO::ColorSpaceRcPtr curve_space(const char* name, const char* description, double gamma,
                                  double offset, std::initializer_list<const char*> aliases) {
  auto cs = space(name, description, aliases);
  auto t = OCIO::ExponentWithLinearTransform::Create();
  t->setGamma({gamma, gamma, gamma, 1.0});
  t->setOffset({offset, offset, offset, 0.0});
  cs->setTransform(t, OCIO::COLORSPACE_DIR_TO_REFERENCE);
  return cs;
}

}  // namespace

OCIO::ConstConfigRcPtr make_builtin_color_config() {
  OCIO::ConfigRcPtr config = OCIO::Config::Create();
  config->setName("vtbake");
  config->addColorSpace(
      space("linear", "linear Rec.709 primaries, D65 (the working space)",
            {"lin_srgb", "lin_rec709", "linear_srgb", "Linear Rec.709 (sRGB)", "srgb linear",
             "linear srgb", "rec709 linear", "Utility - Linear - sRGB", "lin_rec709_srgb"}));
  // common/srgb.h's curve: ExponentWithLinear is the exact one (not the 2.2 approximation).
  config->addColorSpace(curve_space("sRGB", "the IEC 61966-2-1 curve over linear Rec.709",
                                    kSrgbGamma, kSrgbOffset,
                                    {"srgb_texture", "sRGB - Texture", "srgb_tx", "srgb texture",
                                     "srgb gamma", "Utility - sRGB - Texture"}));
  config->addColorSpace(curve_space("Rec709", "the BT.709 OETF over linear Rec.709", 1.0 / 0.45,
                                    0.099, {"Rec.709", "rec709_camera", "Camera Rec.709"}));
  config->addColorSpace(gamma_space("Gamma1.8", 1.8, {"Gamma 1.8", "g18_rec709"}));
  config->addColorSpace(gamma_space("Gamma2.2", 2.2, {"Gamma 2.2", "g22_rec709"}));
  config->addColorSpace(gamma_space("Gamma2.4", 2.4, {"Gamma 2.4", "g24_rec709"}));
  auto acescg = space("ACEScg", "ACES AP1 primaries, linear", {"lin_ap1", "ACES - ACEScg"});
  acescg->setTransform(to_rec709(kAp1), OCIO::COLORSPACE_DIR_TO_REFERENCE);
  config->addColorSpace(acescg);
  auto aces =
      space("ACES2065-1", "ACES AP0 primaries, linear", {"lin_ap0", "ACES - ACES2065-1", "aces"});
  aces->setTransform(to_rec709(kAp0), OCIO::COLORSPACE_DIR_TO_REFERENCE);
  config->addColorSpace(aces);
  auto raw = space("raw", "data, never converted", {"Non-Color", "Utility - Raw", "none"});
  raw->setIsData(true);
  config->addColorSpace(raw);

  config->setRole(OCIO::ROLE_SCENE_LINEAR, "linear");
  config->setRole(OCIO::ROLE_DEFAULT, "linear");
  config->setRole(OCIO::ROLE_DATA, "raw");
  config->setRole("aces_interchange", "ACES2065-1");
  // Not used by vtbake; OpenColorIO's validation (and every tool reading the YAML) wants one.
  config->addDisplayView("sRGB", "Standard", "sRGB", "");
  config->addDisplayView("sRGB", "Raw", "raw", "");
  config->validate();
  return config;
}

}  // namespace vt
