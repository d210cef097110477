// Writes the page file the consumers stream, through the installed C++ API: 4 x 3 pages of
// 8 + 2 * 4 texels, raw RGBA8, every texel of a page (level, x, y, 255).
#include <vtbake/format/page_file.h>
#include <vtbake/format/version.h>
#include <cstdio>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: write_page_file OUT.vtpf\n");
    return 2;
  }
  vt::PageFileDesc desc;
  desc.geometry.width = 32;
  desc.geometry.height = 24;
  desc.geometry.payload = 8;
  desc.geometry.border = 4;
  vt::LayerSpec layer;
  layer.name = "albedo";
  layer.codec = vt::PageCodec::kRaw;
  desc.layers = {layer};
  auto writer = vt::PageFileWriter::create(argv[1], desc);
  if (!writer.ok()) {
    std::fprintf(stderr, "%s\n", writer.status().message().c_str());
    return 1;
  }
  const vt::PageGeometry& g = desc.geometry;
  const uint32_t side = g.page_size();
  for (uint32_t l = 0; l < g.level_count(); ++l)
    for (uint32_t y = 0; y < g.pages_y(l); ++y)
      for (uint32_t x = 0; x < g.pages_x(l); ++x) {
        std::vector<uint8_t> page(size_t(side) * side * 4);
        for (size_t i = 0; i < page.size(); i += 4) {
          page[i] = uint8_t(l);
          page[i + 1] = uint8_t(x);
          page[i + 2] = uint8_t(y);
          page[i + 3] = 255;
        }
        if (vt::Status s = (*writer)->add_page({l, x, y}, 0, page); !s.ok()) {
          std::fprintf(stderr, "%s\n", s.message().c_str());
          return 1;
        }
      }
  if (vt::Status s = (*writer)->finish(); !s.ok()) {
    std::fprintf(stderr, "%s\n", s.message().c_str());
    return 1;
  }
  std::printf("wrote %s with vtbake %s (page-file version %u)\n", argv[1],
              vt::library_version_string(), vt::newest_page_file_version());
  return 0;
}
