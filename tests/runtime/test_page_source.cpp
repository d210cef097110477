// make_page_file_source: each stored codec reaches the physical cache in the layer's runtime
// format (DCT -> BC1 transcode, stored BC5 passed through byte for byte, BC7 optionally as
// RGBA8, raw -> BC4), and presence follows every layer.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>

#include "codec/bc.h"
#include "codec/dct.h"
#include "codec/hdr_metrics.h"
#include "common/half.h"
#include "format/layer_codec.h"
#include "format/page_file.h"
#include "format/zstd_frame.h"
#include "runtime/page_source.h"
#include "runtime_test_util.h"

namespace vt {
namespace {

using namespace vt::runtime_test;

// Smooth procedural RGBA content, different per page.
std::vector<uint8_t> page_texels(const PageId& id, uint32_t size, uint32_t channels) {
  std::vector<uint8_t> t(size_t(size) * size * channels);
  for (uint32_t y = 0; y < size; ++y)
    for (uint32_t x = 0; x < size; ++x)
      for (uint32_t c = 0; c < channels; ++c) {
        const double v = 128 + 100 *
                                   std::sin(0.2 * x + 0.13 * y * (c + 1) + id.x + 3.0 * id.level) *
                                   std::cos(0.07 * (x + y) + id.y + c);
        t[(size_t(y) * size + x) * channels + c] = uint8_t(std::lround(v));
      }
  return t;
}

std::vector<uint8_t> zstd(const std::vector<uint8_t>& in) {
  std::vector<uint8_t> out;
  EXPECT_TRUE(zstd_compress(in, 3, out).ok());
  return out;
}

double psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  double se = 0;
  for (size_t i = 0; i < a.size(); ++i) se += double(a[i] - b[i]) * (a[i] - b[i]);
  const double mse = se / double(a.size());
  return mse == 0 ? 99.0 : 10 * std::log10(255.0 * 255.0 / mse);
}

TEST(PageFileSource, EveryCodecToItsRuntimeFormat) {
  PageGeometry g;
  g.payload = 24;
  g.border = 4;  // 32 x 32 pages: multiples of 8 for the DCT, of 4 for BC
  g.width = 60;
  g.height = 50;  // 3 x 3 pages at level 0, levels 3x3, 2x2, 1x1
  const uint32_t ps = g.page_size();
  DctSettings ds;
  ds.quality = 90;
  ds.channels = 3;
  ds.layout = DctPlaneLayout::kYCoCg;
  auto tables = dct_make_tables(ds, int(ps), int(ps));
  ASSERT_TRUE(tables.ok()) << tables.status().message();

  PageFileDesc desc;
  desc.geometry = g;
  LayerSpec albedo = test_layer("albedo", 3, PageCodec::kDct, RuntimeFormat::kBc1);
  albedo.codec_tables = dct_serialize_tables(**tables);
  const LayerSpec normal =
      test_layer("normal", 2, PageCodec::kBcZstd, RuntimeFormat::kBc5, LayerSemantic::kNormal);
  const LayerSpec custom =
      test_layer("custom", 4, PageCodec::kBcZstd, RuntimeFormat::kBc7, LayerSemantic::kCustom);
  const LayerSpec mask =
      test_layer("mask", 1, PageCodec::kRawZstd, RuntimeFormat::kBc4, LayerSemantic::kCustom);
  desc.layers = {albedo, normal, custom, mask};
  const std::string path = temp_file("codecs.vtpf");
  auto writer = PageFileWriter::create(path, desc);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  const PageId absent_in_one{0, 2, 2};
  for (uint32_t l = 0; l < g.level_count(); ++l)
    for (uint32_t y = 0; y < g.pages_y(l); ++y)
      for (uint32_t x = 0; x < g.pages_x(l); ++x) {
        const PageId id{l, x, y};
        std::vector<uint8_t> coded;
        ASSERT_TRUE(
            dct_encode_page(**tables, page_texels(id, ps, 3).data(), int(ps), int(ps), coded).ok());
        ASSERT_TRUE((*writer)->add_page(id, 0, coded).ok());
        for (auto [layer, fmt, ch] :
             {std::tuple{1u, BcFormat::kBc5, 2u}, std::tuple{2u, BcFormat::kBc7, 4u}}) {
          std::vector<uint8_t> blocks(bc_image_bytes(fmt, int(ps), int(ps)));
          ASSERT_TRUE(bc_encode_image(fmt, BcQuality::kRealtime, page_texels(id, ps, ch).data(),
                                      int(ps), int(ps), int(ch), blocks.data())
                          .ok());
          ASSERT_TRUE((*writer)->add_page(id, layer, zstd(blocks)).ok());
        }
        if (id == absent_in_one) continue;
        ASSERT_TRUE((*writer)->add_page(id, 3, zstd(page_texels(id, ps, 1))).ok());
      }
  ASSERT_TRUE((*writer)->finish().ok());

  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  std::shared_ptr<const PageFileReader> shared(std::move(*reader));
  for (bool bc7_as_rgba8 : {false, true}) {
    PageFileSourceOptions o;
    o.bc7_as_rgba8 = bc7_as_rgba8;
    auto src = make_page_file_source(shared, o);
    ASSERT_TRUE(src.ok()) << src.status().message();
    const PageSource& s = **src;
    EXPECT_EQ(s.upload_format(0), RuntimeFormat::kBc1);
    EXPECT_EQ(s.upload_bytes(0), ps * ps / 2);
    EXPECT_EQ(s.upload_format(1), RuntimeFormat::kBc5);
    EXPECT_EQ(s.upload_format(2), bc7_as_rgba8 ? RuntimeFormat::kRgba8 : RuntimeFormat::kBc7);
    EXPECT_EQ(s.upload_bytes(2), bc7_as_rgba8 ? ps * ps * 4 : ps * ps);
    EXPECT_EQ(s.upload_format(3), RuntimeFormat::kBc4);
    EXPECT_FALSE(s.present(absent_in_one));
    EXPECT_TRUE(s.present({0, 1, 2}));
    EXPECT_TRUE(s.present({2, 0, 0}));

    const PageId id{0, 1, 2};
    // DCT -> BC1: the texels survive two lossy steps; the bound is measured (about 35 dB).
    std::vector<uint8_t> bc1(s.upload_bytes(0)), rgb(ps * ps * 3);
    ASSERT_TRUE(s.load(id, 0, bc1).ok());
    ASSERT_TRUE(bc_decode_image(BcFormat::kBc1, bc1.data(), int(ps), int(ps), 3, rgb.data()).ok());
    EXPECT_GT(psnr(rgb, page_texels(id, ps, 3)), 30.0);
    // Stored BC5: byte-identical to what was written.
    std::vector<uint8_t> bc5(s.upload_bytes(1)), want5(bc_image_bytes(BcFormat::kBc5, ps, ps));
    ASSERT_TRUE(s.load(id, 1, bc5).ok());
    ASSERT_TRUE(bc_encode_image(BcFormat::kBc5, BcQuality::kRealtime, page_texels(id, ps, 2).data(),
                                int(ps), int(ps), 2, want5.data())
                    .ok());
    EXPECT_EQ(bc5, want5);
    // BC7: passed through, or decoded to RGBA8 exactly as the BC decoder does.
    std::vector<uint8_t> up7(s.upload_bytes(2)), want7(bc_image_bytes(BcFormat::kBc7, ps, ps));
    ASSERT_TRUE(s.load(id, 2, up7).ok());
    ASSERT_TRUE(bc_encode_image(BcFormat::kBc7, BcQuality::kRealtime, page_texels(id, ps, 4).data(),
                                int(ps), int(ps), 4, want7.data())
                    .ok());
    if (bc7_as_rgba8) {
      std::vector<uint8_t> dec(ps * ps * 4);
      ASSERT_TRUE(
          bc_decode_image(BcFormat::kBc7, want7.data(), int(ps), int(ps), 4, dec.data()).ok());
      EXPECT_EQ(up7, dec);
    } else {
      EXPECT_EQ(up7, want7);
    }
    // Raw -> BC4: one channel, lossy but close.
    std::vector<uint8_t> bc4(s.upload_bytes(3)), r(ps * ps);
    ASSERT_TRUE(s.load(id, 3, bc4).ok());
    ASSERT_TRUE(bc_decode_image(BcFormat::kBc4, bc4.data(), int(ps), int(ps), 1, r.data()).ok());
    EXPECT_GT(psnr(r, page_texels(id, ps, 1)), 35.0);
    // Errors name the file and the page.
    std::vector<uint8_t> wrong(3);
    Status bad = s.load(id, 0, wrong);
    EXPECT_EQ(bad.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(bad.message().find(path), std::string::npos);
    bad = s.load(absent_in_one, 3, bc4);
    EXPECT_FALSE(bad.ok());
    EXPECT_NE(bad.message().find("page (0, 2, 2)"), std::string::npos) << bad.message();
  }
}

// Half-float layers with a BC6H runtime format: raw half pages are encoded at load (real-time
// level), stored BC6H blocks pass through byte for byte, bc6h_as_rgba16f uploads the halves
// (widened, alpha 1.0), and 8-bit layers cannot ask for BC6H.
TEST(PageFileSource, HalfLayersToBc6h) {
  PageGeometry g;
  g.payload = 24;
  g.border = 4;
  g.width = g.height = 48;  // 2 x 2 pages, then 1
  const uint32_t ps = g.page_size();
  LayerSpec raw = test_layer("emissive", 3, PageCodec::kRawZstd, RuntimeFormat::kBc6hUf16,
                             LayerSemantic::kEmissive);
  raw.texel_type = TexelType::kF16;
  LayerSpec blocks =
      test_layer("data", 3, PageCodec::kBcZstd, RuntimeFormat::kBc6hSf16, LayerSemantic::kCustom);
  blocks.texel_type = TexelType::kF16;
  PageFileDesc desc;
  desc.geometry = g;
  desc.layers = {raw, blocks};
  const std::string path = temp_file("bc6h.vtpf");
  auto writer = PageFileWriter::create(path, desc);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  auto raw_codec = LayerCodec::create(raw, ps);
  auto bc_codec = LayerCodec::create(blocks, ps);
  ASSERT_TRUE(raw_codec.ok() && bc_codec.ok());
  auto halves = [&](const PageId& id, bool is_signed) {
    std::vector<uint8_t> t(size_t(ps) * ps * 6);
    for (size_t i = 0; i < t.size() / 2; ++i) {
      const double v = std::exp2(8.0 * std::sin(0.05 * double(i) + id.x + 2.0 * id.y + id.level));
      const uint16_t h = float_to_half(float(is_signed && (i / 97) % 2 ? -v : v));
      std::memcpy(&t[2 * i], &h, 2);
    }
    return t;
  };
  LayerEncodeSettings settings;
  settings.bc_quality = BcQuality::kNormal;
  std::map<std::pair<uint32_t, uint32_t>, std::vector<uint8_t>> stored_blocks;
  for (uint32_t l = 0; l < g.level_count(); ++l)
    for (uint32_t y = 0; y < g.pages_y(l); ++y)
      for (uint32_t x = 0; x < g.pages_x(l); ++x) {
        const PageId id{l, x, y};
        std::vector<uint8_t> bytes;
        ASSERT_TRUE(raw_codec->encode(halves(id, false).data(), settings, bytes).ok());
        ASSERT_TRUE((*writer)->add_page(id, 0, bytes).ok());
        ASSERT_TRUE(bc_codec->encode(halves(id, true).data(), settings, bytes).ok());
        ASSERT_TRUE((*writer)->add_page(id, 1, bytes).ok());
        std::vector<uint8_t> b(bc_codec->bc_page_bytes());
        ASSERT_TRUE(bc_codec->bc_blocks(bytes, b).ok());
        stored_blocks[{l, y * 4 + x}] = b;
      }
  ASSERT_TRUE((*writer)->finish().ok());
  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  std::shared_ptr<const PageFileReader> shared(std::move(*reader));
  auto source = make_page_file_source(shared);
  ASSERT_TRUE(source.ok()) << source.status().message();
  EXPECT_EQ((*source)->upload_format(0), RuntimeFormat::kBc6hUf16);
  EXPECT_EQ((*source)->upload_format(1), RuntimeFormat::kBc6hSf16);
  EXPECT_EQ((*source)->upload_bytes(0), size_t(ps) * ps);  // 1 byte a texel
  const PageId id{0, 1, 0};
  std::vector<uint8_t> up((*source)->upload_bytes(0));
  ASSERT_TRUE((*source)->load(id, 0, up).ok());
  std::vector<uint8_t> want(up.size());
  const std::vector<uint8_t> src = halves(id, false);
  ASSERT_TRUE(bc_encode_image(BcFormat::kBc6hUf16, BcQuality::kRealtime, src.data(), int(ps),
                              int(ps), 3, want.data())
                  .ok());
  EXPECT_EQ(up, want);  // the real-time transcode
  std::vector<uint8_t> back(src.size());
  ASSERT_TRUE(
      bc_decode_image(BcFormat::kBc6hUf16, up.data(), int(ps), int(ps), 3, back.data()).ok());
  HdrError e;
  add_hdr_error(src.data(), back.data(), size_t(ps) * ps, 3, 3, e);
  EXPECT_GT(e.tonemapped_psnr_db(), 30.0);  // measured 31.9 on this hard content (16 stops)
  ASSERT_TRUE((*source)->load(id, 1, up).ok());
  EXPECT_EQ(up, (stored_blocks[{0, 1}]));  // stored blocks, untouched
  // The reader decodes stored BC6H pages to half texels (extract, metrics).
  std::vector<uint8_t> decoded(shared->decoded_page_bytes(1));
  ASSERT_TRUE(shared->read_texels(id, 1, decoded).ok());
  std::vector<uint8_t> expect(decoded.size());
  ASSERT_TRUE(bc_decode_image(BcFormat::kBc6hSf16, stored_blocks[{0, 1}].data(), int(ps), int(ps),
                              3, expect.data())
                  .ok());
  EXPECT_EQ(decoded, expect);

  PageFileSourceOptions as_half;
  as_half.bc6h_as_rgba16f = true;
  auto half_source = make_page_file_source(shared, as_half);
  ASSERT_TRUE(half_source.ok()) << half_source.status().message();
  EXPECT_EQ((*half_source)->upload_format(0), RuntimeFormat::kRgba16f);
  EXPECT_EQ((*half_source)->upload_format(1), RuntimeFormat::kRgba16f);
  std::vector<uint8_t> wide((*half_source)->upload_bytes(0));
  ASSERT_TRUE((*half_source)->load(id, 0, wide).ok());
  for (size_t t = 0; t < size_t(ps) * ps; ++t) {
    ASSERT_EQ(std::memcmp(&wide[t * 8], &src[t * 6], 6), 0) << t;
    uint16_t a;
    std::memcpy(&a, &wide[t * 8 + 6], 2);
    ASSERT_EQ(a, 0x3c00);
  }

  // An 8-bit layer cannot be delivered as BC6H.
  PageFileDesc bad;
  bad.geometry = g;
  bad.layers = {test_layer("albedo", 3, PageCodec::kRawZstd, RuntimeFormat::kBc6hUf16)};
  auto refused = PageFileWriter::create(temp_file("bad.vtpf"), bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("BC6H"), std::string::npos)
      << refused.status().message();
}

}  // namespace
}  // namespace vt
