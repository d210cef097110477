// The OBJ target's input: an OBJ and the MTL library beside it in one input, split at the first
// kMtlMarker line. The seeds' OBJ says "mtllib m.mtl", the name the MTL part is written under.
#pragma once

#include <string_view>

namespace vt::fuzz {

inline constexpr std::string_view kMtlMarker = "\n#%%m.mtl%%\n";
inline constexpr const char* kMtlName = "m.mtl";

}  // namespace vt::fuzz
