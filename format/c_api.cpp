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

int fail_null(const char* what) {
  return fail(Error(ErrorCode::kInvalidArgument, std::string(what) + " is NULL"));
}

}  // namespace vt::c_api

extern "C" const char* vt_last_error(void) {
  return vt::c_api::last_error().c_str();
}
