/* Compiled as C so that the build proves runtime/vt_runtime_c.h holds no C++. */
#include "runtime/vt_runtime_c.h"

int vtrt_c_header_is_c(void) {
  return VT_OK;
}
