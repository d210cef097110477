// Filters and pull-push: constant stays constant, a checkerboard averages to its mean, a ramp's
// energy is preserved, normals stay unit length, uncovered colour never reaches covered texels.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "bake/pyramid.h"

namespace vt {
namespace {

const MipFilter kFilters[] = {MipFilter::kBox, MipFilter::kKaiser, MipFilter::kLanczos3};
const AddressMode kModes[] = {AddressMode::kClamp, AddressMode::kWrap};

TEST(Kernel, NormalisedAndSymmetric) {
  for (MipFilter f : kFilters) {
    DownsampleKernel k = make_downsample_kernel(f);
    double sum = 0, even = 0;
    for (int t = 0; t < k.taps(); ++t) {
      sum += k.weights[t];
      if ((k.first + t) % 2 == 0) even += k.weights[t];
      EXPECT_NEAR(k.weights[t], k.weights[k.taps() - 1 - t], 1e-15) << to_string(f);
    }
    EXPECT_NEAR(sum, 1.0, 1e-14);
    EXPECT_NEAR(even, 0.5, 1e-14);  // every source texel gives half its weight: energy kept
  }
  EXPECT_EQ(make_downsample_kernel(MipFilter::kBox).taps(), 2);
  EXPECT_EQ(make_downsample_kernel(MipFilter::kLanczos3).taps(), 12);
  EXPECT_FALSE(parse_mip_filter("bicubic").ok());
  EXPECT_EQ(*parse_mip_filter("kaiser"), MipFilter::kKaiser);
}

TEST(Filters, NamesReadBackAndLanczosIsAnAlias) {
  for (MipFilter f : kFilters) {
    auto back = parse_mip_filter(to_string(f));
    ASSERT_TRUE(back.ok()) << to_string(f);
    EXPECT_EQ(*back, f);
  }
  EXPECT_STREQ(to_string(MipFilter::kLanczos3), "lanczos3");
  EXPECT_EQ(*parse_mip_filter("lanczos"), MipFilter::kLanczos3);
  EXPECT_FALSE(parse_mip_filter(nullptr).ok());
  EXPECT_FALSE(parse_mip_filter("Box").ok());
}

TEST(Filters, ConstantStaysConstantAtEveryLevel) {
  const float kValues[] = {0.3f, 1.0f, std::numeric_limits<float>::max()};
  for (MipFilter f : kFilters) {
    for (AddressMode m : kModes) {
      for (float v : kValues) {
        DownsampleKernel k = make_downsample_kernel(f);
        DownsampleRules rules;
        rules.address = m;
        uint32_t w = 37, h = 21;
        std::vector<float> img(size_t(w) * h * 3, v);
        while (w > 1 || h > 1) {
          img = downsample_level(k, rules, img.data(), w, h, 3);
          w = (w + 1) / 2, h = (h + 1) / 2;
          for (float t : img) ASSERT_EQ(t, v) << to_string(f) << " " << w << "x" << h;
        }
      }
    }
  }
}

TEST(Filters, CheckerboardAveragesToItsMean) {
  for (MipFilter f : kFilters) {
    DownsampleKernel k = make_downsample_kernel(f);
    DownsampleRules rules;
    rules.address = AddressMode::kWrap;  // no edge: every texel sees the pattern
    const uint32_t n = 32;
    std::vector<float> img(n * n);
    for (uint32_t y = 0; y < n; ++y) {
      for (uint32_t x = 0; x < n; ++x) img[y * n + x] = ((x + y) & 1) ? 0.9f : 0.1f;
    }
    auto half = downsample_level(k, rules, img.data(), n, n, 1);
    for (float t : half) ASSERT_NEAR(t, 0.5f, 1e-6f) << to_string(f);
  }
}

TEST(Filters, LinearRampEnergyPreserved) {
  for (MipFilter f : kFilters) {
    DownsampleKernel k = make_downsample_kernel(f);
    DownsampleRules rules;
    rules.address = AddressMode::kWrap;
    const uint32_t w = 64, h = 16;
    std::vector<float> img(w * h);
    double sum0 = 0;
    for (uint32_t y = 0; y < h; ++y) {
      for (uint32_t x = 0; x < w; ++x) sum0 += img[y * w + x] = 0.25f + 0.5f * x / (w - 1);
    }
    auto half = downsample_level(k, rules, img.data(), w, h, 1);
    double sum1 = 0;
    for (float t : half) sum1 += t;
    EXPECT_NEAR(sum1 * 4, sum0, 1e-4) << to_string(f);
    // Interior texels of a ramp stay on the ramp (the filters are symmetric).
    uint32_t x = 8;
    EXPECT_NEAR(half[2 * (w / 2) + x], 0.25 + 0.5 * (2 * x + 0.5) / (w - 1), 1e-5);
  }
}

TEST(Filters, HdrExtremesNeverOverflow) {
  const float big = std::numeric_limits<float>::max();
  for (MipFilter f : kFilters) {
    DownsampleKernel k = make_downsample_kernel(f);
    DownsampleRules rules;
    std::vector<float> img(16 * 16);
    for (size_t i = 0; i < img.size(); ++i) img[i] = (i * 7 % 3) ? big : 0.0f;
    auto half = downsample_level(k, rules, img.data(), 16, 16, 1);
    for (float t : half) ASSERT_TRUE(std::isfinite(t)) << to_string(f);
  }
}

TEST(Filters, NormalsStayUnitLength) {
  std::mt19937 rng(3);
  std::normal_distribution<float> nd;
  const uint32_t w = 40, h = 24;
  std::vector<float> img(w * h * 3);
  for (size_t i = 0; i < w * h; ++i) {
    float x = nd(rng), y = nd(rng), z = std::abs(nd(rng)) + 0.1f;
    img[i * 3] = x, img[i * 3 + 1] = y, img[i * 3 + 2] = z;
  }
  renormalize_normals(img.data(), w * h, 3);
  img[5 * 3] = -img[4 * 3], img[5 * 3 + 1] = -img[4 * 3 + 1], img[5 * 3 + 2] = -img[4 * 3 + 2];
  for (MipFilter f : kFilters) {
    DownsampleKernel k = make_downsample_kernel(f);
    DownsampleRules rules;
    rules.renormalize_xyz = true;
    for (int c = 0; c < 3; ++c) rules.min_value[c] = -1, rules.max_value[c] = 1;
    std::vector<float> lvl = img;
    uint32_t lw = w, lh = h;
    while (lw > 1 || lh > 1) {
      lvl = downsample_level(k, rules, lvl.data(), lw, lh, 3);
      lw = (lw + 1) / 2, lh = (lh + 1) / 2;
      for (size_t i = 0; i < size_t(lw) * lh; ++i) {
        double len =
            std::sqrt(double(lvl[i * 3]) * lvl[i * 3] + double(lvl[i * 3 + 1]) * lvl[i * 3 + 1] +
                      double(lvl[i * 3 + 2]) * lvl[i * 3 + 2]);
        ASSERT_NEAR(len, 1.0, 1e-6) << to_string(f);
      }
    }
  }
}

TEST(PullPush, UncoveredColourNeverReachesCoveredTexels) {
  const uint32_t w = 53, h = 41;
  std::vector<float> img(w * h * 3);
  std::vector<uint8_t> cov(w * h);
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < w; ++x) {
      float dx = x - 20.0f, dy = y - 18.0f;
      bool in = dx * dx + dy * dy < 120.0f || (x > 40 && y > 30);
      cov[y * w + x] = in;
      float* t = &img[(y * w + x) * 3];
      // Background is pure red; charts have no red at all.
      t[0] = in ? 0.0f : 1000.0f, t[1] = in ? 0.2f + 0.01f * x : 0.0f, t[2] = in ? 0.5f : 0.0f;
    }
  }
  auto before = img;
  uint64_t filled = pull_push(img.data(), cov.data(), w, h, 3);
  uint64_t uncovered = 0;
  for (uint8_t c : cov) uncovered += !c;
  EXPECT_EQ(filled, uncovered);
  for (size_t i = 0; i < w * h; ++i) {
    if (cov[i]) {
      ASSERT_EQ(img[i * 3 + 1], before[i * 3 + 1]);  // covered texels unchanged
    }
    ASSERT_EQ(img[i * 3], 0.0f) << "red reached texel " << i;
    ASSERT_GE(img[i * 3 + 1], 0.2f);  // fill is an average of chart colours
  }
  // The whole pyramid stays red-free, whatever the filter.
  for (MipFilter f : kFilters) {
    DownsampleKernel k = make_downsample_kernel(f);
    DownsampleRules rules;
    std::vector<float> lvl = img;
    std::vector<uint8_t> c = cov;
    uint32_t lw = w, lh = h;
    while (lw > 1 || lh > 1) {
      lvl = downsample_level(k, rules, lvl.data(), lw, lh, 3);
      c = downsample_coverage(c.data(), lw, lh);
      lw = (lw + 1) / 2, lh = (lh + 1) / 2;
      pull_push(lvl.data(), c.data(), lw, lh, 3);
      for (size_t i = 0; i < size_t(lw) * lh; ++i) ASSERT_EQ(lvl[i * 3], 0.0f);
    }
  }
}

