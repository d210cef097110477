#include "cli/json_output.h"

#include <cstdio>

namespace vt::cli {
namespace {
bool g_json = false;
}  // namespace

void set_json_output(bool on) {
  g_json = on;
}
bool json_output() {
  return g_json;
}

void print_json(const char* command, int exit_code, const nlohmann::json& body) {
  // ordered_json keeps the envelope first, so a reader of a log line sees the command at once.
  nlohmann::ordered_json j = {
      {"schema", kJsonSchema}, {"command", command}, {"ok", exit_code == 0}, {"exit", exit_code}};
  for (const auto& [key, value] : body.items()) j[key] = value;
  // Messages quote paths as the disk spells them, which need not be UTF-8: such bytes become
  // U+FFFD rather than an exception that loses the report.
  std::printf("%s\n",
              j.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace).c_str());
  std::fflush(stdout);
}

const char* error_code_json(ErrorCode code) {
  switch (code) {
    case ErrorCode::kOk:
      return "ok";
    case ErrorCode::kInvalidArgument:
      return "invalid_argument";
    case ErrorCode::kNotFound:
      return "not_found";
    case ErrorCode::kIo:
      return "io";
    case ErrorCode::kCorrupt:
      return "corrupt";
    case ErrorCode::kUnsupported:
      return "unsupported";
    case ErrorCode::kResourceLimit:
      return "resource_limit";
    case ErrorCode::kCancelled:
      return "cancelled";
    case ErrorCode::kInternal:
      return "internal";
  }
  return "internal";
}

nlohmann::json error_json(const Status& status) {
  return {{"code", error_code_json(status.code())}, {"message", status.message()}};
}

void print_json_error(const char* command, int exit_code, const nlohmann::json& error) {
  print_json(command, exit_code, {{"error", error}});
}

}  // namespace vt::cli
