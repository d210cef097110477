// Encoding one layer's pages for the page file: the baker's choices for a layer (codec, runtime
// format, DCT settings and training) over format/layer_codec.h, which codes the pages. A page
// whose texels are all one value becomes a constant; lossy codecs report the error of the stored
// page against the texels it was made from.
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "codec/bc.h"
#include "codec/dct.h"
#include "codec/runtime_error.h"
#include "common/status.h"
#include "format/layer_codec.h"
#include "format/page_file.h"

namespace vt {

// The codec a build asks for; the exact PageCodec and runtime format follow from the layer.
enum class CodecKind : uint8_t { kDct = 0, kBc = 1, kRaw = 2 };

// How a colour or data layer whose source holds floats (EXR, float TIFF, HDR) is stored.
// Normal layers are 8-bit whatever the source.
enum class FloatTexels : uint8_t {
  kAuto = 0,   // 32-bit float with CodecKind::kRaw, else 8 bits in the codec asked for: values
               // outside [0, 1] are clipped, counted and warned about (LayerSummary::clipped)
  kHalf = 1,   // half float, raw + zstd (BC6H blocks + zstd with CodecKind::kBc); BC6H at run
               // time for 1-3 channels (RGBA16F with alpha, or with HalfRuntime::kRgba16f)
  kFloat = 2,  // 32-bit float, raw + zstd (RGBA32F at run time)
};
Expected<FloatTexels> parse_float_texels(const std::string& name);
const char* to_string(FloatTexels v);

// The runtime format of half-float layers of 1-3 channels (four channels keep RGBA16F: BC6H has
// no alpha). BC6H is unsigned (0..65504) but for custom layers, which may hold signed data.
enum class HalfRuntime : uint8_t { kBc6h = 0, kRgba16f = 1 };
Expected<HalfRuntime> parse_half_runtime(const std::string& name);
const char* to_string(HalfRuntime v);

inline constexpr double kDefaultPageFloor = -1;

struct PageEncoderOptions {
  CodecKind codec = CodecKind::kDct;
  FloatTexels float_texels = FloatTexels::kAuto;
  HalfRuntime half_runtime = HalfRuntime::kBc6h;
  int dct_quality = 75;
  bool dct_adaptive = false;  // DctSettings::adaptive: smaller pages, slower decoding
  BcQuality bc_quality = BcQuality::kNormal;
  int zstd_level = 3;
  // DCT layers: the per-page mode decision (format/dct_page_modes.h) and its error floor, a
  // PSNR per page in dB (0: none), for every layer or by layer name. kDefaultPageFloor: the
  // layer's page bound (format/page_error_bounds.h) plus its margin.
  bool dct_page_modes = true;
  double min_psnr = kDefaultPageFloor;
  std::map<std::string, double> layer_min_psnr;
};

// The BC format a layer is transcoded to: albedo/emissive RGB BC1, RGBA BC3; normal (XY) BC5;
// one channel BC4; two channels BC5; other RGB BC1, RGBA BC3.
BcFormat bc_format_for(LayerSemantic semantic, uint32_t channels);

struct EncodedPage {
  PageState state = PageState::kStored;
  std::vector<uint8_t> bytes;  // kStored: the coded page
  uint8_t constant[16] = {};   // kConstant: the texel value
  // Against the texels given (or their unclipped reference): the sum over channels and texels,
  // in 8-bit units; 0 for a lossless page without a reference. A constant page is measured
  // (samples > 0) only with a reference.
  double squared_error = 0.0;
  uint32_t max_error = 0;  // largest absolute channel error (8-bit units, rounded)
  uint64_t samples = 0;    // channel values compared (every stored 8-bit page's)
  uint8_t dct_mode = 0;    // DCT layers: the page mode chosen (format/dct_page_modes.h)
  RuntimeError runtime;    // after the runtime BC format (layers that have one)
  // Half-float pages given their float values (`reference`): the stored page (halves, or BC6H
  // blocks) against them; empty otherwise.
  HdrError hdr;
};

class PageEncoder {
 public:
  // Completes `layer` (codec, runtime_format, codec_tables) for the options; layer.channels,
  // texel_type and semantic must be set. Float layers always use raw + zstd.
  static Expected<PageEncoder> create(LayerSpec& layer, const PageEncoderOptions& options,
                                      uint32_t page_size);

  // Encodes page_size^2 texels of layer.texel_bytes() each. Thread-safe. `reference`, when not
  // null, holds for 8-bit layers what the texels were before clipping (page_bytes() values in
  // 8-bit code units, LayerPlan::store_page), for half layers the floats they were rounded from
  // (page_size^2 * channels): the errors, stored and runtime, are measured against it, so a
  // lossless page of clipped texels reports what clipping lost and a half page what rounding to
  // half lost.
  Status encode(const uint8_t* texels, EncodedPage& out, const float* reference = nullptr) const;
  // Decodes a stored page back to texels (tests and verification). Thread-safe.
  Status decode(std::span<const uint8_t> bytes, uint8_t* texels) const;
  // True when every texel of the page equals the first (such a page is stored as a constant).
  bool is_constant(const uint8_t* texels) const;

  // DCT layers start with untrained tables (adaptive token models: about 13% larger pages and
  // slower decoding than trained ones). train() fits them to some of the layer's own
  // non-constant pages (each page_bytes()) and returns the new tables' bytes, which the file
  // must then hold; pages encoded before it used the old tables. Not thread-safe.
  bool wants_training() const { return codec() == PageCodec::kDct && !trained_; }
  Expected<std::vector<uint8_t>> train(std::span<const std::span<const uint8_t>> pages);
  // Takes tables trained before (a previous file's, for update mode and --tables-from) instead
  // of training: they must code this layer's channels and page size. Not thread-safe.
  Status use_tables(std::span<const uint8_t> tables);

  PageCodec codec() const { return layer_.codec(); }
  size_t page_bytes() const { return layer_.page_bytes(); }
  size_t texel_count() const { return size_t(layer_.page_size()) * layer_.page_size(); }

 private:
  PageEncoder(LayerCodec layer, const LayerSpec& spec, const PageEncoderOptions& options)
      : layer_(std::move(layer)),
        spec_(spec),
        settings_{options.zstd_level, options.bc_quality, options.dct_page_modes,
                  options.min_psnr} {}
  Status measure_runtime(const uint8_t* texels, const uint8_t* stored, const float* reference,
                         EncodedPage& out) const;

  LayerCodec layer_;
  LayerSpec spec_;  // the completed layer, for remaking layer_ with trained tables
  LayerEncodeSettings settings_;
  DctSettings dct_settings_;
  bool trained_ = false;
};

}  // namespace vt