// Flat charts 8 texels apart (the default padding) at every alignment: through level 3 each
// covered texel holds its own chart's colour exactly, whatever the filter; the filter without
// coverage reads across the gutter (so the check can fail).
TEST(Filters, ChartsAPaddingApartShareNoTexelThroughLevelLog2Padding) {
  constexpr uint32_t kPadding = 8, kLevels = 3;
  std::vector<uint32_t> starts_x, starts_y;  // chart sizes 5..12: every alignment mod 8
  uint32_t w = 0, h = 0;
  for (uint32_t size = 5, x = 0; size <= 12; x += size + kPadding, ++size)
    starts_x.push_back(x), w = x + size;
  for (uint32_t size = 12, y = 0; size >= 5; y += size + kPadding, --size)
    starts_y.push_back(y), h = y + size;
  std::vector<int> chart(size_t(w) * h, -1);
  for (size_t cy = 0; cy < starts_y.size(); ++cy)
    for (size_t cx = 0; cx < starts_x.size(); ++cx)
      for (uint32_t y = starts_y[cy]; y < starts_y[cy] + 12 - cy; ++y)
        for (uint32_t x = starts_x[cx]; x < starts_x[cx] + 5 + cx; ++x)
          chart[size_t(y) * w + x] = int(cy * starts_x.size() + cx);
  auto colour = [](int c, int k) { return float((c * 37 + k * 11) % 23) / 22.0f; };
  std::vector<float> base(size_t(w) * h * 3, 0.0f);
  std::vector<uint8_t> base_cov(size_t(w) * h);
  for (size_t i = 0; i < chart.size(); ++i) {
    base_cov[i] = chart[i] >= 0;
    for (int k = 0; k < 3; ++k) base[i * 3 + k] = chart[i] >= 0 ? colour(chart[i], k) : 0.0f;
  }
  pull_push(base.data(), base_cov.data(), w, h, 3);
  for (MipFilter f : kFilters) {
    for (bool with_coverage : {true, false}) {
      const DownsampleKernel k = make_downsample_kernel(f);
      std::vector<float> lvl = base;
      std::vector<uint8_t> cov = base_cov;
      uint32_t lw = w, lh = h;
      double worst = 0;
      for (uint32_t level = 1; level <= kLevels; ++level) {
        lvl = downsample_level(k, DownsampleRules{}, lvl.data(), lw, lh, 3,
                               with_coverage ? cov.data() : nullptr);
        cov = downsample_coverage(cov.data(), lw, lh);
        lw = (lw + 1) / 2, lh = (lh + 1) / 2;
        pull_push(lvl.data(), cov.data(), lw, lh, 3);
        const uint32_t s = 1u << level;
        for (uint32_t y = 0; y < lh; ++y) {
          for (uint32_t x = 0; x < lw; ++x) {
            if (!cov[size_t(y) * lw + x]) continue;
            int owner = -1;  // the one chart under the texel's footprint at level 0
            for (uint32_t v = y * s; v < std::min(h, (y + 1) * s); ++v)
              for (uint32_t u = x * s; u < std::min(w, (x + 1) * s); ++u) {
                const int c = chart[size_t(v) * w + u];
                if (c < 0) continue;
                ASSERT_TRUE(owner < 0 || owner == c) << "charts meet at level " << level;
                owner = c;
              }
            for (int c = 0; c < 3; ++c)
              worst = std::max(
                  worst, std::abs(double(lvl[(size_t(y) * lw + x) * 3 + c]) - colour(owner, c)));
          }
        }
      }
      if (with_coverage) {
        EXPECT_LT(worst, 1e-6) << to_string(f);
      } else if (f != MipFilter::kBox) {
        EXPECT_GT(worst, 0.01) << to_string(f) << ": the plain filter should cross the gutter";
      }
    }
  }
}

