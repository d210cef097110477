#include "format/zstd_frame.h"

#include <zstd.h>

#include <memory>
#include <string>

namespace vt {

namespace {

struct DctxDeleter {
  void operator()(ZSTD_DCtx* c) const { ZSTD_freeDCtx(c); }
};
struct CctxDeleter {
  void operator()(ZSTD_CCtx* c) const { ZSTD_freeCCtx(c); }
};

// One per thread too: ZSTD_compress would allocate (and first-touch) a fresh workspace per call,
// and ZSTD_compressCCtx gives the same bytes.
ZSTD_CCtx* thread_cctx() {
  thread_local std::unique_ptr<ZSTD_CCtx, CctxDeleter> ctx(ZSTD_createCCtx());
  return ctx.get();
}

// One context per thread: decompression then needs no allocation and no lock.
ZSTD_DCtx* thread_dctx() {
  thread_local std::unique_ptr<ZSTD_DCtx, DctxDeleter> ctx(ZSTD_createDCtx());
  return ctx.get();
}

Status wrong_size(unsigned long long got, size_t expected) {
  return Error(ErrorCode::kCorrupt, "zstd frame holds " + std::to_string(got) +
                                        " bytes, expected " + std::to_string(expected));
}

}  // namespace

Status zstd_compress(std::span<const uint8_t> data, int level, std::vector<uint8_t>& out) {
  ZSTD_CCtx* ctx = thread_cctx();
  if (!ctx) return Error(ErrorCode::kResourceLimit, "cannot create a zstd context");
  out.resize(ZSTD_compressBound(data.size()));
  const size_t n = ZSTD_compressCCtx(ctx, out.data(), out.size(), data.data(), data.size(), level);
  if (ZSTD_isError(n))
    return Error(ErrorCode::kInternal, std::string("zstd: ") + ZSTD_getErrorName(n));
  out.resize(n);
  return Status::Ok();
}

Status zstd_decompress_exact(std::span<const uint8_t> frame, std::span<uint8_t> out) {
  const unsigned long long content = ZSTD_getFrameContentSize(frame.data(), frame.size());
  if (content == ZSTD_CONTENTSIZE_ERROR)
    return Error(ErrorCode::kCorrupt, "page is not a zstd frame");
  if (content != ZSTD_CONTENTSIZE_UNKNOWN && content != out.size())
    return wrong_size(content, out.size());
  ZSTD_DCtx* ctx = thread_dctx();
  if (!ctx) return Error(ErrorCode::kResourceLimit, "cannot create a zstd context");
  const size_t n = ZSTD_decompressDCtx(ctx, out.data(), out.size(), frame.data(), frame.size());
  if (ZSTD_isError(n))
    return Error(ErrorCode::kCorrupt, std::string("zstd: ") + ZSTD_getErrorName(n));
  if (n != out.size()) return wrong_size(n, out.size());
  return Status::Ok();
}

}  // namespace vt
