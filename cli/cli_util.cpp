#include "cli/cli_util.h"

#include <unistd.h>

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>

#include "cli/command.h"
#include "cli/json_output.h"

namespace vt::cli {

int exit_code_for(const Status& status) {
  switch (status.code()) {
    case ErrorCode::kInvalidArgument:
    case ErrorCode::kNotFound:
    case ErrorCode::kCorrupt:
    case ErrorCode::kUnsupported:
      return kExitBadInput;
    default:
      return kExitFailure;
  }
}

int report_error(const char* command, const Status& status) {
  std::fprintf(stderr, "vtbake %s: %s\n", command, status.message().c_str());
  const int exit_code = exit_code_for(status);
  if (json_output()) print_json_error(command, exit_code, error_json(status));
  return exit_code;
}

int bad_usage(const char* command, const std::string& message) {
  std::fprintf(stderr, "vtbake %s: %s\n", command, message.c_str());
  if (json_output())
    print_json_error(command, kExitBadInput, {{"code", "usage"}, {"message", message}});
  return kExitBadInput;
}

ProgressLine::ProgressLine(bool quiet)
    : enabled_(!quiet && isatty(STDERR_FILENO)), start_(Clock::now()) {}

bool ProgressLine::due(bool force) {
  if (!enabled_) return false;
  const Clock::time_point now = Clock::now();
  if (!force && now - last_ < std::chrono::milliseconds(200)) return false;
  last_ = now;
  return true;
}

double ProgressLine::elapsed_seconds() const {
  return std::chrono::duration<double>(Clock::now() - start_).count();
}

void ProgressLine::print(const char* format, ...) {
  std::fputc('\r', stderr);
  va_list args;
  va_start(args, format);
  std::vfprintf(stderr, format, args);
  va_end(args);
  std::fflush(stderr);
}

void ProgressLine::done() {
  if (enabled_) std::fputc('\n', stderr);
}

Status parse_codec(const std::string& text, PageEncoderOptions* options) {
  const size_t colon = text.find(':');
  const std::string kind = text.substr(0, colon);
  const std::string arg = colon == std::string::npos ? "" : text.substr(colon + 1);
  const Status bad =
      Error(ErrorCode::kInvalidArgument,
            "--codec: expected dct[:1-100][:adaptive], bc[:high|fast] or raw, got '" + text + "'");
  if (kind == "dct") {
    options->codec = CodecKind::kDct;
    if (colon == std::string::npos) return Status::Ok();
    // dct:QUALITY, dct:adaptive or dct:QUALITY:adaptive.
    std::string rest = arg;
    const size_t second = rest.find(':');
    if (second != std::string::npos) {
      if (rest.substr(second + 1) != "adaptive") return bad;
      options->dct_adaptive = true;
      rest = rest.substr(0, second);
    } else if (rest == "adaptive") {
      options->dct_adaptive = true;
      return Status::Ok();
    }
    char* end = nullptr;
    long quality = std::strtol(rest.c_str(), &end, 10);
    if (rest.empty() || *end || quality < 1 || quality > 100) return bad;
    options->dct_quality = int(quality);
    return Status::Ok();
  }
  if (kind == "bc") {
    options->codec = CodecKind::kBc;
    if (arg == "high") {
      options->bc_quality = BcQuality::kHigh;
    } else if (arg == "fast") {
      options->bc_quality = BcQuality::kRealtime;
    } else if (colon != std::string::npos) {
      return bad;
    }
    return Status::Ok();
  }
  if (kind == "raw" && colon == std::string::npos) {
    options->codec = CodecKind::kRaw;
    return Status::Ok();
  }
  return bad;
}

Status parse_procedural_size(const std::string& text, uint32_t* width, uint32_t* height) {
  const std::string prefix = "procedural:";
  const Status bad = Error(ErrorCode::kInvalidArgument,
                           "'" + text + "': expected procedural:WIDTHxHEIGHT, each 1..16777216");
  if (text.rfind(prefix, 0) != 0) return bad;
  uint64_t side[2] = {0, 0};
  size_t pos = prefix.size();
  for (int i = 0; i < 2; ++i) {
    const size_t start = pos;
    while (pos < text.size() && text[pos] >= '0' && text[pos] <= '9' && side[i] <= (1u << 24))
      side[i] = side[i] * 10 + uint64_t(text[pos++] - '0');
    if (pos == start || side[i] == 0 || side[i] > (1u << 24)) return bad;
    if (i == 0 && (pos >= text.size() || text[pos++] != 'x')) return bad;
  }
  if (pos != text.size()) return bad;
  *width = uint32_t(side[0]);
  *height = uint32_t(side[1]);
  return Status::Ok();
}

Status parse_byte_size(const std::string& text, uint64_t* bytes) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  const std::string unit(end);
  double scale = 0;
  if (unit.empty()) scale = 1;
  if (unit == "K" || unit == "k" || unit == "KiB") scale = 1024.0;
  if (unit == "M" || unit == "m" || unit == "MiB") scale = 1024.0 * 1024;
  if (unit == "G" || unit == "g" || unit == "GiB") scale = 1024.0 * 1024 * 1024;
  // 2^62 bytes bounds the conversion so that huge inputs give an error, not an overflow.
  if (end == text.c_str() || !(value > 0) || scale == 0 || !(value * scale < 0x1p62)) {
    return Error(ErrorCode::kInvalidArgument,
                 "expected a size such as 512M or 2G, got '" + text + "'");
  }
  *bytes = uint64_t(value * scale);
  return Status::Ok();
}

std::string format_byte_size(uint64_t bytes) {
  for (auto [unit, shift] : {std::pair{"G", 30}, std::pair{"M", 20}, std::pair{"K", 10}}) {
    if (bytes != 0 && bytes % (uint64_t(1) << shift) == 0) {
      return std::to_string(bytes >> shift) + unit;
    }
  }
  return std::to_string(bytes);
}

}  // namespace vt::cli
