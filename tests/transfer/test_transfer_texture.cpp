// The transfer's texture sampler (bake/transfer_texture.h): glTF's wrap modes, nearest and
// bilinear taps, colour MIP levels averaged in linear light, the footprint average under
// minification, and the scratch-mapped texels giving the same samples.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <vector>

#include "bake/color.h"
#include "bake/transfer_texture.h"
#include "scene/image_load.h"
#include "tests/scene/bmp_tga_files.h"
#include "tests/transfer/scratch_dir.h"

namespace vt {
namespace {

using scene::WrapMode;

// A w x h 8-bit or float image; f(x, y, c) gives each texel's channels.
void write_image(const std::string& path, int w, int h, int channels,
                 const std::function<float(int, int, int)>& f, bool is_float = false) {
  std::vector<float> texels(size_t(w) * h * channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c) texels[(size_t(y) * w + x) * channels + c] = f(x, y, c);
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out);
  OIIO::ImageSpec spec(w, h, channels, is_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  ASSERT_TRUE(out->open(path, spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, texels.data()));
  out->close();
}

float at(const TransferTexture& t, double s, double u, WrapMode ws = WrapMode::kRepeat,
         WrapMode wt = WrapMode::kRepeat, bool nearest = false) {
  TextureLookup q;
  q.s = s, q.t = u, q.wrap_s = ws, q.wrap_t = wt, q.nearest = nearest;
  float v[4] = {0, 0, 0, 0};
  t.sample(q, v);
  return v[0];
}

// A 4 x 1 ramp 0, 1/3, 2/3, 1 (codes 0, 85, 170, 255) as data: bilinear between texel centres,
// each wrap mode past the edges.
TEST(TransferTexture, WrapModesAndBilinearTaps) {
  test::ScratchDir dir;
  const std::string p = dir.file("ramp.png");
  write_image(p, 4, 1, 1, [](int x, int, int) { return x / 3.0f; });
  auto t = TransferTexture::load(p, nullptr);
  ASSERT_TRUE(t.ok()) << t.status().message();
  EXPECT_EQ(t->channels(), 1);
  EXPECT_EQ(t->levels(), 3u);           // 4x1, 2x1, 1x1
  const double c0 = 0.125, c1 = 0.375;  // texel centres
  EXPECT_FLOAT_EQ(at(*t, c0, 0.5), 0.0f);
  EXPECT_FLOAT_EQ(at(*t, c1, 0.5), 1.0f / 3);
  EXPECT_NEAR(at(*t, (c0 + c1) / 2, 0.5), 1.0f / 6, 1e-6);
  // Left of the first centre: repeat blends with the last texel, clamp holds the first, mirror
  // reflects onto the first itself.
  EXPECT_NEAR(at(*t, 0.0, 0.5, WrapMode::kRepeat), 0.5f, 1e-6);
  EXPECT_NEAR(at(*t, 0.0, 0.5, WrapMode::kClampToEdge), 0.0f, 1e-6);
  EXPECT_NEAR(at(*t, 0.0, 0.5, WrapMode::kMirroredRepeat), 0.0f, 1e-6);
  // One period on: repeat returns, mirror reads backwards (s = 1.375 is texel 2 mirrored: 1 - ...)
  EXPECT_NEAR(at(*t, 1.0 + c1, 0.5, WrapMode::kRepeat), 1.0f / 3, 1e-6);
  EXPECT_NEAR(at(*t, 1.0 + c1, 0.5, WrapMode::kMirroredRepeat), 2.0f / 3, 1e-6);
  EXPECT_NEAR(at(*t, 5.0, 0.5, WrapMode::kClampToEdge), 1.0f, 1e-6);
  // Nearest takes whole texels.
  EXPECT_FLOAT_EQ(at(*t, 0.49, 0.5, WrapMode::kRepeat, WrapMode::kRepeat, true), 1.0f / 3);
  EXPECT_FLOAT_EQ(at(*t, 0.51, 0.5, WrapMode::kRepeat, WrapMode::kRepeat, true), 2.0f / 3);
  EXPECT_FLOAT_EQ(at(*t, -0.01, 0.5, WrapMode::kRepeat, WrapMode::kRepeat, true), 1.0f);
  // Non-finite coordinates sample (0, 0).
  EXPECT_TRUE(std::isfinite(at(*t, NAN, INFINITY)));
}

// REPEAT whole periods away, on either side and far out, samples what the first period does,
// bit for bit: for a power-of-two side (wrapped with a mask) and for another (wrap_texel).
TEST(TransferTexture, RepeatPeriodsSampleTheFirstPeriodExactly) {
  test::ScratchDir dir;
  for (int w : {8, 6}) {
    const std::string p = dir.file("noise" + std::to_string(w) + ".png");
    write_image(p, w, 4, 1, [](int x, int y, int) { return float((x * 37 + y * 11) % 64) / 63; });
    auto t = TransferTexture::load(p, nullptr);
    ASSERT_TRUE(t.ok()) << t.status().message();
    for (double s : {0.0, 0.03125, 0.3125, 0.5, 0.96875}) {  // dyadic: s + k is exact
      for (double u : {0.0, 0.203125, 0.90625}) {
        const float first = at(*t, s, u);
        for (double k : {-3.0, -1.0, 1.0, 2.0, 1024.0}) {
          EXPECT_EQ(at(*t, s + k, u), first) << w << " " << s << " " << k;
          EXPECT_EQ(at(*t, s, u + k), first) << w << " " << u << " " << k;
          EXPECT_EQ(at(*t, s + k, u, WrapMode::kRepeat, WrapMode::kRepeat, true),
                    at(*t, s, u, WrapMode::kRepeat, WrapMode::kRepeat, true));
        }
      }
    }
  }
}

// sRGB codes 0 and 255 side by side: taps filter the codes as stored (the caller converts the
// sample, as the validator's UNORM reference does), while the made 1x1 level is the mean in
// linear light, re-encoded: linear_to_srgb(0.5) = 0.7354, not the codes' mean 0.5.
TEST(TransferTexture, ColourLevelsAreAveragedInLinearLight) {
  test::ScratchDir dir;
  const std::string p = dir.file("bw.png");
  write_image(p, 2, 1, 3, [](int x, int, int) { return float(x); });
  auto to_linear = ColorConverter::create("sRGB", "linear");
  auto from_linear = ColorConverter::create("linear", "sRGB");
  ASSERT_TRUE(to_linear.ok() && from_linear.ok());
  auto t = TransferTexture::load(p, to_linear->get(), from_linear->get());
  ASSERT_TRUE(t.ok());
  EXPECT_NEAR(at(*t, 0.5, 0.5, WrapMode::kClampToEdge, WrapMode::kClampToEdge), 0.5f, 1e-6);
  TextureLookup q;
  q.s = q.t = 0.5, q.d = {4, 0, 0, 4};  // past the last level
  float v[4];
  t->sample(q, v);
  EXPECT_NEAR(v[0], 0.7354f, 1e-4);
  // As data, the plain mean.
  auto data = TransferTexture::load(p);
  ASSERT_TRUE(data.ok());
  data->sample(q, v);
  EXPECT_NEAR(v[0], 0.5f, 1e-6);
}

// Fine stripes under 8x minification along s only (an anisotropic footprint): the sample is the
// footprint's mean, not aliased stripes; along the isotropic diagonal likewise.
TEST(TransferTexture, MinifiedFootprintAveragesTheTexels) {
  test::ScratchDir dir;
  const std::string p = dir.file("stripes.exr");
  write_image(
      p, 256, 256, 1, [](int x, int, int) { return float(x % 2); }, true);
  auto t = TransferTexture::load(p, nullptr);
  ASSERT_TRUE(t.ok());
  EXPECT_EQ(t->levels(), 9u);
  double worst = 0;
  for (int i = 0; i < 64; ++i) {
    TextureLookup q;
    q.s = (i + 0.37) / 64, q.t = (i * 7 % 64 + 0.5) / 64;
    q.d = {8.0 / 256, 0, 0, 1.0 / 256};  // 8 texels along s, 1 along t
    float v[4];
    t->sample(q, v);
    worst = std::max(worst, std::abs(v[0] - 0.5));
    q.d = {8.0 / 256, 0, 0, 8.0 / 256};
    t->sample(q, v);
    worst = std::max(worst, std::abs(v[0] - 0.5));
  }
  EXPECT_LT(worst, 0.07);  // one texel stripe's share of an 8-texel footprint at most
}

TEST(TransferTexture, ScratchMappedTexelsSampleTheSame) {
  test::ScratchDir dir;
  const std::string p = dir.file("noise.png");
  write_image(p, 37, 19, 4,
              [](int x, int y, int c) { return ((x * 31 + y * 17 + c * 7) % 256) / 255.0f; });
  auto a = TransferTexture::load(p, nullptr);
  auto b = TransferTexture::load(p, nullptr);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_TRUE(b->move_to_scratch(dir.file("")).ok());
  EXPECT_TRUE(a->in_memory());
  EXPECT_FALSE(b->in_memory());
  EXPECT_EQ(a->bytes(), b->bytes());
  for (int i = 0; i < 200; ++i) {
    TextureLookup q;
    q.s = i * 0.0137 - 0.5, q.t = i * 0.0291;
    q.d = {0.003 * (i % 7), 0.001 * (i % 3), 0.0, 0.004 * (i % 5)};
    float va[4], vb[4];
    a->sample(q, va);
    b->sample(q, vb);
    for (int c = 0; c < 4; ++c) EXPECT_EQ(va[c], vb[c]);
  }
}

TEST(TransferTexture, UnreadableFileIsNotFound) {
  test::ScratchDir dir;
  auto t = TransferTexture::load(dir.file("none.png"), nullptr);
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.status().code(), ErrorCode::kNotFound);
  EXPECT_FALSE(t.status().message().empty());
}

// A 32-bit BMP's padding byte (0 in every texel) is no alpha for the transfer's texture or the
// validator's reference image: both read the colour, opaque.
TEST(TransferTexture, BmpPaddingByteIsNotAlpha) {
  test::ScratchDir dir;
  const std::string p = dir.file("padding.bmp");
  const std::vector<uint8_t> rgba = {200, 100, 50, 0, 10, 20, 30, 0};  // 2 x 1
  ASSERT_TRUE(test::write_bmp32(p, 2, 1, rgba));
  auto t = TransferTexture::load(p, nullptr);
  ASSERT_TRUE(t.ok()) << t.status().message();
  EXPECT_EQ(t->channels(), 3);
  TextureLookup q;
  q.s = 0.25, q.t = 0.5, q.nearest = true;
  float v[4] = {0, 0, 0, 0};
  t->sample(q, v);
  EXPECT_NEAR(v[0], 200 / 255.0f, 1e-6f);
  EXPECT_NEAR(v[2], 50 / 255.0f, 1e-6f);
  scene::Image image;
  image.path = p;
  auto img = scene::load_float_image(image);
  ASSERT_TRUE(img.ok()) << img.status().message();
  EXPECT_EQ(img->channels, 3u);
  EXPECT_EQ(img->at(1, 0)[3], 1.0f);
  EXPECT_NEAR(img->at(1, 0)[2], 30 / 255.0f, 1e-6f);
}

// A texture cut short is bad input (kCorrupt: exit 2, as the build says of its images), not a
// failed write or read of the machine (kIo: exit 1).
TEST(TransferTexture, CutShortFileIsCorrupt) {
  test::ScratchDir dir;
  const std::string p = dir.file("cut.tga");
  const std::vector<uint8_t> rgba(64 * 64 * 4, 200);
  ASSERT_TRUE(test::write_tga32(p, 64, 64, rgba, 8));
  std::filesystem::resize_file(p, 18 + 64 * 4 * 3);
  auto t = TransferTexture::load(p, nullptr);
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.status().code(), ErrorCode::kCorrupt) << t.status().message();
}

}  // namespace
}  // namespace vt
