// LayerCodec (every PageCodec both ways, BC pass-through, tables checked against the layer), the
// zstd frame helper and the runtime-format table.
#include <gtest/gtest.h>

#include "codec/bc.h"
#include "codec/dct.h"
#include "format/layer_codec.h"
#include "format/runtime_format.h"
#include "format/zstd_frame.h"
#include "page_file_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;

constexpr uint32_t kSize = 16;

std::vector<uint8_t> gradient(uint32_t channels, uint32_t seed) {
  std::vector<uint8_t> t(size_t(kSize) * kSize * channels);
  for (size_t i = 0; i < t.size(); ++i) t[i] = uint8_t((i * 7 + (i / 48) * 3 + seed * 29) & 255);
  return t;
}

LayerSpec dct_layer(uint8_t channels, int table_channels, int table_size) {
  LayerSpec spec = layer("albedo", channels, TexelType::kU8, PageCodec::kDct);
  DctSettings s;
  s.channels = table_channels;
  s.layout = DctPlaneLayout::kPlanes;
  auto tables = dct_make_tables(s, table_size, table_size);
  EXPECT_TRUE(tables.ok()) << tables.status().message();
  spec.codec_tables = dct_serialize_tables(**tables);
  return spec;
}

TEST(RuntimeFormat, TableAgreesWithTheBlockFormats) {
  for (uint8_t v = 0; v <= uint8_t(RuntimeFormat::kBc6hSf16); ++v) {
    const RuntimeFormat f = RuntimeFormat(v);
    const RuntimeFormatInfo* info = runtime_format_info(f);
    ASSERT_NE(info, nullptr);
    EXPECT_EQ(info->format, f);
    EXPECT_STREQ(to_string(f), info->name);
    EXPECT_EQ(runtime_bc_format(f), info->bc);
    if (info->bc) {
      EXPECT_EQ(runtime_format_page_bytes(f, 128), bc_image_bytes(*info->bc, 128, 128));
      EXPECT_EQ(info->channels, uint32_t(bc_format_channels(*info->bc)));
      EXPECT_EQ(runtime_format_of(*info->bc), f);
      EXPECT_EQ(info->is_float, bc_is_bc6h(*info->bc));  // BC6H: half floats
    } else {
      EXPECT_EQ(runtime_format_page_bytes(f, 128),
                size_t(128) * 128 * info->channels * (info->is_float ? (v == 8 ? 2 : 4) : 1));
    }
  }
  EXPECT_EQ(runtime_format_page_bytes(RuntimeFormat::kBc1, 128), 8192u);
  EXPECT_EQ(runtime_format_page_bytes(RuntimeFormat::kRg8, 4), 32u);
  EXPECT_STREQ(to_string(RuntimeFormat::kRgba16f), "rgba16f");
  EXPECT_STREQ(to_string(RuntimeFormat::kBc6hUf16), "bc6h_uf16");
  EXPECT_STREQ(to_string(RuntimeFormat::kBc6hSf16), "bc6h_sf16");
  EXPECT_EQ(runtime_format_info(RuntimeFormat(12)), nullptr);
  EXPECT_EQ(runtime_format_page_bytes(RuntimeFormat(200), 128), 0u);
  EXPECT_FALSE(runtime_bc_format(RuntimeFormat(200)));
  EXPECT_STREQ(to_string(RuntimeFormat(12)), "unknown");
}

TEST(ZstdFrame, DecompressesOnlyToTheExactSize) {
  const std::vector<uint8_t> data = gradient(4, 1);
  std::vector<uint8_t> frame;
  ASSERT_TRUE(zstd_compress(data, 3, frame).ok());
  EXPECT_LT(frame.size(), data.size());
  std::vector<uint8_t> back(data.size());
  ASSERT_TRUE(zstd_decompress_exact(frame, back).ok());
  EXPECT_EQ(back, data);
  std::vector<uint8_t> small(data.size() - 1), large(data.size() + 1);
  EXPECT_EQ(zstd_decompress_exact(frame, small).code(), ErrorCode::kCorrupt);
  EXPECT_EQ(zstd_decompress_exact(frame, large).code(), ErrorCode::kCorrupt);
  EXPECT_EQ(zstd_decompress_exact(std::span(frame).first(frame.size() / 2), back).code(),
            ErrorCode::kCorrupt);
  EXPECT_EQ(zstd_decompress_exact(data, back).code(), ErrorCode::kCorrupt);
  EXPECT_EQ(zstd_decompress_exact({}, back).code(), ErrorCode::kCorrupt);
}

