/* Version queries of the vtbake C APIs, for an engine that checks at start-up what it loaded
 * (a shared library may be newer than the headers it was built with). */
#ifndef VTBAKE_FORMAT_VT_VERSION_C_H_
#define VTBAKE_FORMAT_VT_VERSION_C_H_

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The library's version as (major << 16) | (minor << 8) | patch. */
uint32_t vt_version(void);
/* The library's version as "major.minor.patch" (static storage). */
const char* vt_version_string(void);
/* The newest page-file version (docs/FORMAT.md) this library reads; older ones are read too. */
uint32_t vtpf_newest_version(void);

#ifdef __cplusplus
}
#endif

#endif /* VTBAKE_FORMAT_VT_VERSION_C_H_ */
