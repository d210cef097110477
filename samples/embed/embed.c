/* The runtime embedding example: what an engine's frame loop does with the C API. It opens a
 * page file, flies a camera over a ground plane textured with the whole virtual texture, makes
 * each frame's feedback buffer from that view (standing in for the GPU feedback pass), streams
 * pages within a memory budget and prints per-frame statistics and timings.
 *
 *   embed FILE.vtpf [--frames N] [--size WxH] [--budget-mib M] [--jobs N] [--textures 1|2]
 *                   [--quiet]
 *
 * --jobs N hands the page work to the engine's own job system (here a small pool of N pthreads)
 * instead of the library's threads; --textures 2 serves two virtual textures (the file opened
 * twice: the left and right halves of the screen) from one feedback buffer.
 * C99 and POSIX (clock_gettime, pthreads); docs/RUNTIME.md walks through it. */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <vtbake/runtime/vt_runtime_c.h>

/* The engine's job system, as small as one can be: a FIFO of jobs and N worker threads. */
typedef struct job {
  void (*run)(void*);
  void* arg;
  struct job* next;
} job;

typedef struct job_pool {
  pthread_mutex_t mutex;
  pthread_cond_t cond;
  job *head, *tail;
  int stop;
  uint32_t count;
  pthread_t* threads;
} job_pool;

static void* job_worker(void* p) {
  job_pool* pool = p;
  pthread_mutex_lock(&pool->mutex);
  for (;;) {
    while (!pool->head && !pool->stop) pthread_cond_wait(&pool->cond, &pool->mutex);
    if (!pool->head) break; /* stopping, queue drained */
    job* j = pool->head;
    pool->head = j->next;
    if (!pool->head) pool->tail = NULL;
    pthread_mutex_unlock(&pool->mutex);
    j->run(j->arg);
    free(j);
    pthread_mutex_lock(&pool->mutex);
  }
  pthread_mutex_unlock(&pool->mutex);
  return NULL;
}

/* vtrt_job_system.submit: queue the job; a worker runs it. */
static void job_submit(void (*run)(void*), void* arg, void* user) {
  job_pool* pool = user;
  job* j = malloc(sizeof *j);
  if (!j) {
    run(arg); /* no memory for the queue: run it here rather than never */
    return;
  }
  j->run = run;
  j->arg = arg;
  j->next = NULL;
  pthread_mutex_lock(&pool->mutex);
  if (pool->tail)
    pool->tail->next = j;
  else
    pool->head = j;
  pool->tail = j;
  pthread_cond_signal(&pool->cond);
  pthread_mutex_unlock(&pool->mutex);
}

static int job_pool_start(job_pool* pool, uint32_t count) {
  memset(pool, 0, sizeof *pool);
  pthread_mutex_init(&pool->mutex, NULL);
  pthread_cond_init(&pool->cond, NULL);
  pool->threads = calloc(count, sizeof *pool->threads);
  if (!pool->threads) return 0;
  for (; pool->count < count; ++pool->count)
    if (pthread_create(&pool->threads[pool->count], NULL, job_worker, pool) != 0) return 0;
  return 1;
}

/* Runs what is still queued (jobs of a closed streamer return at once) and joins. */
static void job_pool_stop(job_pool* pool) {
  pthread_mutex_lock(&pool->mutex);
  pool->stop = 1;
  pthread_cond_broadcast(&pool->cond);
  pthread_mutex_unlock(&pool->mutex);
  for (uint32_t i = 0; i < pool->count; ++i) pthread_join(pool->threads[i], NULL);
  free(pool->threads);
  pthread_cond_destroy(&pool->cond);
  pthread_mutex_destroy(&pool->mutex);
}

