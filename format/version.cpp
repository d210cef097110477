// The library's version comes from the project version (format/CMakeLists.txt), the page-file
// version from the layout the reader implements.
#include "format/version.h"

#include "format/page_file_layout.h"
#include "format/vt_version_c.h"

#define VT_STRINGIFY_(x) #x
#define VT_STRINGIFY(x) VT_STRINGIFY_(x)

namespace vt {

LibraryVersion library_version() {
  return {VT_LIBRARY_VERSION_MAJOR, VT_LIBRARY_VERSION_MINOR, VT_LIBRARY_VERSION_PATCH};
}

const char* library_version_string() {
  return VT_STRINGIFY(VT_LIBRARY_VERSION_MAJOR) "." VT_STRINGIFY(
      VT_LIBRARY_VERSION_MINOR) "." VT_STRINGIFY(VT_LIBRARY_VERSION_PATCH);
}

uint32_t newest_page_file_version() {
  return pagefile::kVersion;
}

}  // namespace vt

extern "C" {

uint32_t vt_version(void) {
  const vt::LibraryVersion v = vt::library_version();
  return (v.major << 16) | (v.minor << 8) | v.patch;
}

const char* vt_version_string(void) {
  return vt::library_version_string();
}

uint32_t vtpf_newest_version(void) {
  return vt::newest_page_file_version();
}

}  // extern "C"
