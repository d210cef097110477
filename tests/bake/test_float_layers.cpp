// Float sources in a build: values an 8-bit layer clips are counted, warned about and measured
// against (never clipped silently), and --float-texels half stores them as half floats (raw +
// zstd, RGBA16F at run time). Also the half conversions of common/half.h.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "common/half.h"
#include "tests/bake/bake_test_util.h"

namespace vt {
namespace {

constexpr uint32_t kW = 40, kH = 24;  // 3 x 2 pages of 16 payload texels at level 0

std::shared_ptr<ImageSource> float_image(uint32_t ch, std::vector<float> texels,
                                         bool is_float = true) {
  ImageInfo info;
  info.width = kW, info.height = kH, info.channels = ch, info.is_float = is_float;
  info.color_space = is_float ? "linear" : "sRGB";
  return std::make_shared<MemoryImageSource>(info, std::move(texels));
}

// A smooth linear RGB ramp in [0.05, 0.85] with `hot` texels (the first of every 7th row, 8
// of them along it) at 8.0 in red and 3.0 in green: an emissive-like HDR source.
std::vector<float> hdr_rgb(bool clamp_to_one = false) {
  std::vector<float> t(size_t(kW) * kH * 3);
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < kW; ++x)
      for (uint32_t c = 0; c < 3; ++c)
        t[(size_t(y) * kW + x) * 3 + c] = 0.05f + 0.7f * float(x + y) / float(kW + kH) + 0.05f * c;
  for (uint32_t y = 0; y < kH; y += 7)
    for (uint32_t x = 0; x < 8; ++x) {
      t[(size_t(y) * kW + x) * 3 + 0] = clamp_to_one ? 1.0f : 8.0f;
      t[(size_t(y) * kW + x) * 3 + 1] = clamp_to_one ? 1.0f : 3.0f;
    }
  return t;
}
constexpr uint64_t kHotTexels = 4 * 8;  // rows 0, 7, 14, 21

BuildOptions options_for(LayerSemantic semantic, std::shared_ptr<ImageSource> source) {
  BuildOptions o;
  o.layers.push_back(test::layer_input(semantic, std::move(source)));
  o.payload = 16;
  o.threads = 2;
  return o;
}

TEST(Half, RoundTripsEveryHalfAndRoundsToNearestEven) {
  for (uint32_t h = 0; h < 0x10000; ++h) {
    const uint16_t v = uint16_t(h);
    const float f = half_to_float(v);
    if (std::isnan(f)) {
      EXPECT_TRUE(std::isnan(half_to_float(float_to_half(f)))) << h;
      continue;
    }
    ASSERT_EQ(float_to_half(f), v) << h;
  }
  EXPECT_EQ(half_to_float(0x3c00), 1.0f);
  EXPECT_EQ(half_to_float(0x7bff), kHalfMax);
  EXPECT_EQ(half_to_float(0x0001), std::ldexp(1.0f, -24));
  // Halfway cases go to the even neighbour; just past halfway rounds up.
  EXPECT_EQ(float_to_half(1.0f + std::ldexp(1.0f, -11)), 0x3c00);
  EXPECT_EQ(float_to_half(1.0f + 3 * std::ldexp(1.0f, -11)), 0x3c02);
  EXPECT_EQ(float_to_half(std::nextafter(1.0f + std::ldexp(1.0f, -11), 2.0f)), 0x3c01);
  EXPECT_EQ(float_to_half(std::ldexp(1.0f, -25)), 0x0000);      // half the smallest: even
  EXPECT_EQ(float_to_half(3 * std::ldexp(1.0f, -25)), 0x0002);  // 1.5 x smallest: even
  EXPECT_EQ(float_to_half(std::ldexp(1023.5f, -24)), 0x0400);   // rounds into the normals
  EXPECT_EQ(float_to_half(-2.0f), 0xc000);
  // Past the largest finite half: the largest, not infinity; infinities stay.
  EXPECT_EQ(float_to_half(65519.0f), 0x7bff);
  EXPECT_EQ(float_to_half(1e30f), 0x7bff);
  EXPECT_EQ(float_to_half(-1e30f), 0xfbff);
  EXPECT_EQ(float_to_half(std::numeric_limits<float>::infinity()), 0x7c00);
}

TEST(FloatLayers, ClippedHdrIsCountedWarnedAndMeasured) {
  // The same build of the source clamped to 1 stores the same bytes: only the figures differ.
  BuildOptions o = options_for(LayerSemantic::kAlbedo, float_image(3, hdr_rgb()));
  BuildOptions clamped = options_for(LayerSemantic::kAlbedo, float_image(3, hdr_rgb(true)));
  for (CodecKind codec : {CodecKind::kDct, CodecKind::kBc}) {
    o.codec.codec = clamped.codec.codec = codec;
    auto hdr = test::build_in_memory(o);
    auto ldr = test::build_in_memory(clamped);
    ASSERT_TRUE(hdr && ldr);
    const LayerSummary& l = hdr->summary.layers[0];
    EXPECT_EQ(l.spec.texel_type, TexelType::kU8);
    EXPECT_EQ(l.clipped.texels, kHotTexels);
    EXPECT_EQ(l.clipped.values, 2 * kHotTexels);
    EXPECT_EQ(l.clipped.max_value, 8.0f);
    EXPECT_EQ(l.clipped.min_value, 3.0f);
    EXPECT_FALSE(ldr->summary.layers[0].clipped.any());
    EXPECT_TRUE(ldr->summary.warnings.empty());
    ASSERT_EQ(hdr->summary.warnings.size(), 1u);
    const std::string& w = hdr->summary.warnings[0];
    EXPECT_EQ(w.rfind("layer 'albedo': 32 texels (64 values) outside [0, 1], up to 8, clipped", 0),
              0u)
        << w;
    EXPECT_NE(w.find("--float-texels"), std::string::npos) << w;
    // Level 0 stores the same bytes (coarser levels filter 8 and 1 apart, then clip).
    ASSERT_EQ(hdr->sink.pages.size(), ldr->sink.pages.size());
    for (const auto& [key, page] : hdr->sink.pages)
      if (std::get<1>(key) == 0) ASSERT_EQ(page.bytes, ldr->sink.pages.at(key).bytes);
    // Measured against the unclipped values: sRGB(8) is code 626 where 255 is stored.
    EXPECT_LT(l.psnr_db, ldr->summary.layers[0].psnr_db - 10);
    EXPECT_GE(l.max_error, 360u);
    EXPECT_LT(l.runtime.psnr_db(), ldr->summary.layers[0].runtime.psnr_db() - 10);
    EXPECT_GE(l.runtime.max_error, 360u);
  }
}

TEST(FloatLayers, ClippedColourUnderAlphaCostsWhatItComposites) {
  // The hot texels at alpha `a`: clipping 8.0 to 1 changes what composites by (8 - 1) x a.
  auto rgba = [](float a) {
    const std::vector<float> rgb = hdr_rgb();
    std::vector<float> t(size_t(kW) * kH * 4);
    for (size_t i = 0; i < size_t(kW) * kH; ++i) {
      std::copy_n(&rgb[i * 3], 3, &t[i * 4]);
      t[i * 4 + 3] = rgb[i * 3] == 8.0f ? a : 1.0f;
    }
    return float_image(4, std::move(t));
  };
  for (CodecKind codec : {CodecKind::kDct, CodecKind::kBc}) {
    BuildOptions opaque = options_for(LayerSemantic::kAlbedo, rgba(1.0f));
    BuildOptions faint = options_for(LayerSemantic::kAlbedo, rgba(0.01f));
    opaque.codec.codec = faint.codec.codec = codec;
    auto o = test::build_in_memory(opaque);
    auto f = test::build_in_memory(faint);
    ASSERT_TRUE(o && f);
    ASSERT_EQ(f->summary.layers[0].spec.channels, 4u);
    EXPECT_EQ(f->summary.layers[0].clipped.values, 2 * kHotTexels);  // still counted and warned
    EXPECT_GE(o->summary.layers[0].max_error, 360u);
    // sRGB(8) - 255 is 371 codes; at alpha 0.01 that is under 4 (plus the codec's own error).
    EXPECT_LE(f->summary.layers[0].max_error, 40u) << int(codec);
    EXPECT_GT(f->summary.layers[0].psnr_db, o->summary.layers[0].psnr_db + 10);
  }
}

TEST(FloatLayers, DataLayersClipBothWaysAndLosslessLayersReportIt) {
  // A one-channel custom layer from an 8-bit source holding out-of-range values: stored raw
  // (lossless) it is still not exact, and its PSNR says so.
  std::vector<float> t(size_t(kW) * kH, 0.5f);
  t[5] = 1.5f;
  t[kW * 10 + 3] = -0.25f;
  BuildOptions o = options_for(LayerSemantic::kCustom, float_image(1, t, false));
  o.codec.codec = CodecKind::kRaw;
  auto b = test::build_in_memory(o);
  ASSERT_TRUE(b);
  const LayerSummary& l = b->summary.layers[0];
  EXPECT_EQ(l.spec.texel_type, TexelType::kU8);
  EXPECT_EQ(l.clipped.texels, 2u);
  EXPECT_EQ(l.clipped.min_value, -0.25f);
  EXPECT_EQ(l.clipped.max_value, 1.5f);
  EXPECT_TRUE(std::isfinite(l.psnr_db));
  EXPECT_EQ(l.max_error, 128u);  // 1.5 * 255 = 382.5 against 255
  ASSERT_EQ(b->summary.warnings.size(), 1u);
  EXPECT_NE(b->summary.warnings[0].find("from -0.25 to 1.5"), std::string::npos)
      << b->summary.warnings[0];

  // In range, a raw layer is exact and reports no clipping.
  t[5] = 1.0f, t[kW * 10 + 3] = 0.0f;
  b = test::build_in_memory(options_for(LayerSemantic::kCustom, float_image(1, t, false)));
  ASSERT_TRUE(b);
  EXPECT_FALSE(b->summary.layers[0].clipped.any());
  EXPECT_TRUE(b->summary.warnings.empty());
}

TEST(FloatLayers, NormalsAndFloatLayersNeverClip) {
  // Float normals are unit vectors: nothing to clip even though x and y are negative.
  std::vector<float> n(size_t(kW) * kH * 3);
  for (size_t i = 0; i < size_t(kW) * kH; ++i)
    n[i * 3 + 0] = -0.6f, n[i * 3 + 1] = 0.0f, n[i * 3 + 2] = 0.8f;
  auto b = test::build_in_memory(options_for(LayerSemantic::kNormal, float_image(3, n)));
  ASSERT_TRUE(b);
  EXPECT_FALSE(b->summary.layers[0].clipped.any());
  EXPECT_TRUE(b->summary.warnings.empty());
  // Raw storage keeps a float source as float (FloatTexels::kAuto).
  BuildOptions o = options_for(LayerSemantic::kAlbedo, float_image(3, hdr_rgb()));
  o.codec.codec = CodecKind::kRaw;
  b = test::build_in_memory(o);
  ASSERT_TRUE(b);
  EXPECT_EQ(b->summary.layers[0].spec.texel_type, TexelType::kF32);
  EXPECT_FALSE(b->summary.layers[0].clipped.any());
  EXPECT_TRUE(b->summary.warnings.empty());
}

TEST(FloatLayers, HalfStorageKeepsTheRange) {
  for (CodecKind codec : {CodecKind::kDct, CodecKind::kBc, CodecKind::kRaw}) {
    BuildOptions o = options_for(LayerSemantic::kEmissive, float_image(3, hdr_rgb()));
    o.codec.codec = codec;
    o.codec.float_texels = FloatTexels::kHalf;
    auto b = test::build_in_memory(o);
    ASSERT_TRUE(b);
    const LayerSummary& l = b->summary.layers[0];
    EXPECT_EQ(l.spec.texel_type, TexelType::kF16);
    // RGB half: BC6H at run time; --codec bc stores the BC6H blocks (lossy), else raw + zstd.
    EXPECT_EQ(l.spec.codec, codec == CodecKind::kBc ? PageCodec::kBcZstd : PageCodec::kRawZstd);
    EXPECT_EQ(l.spec.runtime_format, RuntimeFormat::kBc6hUf16);
    EXPECT_EQ(l.spec.color_space, ColorSpace::kLinear);
    EXPECT_FALSE(l.clipped.any());
    EXPECT_TRUE(b->summary.warnings.empty());
    // The HDR error after BC6H is reported (log space and tone-mapped).
    EXPECT_GT(l.runtime.hdr.samples, 0u);
    EXPECT_GT(l.runtime.hdr.tonemapped_psnr_db(), 30.0);
    if (codec == CodecKind::kBc) {
      EXPECT_GT(l.hdr.samples, 0u);  // stored lossy: its own error, against the floats
      EXPECT_GT(l.hdr.tonemapped_psnr_db(), 30.0);
      EXPECT_GT(l.hdr.relative_max, 0x1p-11);
      continue;
    }
    // Raw halves are not lossless: the stored error is the rounding to half, measured against
    // the float source (a relative error up to 2^-11, here never zero).
    EXPECT_GT(l.hdr.samples, 0u);
    EXPECT_GT(l.hdr.relative_max, 0.0);
    EXPECT_LE(l.hdr.relative_max, 0x1p-11);
    EXPECT_GT(l.hdr.tonemapped_psnr_db(), 60.0);
    // Level 0 is the source rounded to half, texel for texel.
    const std::vector<float> src = hdr_rgb();
    auto level = test::reassemble_level(*b, 0, 0, test::encoder_for(*b, 0, o));
    ASSERT_EQ(level.size(), src.size() * 2);
    for (size_t i = 0; i < src.size(); ++i) {
      uint16_t h;
      std::memcpy(&h, &level[2 * i], 2);
      ASSERT_EQ(h, float_to_half(src[i])) << i;
    }
    // Coarser levels keep values above 1 (filtered in linear light).
    auto top = test::reassemble_level(*b, 0, 1, test::encoder_for(*b, 0, o));
    float brightest = 0;
    for (size_t i = 0; i < top.size() / 2; ++i) {
      uint16_t h;
      std::memcpy(&h, &top[2 * i], 2);
      brightest = std::max(brightest, half_to_float(h));
    }
    EXPECT_GT(brightest, 2.0f);
  }
  // Past the half range: clamped to 65504, counted and warned about; so is an alpha above 1.
  {
    std::vector<float> t(size_t(kW) * kH * 4, 0.5f);
    t[(size_t(3) * kW + 4) * 4 + 0] = 1e6f;
    t[(size_t(9) * kW + 2) * 4 + 3] = 1.5f;  // alpha
    BuildOptions o = options_for(LayerSemantic::kAlbedo, float_image(4, t));
    o.codec.float_texels = FloatTexels::kHalf;
    auto b = test::build_in_memory(o);
    ASSERT_TRUE(b);
    const LayerSummary& l = b->summary.layers[0];
    EXPECT_EQ(l.spec.texel_type, TexelType::kF16);
    EXPECT_EQ(l.clipped.texels, 2u);
    EXPECT_EQ(l.clipped.max_value, 1e6f);
    ASSERT_EQ(b->summary.warnings.size(), 1u);
    EXPECT_NE(b->summary.warnings[0].find("half-float range"), std::string::npos)
        << b->summary.warnings[0];
    auto level = test::reassemble_level(*b, 0, 0, test::encoder_for(*b, 0, o));
    uint16_t h;
    std::memcpy(&h, &level[((size_t(3) * kW + 4) * 4 + 0) * 2], 2);
    EXPECT_EQ(h, 0x7bff);
  }
  // FloatTexels::kFloat: 32-bit float whatever the codec; the names parse.
  BuildOptions o = options_for(LayerSemantic::kCustom, float_image(3, hdr_rgb()));
  o.codec.float_texels = FloatTexels::kFloat;
  auto b = test::build_in_memory(o);
  ASSERT_TRUE(b);
  EXPECT_EQ(b->summary.layers[0].spec.texel_type, TexelType::kF32);
  EXPECT_EQ(*parse_float_texels("half"), FloatTexels::kHalf);
  EXPECT_EQ(*parse_float_texels("auto"), FloatTexels::kAuto);
  EXPECT_FALSE(parse_float_texels("bc6h").ok());
}

}  // namespace
}  // namespace vt
