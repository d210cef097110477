// Per-codec encode and decode of stored pages: raw, raw+zstd, DCT (codec/dct.h) and the layer's
// BC blocks + zstd (codec/bc.h).
#include "format/layer_codec.h"

#include <cstring>
#include <string>

#include "format/dct_page_modes.h"
#include "format/zstd_frame.h"

namespace vt {

namespace {

Status check_dct_shape(const DctTables& tables, const LayerSpec& spec, uint32_t page_size) {
  const DctTablesShape shape = dct_tables_shape(tables);
  if (shape.channels != int(spec.channels))
    return Error(ErrorCode::kCorrupt, "dct tables code " + std::to_string(shape.channels) +
                                          " channels, the layer has " +
                                          std::to_string(spec.channels));
  if (shape.width != int(page_size) || shape.height != int(page_size))
    return Error(ErrorCode::kCorrupt, "dct tables code " + std::to_string(shape.width) + "x" +
                                          std::to_string(shape.height) + " pages, the file has " +
                                          std::to_string(page_size) + "x" +
                                          std::to_string(page_size));
  return Status::Ok();
}

}  // namespace

Expected<LayerCodec> LayerCodec::create(const LayerSpec& spec, uint32_t page_size,
                                        std::shared_ptr<const DctTables> dct_tables) {
  LayerCodec c;
  c.codec_ = spec.codec;
  c.bc_ = runtime_bc_format(spec.runtime_format);
  c.page_size_ = page_size;
  c.channels_ = spec.channels;
  c.texel_bytes_ = spec.texel_bytes();
  if (spec.codec == PageCodec::kBcZstd && !c.bc_)
    return Error(ErrorCode::kCorrupt, "bc+zstd layer with no BC runtime format");
  if (spec.codec == PageCodec::kDct) {
    if (!dct_tables) {
      auto parsed = dct_parse_tables(spec.codec_tables);
      if (!parsed.ok()) return parsed.status().with_context("dct tables");
      dct_tables =
          std::shared_ptr<const DctTables>(std::move(parsed).value().release(), DctTablesDeleter());
    }
    VT_RETURN_IF_ERROR(check_dct_shape(*dct_tables, spec, page_size));
    c.dct_ = std::move(dct_tables);
  }
  return c;
}

size_t LayerCodec::bc_page_bytes() const {
  return bc_ ? bc_image_bytes(*bc_, int(page_size_), int(page_size_)) : 0;
}

Status LayerCodec::encode(const uint8_t* texels, const LayerEncodeSettings& settings,
                          std::vector<uint8_t>& out, uint8_t* decoded, uint8_t* dct_mode) const {
  const std::span<const uint8_t> page(texels, page_bytes());
  const int size = int(page_size_);
  switch (codec_) {
    case PageCodec::kRaw:
    case PageCodec::kRawZstd:
      if (decoded) std::memcpy(decoded, texels, page.size());
      if (codec_ == PageCodec::kRawZstd) return zstd_compress(page, settings.zstd_level, out);
      out.assign(page.begin(), page.end());
      return Status::Ok();
    case PageCodec::kDct: {
      const DctModeSettings modes{settings.dct_page_modes, settings.dct_min_psnr,
                                  settings.zstd_level};
      VT_ASSIGN_OR_RETURN(uint8_t mode, dct_encode_page_modes(*dct_, texels, size, int(channels_),
                                                              modes, out, decoded));
      if (dct_mode) *dct_mode = mode;
      return Status::Ok();
    }
    case PageCodec::kBcZstd: {
      std::vector<uint8_t> blocks(bc_page_bytes());
      VT_RETURN_IF_ERROR(bc_encode_image(*bc_, settings.bc_quality, texels, size, size,
                                         int(channels_), blocks.data()));
      if (decoded)
        VT_RETURN_IF_ERROR(
            bc_decode_image(*bc_, blocks.data(), size, size, int(channels_), decoded));
      return zstd_compress(blocks, settings.zstd_level, out);
    }
  }
  return Error(ErrorCode::kInternal, "unknown page codec");
}

Status LayerCodec::decode(std::span<const uint8_t> data, std::span<uint8_t> out) const {
  if (out.size() != page_bytes())
    return Error(ErrorCode::kInvalidArgument, "decoded page buffer of " +
                                                  std::to_string(out.size()) + " bytes, expected " +
                                                  std::to_string(page_bytes()));
  const int size = int(page_size_);
  switch (codec_) {
    case PageCodec::kRaw:
      if (data.size() != out.size())
        return Error(ErrorCode::kCorrupt, "raw page of " + std::to_string(data.size()) +
                                              " bytes, expected " + std::to_string(out.size()));
      std::memcpy(out.data(), data.data(), out.size());
      return Status::Ok();
    case PageCodec::kRawZstd:
      return zstd_decompress_exact(data, out);
    case PageCodec::kDct:
      return dct_decode_page_modes(*dct_, data, size, out);
    case PageCodec::kBcZstd: {
      std::vector<uint8_t> blocks(bc_page_bytes());
      VT_RETURN_IF_ERROR(zstd_decompress_exact(data, blocks));
      return bc_decode_image(*bc_, blocks.data(), size, size, int(channels_), out.data());
    }
  }
  return Error(ErrorCode::kCorrupt, "unknown page codec");
}

Status LayerCodec::bc_blocks(std::span<const uint8_t> data, std::span<uint8_t> blocks) const {
  if (codec_ != PageCodec::kBcZstd)
    return Error(ErrorCode::kInvalidArgument,
                 std::string(to_string(codec_)) + " pages hold no BC blocks");
  if (blocks.size() != bc_page_bytes())
    return Error(ErrorCode::kInvalidArgument,
                 "BC block buffer of " + std::to_string(blocks.size()) + " bytes, expected " +
                     std::to_string(bc_page_bytes()));
  return zstd_decompress_exact(data, blocks);
}

}  // namespace vt
