// Page-file inspection: statistics from the index, checksum verification over threads, and
// level reassembly with ancestor fill for absent pages.
#include "format/page_file_inspect.h"
#include "common/parallel.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <map>
#include <tuple>

namespace vt {

namespace {

// "68719476736 bytes (64.0 GiB)": exact, and readable at a glance.
std::string format_bytes(uint64_t bytes) {
  char text[64];
  std::snprintf(text, sizeof text, "%llu bytes (%.1f GiB)", (unsigned long long)bytes,
                double(bytes) / double(uint64_t(1) << 30));
  return text;
}

}  // namespace

PageFileStats page_file_stats(const PageFileReader& reader) {
  const PageGeometry& g = reader.geometry();
  const uint32_t layers = uint32_t(reader.layers().size());
  PageFileStats stats;
  for (uint32_t level = 0; level < g.level_count(); ++level) {
    LevelStats s;
    s.level = level;
    s.pages_x = g.pages_x(level);
    s.pages_y = g.pages_y(level);
    for (uint32_t y = 0; y < s.pages_y; ++y)
      for (uint32_t x = 0; x < s.pages_x; ++x)
        for (uint32_t layer = 0; layer < layers; ++layer) {
          auto e = reader.entry({level, x, y}, layer);
          if (!e.ok() || e->state == PageState::kAbsent) {
            ++s.absent_pages;
            continue;
          }
          s.raw_bytes += reader.decoded_page_bytes(layer);
          if (e->state == PageState::kConstant) {
            ++s.constant_pages;
          } else {
            ++s.stored_pages;
            s.bytes += e->size;
          }
        }
    stats.stored_bytes += s.bytes;
    stats.raw_bytes += s.raw_bytes;
    stats.levels.push_back(s);
  }
  stats.compression_ratio =
      stats.stored_bytes ? double(stats.raw_bytes) / double(stats.stored_bytes) : 0.0;
  return stats;
}

VerifyReport verify_pages(const PageFileReader& reader, int threads) {
  const PageGeometry& g = reader.geometry();
  const uint32_t layers = uint32_t(reader.layers().size());
  struct Item {
    PageId id;
    uint32_t layer;
  };
  std::vector<Item> items;
  for (uint32_t level = 0; level < g.level_count(); ++level)
    for (uint32_t y = 0; y < g.pages_y(level); ++y)
      for (uint32_t x = 0; x < g.pages_x(level); ++x)
        for (uint32_t layer = 0; layer < layers; ++layer) {
          auto e = reader.entry({level, x, y}, layer);
          if (e.ok() && e->state == PageState::kStored) items.push_back({{level, x, y}, layer});
        }

  std::vector<Status> results(items.size());
  parallel_for(items.size(), threads,
               [&](size_t i) { results[i] = reader.verify_page(items[i].id, items[i].layer); });

  VerifyReport report;
  report.pages_checked = items.size();
  for (size_t i = 0; i < items.size(); ++i)
    if (!results[i].ok()) report.bad_pages.push_back({items[i].id, items[i].layer, results[i]});
  return report;
}

Status PageFileReader::verify() const {
  const VerifyReport report = verify_pages(*this, 1);
  return report.bad_pages.empty() ? Status::Ok() : report.bad_pages.front().status;
}

Expected<LevelImage> extract_level(const PageFileReader& reader, uint32_t level, uint32_t layer,
                                   uint64_t max_bytes) {
  const PageGeometry& g = reader.geometry();
  if (level >= g.level_count())
    return Error(ErrorCode::kInvalidArgument, reader.path() + ": no level " +
                                                  std::to_string(level) + " (the file has " +
                                                  std::to_string(g.level_count()) + ")");
  if (layer >= reader.layers().size())
    return Error(ErrorCode::kInvalidArgument, reader.path() + ": no layer " +
                                                  std::to_string(layer) + " (the file has " +
                                                  std::to_string(reader.layers().size()) + ")");
  const LayerSpec& spec = reader.layers()[layer];
  const size_t tb = spec.texel_bytes();
  const uint32_t P = g.payload, B = g.border, S = g.page_size();
  // Width and height are below 2^24 (PageGeometry::validate): the product fits 64 bits.
  const uint64_t bytes = uint64_t(g.level_width(level)) * g.level_height(level) * tb;
  if (bytes > max_bytes)
    return Error(ErrorCode::kInvalidArgument,
                 reader.path() + ": level " + std::to_string(level) + " of layer " +
                     std::to_string(layer) + " is " + std::to_string(g.level_width(level)) + "x" +
                     std::to_string(g.level_height(level)) + " texels of " + std::to_string(tb) +
                     " bytes: " + format_bytes(bytes) + ", more than the " +
                     format_bytes(max_bytes) + " an extracted image may hold");
  LevelImage image;
  image.width = g.level_width(level);
  image.height = g.level_height(level);
  image.channels = spec.channels;
  image.texel_type = spec.texel_type;
  image.texels.assign(size_t(image.width) * image.height * tb, 0);

  // Decoded ancestor pages, kept while their descendants are filled.
  std::map<std::tuple<uint32_t, uint32_t, uint32_t>, std::vector<uint8_t>> ancestors;
  std::vector<uint8_t> page(reader.decoded_page_bytes(layer));
  for (uint32_t py = 0; py < g.pages_y(level); ++py)
    for (uint32_t px = 0; px < g.pages_x(level); ++px) {
      const uint32_t x0 = px * P, y0 = py * P;
      const uint32_t x1 = std::min(x0 + P, image.width), y1 = std::min(y0 + P, image.height);
      VT_ASSIGN_OR_RETURN(PageEntry e, reader.entry({level, px, py}, layer));
      if (e.state != PageState::kAbsent) {
        VT_RETURN_IF_ERROR(reader.read_texels({level, px, py}, layer, page));
        for (uint32_t ty = y0; ty < y1; ++ty)
          std::memcpy(&image.texels[(size_t(ty) * image.width + x0) * tb],
                      &page[(size_t(ty - y0 + B) * S + B) * tb], size_t(x1 - x0) * tb);
        continue;
      }
      uint32_t d = 1;
      const std::vector<uint8_t>* source = nullptr;
      for (; level + d < g.level_count(); ++d) {
        const PageId id{level + d, px >> d, py >> d};
        auto key = std::make_tuple(id.level, id.x, id.y);
        if (auto it = ancestors.find(key); it != ancestors.end()) {
          source = &it->second;
          break;
        }
        VT_ASSIGN_OR_RETURN(PageEntry ae, reader.entry(id, layer));
        if (ae.state == PageState::kAbsent) continue;
        std::vector<uint8_t> decoded(page.size());
        VT_RETURN_IF_ERROR(reader.read_texels(id, layer, decoded));
        source = &(ancestors[key] = std::move(decoded));
        break;
      }
      if (!source) {
        ++image.filled_with_zero;
        continue;
      }
      ++image.filled_from_ancestor;
      const uint32_t ax0 = (px >> d) * P, ay0 = (py >> d) * P;
      for (uint32_t ty = y0; ty < y1; ++ty)
        for (uint32_t tx = x0; tx < x1; ++tx) {
          const uint32_t ax = (tx >> d) - ax0 + B, ay = (ty >> d) - ay0 + B;
          std::memcpy(&image.texels[(size_t(ty) * image.width + tx) * tb],
                      &(*source)[(size_t(ay) * S + ax) * tb], tb);
        }
    }
  return image;
}

}  // namespace vt
