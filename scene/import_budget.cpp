// Messages and checks of the scene-import resource budget (import_budget.h).
#include "scene/import_budget.h"

#include <cstdio>

namespace vt::scene::detail {
namespace {

std::string with_separators(uint64_t v) {
  std::string digits = std::to_string(v), out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out.push_back(',');
    out.push_back(digits[i]);
  }
  return out;
}

}  // namespace

std::string format_bytes(double bytes) {
  if (bytes < 1024.0 * 1024.0) {
    uint64_t n = static_cast<uint64_t>(bytes);
    return with_separators(n) + (n == 1 ? " byte" : " bytes");
  }
  const char* units[] = {"MiB", "GiB", "TiB", "PiB", "EiB"};
  double v = bytes / (1024.0 * 1024.0);
  int u = 0;
  while (v >= 1024.0 && u < 4) v /= 1024.0, ++u;
  char text[48];
  std::snprintf(text, sizeof(text), "%.1f %s", v, units[u]);
  return text;
}

std::string needs_but_holds(uint64_t count, uint64_t unit, const std::string& holder,
                            uint64_t held) {
  // Doubles: count * unit may not fit in 64 bits, and the message needs no exact figure.
  double needs = static_cast<double>(count) * static_cast<double>(unit);
  return "count " + std::to_string(count) + " x " + format_bytes(static_cast<double>(unit)) +
         " needs " + format_bytes(needs) + " but " + holder + " holds " +
         format_bytes(static_cast<double>(held));
}

Status check_backed(const std::string& what, uint64_t count, uint64_t unit,
                    const std::string& holder, uint64_t held) {
  if (unit == 0 || count <= held / unit) return Status::Ok();
  return Error(ErrorCode::kCorrupt, what + ": " + needs_but_holds(count, unit, holder, held));
}

Status check_ceiling(const std::string& what, uint64_t count, uint64_t ceiling,
                     const std::string& noun) {
  if (count <= ceiling) return Status::Ok();
  return Error(ErrorCode::kResourceLimit,
               what + ": count " + std::to_string(count) + " exceeds the ceiling of " +
                   with_separators(ceiling) + " " + noun + " per primitive");
}

}  // namespace vt::scene::detail
