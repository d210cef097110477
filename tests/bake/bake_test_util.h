// Helpers for the bake tests: a level-0 check of a raw page file, a page sink that keeps pages in
// memory, and reassembly of level images from the pages' payloads.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <map>
#include <mutex>
#include <tuple>
#include <vector>

#include "bake/build.h"
#include "bake/build_plan.h"
#include "bake/page_encoder.h"
#include "bake/paging.h"
#include "format/page_file.h"
#include "format/page_file_inspect.h"

namespace vt::test {

// A layer from its semantic and source, the other members at their defaults.
inline LayerInput layer_input(LayerSemantic semantic, std::shared_ptr<ImageSource> source,
                              std::string name = "") {
  LayerInput layer;
  layer.semantic = semantic;
  layer.name = std::move(name);
  layer.source = std::move(source);
  return layer;
}

// Checks that level 0 of layer 0 of the page file at `path` holds w x h RGB texels and that
// texel (x, y) channel c is want(x, y, c) (raw codec: the stored payload exactly).
inline void expect_level0_rgb(
    const std::string& path, uint32_t w, uint32_t h,
    const std::function<uint8_t(uint32_t x, uint32_t y, uint32_t c)>& want) {
  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  auto level = extract_level(**reader, 0, 0);
  ASSERT_TRUE(level.ok()) << level.status().message();
  ASSERT_EQ(level->width, w);
  ASSERT_EQ(level->height, h);
  ASSERT_EQ(level->channels, 3u);
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < w; ++x) {
      for (uint32_t c = 0; c < 3; ++c) {
        ASSERT_EQ(level->texels[(size_t(y) * w + x) * 3 + c], want(x, y, c))
            << x << "," << y << " c" << c;
      }
    }
  }
}

struct StoredPage {
  PageState state = PageState::kAbsent;
  std::vector<uint8_t> bytes;  // stored bytes, or the constant texel
};

class MemorySink final : public PageSink {
 public:
  using Key = std::tuple<uint32_t, uint32_t, uint32_t, uint32_t>;  // layer, level, y, x
  Status add_page(const PageId& id, uint32_t layer, std::span<const uint8_t> data) override {
    return put(id, layer, PageState::kStored, data);
  }
  Status add_constant_page(const PageId& id, uint32_t layer,
                           std::span<const uint8_t> texel) override {
    return put(id, layer, PageState::kConstant, texel);
  }
  std::map<Key, StoredPage> pages;

 private:
  Status put(const PageId& id, uint32_t layer, PageState state, std::span<const uint8_t> bytes) {
    std::lock_guard<std::mutex> lock(mu_);
    auto& p = pages[{layer, id.level, id.y, id.x}];
    if (p.state != PageState::kAbsent) return Error(ErrorCode::kInternal, "page given twice");
    p.state = state;
    p.bytes.assign(bytes.begin(), bytes.end());
    return Status::Ok();
  }
  std::mutex mu_;
};

struct BuiltPages {
  PageFileDesc desc;
  BuildSummary summary;
  MemorySink sink;
};

inline std::unique_ptr<BuiltPages> build_in_memory(const BuildOptions& options) {
  auto out = std::make_unique<BuiltPages>();
  auto plan = plan_build(options);
  EXPECT_TRUE(plan.ok()) << plan.status().message();
  if (!plan.ok()) return nullptr;
  out->desc = plan->desc;
  auto sum = build_pages(*plan, out->sink);
  EXPECT_TRUE(sum.ok()) << sum.status().message();
  if (!sum.ok()) return nullptr;
  out->summary = *sum;
  return out;
}

// Decoded texels (page_size^2 * texel_bytes) of a page, or empty when absent.
inline std::vector<uint8_t> page_texels(const BuiltPages& b, uint32_t layer, const PageId& id,
                                        const PageEncoder& enc) {
  auto it = b.sink.pages.find({layer, id.level, id.y, id.x});
  if (it == b.sink.pages.end()) return {};
  std::vector<uint8_t> t(enc.page_bytes());
  if (it->second.state == PageState::kConstant) {
    size_t tb = it->second.bytes.size();
    for (size_t i = 0; i < t.size(); i += tb) std::memcpy(&t[i], it->second.bytes.data(), tb);
  } else {
    Status s = enc.decode(it->second.bytes, t.data());
    EXPECT_TRUE(s.ok()) << s.message();
  }
  return t;
}

inline PageEncoder encoder_for(const BuiltPages& b, uint32_t layer, const BuildOptions& o) {
  LayerSpec spec = b.desc.layers[layer];
  auto enc = PageEncoder::create(spec, o.codec, b.desc.geometry.page_size());
  EXPECT_TRUE(enc.ok());
  return std::move(enc).value();
}

// Level image (level_width x level_height texels of texel_bytes) from the pages' payloads.
// Texels of absent pages stay zero; `present` marks which texels came from a page.
inline std::vector<uint8_t> reassemble_level(const BuiltPages& b, uint32_t layer, uint32_t level,
                                             const PageEncoder& enc,
                                             std::vector<uint8_t>* present = nullptr) {
  const PageGeometry& g = b.desc.geometry;
  const uint32_t tb = b.desc.layers[layer].texel_bytes();
  const uint32_t lw = g.level_width(level), lh = g.level_height(level), S = g.page_size();
  std::vector<uint8_t> img(size_t(lw) * lh * tb);
  if (present) present->assign(size_t(lw) * lh, 0);
  for (uint32_t py = 0; py < g.pages_y(level); ++py) {
    for (uint32_t px = 0; px < g.pages_x(level); ++px) {
      auto t = page_texels(b, layer, {level, px, py}, enc);
      if (t.empty()) continue;
      for (uint32_t j = 0; j < g.payload; ++j) {
        uint32_t y = py * g.payload + j;
        if (y >= lh) break;
        for (uint32_t i = 0; i < g.payload; ++i) {
          uint32_t x = px * g.payload + i;
          if (x >= lw) break;
          size_t src = (size_t(j + g.border) * S + i + g.border) * tb;
          std::memcpy(&img[(size_t(y) * lw + x) * tb], &t[src], tb);
          if (present) (*present)[size_t(y) * lw + x] = 1;
        }
      }
    }
  }
  return img;
}

inline std::vector<float> as_floats(const std::vector<uint8_t>& bytes) {
  std::vector<float> f(bytes.size() / 4);
  std::memcpy(f.data(), bytes.data(), f.size() * 4);
  return f;
}

}  // namespace vt::test