static double now_ms(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

/* A camera `height` units above a ground plane of world x world units that carries the virtual
 * texture once, looking along `yaw`, 45 degrees down at the centre of the view. */
typedef struct camera {
  double x, z, height, yaw;
} camera;

/* The feedback pass on the CPU: for each pixel the page and mip level its texel footprint
 * asks for (feedback format of runtime/feedback.h), none above the horizon. */
static void make_feedback(const vtrt_geometry* g, const camera* c, uint32_t w, uint32_t h,
                          uint32_t textures, uint32_t* out) {
  const double world = 64.0, focal = 0.5 * h, pitch = 0.7853981633974483;
  const double texels_per_unit = g->width / world;
  for (uint32_t py = 0; py < h; ++py) {
    for (uint32_t px = 0; px < w; ++px) {
      /* View ray in camera space (x right, y down, z forward), pitched down. */
      const double rx = (px + 0.5 - 0.5 * w) / focal, ry0 = (py + 0.5 - 0.5 * h) / focal;
      const double ry = ry0 * cos(pitch) + sin(pitch), rz = cos(pitch) - ry0 * sin(pitch);
      uint32_t* f = &out[(size_t)py * w + px];
      if (ry <= 1e-3) {
        *f = VTRT_FEEDBACK_NONE;
        continue;
      }
      const double t = c->height / ry; /* distance along the ray to the plane */
      const double wx = c->x + t * (rx * cos(c->yaw) + rz * sin(c->yaw));
      const double wz = c->z + t * (rz * cos(c->yaw) - rx * sin(c->yaw));
      double u = wx / world, v = wz / world;
      u -= floor(u);
      v -= floor(v);
      /* Texels per pixel: the ray's length per pixel, stretched by the grazing angle. */
      const double len = sqrt(rx * rx + ry * ry + rz * rz);
      const double footprint = t * len / focal / sqrt(ry / len) * texels_per_unit;
      uint32_t level = footprint > 1.0 ? (uint32_t)log2(footprint) : 0;
      if (level >= g->level_count) level = g->level_count - 1;
      const uint32_t page = g->payload << level;
      uint32_t x = (uint32_t)(u * g->width) / page, y = (uint32_t)(v * g->height) / page;
      /* With two textures the right half of the screen shows texture 1. */
      *f = VTRT_FEEDBACK_TEX(textures > 1 && px >= w / 2 ? 1 : 0, level, x, y);
    }
  }
}

static int fail(const char* what) {
  fprintf(stderr, "embed: %s: %s\n", what, vt_last_error());
  return 1;
}

int main(int argc, char** argv) {
  const char* path = NULL;
  uint32_t frames = 120, w = 1920, h = 1080, budget_mib = 256, jobs = 0, textures = 1;
  int quiet = 0;
  const char* usage =
      "usage: embed FILE.vtpf [--frames N] [--size WxH] [--budget-mib M] [--jobs N] "
      "[--textures 1|2] [--quiet]\n";
  for (int i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--frames") && i + 1 < argc) {
      frames = (uint32_t)atoi(argv[++i]);
    } else if (!strcmp(argv[i], "--size") && i + 1 < argc) {
      if (sscanf(argv[++i], "%ux%u", &w, &h) != 2 || !w || !h)
        return fprintf(stderr, "embed: --size WxH\n"), 2;
    } else if (!strcmp(argv[i], "--budget-mib") && i + 1 < argc) {
      budget_mib = (uint32_t)atoi(argv[++i]);
    } else if (!strcmp(argv[i], "--jobs") && i + 1 < argc) {
      jobs = (uint32_t)atoi(argv[++i]);
      if (jobs > 64) return fprintf(stderr, "embed: --jobs 0..64\n"), 2;
    } else if (!strcmp(argv[i], "--textures") && i + 1 < argc) {
      textures = (uint32_t)atoi(argv[++i]);
      if (textures < 1 || textures > 2) return fprintf(stderr, "embed: --textures 1|2\n"), 2;
    } else if (!strcmp(argv[i], "--quiet")) {
      quiet = 1;
    } else if (!path && argv[i][0] != '-') {
      path = argv[i];
    } else {
      return fprintf(stderr, "%s", usage), 2;
    }
  }
  if (!path) return fprintf(stderr, "%s", usage), 2;

  job_pool pool;
  vtrt_job_system job_system = {job_submit, &pool};
  if (jobs && !job_pool_start(&pool, jobs))
    return fprintf(stderr, "embed: cannot start %u job threads\n", jobs), 1;

  /* One streamer per virtual texture, each with its share of the budget. */
  vtrt_options options;
  vtrt_default_options(&options);
  options.memory_budget_bytes = ((uint64_t)budget_mib << 20) / textures;
  vtrt_streamer* streamers[2] = {NULL, NULL};
  const double t_open = now_ms();
  for (uint32_t t = 0; t < textures; ++t) {
    vtrt_open_info info;
    memset(&info, 0, sizeof info);
    info.struct_size = sizeof info;
    info.path = path;
    info.options = &options;
    info.jobs = jobs ? &job_system : NULL;
    info.texture_id = t;
    if (vtrt_open_ex(&info, &streamers[t]) != VT_OK) return fail("vtrt_open_ex");
  }
  const double open_ms = now_ms() - t_open;
  vtrt_geometry g;
  if (vtrt_get_geometry(streamers[0], &g) != VT_OK) return fail("vtrt_get_geometry");

  uint32_t* feedback = malloc((size_t)w * h * sizeof *feedback);
  if (!feedback) return fprintf(stderr, "embed: out of memory\n"), 1;
  double update_ms_total = 0, update_ms_max = 0, first_page_ms = -1;
  uint64_t uploads = 0;
  for (uint32_t frame = 0; frame < frames; ++frame) {
    /* The camera path: a slow circle over the plane, turning as it goes. */
    const double a = 6.283185307179586 * frame / (frames ? frames : 1);
    camera c = {32.0 + 16.0 * cos(a), 32.0 + 16.0 * sin(a), 2.0, a + 1.5707963267948966};
    make_feedback(&g, &c, w, h, textures, feedback);
    /* Every streamer reads the whole buffer and keeps the values of its own texture id. */
    for (uint32_t t = 0; t < textures; ++t) {
      vtrt_streamer* streamer = streamers[t];
      const double t0 = now_ms();
      vtrt_frame_stats st;
      if (vtrt_update(streamer, feedback, (size_t)w * h, &st) != VT_OK) return fail("vtrt_update");
      const double ms = now_ms() - t0;
      update_ms_total += ms;
      if (ms > update_ms_max) update_ms_max = ms;
      /* An engine copies each upload into its cache textures here (vtrt_get_upload per layer)
       * and the page table's dirty rectangles (vtrt_get_page_table_level). */
      for (uint32_t i = 0; i < vtrt_upload_count(streamer); ++i) {
        vtrt_upload u;
        if (vtrt_get_upload(streamer, i, 0, &u) != VT_OK) return fail("vtrt_get_upload");
        if (first_page_ms < 0 && u.level + 1 < g.level_count) first_page_ms = now_ms() - t_open;
      }
      uploads += vtrt_upload_count(streamer);
      if (!quiet)
        printf(
            "frame %3u tex %u: needed %5u hits %5u queued %4u mapped %4u evicted %4u bias %u%s"
            "  %.2f ms\n",
            frame, t, st.needed, st.resident_hits, st.queued, st.mapped, st.evicted, st.lod_bias,
            st.thrashing ? " thrashing" : "", ms);
    }
  }
  printf("%s: %ux%u texels, %u levels; %u frames at %ux%u, budget %u MiB, %u texture(s), %s\n",
         path, g.width, g.height, g.level_count, frames, w, h, budget_mib, textures,
         jobs ? "engine job system" : "library threads");
  if (jobs) printf("job system: %u threads\n", jobs);
  printf("vtrt_open %.2f ms, first requested page uploaded %.2f ms after open\n", open_ms,
         first_page_ms);
  printf("vtrt_update: %.3f ms per frame on average, %.3f ms at most; %llu uploads\n",
         frames ? update_ms_total / frames : 0.0, update_ms_max, (unsigned long long)uploads);
  free(feedback);
  for (uint32_t t = 0; t < textures; ++t) vtrt_close(streamers[t]);
  if (jobs) job_pool_stop(&pool); /* after the close: late jobs of a closed streamer are no-ops */
  return uploads > 0 ? 0 : 1;
}
