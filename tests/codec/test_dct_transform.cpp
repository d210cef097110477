// The DCT decoder's pixel back end (codec/dct_transform.h): every SIMD implementation gives the
// scalar reference's bytes on random and extreme inputs, the reference keeps the original
// decoder's arithmetic where the spec did not change it, and it is close to a real IDCT.
#include "codec/dct_transform.h"
#include "common/hash.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace vt::dct_detail {
namespace {

// The decoder's IDCT before the int16 saturation of pass 1 (codec/dct.cpp as it was).
void idct_unsaturated(const int16_t* f, int16_t* out) {
  int32_t tmp[8][8];
  for (int y = 0; y < 8; y++)
    for (int u = 0; u < 8; u++) {
      int32_t acc = 0;
      for (int v = 0; v < 8; v++) acc += kIdctBasis[y][v] * f[v * 8 + u];
      tmp[y][u] = (acc + 256) >> 9;
    }
  for (int y = 0; y < 8; y++)
    for (int x = 0; x < 8; x++) {
      int32_t acc = 0;
      for (int u = 0; u < 8; u++) acc += tmp[y][u] * kIdctBasis[x][u];
      out[y * 8 + x] = int16_t(std::clamp((acc + 2048) >> 12, -4095, 4095));
    }
}

std::vector<const TransformImpl*> simd_impls() {
  std::vector<const TransformImpl*> v;
  for (const TransformImpl& impl : transform_impls()) {
    if (std::string(impl.name) != "scalar") v.push_back(&impl);
  }
  return v;
}

// A block with nonzeros only in rows < nv, columns < nu.
void random_block(Lcg64& rng, int nv, int nu, int amp, int density_pct, int16_t* f) {
  std::memset(f, 0, 64 * sizeof(int16_t));
  for (int v = 0; v < nv; v++)
    for (int u = 0; u < nu; u++) {
      if (rng.range(0, 99) < density_pct) f[v * 8 + u] = int16_t(rng.range(-amp, amp));
    }
}

// Runs `f` through every SIMD implementation at an odd stride and compares with the reference.
void expect_idct_matches(const int16_t* f, int nv, int nu, const char* what) {
  constexpr int kStride = 13;
  int16_t ref[8 * kStride], got[8 * kStride];
  std::fill(std::begin(ref), std::end(ref), int16_t(0x5A5A));
  std::fill(std::begin(got), std::end(got), int16_t(0x5A5A));
  idct_block_scalar(f, nv, nu, ref, kStride);
  for (const TransformImpl* impl : simd_impls()) {
    impl->idct_block(f, nv, nu, got, kStride);
    ASSERT_EQ(0, std::memcmp(ref, got, sizeof(ref)))
        << impl->name << " " << what << " nv=" << nv << " nu=" << nu;
  }
  // nv, nu only select a fast path.
  int16_t full[8 * kStride];
  std::fill(std::begin(full), std::end(full), int16_t(0x5A5A));
  idct_block_scalar(f, 8, 8, full, kStride);
  ASSERT_EQ(0, std::memcmp(ref, full, sizeof(ref))) << what << " nv=" << nv << " nu=" << nu;
}

TEST(DctTransform, HostHasASimdImplementationOnX86) {
#if defined(__x86_64__) && !defined(VT_TRANSFORM_NO_SIMD)
  EXPECT_FALSE(simd_impls().empty());
#endif
  EXPECT_STREQ("scalar", transform_impls().back().name);
}

TEST(DctTransform, IdctSimdMatchesScalarOnRandomBlocks) {
  Lcg64 rng{1};
  for (int i = 0; i < 40000; i++) {
    const int nv = rng.range(1, 8), nu = rng.range(1, 8);
    const int amp = i % 4 == 0 ? 2047 : i % 4 == 1 ? 300 : i % 4 == 2 ? 60 : 8;
    int16_t f[64];
    random_block(rng, nv, nu, amp, rng.range(10, 100), f);
    expect_idct_matches(f, nv, nu, "random");
    if (HasFatalFailure()) return;
  }
}

TEST(DctTransform, IdctSimdMatchesScalarOnExtremeBlocks) {
  std::vector<std::vector<int16_t>> blocks;
  for (int s : {2047, -2047}) {
    blocks.push_back(std::vector<int16_t>(64, int16_t(s)));
    std::vector<int16_t> alt(64), chk(64), rows(64), cols(64), sgn(64), sgn2(64);
    for (int i = 0; i < 64; i++) {
      const int v = i / 8, u = i % 8;
      alt[i] = int16_t(i % 2 ? s : -s);
      chk[i] = int16_t((u + v) % 2 ? s : -s);
      rows[i] = int16_t(v % 2 ? s : -s);
      cols[i] = int16_t(u % 2 ? s : -s);
      // Signs that line up with basis rows 0 and 7: the largest pass-1 sums.
      sgn[i] = int16_t(kIdctBasis[0][v] >= 0 ? s : -s);
      sgn2[i] = int16_t(kIdctBasis[7][v] * (u % 3 == 0 ? 1 : -1) >= 0 ? s : -s);
    }
    for (auto* b : {&alt, &chk, &rows, &cols, &sgn, &sgn2}) blocks.push_back(*b);
  }
  // Every basis row's sign pattern, per column sign pattern.
  for (int y = 0; y < 8; y++)
    for (int x = 0; x < 8; x++) {
      std::vector<int16_t> b(64);
      for (int i = 0; i < 64; i++) {
        const int v = i / 8, u = i % 8;
        b[i] = int16_t(kIdctBasis[y][v] * kIdctBasis[x][u] >= 0 ? 2047 : -2047);
      }
      blocks.push_back(b);
    }
  Lcg64 rng{7};
  for (int i = 0; i < 2000; i++) {
    std::vector<int16_t> b(64);
    for (auto& c : b) c = int16_t(rng.range(0, 2) == 0 ? 0 : rng.range(0, 1) ? 2047 : -2047);
    blocks.push_back(b);
  }
  bool saturated = false;
  for (const auto& b : blocks) {
    for (int nv : {2, 4, 8})
      for (int nu : {2, 4, 8}) {
        // Keep the contract: zero outside nv x nu.
        int16_t f[64] = {};
        for (int v = 0; v < nv; v++)
          for (int u = 0; u < nu; u++) f[v * 8 + u] = b[v * 8 + u];
        expect_idct_matches(f, nv, nu, "extreme");
        if (HasFatalFailure()) return;
        int16_t sat[64], unsat[64];
        idct_block_scalar(f, 8, 8, sat, 8);
        idct_unsaturated(f, unsat);
        saturated |= std::memcmp(sat, unsat, sizeof(sat)) != 0;
      }
  }
  // The saturation of pass 1 is exercised (and is a real change for such blocks).
  EXPECT_TRUE(saturated);
}

TEST(DctTransform, IdctKeepsTheOriginalArithmeticOnValidBlocks) {
  // Pass 1 saturates only when several large coefficients share a column; realistic blocks,
  // and any with |F| <= 1000, decode exactly as before.
  Lcg64 rng{3};
  for (int i = 0; i < 20000; i++) {
    int16_t f[64], a[64], b[64];
    random_block(rng, 8, 8, i % 2 ? 1000 : 200, rng.range(5, 100), f);
    idct_block_scalar(f, 8, 8, a, 8);
    idct_unsaturated(f, b);
    ASSERT_EQ(0, std::memcmp(a, b, sizeof(a))) << "block " << i;
  }
}

TEST(DctTransform, DcBlockMatchesFullIdctForEveryDc) {
  for (int dc = -2047; dc <= 2047; dc++) {
    int16_t f[64] = {};
    f[0] = int16_t(dc);
    int16_t ref[8 * 11], got[8 * 11];
    idct_block_scalar(f, 1, 1, ref, 11);
    std::fill(got, got + 8 * 11, int16_t(-1));
    idct_dc_block(dc, got, 11);
    for (int y = 0; y < 8; y++)
      for (int x = 0; x < 8; x++) ASSERT_EQ(ref[y * 11 + x], got[y * 11 + x]) << "dc=" << dc;
    for (const TransformImpl& impl : transform_impls()) {
      impl.idct_block(f, 1, 1, got, 11);
      for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++) {
          ASSERT_EQ(ref[y * 11 + x], got[y * 11 + x]) << impl.name << " dc=" << dc;
        }
    }
  }
}

