#include "bake/page_encoder.h"

#include <zstd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>

namespace vt {
namespace {

Status zstd_compress(const uint8_t* data, size_t size, int level, std::vector<uint8_t>& out) {
  out.resize(ZSTD_compressBound(size));
  size_t n = ZSTD_compress(out.data(), out.size(), data, size, level);
  if (ZSTD_isError(n)) {
    return Error(ErrorCode::kInternal, std::string("zstd: ") + ZSTD_getErrorName(n));
  }
  out.resize(n);
  return Status::Ok();
}

Status zstd_decompress(std::span<const uint8_t> in, uint8_t* out, size_t size) {
  size_t n = ZSTD_decompress(out, size, in.data(), in.size());
  if (ZSTD_isError(n) || n != size) return Error(ErrorCode::kCorrupt, "bad zstd page data");
  return Status::Ok();
}

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

}  // namespace

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

static RuntimeFormat runtime_of(BcFormat f) {
  switch (f) {
    case BcFormat::kBc1:
      return RuntimeFormat::kBc1;
    case BcFormat::kBc3:
      return RuntimeFormat::kBc3;
    case BcFormat::kBc4:
      return RuntimeFormat::kBc4;
    case BcFormat::kBc5:
      return RuntimeFormat::kBc5;
    case BcFormat::kBc7:
      return RuntimeFormat::kBc7;
  }
  return RuntimeFormat::kRgba8;
}

Expected<PageEncoder> PageEncoder::create(LayerSpec& layer, const PageEncoderOptions& options,
                                          uint32_t page_size) {
  if (layer.channels < 1 || layer.channels > 4) {
    return Status(ErrorCode::kInvalidArgument, "layer '" + layer.name + "': 1-4 channels");
  }
  PageEncoder e;
  e.page_size_ = page_size;
  e.channels_ = layer.channels;
  e.texel_bytes_ = layer.texel_bytes();
  e.zstd_level_ = options.zstd_level;
  e.bc_quality_ = options.bc_quality;
  e.bc_format_ = bc_format_for(layer.semantic, layer.channels);
  layer.codec_tables.clear();
  if (layer.texel_type != TexelType::kU8) {
    e.codec_ = PageCodec::kRawZstd;
    layer.runtime_format =
        layer.texel_type == TexelType::kF16 ? RuntimeFormat::kRgba16f : RuntimeFormat::kRgba32f;
  } else {
    layer.runtime_format = runtime_of(e.bc_format_);
    switch (options.codec) {
      case CodecKind::kRaw:
        e.codec_ = PageCodec::kRawZstd;
        break;
      case CodecKind::kBc:
        e.codec_ = PageCodec::kBcZstd;
        break;
      case CodecKind::kDct: {
        e.codec_ = PageCodec::kDct;
        DctSettings s;
        s.quality = std::clamp(options.dct_quality, 1, 100);
        s.adaptive = options.dct_adaptive;
        s.channels = int(layer.channels);
        // Chroma subsampling suits colour only; packed data and normals lose too much to it.
        bool colour =
            layer.semantic == LayerSemantic::kAlbedo || layer.semantic == LayerSemantic::kEmissive;
        s.layout =
            colour && layer.channels >= 3 ? DctPlaneLayout::kYCoCg420 : DctPlaneLayout::kPlanes;
        auto tables = dct_make_tables(s, int(page_size), int(page_size));
        if (!tables.ok()) return tables.status().with_context("layer '" + layer.name + "'");
        layer.codec_tables = dct_serialize_tables(**tables);
        e.dct_ =
            std::shared_ptr<DctTables>(std::move(tables).value().release(), DctTablesDeleter());
        e.dct_settings_ = s;
        break;
      }
    }
  }
  layer.codec = e.codec_;
  return e;
}

bool PageEncoder::is_constant(const uint8_t* texels) const {
  const size_t n = size_t(page_size_) * page_size_;
  for (size_t i = 1; i < n; ++i) {
    if (std::memcmp(texels, texels + i * texel_bytes_, texel_bytes_) != 0) return false;
  }
  return true;
}

Expected<std::vector<uint8_t>> PageEncoder::train(std::span<const std::span<const uint8_t>> pages) {
  if (codec_ != PageCodec::kDct) {
    return Status(ErrorCode::kInvalidArgument, "only DCT layers have tables to train");
  }
  VT_ASSIGN_OR_RETURN(DctTablesPtr tables,
                      dct_make_tables(dct_settings_, int(page_size_), int(page_size_), pages));
  dct_ = std::shared_ptr<DctTables>(tables.release(), DctTablesDeleter());
  trained_ = true;
  return dct_serialize_tables(*dct_);
}

Status PageEncoder::encode(const uint8_t* texels, EncodedPage& out) const {
  out.bytes.clear();
  out.squared_error = 0;
  out.max_error = 0;
  out.samples = 0;
  if (is_constant(texels)) {
    out.state = PageState::kConstant;
    std::memset(out.constant, 0, sizeof(out.constant));
    std::memcpy(out.constant, texels, texel_bytes_);
    return Status::Ok();
  }
  out.state = PageState::kStored;
  const size_t bytes = page_bytes();
  switch (codec_) {
    case PageCodec::kRaw:
      out.bytes.assign(texels, texels + bytes);
      return Status::Ok();
    case PageCodec::kRawZstd:
      return zstd_compress(texels, bytes, zstd_level_, out.bytes);
    case PageCodec::kDct: {
      VT_RETURN_IF_ERROR(
          dct_encode_page(*dct_, texels, int(page_size_), int(page_size_), out.bytes));
      std::vector<uint8_t> back(bytes);
      VT_RETURN_IF_ERROR(
          dct_decode_page(*dct_, out.bytes, int(page_size_), int(page_size_), back.data()));
      measure(texels, back.data(), bytes, out);
      return Status::Ok();
    }
    case PageCodec::kBcZstd: {
      std::vector<uint8_t> blocks(bc_image_bytes(bc_format_, int(page_size_), int(page_size_)));
      VT_RETURN_IF_ERROR(bc_encode_image(bc_format_, bc_quality_, texels, int(page_size_),
                                         int(page_size_), int(channels_), blocks.data()));
      std::vector<uint8_t> back(bytes);
      VT_RETURN_IF_ERROR(bc_decode_image(bc_format_, blocks.data(), int(page_size_),
                                         int(page_size_), int(channels_), back.data()));
      // BC formats store fewer channels than some layers hold (BC1 has no alpha): compare
      // only what the format keeps.
      measure(texels, back.data(), bytes, out);
      return zstd_compress(blocks.data(), blocks.size(), zstd_level_, out.bytes);
    }
  }
  return Error(ErrorCode::kInternal, "unknown page codec");
}

Status PageEncoder::decode(std::span<const uint8_t> data, uint8_t* texels) const {
  const size_t bytes = page_bytes();
  switch (codec_) {
    case PageCodec::kRaw:
      if (data.size() != bytes) return Error(ErrorCode::kCorrupt, "raw page of wrong size");
      std::memcpy(texels, data.data(), bytes);
      return Status::Ok();
    case PageCodec::kRawZstd:
      return zstd_decompress(data, texels, bytes);
    case PageCodec::kDct:
      return dct_decode_page(*dct_, data, int(page_size_), int(page_size_), texels);
    case PageCodec::kBcZstd: {
      std::vector<uint8_t> blocks(bc_image_bytes(bc_format_, int(page_size_), int(page_size_)));
      VT_RETURN_IF_ERROR(zstd_decompress(data, blocks.data(), blocks.size()));
      return bc_decode_image(bc_format_, blocks.data(), int(page_size_), int(page_size_),
                             int(channels_), texels);
    }
  }
  return Error(ErrorCode::kInternal, "unknown page codec");
}

}  // namespace vt
