/* The engine's own storage for a page file, for vtpf_open_callbacks and vtrt_open_callbacks:
 * pak files, virtual file systems, network. */
#ifndef VTBAKE_FORMAT_VT_IO_C_H_
#define VTBAKE_FORMAT_VT_IO_C_H_

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vt_read_callbacks {
  void* user;    /* passed to every call */
  uint64_t size; /* total bytes of the page file */
  /* Reads up to `size` bytes at `offset` into `buf`: the count read (0 at the end of the data)
   * or -1 on failure. Called from several threads at once (the loader threads). */
  int64_t (*read)(void* user, uint64_t offset, void* buf, size_t size);
  /* NULL, or called once when the last handle reading through these callbacks is closed. */
  void (*release)(void* user);
} vt_read_callbacks;

#ifdef __cplusplus
}
#endif

#endif /* VTBAKE_FORMAT_VT_IO_C_H_ */