TEST(DctTransform, IdctBasisIsTheRoundedOrthonormalBasis) {
  const double pi = std::acos(-1.0);
  for (int x = 0; x < 8; x++)
    for (int u = 0; u < 8; u++) {
      const double c = (u == 0 ? std::sqrt(0.125) : 0.5) * std::cos((2 * x + 1) * u * pi / 16);
      EXPECT_EQ(kIdctBasis[x][u], std::lround(4096 * c)) << x << "," << u;
    }
}

TEST(DctTransform, ScalarIdctIsCloseToDoublePrecisionIdct) {
  // Realistic blocks: forward DCT (double) of smooth-ish pixel blocks in 1/8 units, rounded.
  const double pi = std::acos(-1.0);
  double c[8][8];  // c[x][u]
  for (int x = 0; x < 8; x++)
    for (int u = 0; u < 8; u++) {
      c[x][u] = (u == 0 ? std::sqrt(0.125) : 0.5) * std::cos((2 * x + 1) * u * pi / 16);
    }
  Lcg64 rng{11};
  int worst = 0;
  double sum_err = 0;
  int count = 0;
  for (int i = 0; i < 5000; i++) {
    double px[8][8];  // texel units, centred on 0
    const double gx = rng.range(-30, 30), gy = rng.range(-30, 30), base = rng.range(-120, 120);
    const int noise = i % 3 == 0 ? 0 : i % 3 == 1 ? 10 : 60;
    for (int y = 0; y < 8; y++)
      for (int x = 0; x < 8; x++) {
        px[y][x] = std::clamp(base + gx * (x - 3.5) + gy * (y - 3.5) + rng.range(-noise, noise),
                              -127.0, 127.0);
      }
    int16_t f[64];
    for (int v = 0; v < 8; v++)
      for (int u = 0; u < 8; u++) {
        double s = 0;
        for (int y = 0; y < 8; y++)
          for (int x = 0; x < 8; x++) s += c[y][v] * c[x][u] * px[y][x];
        f[v * 8 + u] = int16_t(std::clamp(int(std::lround(s)), -2047, 2047));
      }
    int16_t out[64];
    idct_block_scalar(f, 8, 8, out, 8);
    for (int y = 0; y < 8; y++)
      for (int x = 0; x < 8; x++) {
        double s = 0;
        for (int v = 0; v < 8; v++)
          for (int u = 0; u < 8; u++) s += c[y][v] * c[x][u] * f[v * 8 + u];
        const int err = std::abs(out[y * 8 + x] - int(std::lround(8 * s)));
        worst = std::max(worst, err);
        sum_err += err;
        count++;
      }
  }
  // 1/8 texel units: within a quarter texel, a small fraction of a unit on average.
  EXPECT_LE(worst, 2);
  EXPECT_LT(sum_err / count, 0.3);
}

