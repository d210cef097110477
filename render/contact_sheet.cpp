#include "render/contact_sheet.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "render/report.h"

namespace vt::render {
namespace {

// 5 x 7 glyphs for ASCII 32 (' ') .. 95 ('_'): seven rows, bit 4 the leftmost pixel.
constexpr uint8_t kGlyphs[64][7] = {
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00},  // ' '
    {0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x04},  // !
    {0x0A, 0x0A, 0x0A, 0x00, 0x00, 0x00, 0x00},  // "
    {0x0A, 0x0A, 0x1F, 0x0A, 0x1F, 0x0A, 0x0A},  // #
    {0x04, 0x0F, 0x14, 0x0E, 0x05, 0x1E, 0x04},  // $
    {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03},  // %
    {0x0C, 0x12, 0x14, 0x08, 0x15, 0x12, 0x0D},  // &
    {0x0C, 0x04, 0x08, 0x00, 0x00, 0x00, 0x00},  // '
    {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02},  // (
    {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08},  // )
    {0x00, 0x04, 0x15, 0x0E, 0x15, 0x04, 0x00},  // *
    {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00},  // +
    {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08},  // ,
    {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00},  // -
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C},  // .
    {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00},  // /
    {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E},  // 0
    {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E},  // 1
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F},  // 2
    {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E},  // 3
    {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02},  // 4
    {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E},  // 5
    {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E},  // 6
    {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08},  // 7
    {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E},  // 8
    {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C},  // 9
    {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00},  // :
    {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x04, 0x08},  // ;
    {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02},  // <
    {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00},  // =
    {0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08},  // >
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04},  // ?
    {0x0E, 0x11, 0x01, 0x0D, 0x15, 0x15, 0x0E},  // @
    {0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11},  // A
    {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E},  // B
    {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E},  // C
    {0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C},  // D
    {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F},  // E
    {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10},  // F
    {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F},  // G
    {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11},  // H
    {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E},  // I
    {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C},  // J
    {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11},  // K
    {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F},  // L
    {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11},  // M
    {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11},  // N
    {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E},  // O
    {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10},  // P
    {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D},  // Q
    {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11},  // R
    {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E},  // S
    {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04},  // T
    {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E},  // U
    {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04},  // V
    {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A},  // W
    {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11},  // X
    {0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04},  // Y
    {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F},  // Z
    {0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E},  // [
    {0x00, 0x10, 0x08, 0x04, 0x02, 0x01, 0x00},  // backslash
    {0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E},  // ]
    {0x04, 0x0A, 0x11, 0x00, 0x00, 0x00, 0x00},  // ^
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F},  // _
};

constexpr int kGlyphW = 5, kGlyphH = 7, kAdvance = 6;
constexpr Rgb8 kBackground{28, 28, 28}, kText{225, 225, 225}, kPass{90, 215, 90},
    kFail{255, 48, 48};
constexpr int kMargin = 12, kGap = 8, kLabelScale = 2, kCaptionScale = 1;
constexpr int kLabelH = kGlyphH * kLabelScale, kCaptionH = kGlyphH * kCaptionScale;
constexpr int kOutline = 3;  // a failing view's or heat map's red frame

const uint8_t* glyph(char c) {
  unsigned u = unsigned(std::toupper(static_cast<unsigned char>(c)));
  if (u < 32 || u > 95) u = '?';
  return kGlyphs[u - 32];
}

void put(Rgba8Image& img, int x, int y, Rgb8 c) {
  if (x < 0 || y < 0 || x >= int(img.width) || y >= int(img.height)) return;
  uint8_t* p = &img.texels[(size_t(y) * img.width + size_t(x)) * 4];
  p[0] = c.r, p[1] = c.g, p[2] = c.b, p[3] = 255;
}

void fill_rect(Rgba8Image& img, int x, int y, int w, int h, Rgb8 c) {
  for (int j = y; j < y + h; ++j)
    for (int i = x; i < x + w; ++i) put(img, i, j, c);
}

// A frame `t` pixels thick just inside (x, y, w, h).
void outline(Rgba8Image& img, int x, int y, int w, int h, int t, Rgb8 c) {
  fill_rect(img, x, y, w, t, c);
  fill_rect(img, x, y + h - t, w, t, c);
  fill_rect(img, x, y, t, h, c);
  fill_rect(img, x + w - t, y, t, h, c);
}

void blit(Rgba8Image& dst, const Rgba8Image& src, int x, int y) {
  for (uint32_t j = 0; j < src.height; ++j) {
    for (uint32_t i = 0; i < src.width; ++i) {
      const uint8_t* s = &src.texels[(size_t(j) * src.width + i) * 4];
      put(dst, x + int(i), y + int(j), {s[0], s[1], s[2]});
    }
  }
}

