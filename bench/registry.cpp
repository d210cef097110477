#include "bench/registry.h"

#include <cstdlib>
#include <sstream>

#include "bench/bc6h_bench.h"
#include "bench/codec_bench.h"
#include "bench/file_decode_bench.h"
#include "bench/hard_content_bench.h"

namespace vt::bench {

const std::vector<BenchKind>& bench_kinds() {
  static const std::vector<BenchKind> kinds = {
      codec_bench_kind(),
      hard_content_bench_kind(),
      bc6h_bench_kind(),
      file_decode_bench_kind(),
  };
  return kinds;
}

namespace {

Expected<int> parse_int(const std::string& name, const std::string& text, int min, int max) {
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || end == nullptr || *end != '\0' || v < min || v > max) {
    return Error(ErrorCode::kInvalidArgument, "--" + name + ": '" + text +
                                                  "' is not an integer in " + std::to_string(min) +
                                                  ".." + std::to_string(max));
  }
  return int(v);
}

}  // namespace

Expected<int> option_int(const BenchRequest& request, const std::string& name, int min, int max) {
  auto it = request.values.find(name);
  if (it == request.values.end()) {
    return Error(ErrorCode::kInvalidArgument, "--" + name + ": no such option");
  }
  return parse_int(name, it->second, min, max);
}

Expected<std::vector<int>> option_int_list(const BenchRequest& request, const std::string& name,
                                           int min, int max) {
  auto it = request.values.find(name);
  if (it == request.values.end()) {
    return Error(ErrorCode::kInvalidArgument, "--" + name + ": no such option");
  }
  std::vector<int> out;
  std::stringstream ss(it->second);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    VT_ASSIGN_OR_RETURN(int v, parse_int(name, item, min, max));
    out.push_back(v);
  }
  return out;
}

}  // namespace vt::bench