// ---- colour ----

struct Planes {
  int width, height, ystride, cstride;
  std::vector<int16_t> y, co, cg;
};

enum class Fill { kRandom, kExtreme, kRealistic };

Planes make_planes(Lcg64& rng, int width, int height, bool half, Fill fill, int chroma_max) {
  Planes p;
  p.width = width;
  p.height = height;
  p.ystride = width + 2 * rng.range(0, 3) + 1;  // odd strides
  const int cw = half ? width / 2 : width, ch = half ? height / 2 : height;
  p.cstride = cw + 2 * rng.range(0, 3) + 1;
  p.y.resize(size_t(p.ystride) * height);
  p.co.resize(size_t(p.cstride) * ch);
  p.cg.resize(size_t(p.cstride) * ch);
  auto gen = [&](int lim) {
    switch (fill) {
      case Fill::kRandom:
        return int16_t(rng.range(-lim, lim));
      case Fill::kExtreme:
        return int16_t(rng.range(0, 1) ? lim : -lim);
      case Fill::kRealistic:
        break;
    }
    return int16_t(rng.range(-std::min(lim, 1020), std::min(lim, 1020)));
  };
  for (auto& v : p.y) v = gen(4095);
  for (auto& v : p.co) v = gen(chroma_max);
  for (auto& v : p.cg) v = gen(chroma_max);
  return p;
}

