// The error half shared by the C APIs: one thread-local message, codes equal to vt::ErrorCode.
#include "format/c_api_internal.h"

namespace vt::c_api {

namespace {

static_assert(VT_OK == int(ErrorCode::kOk) &&
              VT_ERR_INVALID_ARGUMENT == int(ErrorCode::kInvalidArgument) &&
              VT_ERR_NOT_FOUND == int(ErrorCode::kNotFound) && VT_ERR_IO == int(ErrorCode::kIo) &&
              VT_ERR_CORRUPT == int(ErrorCode::kCorrupt) &&
              VT_ERR_UNSUPPORTED == int(ErrorCode::kUnsupported) &&
              VT_ERR_RESOURCE_LIMIT == int(ErrorCode::kResourceLimit) &&
              VT_ERR_CANCELLED == int(ErrorCode::kCancelled) &&
              VT_ERR_INTERNAL == int(ErrorCode::kInternal));

std::string& last_error() {
  thread_local std::string message;
  return message;
}

}  // namespace

int fail(const Status& status) {
  last_error() = status.message();
  return int(status.code());
}

namespace {

class CallbackByteSource final : public ByteSource {
 public:
  explicit CallbackByteSource(const vt_read_callbacks& io) : io_(io) {}
  ~CallbackByteSource() override {
    if (io_.release) io_.release(io_.user);
  }
  uint64_t size() const override { return io_.size; }
  Expected<size_t> read_some(uint64_t offset, std::span<uint8_t> out) const override {
    const int64_t n = io_.read(io_.user, offset, out.data(), out.size());
    if (n < 0 || uint64_t(n) > out.size())
      return Error(ErrorCode::kIo, n < 0 ? "read callback failed"
                                         : "read callback returned more bytes than asked for");
    return size_t(n);
  }

 private:
  vt_read_callbacks io_;
};

}  // namespace

std::shared_ptr<const ByteSource> callback_byte_source(const vt_read_callbacks* io) {
  if (!io) return fail_null("io"), nullptr;
  if (!io->read) return fail_null("io->read"), nullptr;
  return std::make_shared<CallbackByteSource>(*io);
}

int fail_null(const char* what) {
  return fail(Error(ErrorCode::kInvalidArgument, std::string(what) + " is NULL"));
}

}  // namespace vt::c_api

extern "C" const char* vt_last_error(void) {
  return vt::c_api::last_error().c_str();
}
