/* What every vtbake C API (format/page_file_c.h, runtime/vt_runtime_c.h) has in common:
 * - a function that can fail returns int: VT_OK (0) or a VT_ERR_* code, the values of
 *   vt::ErrorCode (common/status.h);
 * - the message of the calling thread's last failure is vt_last_error(), whichever API failed;
 * - handles come from <api>_open(..., &handle) and go to <api>_close (NULL is a no-op);
 * - accessors that can fail are <api>_get_<what>(handle, ..., out); queries that cannot fail
 *   return their value (0 or NULL for a NULL handle or an index out of range);
 * - no C++ exception crosses into C (an allocation failure is VT_ERR_RESOURCE_LIMIT). */
#ifndef VTBAKE_FORMAT_VT_ERROR_C_H_
#define VTBAKE_FORMAT_VT_ERROR_C_H_

#ifdef __cplusplus
extern "C" {
#endif

enum vt_error {
  VT_OK = 0,
  VT_ERR_INVALID_ARGUMENT = 1,
  VT_ERR_NOT_FOUND = 2,
  VT_ERR_IO = 3,
  VT_ERR_CORRUPT = 4,
  VT_ERR_UNSUPPORTED = 5,
  VT_ERR_RESOURCE_LIMIT = 6,
  VT_ERR_CANCELLED = 7,
  VT_ERR_INTERNAL = 8
};

/* The calling thread's last error message ("" when none); valid until its next failing call. */
const char* vt_last_error(void);

#ifdef __cplusplus
}
#endif

#endif /* VTBAKE_FORMAT_VT_ERROR_C_H_ */