TEST(LayerCodec, EveryCodecDecodesWhatItEncodes) {
  LayerSpec bc = layer("normal", 2, TexelType::kU8, PageCodec::kBcZstd);
  bc.runtime_format = RuntimeFormat::kBc5;
  const LayerSpec specs[] = {layer("raw", 3, TexelType::kU8, PageCodec::kRaw),
                             layer("zstd", 4, TexelType::kF16, PageCodec::kRawZstd),
                             dct_layer(3, 3, kSize), bc};
  for (const LayerSpec& spec : specs) {
    SCOPED_TRACE(to_string(spec.codec));
    auto codec = LayerCodec::create(spec, kSize);
    ASSERT_TRUE(codec.ok()) << codec.status().message();
    ASSERT_EQ(codec->codec(), spec.codec);
    ASSERT_EQ(codec->page_bytes(), size_t(kSize) * kSize * spec.texel_bytes());
    const std::vector<uint8_t> texels = gradient(spec.texel_bytes(), 2);
    std::vector<uint8_t> stored, expected(texels.size()), decoded(texels.size());
    ASSERT_TRUE(codec->encode(texels.data(), {}, stored, expected.data()).ok());
    ASSERT_TRUE(codec->decode(stored, decoded).ok());
    EXPECT_EQ(decoded, expected);
    if (!codec->lossy()) {
      EXPECT_EQ(decoded, texels);
    }

    std::vector<uint8_t> wrong(decoded.size() + 1);
    EXPECT_EQ(codec->decode(stored, wrong).code(), ErrorCode::kInvalidArgument);
    // Damaged bytes give an error or some texels, never a read or write out of bounds.
    std::vector<uint8_t> cut(stored.begin(), stored.begin() + stored.size() / 2);
    EXPECT_FALSE(codec->decode(cut, decoded).ok());
  }
}

TEST(LayerCodec, PassesStoredBcBlocksThrough) {
  LayerSpec spec = layer("albedo", 3, TexelType::kU8, PageCodec::kBcZstd);
  spec.runtime_format = RuntimeFormat::kBc1;
  auto codec = LayerCodec::create(spec, kSize);
  ASSERT_TRUE(codec.ok()) << codec.status().message();
  EXPECT_EQ(codec->bc_format(), BcFormat::kBc1);
  ASSERT_EQ(codec->bc_page_bytes(), bc_image_bytes(BcFormat::kBc1, kSize, kSize));
  const std::vector<uint8_t> texels = gradient(3, 3);
  std::vector<uint8_t> want(codec->bc_page_bytes()), stored, got(want.size());
  ASSERT_TRUE(
      bc_encode_image(BcFormat::kBc1, BcQuality::kHigh, texels.data(), kSize, kSize, 3, want.data())
          .ok());
  ASSERT_TRUE(codec->encode(texels.data(), {3, BcQuality::kHigh}, stored).ok());
  ASSERT_TRUE(codec->bc_blocks(stored, got).ok());
  EXPECT_EQ(got, want);
  std::vector<uint8_t> short_blocks(want.size() - 8);
  EXPECT_EQ(codec->bc_blocks(stored, short_blocks).code(), ErrorCode::kInvalidArgument);

  auto raw = LayerCodec::create(layer("raw", 3, TexelType::kU8, PageCodec::kRawZstd), kSize);
  ASSERT_TRUE(raw.ok());
  EXPECT_EQ(raw->bc_page_bytes(), 0u);  // rgba8 runtime format
  EXPECT_EQ(raw->bc_blocks(stored, got).code(), ErrorCode::kInvalidArgument);
}

TEST(LayerCodec, RejectsTablesThatDoNotFitTheLayer) {
  // A decoder writes page_size^2 * table channels bytes: a file whose tables code more channels
  // than its layer holds must not open, or decoding would write past the page.
  for (const LayerSpec& spec : {dct_layer(1, 4, kSize), dct_layer(3, 3, 2 * kSize)}) {
    auto codec = LayerCodec::create(spec, kSize);
    ASSERT_FALSE(codec.ok());
    EXPECT_EQ(codec.status().code(), ErrorCode::kCorrupt);
    EXPECT_NE(codec.status().message().find("dct tables code"), std::string::npos);

    PageFileDesc desc;
    desc.geometry = {kSize - 4, kSize - 4, kSize - 4, 2};  // one page
    desc.layers = {spec};
    const std::string path = temp_path("tables.vtpf");
    auto writer = PageFileWriter::create(path, desc);
    ASSERT_TRUE(writer.ok()) << writer.status().message();
    ASSERT_TRUE((*writer)->add_page({0, 0, 0}, 0, std::vector<uint8_t>(64, 1)).ok());
    ASSERT_TRUE((*writer)->finish().ok());
    auto reader = PageFileReader::open(path);
    ASSERT_FALSE(reader.ok());
    EXPECT_EQ(reader.status().code(), ErrorCode::kCorrupt);
    EXPECT_NE(reader.status().message().find("layer 0: dct tables code"), std::string::npos)
        << reader.status().message();
  }
  LayerSpec broken = dct_layer(3, 3, kSize);
  broken.codec_tables.resize(broken.codec_tables.size() / 2);
  EXPECT_EQ(LayerCodec::create(broken, kSize).status().code(), ErrorCode::kCorrupt);
}

}  // namespace
}  // namespace vt
