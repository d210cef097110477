// Status and Expected<T>: how every vtbake library reports failure. Library code never prints
// or exits; it returns one of these and cli/ decides what to say and which exit code to use.
#pragma once

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace vt {

enum class ErrorCode {
  kOk = 0,
  kInvalidArgument,  // the caller passed something that can never work
  kNotFound,         // a file, layer, page or key that does not exist
  kIo,               // the operating system refused a read, write, rename or fsync
  kCorrupt,          // input data is malformed: bad magic, checksum, size, offset
  kUnsupported,      // well-formed but beyond what this version handles (future version)
  kResourceLimit,    // the work would exceed a memory or size limit
  kCancelled,
  kInternal,
};

const char* error_code_name(ErrorCode code);

class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(ErrorCode code, std::string message) : code_(code), message_(std::move(message)) {}

  static Status Ok() { return {}; }

  bool ok() const { return code_ == ErrorCode::kOk; }
  explicit operator bool() const { return ok(); }
  ErrorCode code() const { return code_; }
  const std::string& message() const { return message_; }

  // Prefixes context ("page (2, 3, 1): " or "file.vtpf: ") so errors name what failed.
  Status with_context(const std::string& context) const {
    if (ok()) return *this;
    return Status(code_, context + ": " + message_);
  }

 private:
  ErrorCode code_ = ErrorCode::kOk;
  std::string message_;
};

inline Status Error(ErrorCode code, std::string message) {
  return {code, std::move(message)};
}

// A value or the Status explaining why there is none (C++23's std::expected, trimmed).
template <typename T>
class [[nodiscard]] Expected {
 public:
  Expected(T value) : data_(std::move(value)) {}
  Expected(Status status) : data_(std::move(status)) { assert(!std::get<Status>(data_).ok()); }

  bool ok() const { return std::holds_alternative<T>(data_); }
  explicit operator bool() const { return ok(); }

  const Status& status() const {
    static const Status kOkStatus;
    return ok() ? kOkStatus : std::get<Status>(data_);
  }
  T& value() & { return std::get<T>(data_); }
  const T& value() const& { return std::get<T>(data_); }
  T&& value() && { return std::get<T>(std::move(data_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

 private:
  std::variant<T, Status> data_;
};

inline const char* error_code_name(ErrorCode code) {
  switch (code) {
    case ErrorCode::kOk:
      return "ok";
    case ErrorCode::kInvalidArgument:
      return "invalid argument";
    case ErrorCode::kNotFound:
      return "not found";
    case ErrorCode::kIo:
      return "i/o error";
    case ErrorCode::kCorrupt:
      return "corrupt data";
    case ErrorCode::kUnsupported:
      return "unsupported";
    case ErrorCode::kResourceLimit:
      return "resource limit";
    case ErrorCode::kCancelled:
      return "cancelled";
    case ErrorCode::kInternal:
      return "internal error";
  }
  return "unknown";
}

}  // namespace vt

// Propagates a failed Status out of the enclosing function.
#define VT_RETURN_IF_ERROR(expr)             \
  do {                                       \
    ::vt::Status vt_status_ = (expr);        \
    if (!vt_status_.ok()) return vt_status_; \
  } while (0)

#define VT_CONCAT_INNER_(a, b) a##b
#define VT_CONCAT_(a, b) VT_CONCAT_INNER_(a, b)
#define VT_ASSIGN_OR_RETURN_IMPL_(tmp, lhs, expr) \
  auto tmp = (expr);                              \
  if (!tmp.ok()) return tmp.status();             \
  lhs = std::move(tmp).value()
// VT_ASSIGN_OR_RETURN(auto file, PageFileReader::open(path));
#define VT_ASSIGN_OR_RETURN(lhs, expr) \
  VT_ASSIGN_OR_RETURN_IMPL_(VT_CONCAT_(vt_expected_, __LINE__), lhs, expr)
