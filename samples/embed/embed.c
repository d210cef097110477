/* The runtime embedding example: what an engine's frame loop does with the C API. It opens a
 * page file, flies a camera over a ground plane textured with the whole virtual texture, makes
 * each frame's feedback buffer from that view (standing in for the GPU feedback pass), streams
 * pages within a memory budget and prints per-frame statistics and timings.
 *
 *   embed FILE.vtpf [--frames N] [--size WxH] [--budget-mib M] [--quiet]
 *
 * C99 and POSIX (clock_gettime); docs/RUNTIME.md walks through it. */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <vtbake/runtime/vt_runtime_c.h>

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
                          uint32_t* out) {
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
      *f = VTRT_FEEDBACK(level, x, y);
    }
  }
}

static int fail(const char* what) {
  fprintf(stderr, "embed: %s: %s\n", what, vt_last_error());
  return 1;
}

int main(int argc, char** argv) {
  const char* path = NULL;
  uint32_t frames = 120, w = 1920, h = 1080, budget_mib = 256;
  int quiet = 0;
  for (int i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--frames") && i + 1 < argc) {
      frames = (uint32_t)atoi(argv[++i]);
    } else if (!strcmp(argv[i], "--size") && i + 1 < argc) {
      if (sscanf(argv[++i], "%ux%u", &w, &h) != 2 || !w || !h)
        return fprintf(stderr, "embed: --size WxH\n"), 2;
    } else if (!strcmp(argv[i], "--budget-mib") && i + 1 < argc) {
      budget_mib = (uint32_t)atoi(argv[++i]);
    } else if (!strcmp(argv[i], "--quiet")) {
      quiet = 1;
    } else if (!path && argv[i][0] != '-') {
      path = argv[i];
    } else {
      fprintf(stderr,
              "usage: embed FILE.vtpf [--frames N] [--size WxH] [--budget-mib M] [--quiet]\n");
      return 2;
    }
  }
  if (!path) return fprintf(stderr, "usage: embed FILE.vtpf [options]\n"), 2;

  vtrt_options options;
  vtrt_default_options(&options);
  options.memory_budget_bytes = (uint64_t)budget_mib << 20;
  const double t_open = now_ms();
  vtrt_streamer* streamer = NULL;
  if (vtrt_open(path, &options, &streamer) != VT_OK) return fail("vtrt_open");
  const double open_ms = now_ms() - t_open;
  vtrt_geometry g;
  if (vtrt_get_geometry(streamer, &g) != VT_OK) return fail("vtrt_get_geometry");

  uint32_t* feedback = malloc((size_t)w * h * sizeof *feedback);
  if (!feedback) return fprintf(stderr, "embed: out of memory\n"), 1;
  double update_ms_total = 0, update_ms_max = 0, first_page_ms = -1;
  uint64_t uploads = 0;
  for (uint32_t frame = 0; frame < frames; ++frame) {
    /* The camera path: a slow circle over the plane, turning as it goes. */
    const double a = 6.283185307179586 * frame / (frames ? frames : 1);
    camera c = {32.0 + 16.0 * cos(a), 32.0 + 16.0 * sin(a), 2.0, a + 1.5707963267948966};
    make_feedback(&g, &c, w, h, feedback);
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
          "frame %3u: needed %5u hits %5u queued %4u mapped %4u evicted %4u bias %u%s  %.2f ms\n",
          frame, st.needed, st.resident_hits, st.queued, st.mapped, st.evicted, st.lod_bias,
          st.thrashing ? " thrashing" : "", ms);
  }
  printf("%s: %ux%u texels, %u levels; %u frames at %ux%u, budget %u MiB\n", path, g.width,
         g.height, g.level_count, frames, w, h, budget_mib);
  printf("vtrt_open %.2f ms, first requested page uploaded %.2f ms after open\n", open_ms,
         first_page_ms);
  printf("vtrt_update: %.3f ms per frame on average, %.3f ms at most; %llu uploads\n",
         frames ? update_ms_total / frames : 0.0, update_ms_max, (unsigned long long)uploads);
  free(feedback);
  vtrt_close(streamer);
  return 0;
}