using ColourFn = void (*)(const int16_t*, int, const int16_t*, const int16_t*, int, int, int, int,
                          uint8_t*);

void expect_colour_matches(const Planes& p, bool half, int ch, Lcg64& rng, const char* what) {
  std::vector<uint8_t> ref(size_t(p.width) * p.height * ch);
  for (auto& b : ref) b = uint8_t(rng.next());  // channel 3 must survive
  const std::vector<uint8_t> before = ref;
  const ColourFn scalar = half ? ycocg420_to_rgb_scalar : ycocg_to_rgb_scalar;
  scalar(p.y.data(), p.ystride, p.co.data(), p.cg.data(), p.cstride, p.width, p.height, ch,
         ref.data());
  if (ch == 4) {
    for (size_t i = 3; i < ref.size(); i += 4) ASSERT_EQ(before[i], ref[i]);
  }
  for (const TransformImpl* impl : simd_impls()) {
    std::vector<uint8_t> got = before;
    const ColourFn fn = half ? impl->ycocg420_to_rgb : impl->ycocg_to_rgb;
    fn(p.y.data(), p.ystride, p.co.data(), p.cg.data(), p.cstride, p.width, p.height, ch,
       got.data());
    ASSERT_EQ(ref, got) << impl->name << " " << what << (half ? " 4:2:0" : " 4:4:4") << " "
                        << p.width << "x" << p.height << " ch=" << ch;
  }
}

TEST(DctTransform, ColourSimdMatchesScalar) {
  Lcg64 rng{5};
  for (bool half : {true, false})
    for (int ch : {3, 4})
      for (int width = 8; width <= 256; width += 8)
        for (Fill fill : {Fill::kRandom, Fill::kExtreme, Fill::kRealistic}) {
          const int height = 8 * rng.range(1, 3);
          // 4:2:0 chroma may be any int16 (clamped to +-2047 first); 4:4:4 chroma is an IDCT
          // output.
          for (int chroma_max :
               half ? std::vector<int>{2047, 4095, 32767} : std::vector<int>{4095}) {
            const Planes p = make_planes(rng, width, height, half, fill, chroma_max);
            expect_colour_matches(p, half, ch, rng, fill == Fill::kExtreme ? "extreme" : "random");
            if (HasFatalFailure()) return;
          }
        }
}

TEST(DctTransform, ColourLargePagesMatchScalar) {
  Lcg64 rng{9};
  for (int size : {128, 512, 4096}) {
    const int width = size, height = size == 4096 ? 16 : size;
    for (bool half : {true, false}) {
      const Planes p = make_planes(rng, width, height, half, Fill::kRandom, 2047);
      expect_colour_matches(p, half, 3, rng, "large");
      expect_colour_matches(p, half, 4, rng, "large");
      if (HasFatalFailure()) return;
    }
  }
}

// The original decoder's 4:2:0 conversion (codec/dct.cpp as it was), no chroma clamp.
void ycocg420_unclamped(const Planes& p, int ch, uint8_t* texels) {
  auto to_u8 = [](int v8) { return uint8_t(std::clamp((v8 + 4) >> 3, 0, 255)); };
  const int cw = p.width / 2, chh = p.height / 2;
  std::vector<int32_t> vco(cw), vcg(cw);
  for (int y = 0; y < p.height; y++) {
    const int cy = y >> 1;
    const int ny = std::clamp((y & 1) ? cy + 1 : cy - 1, 0, chh - 1);
    for (int x = 0; x < cw; x++) {
      vco[x] = 3 * p.co[size_t(cy) * p.cstride + x] + p.co[size_t(ny) * p.cstride + x];
      vcg[x] = 3 * p.cg[size_t(cy) * p.cstride + x] + p.cg[size_t(ny) * p.cstride + x];
    }
    for (int x = 0; x < p.width; x++) {
      const int cx = x / 2, n = x % 2 ? std::min(cx + 1, cw - 1) : std::max(cx - 1, 0);
      const int co8 = (3 * vco[cx] + 8 + vco[n]) >> 4, cg8 = (3 * vcg[cx] + 8 + vcg[n]) >> 4;
      const int yy = p.y[size_t(y) * p.ystride + x] + 1024, t = yy - cg8;
      uint8_t* o = texels + (size_t(y) * p.width + x) * ch;
      o[0] = to_u8(t + co8);
      o[1] = to_u8(yy + cg8);
      o[2] = to_u8(t - co8);
    }
  }
}

