// Codec dispatch for stored pages: raw, raw+zstd, DCT (codec/dct.h) and BC+zstd (codec/bc.h).
#include "format/page_decode.h"

#include <zstd.h>

#include <cstring>
#include <string>
#include <vector>

#include "codec/bc.h"
#include "codec/dct.h"

// A build may define this to 0 to leave the codec decoders out (DCT and BC pages then report
// kUnsupported).
#ifndef VTBAKE_HAVE_CODEC_DECODERS
#define VTBAKE_HAVE_CODEC_DECODERS 1
#endif

namespace vt::pagefile {

namespace {

struct DctxDeleter {
  void operator()(ZSTD_DCtx* c) const { ZSTD_freeDCtx(c); }
};

// One zstd context per thread: decoding is then allocation-free and needs no lock.
ZSTD_DCtx* thread_dctx() {
  thread_local std::unique_ptr<ZSTD_DCtx, DctxDeleter> ctx(ZSTD_createDCtx());
  return ctx.get();
}

// Decompresses a zstd frame that must expand to exactly out.size() bytes.
Status zstd_exact(std::span<const uint8_t> data, std::span<uint8_t> out) {
  unsigned long long content = ZSTD_getFrameContentSize(data.data(), data.size());
  if (content == ZSTD_CONTENTSIZE_ERROR)
    return Error(ErrorCode::kCorrupt, "page is not a zstd frame");
  if (content != ZSTD_CONTENTSIZE_UNKNOWN && content != out.size())
    return Error(ErrorCode::kCorrupt, "zstd frame holds " + std::to_string(content) +
                                          " bytes, expected " + std::to_string(out.size()));
  ZSTD_DCtx* ctx = thread_dctx();
  if (!ctx) return Error(ErrorCode::kResourceLimit, "cannot create a zstd context");
  size_t n = ZSTD_decompressDCtx(ctx, out.data(), out.size(), data.data(), data.size());
  if (ZSTD_isError(n))
    return Error(ErrorCode::kCorrupt, std::string("zstd: ") + ZSTD_getErrorName(n));
  if (n != out.size())
    return Error(ErrorCode::kCorrupt, "zstd frame holds " + std::to_string(n) +
                                          " bytes, expected " + std::to_string(out.size()));
  return Status::Ok();
}

class Decoder final : public LayerDecoder {
 public:
  Decoder(const LayerSpec& spec, uint32_t page_size) : spec_(spec), page_size_(page_size) {}

  Status init() {
#if VTBAKE_HAVE_CODEC_DECODERS
    if (spec_.codec == PageCodec::kDct) {
      auto tables = dct_parse_tables(spec_.codec_tables);
      if (!tables.ok()) return tables.status().with_context("dct tables");
      dct_tables_ = std::move(tables).value();
    }
#endif
    return Status::Ok();
  }

  Status decode(PageCodec codec, std::span<const uint8_t> data,
                std::span<uint8_t> out) const override {
    const int size = int(page_size_);
    switch (codec) {
      case PageCodec::kRaw:
        if (data.size() != out.size())
          return Error(ErrorCode::kCorrupt, "raw page of " + std::to_string(data.size()) +
                                                " bytes, expected " + std::to_string(out.size()));
        std::memcpy(out.data(), data.data(), out.size());
        return Status::Ok();
      case PageCodec::kRawZstd:
        return zstd_exact(data, out);
      case PageCodec::kDct:
#if VTBAKE_HAVE_CODEC_DECODERS
        if (!dct_tables_) return Error(ErrorCode::kCorrupt, "dct page in a layer without tables");
        return dct_decode_page(*dct_tables_, data, size, size, out.data());
#else
        (void)size;
        return Error(ErrorCode::kUnsupported,
                     "dct pages cannot be decoded: this build has no DCT decoder");
#endif
      case PageCodec::kBcZstd: {
        uint8_t bc = 0;
        if (!runtime_bc_format(spec_.runtime_format, &bc))
          return Error(ErrorCode::kCorrupt, "bc+zstd page in a layer with no BC runtime format");
#if VTBAKE_HAVE_CODEC_DECODERS
        const BcFormat format = BcFormat(bc);
        std::vector<uint8_t> blocks(bc_image_bytes(format, size, size));
        VT_RETURN_IF_ERROR(zstd_exact(data, blocks));
        return bc_decode_image(format, blocks.data(), size, size, spec_.channels, out.data());
#else
        return Error(ErrorCode::kUnsupported,
                     "bc+zstd pages cannot be decoded: this build has no BC decoder");
#endif
      }
    }
    return Error(ErrorCode::kCorrupt, "unknown page codec");
  }

 private:
  LayerSpec spec_;
  uint32_t page_size_;
#if VTBAKE_HAVE_CODEC_DECODERS
  DctTablesPtr dct_tables_;
#endif
};

}  // namespace

bool runtime_bc_format(RuntimeFormat format, uint8_t* bc_format) {
  switch (format) {
    case RuntimeFormat::kBc1:
      *bc_format = uint8_t(BcFormat::kBc1);
      return true;
    case RuntimeFormat::kBc3:
      *bc_format = uint8_t(BcFormat::kBc3);
      return true;
    case RuntimeFormat::kBc4:
      *bc_format = uint8_t(BcFormat::kBc4);
      return true;
    case RuntimeFormat::kBc5:
      *bc_format = uint8_t(BcFormat::kBc5);
      return true;
    case RuntimeFormat::kBc7:
      *bc_format = uint8_t(BcFormat::kBc7);
      return true;
    default:
      return false;
  }
}

Expected<std::unique_ptr<LayerDecoder>> LayerDecoder::create(const LayerSpec& spec,
                                                             uint32_t page_size) {
  auto decoder = std::make_unique<Decoder>(spec, page_size);
  VT_RETURN_IF_ERROR(decoder->init());
  return std::unique_ptr<LayerDecoder>(std::move(decoder));
}

}  // namespace vt::pagefile
