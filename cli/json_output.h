// The one shape of every command's --json output (docs/JSON.md): a single JSON object on one
// line of stdout, opened by the same envelope keys, with errors as objects instead of stderr
// lines. Commands build their body and hand it here; nothing else in cli/ prints JSON.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "common/status.h"

namespace vt::cli {

// Bumped when a key changes meaning or is removed; new keys may appear without a bump.
constexpr int kJsonSchema = 1;

// Set once by main() from --json: report_error and bad_usage then print their error object
// on stdout (the stderr line stays, for logs).
void set_json_output(bool on);
bool json_output();

// {"schema", "command", "ok", "exit"} followed by `body`'s keys; printed as one line.
void print_json(const char* command, int exit_code, const nlohmann::json& body);

// The error object of a failed Status: {"code", "message"}; codes are error_code_json names.
nlohmann::json error_json(const Status& status);
// The JSON spelling of an error code: "invalid_argument", "not_found", "io", "corrupt",
// "unsupported", "resource_limit", "cancelled", "internal"; "usage" is a flag error.
const char* error_code_json(ErrorCode code);

// With --json, prints {"...", "ok": false, "exit": exit_code, "error": {...}} for `command`.
void print_json_error(const char* command, int exit_code, const nlohmann::json& error);

}  // namespace vt::cli