// Box filter where it shrinks (every source pixel counts: a one-pixel fault stays visible as a
// tint), nearest where it grows (heat-map cells stay sharp).
Rgba8Image scaled(const Rgba8Image& src, uint32_t w, uint32_t h) {
  Rgba8Image out;
  out.width = w;
  out.height = h;
  out.texels.assign(size_t(w) * h * 4, 255);
  for (uint32_t y = 0; y < h; ++y) {
    const uint32_t y0 = uint32_t(uint64_t(y) * src.height / h);
    const uint32_t y1 = std::max(y0 + 1, uint32_t(uint64_t(y + 1) * src.height / h));
    for (uint32_t x = 0; x < w; ++x) {
      const uint32_t x0 = uint32_t(uint64_t(x) * src.width / w);
      const uint32_t x1 = std::max(x0 + 1, uint32_t(uint64_t(x + 1) * src.width / w));
      uint32_t sum[3] = {0, 0, 0};
      for (uint32_t j = y0; j < y1; ++j) {
        for (uint32_t i = x0; i < x1; ++i) {
          const uint8_t* p = &src.texels[(size_t(j) * src.width + i) * 4];
          for (int c = 0; c < 3; ++c) sum[c] += p[c];
        }
      }
      const uint32_t n = (y1 - y0) * (x1 - x0);
      uint8_t* d = &out.texels[(size_t(y) * w + x) * 4];
      for (int c = 0; c < 3; ++c) d[c] = uint8_t((sum[c] + n / 2) / n);
    }
  }
  return out;
}

// One picture on the sheet with its caption underneath.
struct Tile {
  Rgba8Image image;
  std::string caption;
  bool failed = false;
  int x = 0, y = 0;  // placed by layout()
};

// A labelled group of tiles: a view, or the atlas check.
struct Row {
  std::string label;
  bool failed = false;
  std::vector<Tile> tiles;
  int x = 0, y = 0, w = 0, h = 0;  // placed by layout(), the frame included
};

int tile_h(const Tile& t) {
  return int(t.image.height) + 4 + kCaptionH;
}

// Places the rows top to bottom below a header line, tiles left to right, wrapping past
// max_width; returns the sheet's size.
std::pair<int, int> layout(std::vector<Row>& rows, int max_width) {
  int y = kMargin + kLabelH + kGap, sheet_w = 0;
  for (Row& r : rows) {
    r.x = kMargin;
    r.y = y;
    const int left = r.x + kOutline + kGap / 2, top = r.y + kOutline + kGap / 2 + kLabelH + 6;
    int x = left, line_y = top, line_h = 0, right = left + int(text_width(r.label, kLabelScale));
    for (Tile& t : r.tiles) {
      if (x > left && x + int(t.image.width) > max_width) {
        x = left;
        line_y += line_h + kGap;
        line_h = 0;
      }
      t.x = x;
      t.y = line_y;
      x += int(t.image.width) + kGap;
      right = std::max(right, x - kGap);
      line_h = std::max(line_h, tile_h(t));
    }
    r.w = right + kGap / 2 + kOutline - r.x;
    r.h = line_y + line_h + kGap / 2 + kOutline - r.y;
    y += r.h + kGap;
    sheet_w = std::max(sheet_w, r.x + r.w + kMargin);
  }
  return {sheet_w, y - kGap + kMargin};
}

void draw_row(Rgba8Image& sheet, const Row& r) {
  if (r.failed) outline(sheet, r.x, r.y, r.w, r.h, kOutline, kFail);
  const int pad = kOutline + kGap / 2;
  draw_text(sheet, r.x + pad, r.y + pad, r.label, r.failed ? kFail : kPass, kLabelScale);
  for (const Tile& t : r.tiles) {
    blit(sheet, t.image, t.x, t.y);
    if (t.failed) {
      outline(sheet, t.x - 2, t.y - 2, int(t.image.width) + 4, int(t.image.height) + 4, 2, kFail);
    }
    draw_text(sheet, t.x, t.y + int(t.image.height) + 4, t.caption, t.failed ? kFail : kText,
              kCaptionScale);
  }
}

// "out/view_3_reference.png" -> "reference": what the file shows, without the view's prefix.
std::string caption_for(const std::string& path, uint32_t view) {
  std::string name = std::filesystem::path(path).stem().string();
  const std::string prefix = "view_" + std::to_string(view) + "_";
  if (name.rfind(prefix, 0) == 0) name = name.substr(prefix.size());
  return name;
}

Expected<Row> view_row(const ViewReport& v, const ContactSheetOptions& o) {
  Row row;
  row.failed = !v.failures.empty();
  char label[96];
  std::snprintf(label, sizeof label, "view %u   %.2f dB   tile %.2f dB   %s", v.view,
                v.metrics.psnr_rgb, v.metrics.worst_tile_psnr, row.failed ? "FAIL: " : "pass");
  row.label = label;
  if (row.failed) row.label += v.failures.front();
  // The label never widens the sheet past its limit; report.json has the whole text.
  const size_t max_chars = (o.max_width - 2 * kMargin) / (kAdvance * kLabelScale);
  if (row.label.size() > max_chars) row.label.resize(max_chars);
  for (const std::string& path : v.images) {
    VT_ASSIGN_OR_RETURN(Rgba8Image image, read_png(path));
    const uint32_t h = std::max<uint32_t>(
        1, uint32_t((uint64_t(image.height) * o.thumb_width + image.width / 2) / image.width));
    row.tiles.push_back({scaled(image, o.thumb_width, h), caption_for(path, v.view)});
  }
  return row;
}

