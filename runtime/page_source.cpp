#include "runtime/page_source.h"

#include <zstd.h>

#include <cstring>
#include <optional>
#include <vector>

#include "codec/dct.h"
#include "runtime/feedback.h"

namespace vt {

namespace {

std::optional<BcFormat> bc_format_of(RuntimeFormat f) {
  switch (f) {
    case RuntimeFormat::kBc1:
      return BcFormat::kBc1;
    case RuntimeFormat::kBc3:
      return BcFormat::kBc3;
    case RuntimeFormat::kBc4:
      return BcFormat::kBc4;
    case RuntimeFormat::kBc5:
      return BcFormat::kBc5;
    case RuntimeFormat::kBc7:
      return BcFormat::kBc7;
    default:
      return std::nullopt;
  }
}

uint32_t uncompressed_channels(RuntimeFormat f) {
  switch (f) {
    case RuntimeFormat::kR8:
      return 1;
    case RuntimeFormat::kRg8:
      return 2;
    default:
      return 4;
  }
}

struct LayerPlan {
  RuntimeFormat upload = RuntimeFormat::kRgba8;
  size_t upload_bytes = 0;
  size_t decoded_bytes = 0;
  uint32_t channels = 4;              // stored channels
  bool passthrough = false;           // stored BC blocks are already the upload format
  bool float_copy = false;            // float layers delivered as they are
  std::optional<BcFormat> stored_bc;  // the layer's BC format (kBcZstd pages' blocks)
  std::shared_ptr<DctTables> dct;     // parsed once from the layer's codec tables
};

class PageFileSource final : public PageSource {
 public:
  PageFileSource(std::shared_ptr<const PageFileReader> reader, const PageFileSourceOptions& o,
                 std::vector<LayerPlan> plans, std::vector<uint64_t> presence,
                 std::vector<uint64_t> level_base)
      : reader_(std::move(reader)),
        options_(o),
        plans_(std::move(plans)),
        presence_(std::move(presence)),
        level_base_(std::move(level_base)) {}

  const PageGeometry& geometry() const override { return reader_->geometry(); }
  uint32_t layer_count() const override { return uint32_t(plans_.size()); }
  RuntimeFormat upload_format(uint32_t layer) const override { return plans_[layer].upload; }
  size_t upload_bytes(uint32_t layer) const override { return plans_[layer].upload_bytes; }

  bool present(const PageId& id) const override {
    if (!geometry().contains(id)) return false;
    const uint64_t bit =
        level_base_[id.level] + uint64_t(id.y) * geometry().pages_x(id.level) + id.x;
    return (presence_[bit >> 6] >> (bit & 63)) & 1;
  }