TEST(PullPush, NothingOrEverythingCoveredIsLeftAlone) {
  std::vector<float> img = {1, 2, 3, 4};
  std::vector<uint8_t> none(4, 0), all(4, 1);
  EXPECT_EQ(pull_push(img.data(), none.data(), 2, 2, 1), 0u);
  EXPECT_EQ(pull_push(img.data(), all.data(), 2, 2, 1), 0u);
  EXPECT_EQ(img, (std::vector<float>{1, 2, 3, 4}));
}

// Straight colour back from premultiplied: under zero alpha, the alpha-weighted colour of the
// texels around (not a plain mean: a texel at alpha 0.75 outweighs one at 0.25), alpha kept 0;
// a page without alpha anywhere stays black.
TEST(UnpremultiplyPage, ColourUnderZeroAlphaIsBledFromTheTexelsAround) {
  std::vector<float> page(4 * 4 * 4, 0.0f);
  const float red_a = 0.75f, green_a = 0.25f;
  page[0 * 4 + 0] = 1.0f * red_a, page[0 * 4 + 3] = red_a;      // texel (0, 0): red
  page[1 * 4 + 1] = 0.5f * green_a, page[1 * 4 + 3] = green_a;  // texel (1, 0): half green
  unpremultiply_page(page.data(), 4, 4, 3);
  EXPECT_FLOAT_EQ(page[0], 1.0f);
  EXPECT_FLOAT_EQ(page[3], red_a);
  EXPECT_FLOAT_EQ(page[4 + 1], 0.5f);
  EXPECT_FLOAT_EQ(page[4 + 3], green_a);
  for (size_t i = 2; i < 16; ++i) {
    EXPECT_FLOAT_EQ(page[i * 4 + 0], 0.75f) << i;  // (0.75 * 1 + 0.25 * 0) / (0.75 + 0.25)
    EXPECT_FLOAT_EQ(page[i * 4 + 1], 0.125f) << i;
    EXPECT_EQ(page[i * 4 + 2], 0.0f) << i;
    EXPECT_EQ(page[i * 4 + 3], 0.0f) << i;
  }
  std::vector<float> empty(4 * 4 * 4, 0.0f);
  unpremultiply_page(empty.data(), 4, 4, 3);
  EXPECT_EQ(empty, std::vector<float>(4 * 4 * 4, 0.0f));
}

}  // namespace
}  // namespace vt
