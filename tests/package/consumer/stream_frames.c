/* An engine's frame loop in miniature, through the installed C API: opens the page file
 * write_page_file made, asks for every level-0 page each frame and checks that each upload
 * carries the page it names, until all 12 are resident. Valid C99 and C++17. */
#include <stdio.h>
#include <stdlib.h>
#include <vtbake/format/page_file_c.h>
#include <vtbake/runtime/vt_runtime_c.h>

static int fail(const char* what) {
  fprintf(stderr, "%s: %s\n", what, vt_last_error());
  return 1;
}

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: stream_frames FILE.vtpf\n");
    return 2;
  }
  vtpf_file* file = NULL;
  if (vtpf_open(argv[1], 1, &file) != VT_OK) return fail("vtpf_open");
  vtpf_geometry fg;
  if (vtpf_get_geometry(file, &fg) != VT_OK) return fail("vtpf_get_geometry");
  vtpf_close(file);
  if (fg.version > vtpf_newest_version()) return fail("page-file version");

  vtrt_options options;
  vtrt_default_options(&options);
  options.slots_x = 5;
  options.slots_y = 4;
  vtrt_streamer* streamer = NULL;
  if (vtrt_open(argv[1], &options, &streamer) != VT_OK) return fail("vtrt_open");

  uint32_t feedback[12];
  for (uint32_t y = 0; y < 3; ++y)
    for (uint32_t x = 0; x < 4; ++x) feedback[y * 4 + x] = VTRT_FEEDBACK(0, x, y);
  uint32_t level0_uploads = 0;
  int frame;
  for (frame = 0; frame < 50 && level0_uploads < 12; ++frame) {
    vtrt_frame_stats stats;
    if (vtrt_update(streamer, feedback, 12, &stats) != VT_OK) return fail("vtrt_update");
    for (uint32_t i = 0; i < vtrt_upload_count(streamer); ++i) {
      vtrt_upload u;
      if (vtrt_get_upload(streamer, i, 0, &u) != VT_OK) return fail("vtrt_get_upload");
      if (u.data[0] != u.level || u.data[1] != u.page_x || u.data[2] != u.page_y) {
        fprintf(stderr, "upload %u names page (%u, %u, %u) but holds (%u, %u, %u)\n", i, u.level,
                u.page_x, u.page_y, u.data[0], u.data[1], u.data[2]);
        return 1;
      }
      if (u.level == 0) ++level0_uploads;
    }
    if (level0_uploads < 12) vtrt_wait_idle(streamer);
  }
  vtrt_close(streamer);
  if (level0_uploads != 12) {
    fprintf(stderr, "%u of 12 level-0 pages arrived in %d frames\n", level0_uploads, frame);
    return 1;
  }
  printf("vtbake %s (0x%06x): %u x %u texels, %u levels, 12 pages streamed in %d frames\n",
         vt_version_string(), (unsigned)vt_version(), fg.width, fg.height, fg.level_count, frame);
  return 0;
}
