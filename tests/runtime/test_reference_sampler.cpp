// The border rule and the page-table math, end to end: a raw page file cut from procedural
// level images (borders read from the level image with the layer's address mode), streamed
// through the real reader, cache and page table, then sampled bilinearly through the table
// and a CPU physical cache; every sample must equal sampling the unpaged level bit for bit.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>

#include "format/page_file.h"
#include "runtime/reference_sampler.h"
#include "runtime/streamer.h"
#include "runtime_test_util.h"

namespace vt {
namespace {

using namespace vt::runtime_test;

struct Level {
  uint32_t w, h;
  std::vector<uint8_t> rgba;
};

// Level 0 is a procedural pattern with sharp edges (so a wrong tap shows); level k is a 2x2 box
// filter of level k-1 (edge texels repeated for odd sizes).
std::vector<Level> make_levels(const PageGeometry& g) {
  std::vector<Level> levels(g.level_count());
  levels[0] = {g.width, g.height, std::vector<uint8_t>(size_t(g.width) * g.height * 4)};
  for (uint32_t y = 0; y < g.height; ++y)
    for (uint32_t x = 0; x < g.width; ++x) {
      uint8_t* t = &levels[0].rgba[(size_t(y) * g.width + x) * 4];
      t[0] = uint8_t(x * 7 + y * 3);
      t[1] = uint8_t((x ^ y) * 5);
      t[2] = uint8_t(((x / 3 + y / 5) & 1) ? 230 : 20);
      t[3] = uint8_t(255 - x);
    }
  for (uint32_t k = 1; k < g.level_count(); ++k) {
    const Level& p = levels[k - 1];
    Level& l = levels[k];
    l.w = g.level_width(k);
    l.h = g.level_height(k);
    l.rgba.resize(size_t(l.w) * l.h * 4);
    for (uint32_t y = 0; y < l.h; ++y)
      for (uint32_t x = 0; x < l.w; ++x)
        for (int c = 0; c < 4; ++c) {
          uint32_t sum = 0;
          for (uint32_t dy = 0; dy < 2; ++dy)
            for (uint32_t dx = 0; dx < 2; ++dx) {
              const uint32_t sx = std::min(2 * x + dx, p.w - 1), sy = std::min(2 * y + dy, p.h - 1);
              sum += p.rgba[(size_t(sy) * p.w + sx) * 4 + c];
            }
          l.rgba[(size_t(y) * l.w + x) * 4 + c] = uint8_t((sum + 2) / 4);
        }
  }
  return levels;
}

// Writes every page (except those `absent` names) of the level images as raw RGBA8 pages.
std::string write_file(const PageGeometry& g, AddressMode mode, const std::vector<Level>& levels,
                       bool (*absent)(const PageId&)) {
  PageFileDesc desc;
  desc.geometry = g;
  LayerSpec layer = test_layer("albedo", 4, PageCodec::kRaw, RuntimeFormat::kRgba8);
  layer.address_mode = mode;
  desc.layers.push_back(layer);
  const std::string path = temp_file("sampler.vtpf");
  auto writer = PageFileWriter::create(path, desc);
  EXPECT_TRUE(writer.ok()) << writer.status().message();
  const uint32_t ps = g.page_size();
  std::vector<uint8_t> page(size_t(ps) * ps * 4);
  for (uint32_t k = 0; k < g.level_count(); ++k)
    for (uint32_t py = 0; py < g.pages_y(k); ++py)
      for (uint32_t px = 0; px < g.pages_x(k); ++px) {
        const PageId id{k, px, py};
        if (absent(id)) continue;
        const Level& l = levels[k];
        for (uint32_t j = 0; j < ps; ++j)
          for (uint32_t i = 0; i < ps; ++i) {
            const int64_t sx = address_texel(g.page_origin_x(id) + i, l.w, mode);
            const int64_t sy = address_texel(g.page_origin_y(id) + j, l.h, mode);
            std::memcpy(&page[(size_t(j) * ps + i) * 4], &l.rgba[(size_t(sy) * l.w + sx) * 4], 4);
          }
        EXPECT_TRUE((*writer)->add_page(id, 0, page).ok());
      }
  EXPECT_TRUE((*writer)->finish().ok());
  return path;
}

bool none_absent(const PageId&) {
  return false;
}
bool some_absent(const PageId& id) {
  return id.level == 0 && (id.x + 2 * id.y) % 5 == 1;
}

struct Streamed {
  PageGeometry g;
  std::vector<Level> levels;
  std::unique_ptr<Streamer> streamer;
  PhysicalImage image;
};

Streamed stream_everything(AddressMode mode, bool (*absent)(const PageId&), uint32_t slots_x,
                           uint32_t slots_y, uint32_t want_level, uint32_t region = 4096) {
  Streamed s;
  s.g.width = 301;  // neither a multiple of the payload nor a power of two
  s.g.height = 173;
  s.g.payload = 24;
  s.g.border = 4;
  s.levels = make_levels(s.g);
  const std::string path = write_file(s.g, mode, s.levels, absent);
  auto reader = PageFileReader::open(path);
  EXPECT_TRUE(reader.ok()) << reader.status().message();
  auto source = make_page_file_source(std::shared_ptr<const PageFileReader>(std::move(*reader)));
  EXPECT_TRUE(source.ok()) << source.status().message();
  StreamerOptions o;
  o.slots_x = slots_x;
  o.slots_y = slots_y;
  o.max_lod_bias = 0;  // keep the wanted level even when it does not fit
  auto st = Streamer::create(std::shared_ptr<const PageSource>(std::move(*source)), o);
  EXPECT_TRUE(st.ok()) << st.status().message();
  s.streamer = std::move(*st);
  s.image = make_physical_image(slots_x, slots_y, s.g.page_size(), 4);
  std::vector<uint32_t> fb;
  for (uint32_t y = 0; y < std::min(region, s.g.pages_y(want_level)); ++y)
    for (uint32_t x = 0; x < std::min(region, s.g.pages_x(want_level)); ++x)
      fb.push_back(feedback_pack(want_level, x, y));
  for (int f = 0; f < 200; ++f) {
    const FrameStats fs = s.streamer->update(fb);
    EXPECT_TRUE(apply_uploads(s.image, s.streamer->take_uploads(), 0).ok());
    s.streamer->wait_idle();
    if (fs.queued == 0 && fs.mapped == 0 && s.streamer->idle()) break;
  }
  EXPECT_TRUE(s.streamer->check_invariants().ok());
  return s;
}

// Samples many uv at `level`, concentrated on page edges; returns how many used each level.
std::vector<int> compare(const Streamed& s, AddressMode mode, uint32_t level) {
  const PageTable table = s.streamer->page_table();
  std::vector<int> used(s.g.level_count(), 0);
  std::mt19937 rng(9);
  const uint32_t lw = s.g.level_width(level), lh = s.g.level_height(level);
  std::vector<float> us, vs;
  // Every page edge at this level, +-0.5 and +-1 texel, plus texture edges and random points.
  for (uint32_t p = 0; p <= s.g.pages_x(level); ++p)
    for (float d : {-1.0f, -0.5f, -0.25f, 0.0f, 0.25f, 0.5f, 1.0f})
      us.push_back((float(p * s.g.payload) + d) / float(lw));
  for (uint32_t p = 0; p <= s.g.pages_y(level); ++p)
    for (float d : {-1.0f, -0.5f, 0.0f, 0.5f, 1.0f})
      vs.push_back((float(p * s.g.payload) + d) / float(lh));
  for (int i = 0; i < 60; ++i) {
    us.push_back(float(rng() % 100000) / 100000.0f);
    vs.push_back(float(rng() % 100000) / 100000.0f);
  }
  for (float u : us)
    for (float v : vs) {
      if (mode == AddressMode::kClamp && (u < 0 || u > 1 || v < 0 || v > 1)) continue;
      uint8_t paged[4], direct[4];
      auto got = sample_virtual_bilinear(table, s.image, mode, level, u, v, paged);
      EXPECT_TRUE(got.ok()) << got.status().message() << " u=" << u << " v=" << v;
      if (!got.ok()) continue;
      const uint32_t k = *got;
      EXPECT_GE(k, level);
      ++used[k];
      // Same uv handling as the sampler (wrap into [0, 1)).
      float uu = u, vv = v;
      if (mode == AddressMode::kWrap) {
        uu -= std::floor(uu);
        vv -= std::floor(vv);
      }
      const Level& l = s.levels[k];
      sample_level_bilinear({l.rgba.data(), l.w, l.h, 4}, mode, uu * float(l.w), vv * float(l.h),
                            direct);
      for (int c = 0; c < 4; ++c)
        EXPECT_EQ(int(paged[c]), int(direct[c]))
            << "level " << level << " (resident " << k << ") u=" << u << " v=" << v << " c=" << c;
    }
  return used;
}

TEST(ReferenceSampler, BitExactAtEveryLevelClamp) {
  Streamed s = stream_everything(AddressMode::kClamp, none_absent, 16, 16, 0);
  for (uint32_t level = 0; level < s.g.level_count(); ++level) {
    const auto used = compare(s, AddressMode::kClamp, level);
    EXPECT_GT(used[level], 0) << level;  // everything resident: the wanted level itself
    for (uint32_t k = 0; k < used.size(); ++k) {
      if (k != level) {
        EXPECT_EQ(used[k], 0);
      }
    }
  }
}

TEST(ReferenceSampler, BitExactWrapWithAbsentPages) {
  Streamed s = stream_everything(AddressMode::kWrap, some_absent, 16, 16, 0);
  const auto used = compare(s, AddressMode::kWrap, 0);
  EXPECT_GT(used[0], 0);
  EXPECT_GT(used[1], 0);  // absent level-0 pages read their parent
}

TEST(ReferenceSampler, BitExactWhenCacheHoldsOnlyPartOfTheLevel) {
  // 13 x 8 = 104 pages at level 0, a 6 x 6 cache and a view of the top-left 4 x 4 pages: the
  // rest of level 0 falls back to coarser levels, which must still sample exactly like the
  // level they come from.
  Streamed s = stream_everything(AddressMode::kClamp, none_absent, 6, 6, 0, 4);
  EXPECT_EQ(s.streamer->resident_pages().size(), 16u + 4u + 1u + 1u + 1u);
  const auto used = compare(s, AddressMode::kClamp, 0);
  EXPECT_GT(used[0], 0);
  int coarser = 0;
  for (size_t k = 1; k < used.size(); ++k) coarser += used[k];
  EXPECT_GT(coarser, 0);
}

TEST(ReferenceSampler, WrongBorderIsDetected) {
  // Control: zeroing one resident page's border in the physical image must break equality.
  Streamed s = stream_everything(AddressMode::kClamp, none_absent, 16, 16, 0);
  const PageTable table = s.streamer->page_table();
  const PageTableEntry e = table.entry({0, 3, 2});
  ASSERT_TRUE(e.valid());
  const uint32_t ps = s.g.page_size();
  for (uint32_t j = 0; j < ps; ++j)
    for (uint32_t i = ps - s.g.border; i < ps; ++i)
      std::memset(
          &s.image
               .texels[((size_t(e.slot_y) * ps + j) * s.image.width() + size_t(e.slot_x) * ps + i) *
                       4],
          0, 4);
  // Right edge of page (3, 2): u just left of x = 4 * payload.
  const float u = (4.0f * s.g.payload - 0.25f) / float(s.g.width);
  const float v = (2.5f * s.g.payload) / float(s.g.height);
  uint8_t paged[4], direct[4];
  ASSERT_TRUE(sample_virtual_bilinear(table, s.image, AddressMode::kClamp, 0, u, v, paged).ok());
  const Level& l = s.levels[0];
  sample_level_bilinear({l.rgba.data(), l.w, l.h, 4}, AddressMode::kClamp, u * l.w, v * l.h,
                        direct);
  EXPECT_NE(std::memcmp(paged, direct, 4), 0);
}

TEST(ReferenceSampler, PageFileSourceErrors) {
  EXPECT_FALSE(make_page_file_source(nullptr).ok());
}

}  // namespace
}  // namespace vt
