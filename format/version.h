// Version queries of the C++ API (format/vt_version_c.h is the C form of the same facts).
#pragma once

#include <cstdint>

namespace vt {

struct LibraryVersion {
  uint32_t major = 0, minor = 0, patch = 0;
};

// The version of the vtbake libraries linked (not of the headers compiled against).
LibraryVersion library_version();
// "major.minor.patch".
const char* library_version_string();
// The newest page-file version (docs/FORMAT.md) the reader opens; older versions open too.
uint32_t newest_page_file_version();

}  // namespace vt
