// The out-of-core transfer (transfer_to_stores): bands of rows straight into scratch stores give
// the texels of the in-memory transfer bit for bit, whatever the band height and thread count,
// on charts that cross band edges.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "bake/coverage_mask.h"
#include "bake/level_store.h"
#include "bake/transfer.h"
#include "bake/unwrap/unwrap.h"
#include "samples/sample_scene.h"
#include "tests/transfer/transfer_test_util.h"

namespace vt {
namespace {

void pattern(double u, double v, float* t) {
  t[0] = float(0.5 + 0.45 * std::sin(13 * u + 3 * v));
  t[1] = float(0.5 + 0.45 * std::cos(7 * v - 5 * u));
  t[2] = float(u * v);
  t[3] = float(0.25 + 0.75 * std::fabs(std::sin(9 * u * v)));  // alpha below 1: kept
}

// Every layer's texels, read back from its store when the layer has one.
std::vector<std::vector<float>> texels_of(TransferResult& r) {
  std::vector<std::vector<float>> out;
  for (TransferLayer& l : r.layers) {
    if (!l.store) {
      out.push_back(l.texels);
      continue;
    }
    // A scratch albedo store keeps 4 channels; the layer hands out `channels` of them.
    ImageInfo info;
    info.width = r.width, info.height = r.height, info.channels = l.channels;
    StoredImageSource src(info, l.store);
    std::vector<float> t(size_t(r.width) * r.height * l.channels);
    EXPECT_TRUE(src.read_rows(0, r.height, t.data()).ok());
    out.push_back(std::move(t));
  }
  return out;
}

void expect_banded_equals_in_memory(const scene::Scene& s, TransferOptions o,
                                    const std::string& dir) {
  auto whole = transfer_materials(s, o);
  ASSERT_TRUE(whole.ok()) << whole.status().message();
  const auto want = texels_of(*whole);
  for (uint32_t rows : {16u, 48u, 17u}) {
    for (int threads : {1, 2}) {
      for (int kind = 0; kind < 3; ++kind) {  // scratch, in memory, compressed scratch
        TransferOptions b = o;
        b.band_rows = rows, b.threads = threads, b.stores_in_memory = kind == 1;
        b.compress_scratch = kind == 2;
        b.scratch_dir = dir;
        auto banded = transfer_to_stores(s, b);
        ASSERT_TRUE(banded.ok()) << banded.status().message();
        EXPECT_EQ(*banded->coverage->to_bytes(), *whole->coverage->to_bytes());
        EXPECT_EQ(banded->stats.covered_texels, whole->stats.covered_texels);
        EXPECT_EQ(banded->stats.samples, whole->stats.samples);
        ASSERT_EQ(banded->layers.size(), whole->layers.size());
        const auto got = texels_of(*banded);
        for (size_t l = 0; l < got.size(); ++l) {
          EXPECT_EQ(banded->layers[l].channels, whole->layers[l].channels);
          EXPECT_EQ(banded->layers[l].hdr, whole->layers[l].hdr);
          EXPECT_EQ(banded->layers[l].texels_above_one, whole->layers[l].texels_above_one);
          ASSERT_EQ(got[l].size(), want[l].size());
          EXPECT_EQ(std::memcmp(got[l].data(), want[l].data(), want[l].size() * 4), 0)
              << "layer " << l << " rows " << rows << " threads " << threads << " kind " << kind;
        }
      }
    }
  }
}

// Hand-made atlas: big triangles across band edges (one edge exactly on row 32, a vertex on
// row 16) and a needle through several bands, vertex colours and an RGBA texture.
TEST(BandedTransfer, HandMadeChartsAcrossBandEdgesMatchTheInMemoryTransfer) {
  test::ScratchDir dir;
  ASSERT_TRUE(write_texture(dir.file("t.png"), 32, 32, 4, pattern).ok());
  scene::Primitive p;
  const float atlas[][2] = {{0.05f, 0.03f}, {0.9f, 0.25f},  {0.3f, 0.5f},     // edge to row 32
                            {0.45f, 0.5f},  {0.95f, 0.5f},  {0.7f, 0.97f},    // on row 32
                            {0.02f, 0.55f}, {0.04f, 0.99f}, {0.03f, 0.56f}};  // needle
  for (int i = 0; i < 9; ++i) {
    p.positions.push_back({atlas[i][0], 0.0f, atlas[i][1]});
    p.indices.push_back(uint32_t(i));
    p.colors.push_back({0.5f + 0.5f * atlas[i][0], 0.8f, 1.0f - atlas[i][1], 1.0f});
  }
  p.uvs.resize(2);
  for (int i = 0; i < 9; ++i) {
    p.uvs[0].push_back({atlas[i][1] * 2.0f, atlas[i][0]});  // source UVs
    p.uvs[1].push_back({atlas[i][0], atlas[i][1]});         // atlas UVs
  }
  scene::Scene s = test::textured_scene(p, dir.file("t.png"));
  s.materials[0].emissive_factor = {2.0f, 0.5f, 0.0f};  // above 1: HDR counted per band
  TransferOptions o;
  o.width = 64, o.height = 64;
  o.supersample = 4;
  expect_banded_equals_in_memory(s, o, dir.file(""));
}

TEST(BandedTransfer, SampleSceneMatchesTheInMemoryTransfer) {
  test::ScratchDir dir;
  ASSERT_TRUE(test::write_small_sample_scene(dir.file("sample")).ok());
  auto loaded = scene::load_scene(dir.file("sample/scene.gltf"));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  unwrap::UnwrapOptions uo;
  uo.size_pages = 1;
  auto un = unwrap::unwrap_scene(*loaded, uo);
  ASSERT_TRUE(un.ok()) << un.status().message();
  TransferOptions o = test::atlas_transfer_options(un->stats);
  for (const unwrap::AtlasTriangle& t : un->triangles) o.charts.push_back(t.chart);
  expect_banded_equals_in_memory(un->scene, o, dir.file(""));
}

}  // namespace
}  // namespace vt
