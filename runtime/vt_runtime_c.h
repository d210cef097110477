/* C API of the vtbake runtime (engine-facing): open a page file, feed one feedback buffer per
 * frame, copy the returned uploads into the physical cache textures and the page table into its
 * texture. Formats are those of runtime/feedback.h and runtime/page_table.h. Error codes,
 * messages and naming follow format/vt_error_c.h. A handle may be used from several threads. */
#ifndef VTBAKE_RUNTIME_VT_RUNTIME_C_H_
#define VTBAKE_RUNTIME_VT_RUNTIME_C_H_

#include <stddef.h>
#include <stdint.h>

#include "format/vt_error_c.h"
#include "format/vt_io_c.h"
#include "format/vt_version_c.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vtrt_streamer vtrt_streamer;

/* One feedback value (runtime/feedback.h): page (x, y) of `level` wanted by a pixel; x, y < 4096,
 * level < 32. VTRT_FEEDBACK_NONE marks a pixel that wants nothing. VTRT_FEEDBACK_TEX adds the
 * virtual texture id (0..6) when several streamers share one feedback buffer; VTRT_FEEDBACK is
 * texture 0. */
#define VTRT_FEEDBACK(level, x, y) VTRT_FEEDBACK_TEX(0, level, x, y)
#define VTRT_FEEDBACK_TEX(texture, level, x, y)                                                  \
  (((uint32_t)(x)&0xFFFu) | (((uint32_t)(y)&0xFFFu) << 12) | (((uint32_t)(level)&0x1Fu) << 24) | \
   (((uint32_t)(texture)&7u) << 29))
#define VTRT_FEEDBACK_NONE 0xFFFFFFFFu
#define VTRT_MAX_TEXTURES 7u

typedef struct vtrt_options {
  uint32_t slots_x, slots_y;    /* physical cache in slots (each <= 256) */
  uint64_t memory_budget_bytes; /* 0: bounded by the slot count only */
  uint32_t threads;             /* loader worker threads */
  uint32_t max_in_flight;
  uint64_t upload_byte_limit; /* per frame */
  uint32_t max_lod_bias;
  int bc7_as_rgba8; /* non-zero: upload BC7 layers as RGBA8 */
} vtrt_options;

typedef struct vtrt_geometry {
  uint32_t width, height, payload, border, page_size, level_count;
  uint32_t layer_count;
} vtrt_geometry;

typedef struct vtrt_frame_stats {
  uint64_t frame;
  uint32_t needed, resident_hits, queued, cancelled, mapped, evicted, dropped, load_errors;
  uint32_t lod_bias;
  int thrashing;
} vtrt_frame_stats;

typedef struct vtrt_upload {
  uint32_t level, page_x, page_y;
  uint32_t slot_x, slot_y;
  const uint8_t* data; /* the layer's bytes, valid until the next vtrt_update */
  size_t size;
} vtrt_upload;

/* Engine hooks (runtime/page_buffer.h). The allocator gets every page-sized buffer (staging,
 * uploads, decode scratch): `allocate` returns `size` bytes aligned to `alignment` (a power of
 * two <= 4096) or NULL; both are called from the loader's threads or jobs, so they must be
 * thread-safe, and `user` must stay valid until vtrt_close returns. */
typedef struct vtrt_allocator {
  void* (*allocate)(size_t size, size_t alignment, void* user);
  void (*release)(void* memory, size_t size, void* user);
  void* user;
} vtrt_allocator;

/* The job hook: instead of starting loader threads, the streamer hands each page load to
 * `submit`, which must run `run(job)` exactly once, on any thread, later or inside submit. A job
 * is one page (read, decode, BC encode: 0.2-2 ms) and never waits on another. submit is called
 * from the thread calling vtrt_update. Jobs that run after vtrt_close return at once (the
 * handle's state lives until the last one has run). */
typedef struct vtrt_job_system {
  void (*submit)(void (*run)(void* job), void* job, void* user);
  void* user;
} vtrt_job_system;

/* Everything vtrt_open_ex takes. Set struct_size = sizeof(vtrt_open_info) (later versions add
 * fields at the end); zero what is not used. */
typedef struct vtrt_open_info {
  size_t struct_size;
  const char* path;                /* the page file, or NULL with io */
  const vt_read_callbacks* io;     /* the engine's storage (format/vt_io_c.h), or NULL with path */
  const char* name;                /* stands for the path in messages with io; may be NULL */
  const vtrt_options* options;     /* NULL: the defaults */
  const vtrt_allocator* allocator; /* NULL: the C++ runtime's operator new */
  const vtrt_job_system* jobs;     /* NULL: options->threads loader threads */
  uint32_t texture_id; /* 0..6: the feedback values of this streamer (VTRT_FEEDBACK_TEX) */
} vtrt_open_info;

/* Fills the defaults (32 x 32 slots, 2 threads, 64 in flight, 16 MiB per frame, bias <= 8). */
void vtrt_default_options(vtrt_options* options);
/* Opens `path` and creates a streamer into *out (NULL on failure). options may be NULL (the
 * defaults). */
int vtrt_open(const char* path, const vtrt_options* options, vtrt_streamer** out);
/* vtrt_open over the engine's storage (format/vt_io_c.h): pak files, virtual file systems.
 * `name` stands for the path in messages; io->read is called from the loader threads.
 * io->release, when set, is called once the streamer is closed (or the open failed). */
int vtrt_open_callbacks(const vt_read_callbacks* io, const char* name, const vtrt_options* options,
                        vtrt_streamer** out);
/* The general form of both: path or io, plus the engine hooks and the texture id. */
int vtrt_open_ex(const vtrt_open_info* info, vtrt_streamer** out);
void vtrt_close(vtrt_streamer* streamer);

int vtrt_get_geometry(const vtrt_streamer* streamer, vtrt_geometry* out);
/* Runtime format (format/runtime_format.h RuntimeFormat value) and bytes per slot of a layer. */
int vtrt_get_upload_format(const vtrt_streamer* streamer, uint32_t layer, uint32_t* format,
                           size_t* bytes);

/* One frame. feedback: `count` uint32 values (may be NULL when count is 0). */
int vtrt_update(vtrt_streamer* streamer, const uint32_t* feedback, size_t count,
                vtrt_frame_stats* stats);
/* The uploads of the last vtrt_update. */
uint32_t vtrt_upload_count(const vtrt_streamer* streamer);
int vtrt_get_upload(const vtrt_streamer* streamer, uint32_t index, uint32_t layer,
                    vtrt_upload* out);

/* Page table level (RGBA8, width x height texels, see runtime/page_table.h). `data` points into
 * the streamer's copy taken at the last vtrt_update, valid until the next one. The dirty
 * rectangle is [x0, x1) x [y0, y1) (empty when x0 >= x1) since the previous vtrt_update. */
int vtrt_get_page_table_level(const vtrt_streamer* streamer, uint32_t level, const uint8_t** data,
                              uint32_t* width, uint32_t* height, uint32_t dirty[4]);

/* Blocks until queued loads finish (tools and validation only). */
void vtrt_wait_idle(vtrt_streamer* streamer);
/* 1 when no load is queued or running, else 0. */
int vtrt_idle(const vtrt_streamer* streamer);

#ifdef __cplusplus
}
#endif

#endif /* VTBAKE_RUNTIME_VT_RUNTIME_C_H_ */