  Status load(const PageId& id, uint32_t layer, std::span<uint8_t> out) const override {
    if (layer >= plans_.size() || !geometry().contains(id))
      return Error(ErrorCode::kInvalidArgument, reader_->path() + ": no such page or layer");
    const LayerPlan& plan = plans_[layer];
    if (out.size() != plan.upload_bytes)
      return Error(ErrorCode::kInvalidArgument, reader_->path() + ": wrong upload buffer size");
    const std::string where = reader_->path() + ": page (" + std::to_string(id.level) + ", " +
                              std::to_string(id.x) + ", " + std::to_string(id.y) + ") layer " +
                              std::to_string(layer);
    auto entry = reader_->entry(id, layer);
    if (!entry.ok()) return entry.status().with_context(where);
    std::vector<uint8_t> texels(plan.decoded_bytes);
    const int ps = int(geometry().page_size());
    if (entry->state == PageState::kStored &&
        (entry->codec == PageCodec::kBcZstd || entry->codec == PageCodec::kDct)) {
      // Decoded here rather than by the reader, so BC blocks can skip a decode/re-encode.
      auto stored = reader_->read_stored(id, layer);
      if (!stored.ok()) return stored.status().with_context(where);
      if (entry->codec == PageCodec::kDct) {
        if (!plan.dct) return Error(ErrorCode::kCorrupt, where + ": DCT page without tables");
        VT_RETURN_IF_ERROR(
            dct_decode_page(*plan.dct, *stored, ps, ps, texels.data()).with_context(where));
      } else {
        if (!plan.stored_bc)
          return Error(ErrorCode::kCorrupt, where + ": BC page in a layer with no BC format");
        std::vector<uint8_t> local;
        std::span<uint8_t> blocks = out;
        if (!plan.passthrough) {
          local.resize(bc_image_bytes(*plan.stored_bc, ps, ps));
          blocks = local;
        }
        const unsigned long long size = ZSTD_getFrameContentSize(stored->data(), stored->size());
        if (size != blocks.size())
          return Error(ErrorCode::kCorrupt, where + ": BC page decompresses to the wrong size");
        const size_t got =
            ZSTD_decompress(blocks.data(), blocks.size(), stored->data(), stored->size());
        if (ZSTD_isError(got) || got != blocks.size())
          return Error(ErrorCode::kCorrupt, where + ": zstd: " + ZSTD_getErrorName(got));
        if (plan.passthrough) return Status::Ok();
        VT_RETURN_IF_ERROR(bc_decode_image(*plan.stored_bc, blocks.data(), ps, ps,
                                           int(plan.channels), texels.data())
                               .with_context(where));
      }
    } else {
      VT_RETURN_IF_ERROR(reader_->read_texels(id, layer, texels).with_context(where));
    }
    if (plan.float_copy) {
      std::memcpy(out.data(), texels.data(), out.size());
      return Status::Ok();
    }
    if (auto bc = bc_format_of(plan.upload)) {
      return bc_encode_image(*bc, options_.bc_quality, texels.data(), ps, ps, int(plan.channels),
                             out.data())
          .with_context(where);
    }
    // Uncompressed 8-bit: channel i of the upload reads stored channel i, 0 when missing
    // (255 for a missing alpha of an RGBA upload).
    const uint32_t oc = uncompressed_channels(plan.upload), ic = plan.channels;
    const size_t n = size_t(ps) * ps;
    for (size_t t = 0; t < n; ++t)
      for (uint32_t c = 0; c < oc; ++c)
        out[t * oc + c] = c < ic ? texels[t * ic + c] : (c == 3 ? 255 : 0);
    return Status::Ok();
  }

