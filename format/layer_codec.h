// One layer's page codec: the stored bytes of a page and back, for every PageCodec, made once
// per layer (DCT tables parsed or built once, the BC format read from the runtime format). The
// baker encodes with it (bake/page_encoder.h), the reader decodes with it
// (PageFileReader::layer_codec), and the runtime takes stored BC blocks from it to upload as
// they are. Immutable once made: any number of threads may use one at once.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "codec/bc.h"
#include "codec/dct.h"
#include "common/status.h"
#include "format/page_file.h"

namespace vt {

// How pages are coded (decoding needs none of it).
struct LayerEncodeSettings {
  int zstd_level = 3;
  BcQuality bc_quality = BcQuality::kNormal;
  // DCT layers: the per-page mode decision and its error floor (format/dct_page_modes.h).
  bool dct_page_modes = true;
  double dct_min_psnr = 0;
};

class LayerCodec {
 public:
  // `spec` as a page file's layer table holds it (format/page_file_layout.h checks). A DCT layer
  // uses `dct_tables` when given (tables its encoder just made) and otherwise parses
  // spec.codec_tables; tables that are malformed, or that code another channel count or page
  // size than the layer's, give kCorrupt.
  static Expected<LayerCodec> create(const LayerSpec& spec, uint32_t page_size,
                                     std::shared_ptr<const DctTables> dct_tables = nullptr);

  PageCodec codec() const { return codec_; }
  // The BC format of the layer's runtime format (nullopt when it is not a BC format).
  std::optional<BcFormat> bc_format() const { return bc_; }
  uint32_t page_size() const { return page_size_; }
  uint32_t texel_bytes() const { return texel_bytes_; }
  // Bytes of a page's texels: page_size^2 texels, channels interleaved, row-major.
  size_t page_bytes() const { return size_t(page_size_) * page_size_ * texel_bytes_; }
  // Bytes of a page's BC blocks (0 without a BC format).
  size_t bc_page_bytes() const;
  // Whether decode gives back other texels than were encoded (DCT and BC).
  bool lossy() const { return codec_ == PageCodec::kDct || codec_ == PageCodec::kBcZstd; }

  // Codes page_bytes() of texels with codec() into `out` (replaced). When `decoded` is not
  // null it receives the page_bytes() texels decode() gives back for `out` (error reports);
  // `dct_mode`, when not null, the DCT page mode chosen (kDctModeLossless or a mode byte).
  Status encode(const uint8_t* texels, const LayerEncodeSettings& settings,
                std::vector<uint8_t>& out, uint8_t* decoded = nullptr,
                uint8_t* dct_mode = nullptr) const;
  // Decodes one stored page into `out` (page_bytes()). Trusts no size in `data`: bad data gives
  // kCorrupt, never a read or write out of bounds.
  Status decode(std::span<const uint8_t> data, std::span<uint8_t> out) const;
  // A kBcZstd page's blocks (bc_page_bytes()), only zstd-decompressed: for a cache that holds
  // the layer's BC format, which then needs no decode and re-encode.
  Status bc_blocks(std::span<const uint8_t> data, std::span<uint8_t> blocks) const;

 private:
  LayerCodec() = default;

  PageCodec codec_ = PageCodec::kRaw;
  std::optional<BcFormat> bc_;
  uint32_t page_size_ = 0;
  uint32_t channels_ = 0;
  uint32_t texel_bytes_ = 0;
  std::shared_ptr<const DctTables> dct_;
};

}  // namespace vt