// Red frames around the failing pages of one level's heat-map tile, at least 5 pixels wide so
// that a page smaller than a pixel in the thumbnail still shows.
void outline_failing_pages(Tile& tile, const AtlasLayerReport& layer, uint32_t level,
                           const PageGeometry& g) {
  const double sx = double(tile.image.width) / g.pages_x(level);
  const double sy = double(tile.image.height) / g.pages_y(level);
  for (const AtlasPageError& e : layer.worst) {
    if (!e.failed || e.id.level != level) continue;
    int x0 = int(e.id.x * sx) - 1, y0 = int(e.id.y * sy) - 1;
    int w = std::max(5, int((e.id.x + 1) * sx) - x0 + 1);
    int h = std::max(5, int((e.id.y + 1) * sy) - y0 + 1);
    outline(tile.image, x0, y0, w, h, 1, {255, 0, 0});
  }
}

Expected<Row> atlas_row(const AtlasCheckReport& a, const ContactSheetOptions& o) {
  Row row;
  row.failed = !a.passed();
  row.label = !a.ran ? "atlas check: " + a.note
                     : std::string("atlas check   ") + (row.failed ? "FAIL" : "pass");
  for (const AtlasLayerReport& layer : a.layers) {
    for (uint32_t level = 0; level < layer.heat_maps.size(); ++level) {
      VT_ASSIGN_OR_RETURN(Rgba8Image image, read_png(layer.heat_maps[level]));
      const uint32_t w = std::max<uint32_t>(
          1,
          uint32_t((uint64_t(image.width) * o.heat_map_height + image.height / 2) / image.height));
      Tile tile{scaled(image, w, o.heat_map_height), layer.name + " L" + std::to_string(level)};
      uint32_t failing = 0;
      for (const AtlasPageError& e : layer.worst) failing += e.failed && e.id.level == level;
      if (failing > 0) {
        tile.failed = true;
        tile.caption.append(" ").append(std::to_string(failing)).append(" FAIL");
        if (o.geometry && level < o.geometry->level_count()) {
          outline_failing_pages(tile, layer, level, *o.geometry);
        }
      }
      row.tiles.push_back(std::move(tile));
    }
  }
  return row;
}

}  // namespace

void draw_text(Rgba8Image& image, int x, int y, std::string_view text, Rgb8 colour, int scale) {
  for (size_t k = 0; k < text.size(); ++k) {
    const uint8_t* g = glyph(text[k]);
    const int gx = x + int(k) * kAdvance * scale;
    for (int row = 0; row < kGlyphH; ++row) {
      for (int col = 0; col < kGlyphW; ++col) {
        if (!(g[row] & (0x10 >> col))) continue;
        fill_rect(image, gx + col * scale, y + row * scale, scale, scale, colour);
      }
    }
  }
}

uint32_t text_width(std::string_view text, int scale) {
  return text.empty() ? 0 : uint32_t((text.size() * kAdvance - 1) * scale);
}

Expected<Rgba8Image> make_contact_sheet(const ValidationReport& report,
                                        const ContactSheetOptions& o) {
  if (o.thumb_width == 0 || o.heat_map_height == 0) {
    return Error(ErrorCode::kInvalidArgument, "contact sheet: zero thumbnail size");
  }
  std::vector<Row> rows;
  for (const ViewReport& v : report.views) {
    VT_ASSIGN_OR_RETURN(Row row, view_row(v, o));
    if (!row.tiles.empty()) rows.push_back(std::move(row));
  }
  if (report.atlas.ran || !report.atlas.note.empty()) {
    VT_ASSIGN_OR_RETURN(Row row, atlas_row(report.atlas, o));
    rows.push_back(std::move(row));
  }
  if (rows.empty()) {
    return Error(ErrorCode::kInvalidArgument, "contact sheet: the report lists no image");
  }
  const std::string header = "vtbake validate   " +
                             std::filesystem::path(report.page_file).filename().string() + "   " +
                             (report.passed() ? "PASS" : "FAIL");
  auto [w, h] = layout(rows, int(o.max_width));
  w = std::max(w, int(text_width(header, kLabelScale)) + 2 * kMargin);
  Rgba8Image sheet;
  sheet.width = uint32_t(w);
  sheet.height = uint32_t(h);
  sheet.texels.resize(size_t(w) * h * 4);
  fill_rect(sheet, 0, 0, w, h, kBackground);
  draw_text(sheet, kMargin, kMargin, header, report.passed() ? kPass : kFail, kLabelScale);
  for (const Row& r : rows) draw_row(sheet, r);
  return sheet;
}

Status write_contact_sheet(const std::string& path, const ValidationReport& report,
                           const ContactSheetOptions& options) {
  VT_ASSIGN_OR_RETURN(Rgba8Image sheet, make_contact_sheet(report, options));
  return write_png(path, sheet);
}

}  // namespace vt::render
