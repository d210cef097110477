/* Compiled as C so that the build proves format/page_file_c.h holds no C++. */
#include "format/page_file_c.h"

int vtpf_c_header_is_c(void) {
  return VT_OK;
}