 private:
  std::shared_ptr<const PageFileReader> reader_;
  PageFileSourceOptions options_;
  std::vector<LayerPlan> plans_;
  std::vector<uint64_t> presence_;
  std::vector<uint64_t> level_base_;
};

}  // namespace

size_t runtime_format_page_bytes(RuntimeFormat format, uint32_t page_size) {
  const size_t texels = size_t(page_size) * page_size;
  switch (format) {
    case RuntimeFormat::kBc1:
    case RuntimeFormat::kBc4:
      return texels / 2;
    case RuntimeFormat::kBc3:
    case RuntimeFormat::kBc5:
    case RuntimeFormat::kBc7:
      return texels;
    case RuntimeFormat::kR8:
      return texels;
    case RuntimeFormat::kRg8:
      return texels * 2;
    case RuntimeFormat::kRgba8:
      return texels * 4;
    case RuntimeFormat::kRgba16f:
      return texels * 8;
    case RuntimeFormat::kRgba32f:
      return texels * 16;
  }
  return 0;
}

Expected<std::unique_ptr<PageSource>> make_page_file_source(
    std::shared_ptr<const PageFileReader> reader, const PageFileSourceOptions& options) {
  if (!reader) return Error(ErrorCode::kInvalidArgument, "page file source: no reader");
  const std::string& path = reader->path();
  const PageGeometry& g = reader->geometry();
  if (g.pages_x(0) > kFeedbackMaxPages || g.pages_y(0) > kFeedbackMaxPages ||
      g.level_count() > kFeedbackMaxLevels)
    return Error(ErrorCode::kUnsupported,
                 path + ": more than 4096 x 4096 pages at level 0 (the feedback format's limit)");
  if (g.page_size() % 4 != 0)
    return Error(ErrorCode::kCorrupt, path + ": page size is not a multiple of 4");

  std::vector<LayerPlan> plans;
  for (uint32_t l = 0; l < reader->layers().size(); ++l) {
    const LayerSpec& spec = reader->layers()[l];
    const std::string where = path + ": layer " + std::to_string(l) + " (" + spec.name + ")";
    LayerPlan plan;
    plan.channels = spec.channels;
    plan.decoded_bytes = reader->decoded_page_bytes(l);
    plan.upload = spec.runtime_format;
    if (plan.upload == RuntimeFormat::kBc7 && options.bc7_as_rgba8)
      plan.upload = RuntimeFormat::kRgba8;
    if (spec.texel_type != TexelType::kU8) {
      const bool ok =
          spec.channels == 4 &&
          ((spec.texel_type == TexelType::kF16 && plan.upload == RuntimeFormat::kRgba16f) ||
           (spec.texel_type == TexelType::kF32 && plan.upload == RuntimeFormat::kRgba32f));
      if (!ok)
        return Error(ErrorCode::kUnsupported,
                     where + ": float texels are only delivered as 4-channel float of their size");
      plan.float_copy = true;
    } else if (plan.upload == RuntimeFormat::kRgba16f || plan.upload == RuntimeFormat::kRgba32f) {
      return Error(ErrorCode::kUnsupported, where + ": 8-bit texels with a float runtime format");
    }
    plan.stored_bc = bc_format_of(spec.runtime_format);
    plan.passthrough = plan.stored_bc && plan.upload == spec.runtime_format;
    if (spec.codec == PageCodec::kDct) {
      if (spec.texel_type != TexelType::kU8)
        return Error(ErrorCode::kCorrupt, where + ": DCT layer with float texels");
      auto tables = dct_parse_tables(spec.codec_tables);
      if (!tables.ok()) return tables.status().with_context(where + ": DCT tables");
      plan.dct = std::shared_ptr<DctTables>(tables->release(), DctTablesDeleter());
    }
    plan.upload_bytes = runtime_format_page_bytes(plan.upload, g.page_size());
    if (plan.float_copy && plan.decoded_bytes != plan.upload_bytes)
      return Error(ErrorCode::kCorrupt, where + ": decoded page size does not match its format");
    plans.push_back(plan);
  }
  if (plans.empty()) return Error(ErrorCode::kCorrupt, path + ": no layers");

  std::vector<uint64_t> level_base;
  uint64_t total = 0;
  for (uint32_t l = 0; l < g.level_count(); ++l) {
    level_base.push_back(total);
    total += g.pages_in_level(l);
  }
  std::vector<uint64_t> presence((total + 63) / 64, 0);
  for (uint32_t l = 0; l < g.level_count(); ++l)
    for (uint32_t y = 0; y < g.pages_y(l); ++y)
      for (uint32_t x = 0; x < g.pages_x(l); ++x) {
        bool all = true;
        for (uint32_t layer = 0; layer < plans.size() && all; ++layer) {
          auto e = reader->entry(PageId{l, x, y}, layer);
          if (!e.ok()) return e.status().with_context(path);
          all = e->state != PageState::kAbsent;
        }
        if (all) {
          const uint64_t bit = level_base[l] + uint64_t(y) * g.pages_x(l) + x;
          presence[bit >> 6] |= uint64_t(1) << (bit & 63);
        }
      }
  return std::unique_ptr<PageSource>(new PageFileSource(
      std::move(reader), options, std::move(plans), std::move(presence), std::move(level_base)));
}

}  // namespace vt
