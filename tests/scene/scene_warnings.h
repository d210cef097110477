// The scene tests' look for a load warning.
#pragma once

#include <algorithm>
#include <string>

#include "scene/scene.h"

namespace vt::test {

// True when one of the scene's warnings says `what`.
inline bool warned(const scene::Scene& s, const std::string& what) {
  return std::any_of(s.warnings.begin(), s.warnings.end(),
                     [&](const std::string& w) { return w.find(what) != std::string::npos; });
}

}  // namespace vt::test
