// DCT and BC+zstd pages through the page file: read_texels gives exactly what the codec's own
// decoder gives for the stored bytes, and corrupt coded pages give errors, not crashes.
#include <gtest/gtest.h>

#include "codec/bc.h"
#include "codec/dct.h"
#include "format/page_file.h"
#include "format/zstd_frame.h"
#include "page_file_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;

std::vector<uint8_t> smooth_page(int size, int channels, uint32_t seed) {
  std::vector<uint8_t> t(size_t(size) * size * channels);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      for (int c = 0; c < channels; ++c)
        t[(size_t(y) * size + x) * channels + c] =
            uint8_t((x * 7 + y * 3 + c * 50 + seed * 13) & 255);
  return t;
}

TEST(PageFileCodecs, DctAndBcPagesDecodeLikeTheCodec) {
  const int size = 16;
  PageFileDesc desc;
  desc.geometry = {30, 20, 12, 2};  // 16x16 pages: 3x2 -> 2x1 -> 1x1
  LayerSpec dct = layer("albedo", 3, TexelType::kU8, PageCodec::kDct);
  DctSettings settings;
  settings.channels = 3;
  auto tables = dct_make_tables(settings, size, size);
  ASSERT_TRUE(tables.ok()) << tables.status().message();
  dct.codec_tables = dct_serialize_tables(**tables);
  LayerSpec bc = layer("normal", 2, TexelType::kU8, PageCodec::kBcZstd);
  bc.runtime_format = RuntimeFormat::kBc5;
  bc.semantic = LayerSemantic::kNormal;
  desc.layers = {dct, bc};

  struct Page {
    PageId id;
    std::vector<uint8_t> dct_bytes, bc_bytes, dct_texels, bc_texels;
  };
  std::vector<Page> pages;
  const PageGeometry& g = desc.geometry;
  uint32_t seed = 0;
  for (uint32_t level = 0; level < g.level_count(); ++level)
    for (uint32_t y = 0; y < g.pages_y(level); ++y)
      for (uint32_t x = 0; x < g.pages_x(level); ++x) {
        Page p;
        p.id = {level, x, y};
        auto rgb = smooth_page(size, 3, ++seed);
        ASSERT_TRUE(dct_encode_page(**tables, rgb.data(), size, size, p.dct_bytes).ok());
        p.dct_texels.resize(rgb.size());
        ASSERT_TRUE(dct_decode_page(**tables, p.dct_bytes, size, size, p.dct_texels.data()).ok());
        auto xy = smooth_page(size, 2, ++seed);
        std::vector<uint8_t> blocks(bc_image_bytes(BcFormat::kBc5, size, size));
        ASSERT_TRUE(bc_encode_image(BcFormat::kBc5, BcQuality::kRealtime, xy.data(), size, size, 2,
                                    blocks.data())
                        .ok());
        p.bc_texels.resize(xy.size());
        ASSERT_TRUE(
            bc_decode_image(BcFormat::kBc5, blocks.data(), size, size, 2, p.bc_texels.data()).ok());
        ASSERT_TRUE(zstd_compress(blocks, 3, p.bc_bytes).ok());
        pages.push_back(std::move(p));
      }

  const std::string path = temp_path("codecs.vtpf");
  {
    auto w = PageFileWriter::create(path, desc);
    ASSERT_TRUE(w.ok()) << w.status().message();
    for (auto& p : pages) {
      ASSERT_TRUE((*w)->add_page(p.id, 0, p.dct_bytes).ok());
      ASSERT_TRUE((*w)->add_page(p.id, 1, p.bc_bytes).ok());
    }
    ASSERT_TRUE((*w)->finish().ok());
  }
  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  std::vector<uint8_t> texels;
  for (auto& p : pages) {
    texels.resize((*reader)->decoded_page_bytes(0));
    Status s = (*reader)->read_texels(p.id, 0, texels);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(texels, p.dct_texels);
    texels.resize((*reader)->decoded_page_bytes(1));
    s = (*reader)->read_texels(p.id, 1, texels);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(texels, p.bc_texels);
  }

  // Corrupt coded bytes behind a valid checksum reach the decoders: error or texels, no crash.
  std::vector<uint8_t> bytes = read_bytes(path);
  const uint64_t data_offset = le64(bytes, 64);
  const uint64_t data_size = le64(bytes, 72);
  const std::string mangled = temp_path("codecs_bad.vtpf");
  for (uint64_t at = data_offset; at < data_offset + data_size; at += 5) {
    std::vector<uint8_t> b = bytes;
    b[at] ^= uint8_t(0x5A);
    write_bytes(mangled, b);
    auto r = PageFileReader::open(mangled, {/*verify_checksums=*/false});
    ASSERT_TRUE(r.ok());
    for (auto& p : pages)
      for (uint32_t layer = 0; layer < 2; ++layer) {
        texels.resize((*r)->decoded_page_bytes(layer));
        (void)(*r)->read_texels(p.id, layer, texels);
      }
  }
}

TEST(PageFileCodecs, DctNeedsPageSizeMultipleOf8) {
  PageFileDesc desc;
  desc.geometry = {30, 20, 8, 2};  // 12x12 pages
  LayerSpec dct = layer("albedo", 3, TexelType::kU8, PageCodec::kDct);
  dct.codec_tables = {1};
  desc.layers = {dct};
  EXPECT_EQ(PageFileWriter::create(temp_path("dct12.vtpf"), desc).status().code(),
            ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace vt
