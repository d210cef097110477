#include "runtime/page_source.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "format/layer_codec.h"
#include "runtime/feedback.h"
#include "runtime/page_index.h"

namespace vt {

namespace {

// Float texels of `ic` channels into `oc` >= ic channels of the same size: a missing colour
// channel is 0, a missing alpha 1 (what the 8-bit path does with 0 and 255).
void widen_float_texels(const uint8_t* in, uint32_t ic, uint32_t oc, uint32_t channel_bytes,
                        size_t texels, uint8_t* out) {
  if (ic == oc) {
    std::memcpy(out, in, texels * ic * channel_bytes);
    return;
  }
  const float one_f32 = 1.0f;
  const uint16_t one_f16 = 0x3C00;
  const void* one = channel_bytes == 2 ? static_cast<const void*>(&one_f16) : &one_f32;
  for (size_t t = 0; t < texels; ++t) {
    uint8_t* o = out + t * oc * channel_bytes;
    std::memcpy(o, in + t * ic * channel_bytes, ic * channel_bytes);
    std::memset(o + ic * channel_bytes, 0, (oc - ic) * channel_bytes);
    if (oc == 4) std::memcpy(o + 3 * channel_bytes, one, channel_bytes);
  }
}

struct LayerPlan {
  RuntimeFormat upload = RuntimeFormat::kRgba8;
  size_t upload_bytes = 0;
  size_t decoded_bytes = 0;
  uint32_t channels = 4;     // stored channels
  bool passthrough = false;  // stored BC blocks are already the upload format
  bool float_copy = false;   // float layers delivered in a float format of their channel size
  uint32_t channel_bytes = 1;
};

class PageFileSource final : public PageSource {
 public:
  PageFileSource(std::shared_ptr<const PageFileReader> reader, const PageFileSourceOptions& o,
                 std::vector<LayerPlan> plans, std::vector<uint64_t> presence, PageIndex index)
      : reader_(std::move(reader)),
        options_(o),
        plans_(std::move(plans)),
        presence_(std::move(presence)),
        index_(std::move(index)) {}

  const PageGeometry& geometry() const override { return reader_->geometry(); }
  uint32_t layer_count() const override { return uint32_t(plans_.size()); }
  RuntimeFormat upload_format(uint32_t layer) const override { return plans_[layer].upload; }
  size_t upload_bytes(uint32_t layer) const override { return plans_[layer].upload_bytes; }

  bool present(const PageId& id) const override {
    if (!index_.contains(id)) return false;
    const uint64_t bit = index_.number(id);
    return (presence_[bit >> 6] >> (bit & 63)) & 1;
  }

