#include "bake/page_encoder.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "format/page_error_bounds.h"

namespace vt {
namespace {

void measure(const uint8_t* a, const uint8_t* b, size_t n, EncodedPage& out) {
  uint64_t sse = 0;
  uint32_t mx = 0;
  for (size_t i = 0; i < n; ++i) {
    int d = int(a[i]) - int(b[i]);
    sse += uint64_t(d * d);
    mx = std::max<uint32_t>(mx, uint32_t(std::abs(d)));
  }
  out.squared_error = double(sse);
  out.max_error = mx;
  out.samples = n;
}

// The same against unclipped reference values (8-bit code units, unrounded).
void measure(const float* reference, const uint8_t* b, size_t n, EncodedPage& out) {
  double sse = 0, mx = 0;
  for (size_t i = 0; i < n; ++i) {
    const double d = double(reference[i]) - double(b[i]);
    sse += d * d;
    mx = std::max(mx, std::abs(d));
  }
  out.squared_error = sse;
  out.max_error = uint32_t(std::min(std::round(mx), double(UINT32_MAX)));
  out.samples = n;
}

}  // namespace

Expected<FloatTexels> parse_float_texels(const std::string& name) {
  if (name == "auto") return FloatTexels::kAuto;
  if (name == "half") return FloatTexels::kHalf;
  if (name == "float") return FloatTexels::kFloat;
  return Status(ErrorCode::kInvalidArgument,
                "unknown float storage '" + name + "' (expected auto, half or float)");
}

const char* to_string(FloatTexels v) {
  switch (v) {
    case FloatTexels::kAuto:
      return "auto";
    case FloatTexels::kHalf:
      return "half";
    case FloatTexels::kFloat:
      return "float";
  }
  return "?";
}

Expected<HalfRuntime> parse_half_runtime(const std::string& name) {
  if (name == "bc6h") return HalfRuntime::kBc6h;
  if (name == "rgba16f") return HalfRuntime::kRgba16f;
  return Status(ErrorCode::kInvalidArgument,
                "unknown half-float runtime format '" + name + "' (expected bc6h or rgba16f)");
}

const char* to_string(HalfRuntime v) {
  return v == HalfRuntime::kBc6h ? "bc6h" : "rgba16f";
}

BcFormat bc_format_for(LayerSemantic semantic, uint32_t channels) {
  if (semantic == LayerSemantic::kNormal) return BcFormat::kBc5;
  switch (channels) {
    case 1:
      return BcFormat::kBc4;
    case 2:
      return BcFormat::kBc5;
    case 3:
      return BcFormat::kBc1;
    default:
      return BcFormat::kBc3;
  }
}

Expected<PageEncoder> PageEncoder::create(LayerSpec& layer, const PageEncoderOptions& options,
                                          uint32_t page_size) {
  if (layer.channels < 1 || layer.channels > 4) {
    return Status(ErrorCode::kInvalidArgument, "layer '" + layer.name + "': 1-4 channels");
  }
  layer.codec_tables.clear();
  std::shared_ptr<const DctTables> tables;
  DctSettings dct;
  if (layer.texel_type != TexelType::kU8) {
    layer.codec = PageCodec::kRawZstd;
    layer.runtime_format =
        layer.texel_type == TexelType::kF16 ? RuntimeFormat::kRgba16f : RuntimeFormat::kRgba32f;
    if (layer.texel_type == TexelType::kF16 && layer.channels <= 3 &&
        options.half_runtime == HalfRuntime::kBc6h) {
      layer.runtime_format = layer.semantic == LayerSemantic::kCustom ? RuntimeFormat::kBc6hSf16
                                                                      : RuntimeFormat::kBc6hUf16;
      // --codec bc stores the blocks (offline quality, no transcode at load).
      if (options.codec == CodecKind::kBc) layer.codec = PageCodec::kBcZstd;
    }
  } else {
    layer.runtime_format = runtime_format_of(bc_format_for(layer.semantic, layer.channels));
    switch (options.codec) {
      case CodecKind::kRaw:
        layer.codec = PageCodec::kRawZstd;
        break;
      case CodecKind::kBc:
        layer.codec = PageCodec::kBcZstd;
        break;
      case CodecKind::kDct: {
        layer.codec = PageCodec::kDct;
        dct.quality = std::clamp(options.dct_quality, 1, 100);
        dct.adaptive = options.dct_adaptive;
        dct.channels = int(layer.channels);
        // Chroma subsampling suits colour only; packed data and normals lose too much to it.
        dct.layout = is_colour(layer.semantic) && layer.channels >= 3 ? DctPlaneLayout::kYCoCg420
                                                                      : DctPlaneLayout::kPlanes;
        auto made = dct_make_tables(dct, int(page_size), int(page_size));
        if (!made.ok()) return made.status().with_context("layer '" + layer.name + "'");
        layer.codec_tables = dct_serialize_tables(**made);
        tables =
            std::shared_ptr<const DctTables>(std::move(made).value().release(), DctTablesDeleter());
        break;
      }
    }
  }
  auto codec = LayerCodec::create(layer, page_size, std::move(tables));
  if (!codec.ok()) return codec.status().with_context("layer '" + layer.name + "'");
  PageEncoder e(std::move(codec).value(), layer, options);
  e.dct_settings_ = dct;
  if (options.min_psnr == kDefaultPageFloor)
    e.settings_.dct_min_psnr = kDctPagePsnr.of(layer.semantic) + kDctFloorMarginDb;
  if (auto it = options.layer_min_psnr.find(layer.name); it != options.layer_min_psnr.end())
    e.settings_.dct_min_psnr = it->second;
  return e;
}

bool PageEncoder::is_constant(const uint8_t* texels) const {
  const size_t tb = layer_.texel_bytes(), n = size_t(layer_.page_size()) * layer_.page_size();
  for (size_t i = 1; i < n; ++i) {
    if (std::memcmp(texels, texels + i * tb, tb) != 0) return false;
  }
  return true;
}

Expected<std::vector<uint8_t>> PageEncoder::train(std::span<const std::span<const uint8_t>> pages) {
  if (codec() != PageCodec::kDct) {
    return Status(ErrorCode::kInvalidArgument, "only DCT layers have tables to train");
  }
  const int size = int(layer_.page_size());
  VT_ASSIGN_OR_RETURN(DctTablesPtr made, dct_make_tables(dct_settings_, size, size, pages));
  std::shared_ptr<const DctTables> tables(made.release(), DctTablesDeleter());
  VT_ASSIGN_OR_RETURN(layer_, LayerCodec::create(spec_, layer_.page_size(), tables));
  trained_ = true;
  return dct_serialize_tables(*tables);
}

Status PageEncoder::use_tables(std::span<const uint8_t> bytes) {
  if (codec() != PageCodec::kDct) {
    return Status(ErrorCode::kInvalidArgument, "only DCT layers take tables");
  }
  LayerSpec spec = spec_;
  spec.codec_tables.assign(bytes.begin(), bytes.end());
  VT_ASSIGN_OR_RETURN(layer_, LayerCodec::create(spec, layer_.page_size(), nullptr));
  trained_ = true;
  return Status::Ok();
}

Status PageEncoder::encode(const uint8_t* texels, EncodedPage& out, const float* reference) const {
  out.bytes.clear();
  out.squared_error = 0;
  out.max_error = 0;
  out.samples = 0;
  out.dct_mode = 0;
  out.runtime = RuntimeError{};
  out.hdr = HdrError{};
  if (is_constant(texels)) {
    out.state = PageState::kConstant;
    std::memset(out.constant, 0, sizeof(out.constant));
    std::memcpy(out.constant, texels, layer_.texel_bytes());
    // Exact, and not counted, unless clipped: then what clipping lost counts (half pages: what
    // rounding to half lost).
    if (reference && spec_.texel_type == TexelType::kF16) {
      add_hdr_error(reference, texels, texel_count(), int(spec_.channels),
                    std::min(int(spec_.channels), 3), out.hdr);
    } else if (reference) {
      measure(reference, texels, page_bytes(), out);
    }
    return Status::Ok();
  }
  out.state = PageState::kStored;
  if (!layer_.lossy()) {
    VT_RETURN_IF_ERROR(layer_.encode(texels, settings_, out.bytes));
    if (spec_.texel_type == TexelType::kU8) {
      // Exact unless clipped: every page counts, so a layer's PSNR covers all its pages.
      if (reference) {
        measure(reference, texels, page_bytes(), out);
      } else {
        out.samples = page_bytes();
      }
    } else if (spec_.texel_type == TexelType::kF16 && reference) {
      // Raw halves: exact for the halves, not for the floats they were rounded from.
      add_hdr_error(reference, texels, texel_count(), int(spec_.channels),
                    std::min(int(spec_.channels), 3), out.hdr);
    }
    return measure_runtime(texels, texels, reference, out);
  }
  // BC formats store fewer channels than some layers hold (BC1 has no alpha): compare only
  // what the format keeps.
  thread_local std::vector<uint8_t> back;
  back.resize(page_bytes());
  VT_RETURN_IF_ERROR(layer_.encode(texels, settings_, out.bytes, back.data(), &out.dct_mode));
  if (spec_.texel_type == TexelType::kF16) {
    // BC6H blocks of half texels: the HDR metrics, not 8-bit units, against the floats when
    // given.
    const int kept = std::min(int(spec_.channels), 3);
    if (reference) {
      add_hdr_error(reference, back.data(), texel_count(), int(spec_.channels), kept, out.hdr);
    } else {
      add_hdr_error(texels, back.data(), texel_count(), int(spec_.channels), kept, out.hdr);
    }
    return measure_runtime(texels, back.data(), reference, out);
  }
  if (reference) {
    measure(reference, back.data(), back.size(), out);
  } else {
    measure(texels, back.data(), back.size(), out);
  }
  return measure_runtime(texels, back.data(), reference, out);
}

Status PageEncoder::measure_runtime(const uint8_t* texels, const uint8_t* stored,
                                    const float* reference, EncodedPage& out) const {
  const std::optional<BcFormat> bc = layer_.bc_format();
  const bool hdr = bc && bc_is_bc6h(*bc) && spec_.texel_type == TexelType::kF16;
  if (!bc || (spec_.texel_type != TexelType::kU8 && !hdr)) return Status::Ok();
  thread_local std::vector<uint8_t> blocks;
  const uint8_t* own = nullptr;
  if (codec() == PageCodec::kBcZstd) {
    blocks.resize(layer_.bc_page_bytes());
    VT_RETURN_IF_ERROR(layer_.bc_blocks(out.bytes, blocks));
    own = blocks.data();
  }
  if (hdr)
    return measure_runtime_hdr_error(*bc, texels, stored, own, int(layer_.page_size()),
                                     int(spec_.channels), out.runtime, reference);
  return measure_runtime_error(*bc, spec_.semantic == LayerSemantic::kNormal, texels, stored, own,
                               int(layer_.page_size()), int(layer_.texel_bytes()), out.runtime,
                               reference);
}

Status PageEncoder::decode(std::span<const uint8_t> data, uint8_t* texels) const {
  return layer_.decode(data, std::span<uint8_t>(texels, page_bytes()));
}

}  // namespace vt