TEST(DctTransform, Colour420KeepsTheOriginalArithmeticWithinTheChromaClamp) {
  Lcg64 rng{13};
  for (int width : {8, 64, 128}) {
    Planes p = make_planes(rng, width, 32, true, Fill::kRandom, 2047);
    std::vector<uint8_t> a(size_t(width) * 32 * 3), b(a.size());
    ycocg420_to_rgb_scalar(p.y.data(), p.ystride, p.co.data(), p.cg.data(), p.cstride, width, 32, 3,
                           a.data());
    ycocg420_unclamped(p, 3, b.data());
    EXPECT_EQ(a, b) << width;
    // Beyond +-2047 the chroma is clamped: 3000 reads as 2047.
    Planes q = p;
    for (auto& v : q.co) v = int16_t(v > 1500 ? 3000 : v < -1500 ? -3000 : v);
    for (auto& v : p.co) v = int16_t(v > 1500 ? 2047 : v < -1500 ? -2047 : v);
    ycocg420_to_rgb_scalar(p.y.data(), p.ystride, p.co.data(), p.cg.data(), p.cstride, width, 32, 3,
                           a.data());
    ycocg420_to_rgb_scalar(q.y.data(), q.ystride, q.co.data(), q.cg.data(), q.cstride, width, 32, 3,
                           b.data());
    EXPECT_EQ(a, b) << width;
  }
}

TEST(DctTransform, PlaneToChannelSimdMatchesScalar) {
  Lcg64 rng{17};
  for (int ch = 1; ch <= 4; ch++)
    for (int c = 0; c < ch; c++)
      for (int width = 8; width <= 160; width += 8)
        for (bool extreme : {false, true}) {
          const int height = 8 * rng.range(1, 2), stride = width + 2 * rng.range(0, 2) + 1;
          std::vector<int16_t> src(size_t(stride) * height);
          for (auto& v : src) {
            v = extreme ? int16_t(rng.range(0, 3) == 0 ? -32768
                                  : rng.range(0, 1)    ? 32767
                                                       : -4095)
                        : int16_t(rng.range(-4095, 4095));
          }
          std::vector<uint8_t> ref(size_t(width) * height * ch);
          for (auto& b : ref) b = uint8_t(rng.next());
          const std::vector<uint8_t> before = ref;
          plane_to_channel_scalar(src.data(), stride, width, height, ch, c, ref.data());
          for (size_t i = 0; i < ref.size(); i++) {
            if (int(i % ch) != c) {
              ASSERT_EQ(before[i], ref[i]);
            }
          }
          for (const TransformImpl* impl : simd_impls()) {
            std::vector<uint8_t> got = before;
            impl->plane_to_channel(src.data(), stride, width, height, ch, c, got.data());
            ASSERT_EQ(ref, got) << impl->name << " ch=" << ch << " c=" << c << " width=" << width;
          }
        }
}

TEST(DctTransform, DispatchedFunctionsUseTheBestImplementation) {
  Lcg64 rng{19};
  int16_t f[64];
  random_block(rng, 8, 8, 2047, 100, f);
  int16_t a[64], b[64];
  idct_block(f, 8, 8, a, 8);
  transform_impls().front().idct_block(f, 8, 8, b, 8);
  EXPECT_EQ(0, std::memcmp(a, b, sizeof(a)));
  const Planes p = make_planes(rng, 128, 16, true, Fill::kRandom, 2047);
  std::vector<uint8_t> x(128 * 16 * 4, 7), y(x.size(), 7);
  ycocg420_to_rgb(p.y.data(), p.ystride, p.co.data(), p.cg.data(), p.cstride, 128, 16, 4, x.data());
  ycocg420_to_rgb_scalar(p.y.data(), p.ystride, p.co.data(), p.cg.data(), p.cstride, 128, 16, 4,
                         y.data());
  EXPECT_EQ(x, y);
}

}  // namespace
}  // namespace vt::dct_detail