  Status load(const PageId& id, uint32_t layer, std::span<uint8_t> out) const override {
    if (layer >= plans_.size() || !geometry().contains(id))
      return Error(ErrorCode::kInvalidArgument, reader_->path() + ": no such page or layer");
    const LayerPlan& plan = plans_[layer];
    if (out.size() != plan.upload_bytes)
      return Error(ErrorCode::kInvalidArgument, reader_->path() + ": wrong upload buffer size");
    const std::string where = reader_->path() + ": " + page_name(id, layer);
    auto entry = reader_->entry(id, layer);
    if (!entry.ok()) return entry.status().with_context(where);
    if (plan.passthrough && entry->state == PageState::kStored) {
      // Stored BC blocks of the upload format skip a decode and re-encode.
      auto stored = reader_->read_stored(id, layer);
      if (!stored.ok()) return stored.status();
      return reader_->layer_codec(layer).bc_blocks(*stored, out).with_context(where);
    }
    // Reader errors name the file and the page already.
    PageBuffer texels(plan.decoded_bytes, options_.allocator);
    if (texels.size() != plan.decoded_bytes)
      return Error(ErrorCode::kResourceLimit, where + ": the allocator returned no memory");
    VT_RETURN_IF_ERROR(reader_->read_texels(id, layer, texels));
    const int ps = int(geometry().page_size());
    const RuntimeFormatInfo& upload = *runtime_format_info(plan.upload);
    if (plan.float_copy) {
      widen_float_texels(texels.data(), plan.channels, upload.channels, plan.channel_bytes,
                         size_t(ps) * ps, out.data());
      return Status::Ok();
    }
    if (upload.bc) {
      return bc_encode_image(*upload.bc, options_.bc_quality, texels.data(), ps, ps,
                             int(plan.channels), out.data())
          .with_context(where);
    }
    // Uncompressed 8-bit: channel i of the upload reads stored channel i, 0 when missing
    // (255 for a missing alpha of an RGBA upload).
    const uint32_t oc = upload.channels, ic = plan.channels;
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
  PageIndex index_;  // presence_'s bit of each page
};

}  // namespace

Expected<std::unique_ptr<PageSource>> make_page_file_source(
    std::shared_ptr<const PageFileReader> reader, const PageFileSourceOptions& options) {
  if (!reader) return Error(ErrorCode::kInvalidArgument, "page file source: no reader");
  if (!options.allocator.valid())
    return Error(ErrorCode::kInvalidArgument,
                 "page file source: an allocator needs both allocate and release");
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
    const std::optional<BcFormat> bc = runtime_bc_format(plan.upload);
    const bool bc6h = bc && bc_is_bc6h(*bc);
    if (bc6h && options.bc6h_as_rgba16f) plan.upload = RuntimeFormat::kRgba16f;
    const RuntimeFormatInfo* upload = runtime_format_info(plan.upload);
    if (!upload) return Error(ErrorCode::kCorrupt, where + ": unknown runtime format");
    if (bc6h && plan.upload != RuntimeFormat::kRgba16f) {
      // Half texels encoded to BC6H at load (or stored BC6H blocks passed through).
      if (spec.texel_type != TexelType::kF16)
        return Error(ErrorCode::kUnsupported, where + ": " + upload->name +
                                                  " needs half-float texels, the layer has " +
                                                  to_string(spec.texel_type));
      plan.channel_bytes = 2;
    } else if (spec.texel_type != TexelType::kU8) {
      // Float texels go to the cache as they are, in a float format of their channel size with
      // at least their channels (RGBA16F for half, RGBA32F for float; fewer channels widened).
      plan.channel_bytes = spec.texel_bytes() / std::max<uint32_t>(spec.channels, 1);
      if (!upload->is_float || upload->channels < spec.channels ||
          upload->bits_per_texel != upload->channels * plan.channel_bytes * 8)
        return Error(ErrorCode::kUnsupported,
                     where + ": " + std::to_string(spec.channels) + "-channel " +
                         to_string(spec.texel_type) + " texels cannot be delivered as " +
                         upload->name + " (a float layer needs a float runtime format of its " +
                         "channel size: rgba16f for half, rgba32f for float)");
      plan.float_copy = true;
    } else if (upload->is_float) {
      return Error(ErrorCode::kUnsupported, where + ": 8-bit texels with a float runtime format");
    }
    plan.passthrough = spec.codec == PageCodec::kBcZstd && plan.upload == spec.runtime_format;
    plan.upload_bytes = runtime_format_page_bytes(plan.upload, g.page_size());
    plans.push_back(plan);
  }
  if (plans.empty()) return Error(ErrorCode::kCorrupt, path + ": no layers");

  PageIndex index(g);
  std::vector<uint64_t> presence((index.total + 63) / 64, 0);
  for (uint32_t l = 0; l < index.levels(); ++l)
    for (uint32_t y = 0; y < index.pages_y[l]; ++y)
      for (uint32_t x = 0; x < index.pages_x[l]; ++x) {
        bool all = true;
        for (uint32_t layer = 0; layer < plans.size() && all; ++layer) {
          auto e = reader->entry(PageId{l, x, y}, layer);
          if (!e.ok()) return e.status().with_context(path);
          all = e->state != PageState::kAbsent;
        }
        if (all) {
          const uint64_t bit = index.number(PageId{l, x, y});
          presence[bit >> 6] |= uint64_t(1) << (bit & 63);
        }
      }
  return std::unique_ptr<PageSource>(new PageFileSource(
      std::move(reader), options, std::move(plans), std::move(presence), std::move(index)));
}

}  // namespace vt
