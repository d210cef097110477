/* The page-file reader as a C API, for engines that do not take C++ (docs/FORMAT.md specifies
 * the bytes). Error codes, messages and naming follow format/vt_error_c.h. A vtpf_file may be
 * read from several threads at once. */
#ifndef VTBAKE_FORMAT_PAGE_FILE_C_H_
#define VTBAKE_FORMAT_PAGE_FILE_C_H_

#include <stddef.h>
#include <stdint.h>

#include "format/vt_error_c.h"
#include "format/vt_io_c.h"
#include "format/vt_version_c.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Page states in the index. */
enum { VTPF_PAGE_ABSENT = 0, VTPF_PAGE_CONSTANT = 1, VTPF_PAGE_STORED = 2 };

typedef struct vtpf_file vtpf_file;

typedef struct vtpf_geometry {
  uint32_t width, height;   /* level 0 texels */
  uint32_t payload, border; /* page = payload + 2 * border texels per side */
  uint32_t page_size;
  uint32_t level_count;
  uint32_t layer_count;
  uint32_t version;
} vtpf_geometry;

/* Enum fields use the values of docs/FORMAT.md's layer table. */
typedef struct vtpf_layer_info {
  uint8_t semantic, channels, texel_type, codec, runtime_format, color_space, address_mode;
  uint32_t texel_bytes;      /* channels * bytes per channel */
  const char* name;          /* NUL-terminated, owned by the vtpf_file */
  size_t decoded_page_bytes; /* what vtpf_read_texels writes */
} vtpf_layer_info;

typedef struct vtpf_page_entry {
  uint8_t state; /* VTPF_PAGE_* */
  uint8_t codec;
  uint64_t offset;   /* stored: byte offset in the file */
  uint32_t size;     /* stored: byte count */
  uint64_t checksum; /* XXH3-64 of the stored bytes or of the constant value */
  uint8_t constant[16];
} vtpf_page_entry;

/* Opens and validates a page file into *out (NULL on failure). verify_checksums != 0 checks
 * every page's checksum when it is read. */
int vtpf_open(const char* path, int verify_checksums, vtpf_file** out);
/* vtpf_open over the engine's storage (format/vt_io_c.h); `name` stands for the path in
 * messages. io->release, when set, is called once the file is closed (or the open failed). */
int vtpf_open_callbacks(const vt_read_callbacks* io, const char* name, int verify_checksums,
                        vtpf_file** out);
void vtpf_close(vtpf_file* file);

int vtpf_get_geometry(const vtpf_file* file, vtpf_geometry* out);
/* Pages per row and column of a level (0 when the level does not exist). */
uint32_t vtpf_pages_x(const vtpf_file* file, uint32_t level);
uint32_t vtpf_pages_y(const vtpf_file* file, uint32_t level);
int vtpf_get_layer(const vtpf_file* file, uint32_t layer, vtpf_layer_info* out);
/* The JSON metadata (not NUL-terminated; *size receives its length). */
const char* vtpf_metadata(const vtpf_file* file, size_t* size);

int vtpf_get_entry(const vtpf_file* file, uint32_t level, uint32_t x, uint32_t y, uint32_t layer,
                   vtpf_page_entry* out);
/* Copies a stored page's bytes into buf (capacity bytes). *size receives the page's byte count
 * even when capacity is too small (then VT_ERR_INVALID_ARGUMENT, nothing copied). */
int vtpf_read_stored(const vtpf_file* file, uint32_t level, uint32_t x, uint32_t y, uint32_t layer,
                     void* buf, size_t capacity, size_t* size);
/* Decodes a stored or constant page into out (capacity >= the layer's decoded_page_bytes). Absent
 * pages give VT_ERR_NOT_FOUND. */
int vtpf_read_texels(const vtpf_file* file, uint32_t level, uint32_t x, uint32_t y, uint32_t layer,
                     void* out, size_t capacity);
/* Checks every stored page's checksum. */
int vtpf_verify(const vtpf_file* file);

#ifdef __cplusplus
}
#endif

#endif /* VTBAKE_FORMAT_PAGE_FILE_C_H_ */
