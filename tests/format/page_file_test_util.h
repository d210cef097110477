// Shared by the page-file tests: procedural page files with a known content for every page.
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "format/page_file.h"
#include "format/zstd_frame.h"

namespace vt::testing {

// Removes the test's temporary folders when the test executable exits.
struct TempDirs {
  std::vector<std::filesystem::path> dirs;
  ~TempDirs() {
    std::error_code ec;
    for (auto& d : dirs) std::filesystem::remove_all(d, ec);
  }
};
inline TempDirs temp_dirs;

// A path in a fresh folder of its own (so tests can check what else appears beside it).
inline std::string temp_path(const std::string& name) {
  static std::atomic<int> counter{0};
  auto dir = std::filesystem::temp_directory_path() /
             ("vtbake_format_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
  std::filesystem::create_directories(dir);
  temp_dirs.dirs.push_back(dir);
  return (dir / name).string();
}

inline std::vector<uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

// Rewrites the file in place: truncating to zero first would make ext4 flush it on close
// (auto_da_alloc), which slows the exhaustive corruption loops down tenfold.
inline void write_bytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) return;
  size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = ::pwrite(fd, bytes.data() + done, bytes.size() - done, off_t(done));
    if (n <= 0) break;
    done += size_t(n);
  }
  if (::ftruncate(fd, off_t(bytes.size())) != 0) done = 0;
  ::close(fd);
}

inline uint64_t le64(const std::vector<uint8_t>& b, size_t at) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | b[at + i];
  return v;
}

// What one page of one layer holds in a generated file.
struct ExpectedPage {
  PageId id;
  uint32_t layer = 0;
  PageState state = PageState::kAbsent;
  std::vector<uint8_t> stored;  // the coded bytes (stored pages)
  std::vector<uint8_t> texels;  // decoded texels (stored and constant pages)
};

struct GeneratedFile {
  PageFileDesc desc;
  std::vector<ExpectedPage> pages;  // every (page, layer), level 0 first
};

// Random content for every page of `desc`: a mix of absent, constant and stored pages, with
// texels smooth enough for zstd to compress.
inline GeneratedFile generate(PageFileDesc desc, uint32_t seed) {
  GeneratedFile f;
  f.desc = std::move(desc);
  const PageGeometry& g = f.desc.geometry;
  std::mt19937 rng(seed);
  const size_t texels = size_t(g.page_size()) * g.page_size();
  for (uint32_t level = 0; level < g.level_count(); ++level)
    for (uint32_t y = 0; y < g.pages_y(level); ++y)
      for (uint32_t x = 0; x < g.pages_x(level); ++x)
        for (uint32_t layer = 0; layer < f.desc.layers.size(); ++layer) {
          const LayerSpec& spec = f.desc.layers[layer];
          const size_t tb = spec.texel_bytes();
          ExpectedPage p;
          p.id = {level, x, y};
          p.layer = layer;
          const uint32_t pick = rng() % 8;
          if (pick == 0) {
            p.state = PageState::kAbsent;
          } else if (pick == 1) {
            p.state = PageState::kConstant;
            std::vector<uint8_t> value(tb);
            for (auto& b : value) b = uint8_t(rng());
            p.texels.resize(texels * tb);
            for (size_t i = 0; i < texels; ++i) std::memcpy(&p.texels[i * tb], value.data(), tb);
          } else {
            p.state = PageState::kStored;
            p.texels.resize(texels * tb);
            uint8_t v = uint8_t(rng());
            for (auto& b : p.texels) b = (rng() % 4 == 0) ? (v = uint8_t(rng())) : v;
            if (spec.codec == PageCodec::kRaw) {
              p.stored = p.texels;
            } else {
              EXPECT_TRUE(zstd_compress(p.texels, 1, p.stored).ok());
            }
          }
          f.pages.push_back(std::move(p));
        }
  return f;
}

// Writes the file with `threads` threads, pages in an order shuffled by `order_seed`.
inline Status write_file(const GeneratedFile& f, const std::string& path, int threads,
                         uint32_t order_seed) {
  auto writer = PageFileWriter::create(path, f.desc);
  if (!writer.ok()) return writer.status();
  std::vector<size_t> order(f.pages.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), std::mt19937(order_seed));
  std::vector<Status> results(threads);
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t)
    pool.emplace_back([&, t] {
      for (size_t i = t; i < order.size(); i += threads) {
        const ExpectedPage& p = f.pages[order[i]];
        Status s;
        if (p.state == PageState::kStored)
          s = (*writer)->add_page(p.id, p.layer, p.stored);
        else if (p.state == PageState::kConstant)
          s = (*writer)->add_constant_page(
              p.id, p.layer,
              std::span<const uint8_t>(p.texels.data(), f.desc.layers[p.layer].texel_bytes()));
        if (!s.ok() && results[t].ok()) results[t] = s;
      }
    });
  for (auto& th : pool) th.join();
  for (auto& s : results)
    if (!s.ok()) return s;
  return (*writer)->finish();
}

inline LayerSpec layer(const std::string& name, uint8_t channels, TexelType type, PageCodec codec) {
  LayerSpec l;
  l.name = name;
  l.channels = channels;
  l.texel_type = type;
  l.codec = codec;
  return l;
}

// The small file the corruption tests mangle: 3 levels, 9 pages, 2 layers (raw, raw+zstd).
inline GeneratedFile small_file() {
  PageFileDesc desc;
  desc.geometry = {20, 12, 8, 2};
  desc.layers = {layer("albedo", 1, TexelType::kU8, PageCodec::kRaw),
                 layer("height", 2, TexelType::kU8, PageCodec::kRawZstd)};
  desc.metadata_json = R"({"tool":"test"})";
  // The first seed whose file has absent, constant and stored pages in both layers.
  for (uint32_t seed = 1;; ++seed) {
    GeneratedFile f = generate(desc, seed);
    int seen[2][3] = {};
    for (auto& p : f.pages) seen[p.layer][int(p.state)] = 1;
    if (seen[0][0] && seen[0][1] && seen[0][2] && seen[1][0] && seen[1][1] && seen[1][2]) return f;
  }
}

}  // namespace vt::testing

namespace vt::testing {

// Cuts page (id) out of a level image (width x height texels of tb bytes) with its border,
// clamping at the image edge as the format's clamp address mode says.
inline std::vector<uint8_t> cut_page(const std::vector<uint8_t>& image, uint32_t width,
                                     uint32_t height, size_t tb, const PageGeometry& g,
                                     const PageId& id) {
  const uint32_t size = g.page_size();
  std::vector<uint8_t> page(size_t(size) * size * tb);
  for (uint32_t j = 0; j < size; ++j)
    for (uint32_t i = 0; i < size; ++i) {
      const int64_t tx = address_texel(g.page_origin_x(id) + i, width, AddressMode::kClamp);
      const int64_t ty = address_texel(g.page_origin_y(id) + j, height, AddressMode::kClamp);
      std::memcpy(&page[(size_t(j) * size + i) * tb], &image[(size_t(ty) * width + tx) * tb], tb);
    }
  return page;
}

// Random level images for every level of `g` (tb bytes per texel), level 0 first.
inline std::vector<std::vector<uint8_t>> random_levels(const PageGeometry& g, size_t tb,
                                                       uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<std::vector<uint8_t>> levels;
  for (uint32_t l = 0; l < g.level_count(); ++l) {
    std::vector<uint8_t> img(size_t(g.level_width(l)) * g.level_height(l) * tb);
    for (auto& b : img) b = uint8_t(rng());
    levels.push_back(std::move(img));
  }
  return levels;
}

}  // namespace vt::testing
