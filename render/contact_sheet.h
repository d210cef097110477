// The contact sheet of a validation run: one PNG a person reads at a glance. One row per view
// with a thumbnail of every image the view wrote (ViewReport::images, in order: reference,
// virtual, difference, residency and whatever later checks add), labelled with the view
// number, its PSNR and pass/FAIL; a last row with the atlas check's heat maps, one per layer
// and level. Failing views and failing pages are outlined in red. Text is drawn with a
// built-in 5 x 7 bitmap font, so the sheet needs no font files.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "common/status.h"
#include "format/page_geometry.h"
#include "render/renderer.h"
#include "render/validate.h"

namespace vt::render {

struct Rgb8 {
  uint8_t r = 0, g = 0, b = 0;
};

// Draws `text` with its top-left corner at (x, y), each font pixel a `scale` x `scale` square;
// clipped at the image's edges. Lower case is drawn as upper case; characters outside printable
// ASCII as '?'. A glyph is 5 x 7 pixels, advanced by 6 (times scale).
void draw_text(Rgba8Image& image, int x, int y, std::string_view text, Rgb8 colour, int scale = 1);
// Width in pixels draw_text covers for `text` (no trailing gap).
uint32_t text_width(std::string_view text, int scale = 1);

struct ContactSheetOptions {
  uint32_t thumb_width = 320;      // every view image is scaled to this width, aspect kept
  uint32_t heat_map_height = 160;  // every atlas heat map is scaled to this height
  uint32_t max_width = 2048;       // heat maps wrap onto a new line past this width
  // The page file's geometry, to outline failing pages in the heat maps; none = no outlines.
  std::optional<PageGeometry> geometry;
};

// Builds the sheet from the report and the PNGs it lists (views' images, atlas heat maps).
// Errors: a listed image that cannot be read (kIo, naming the file); a report with neither
// views nor heat maps (kInvalidArgument).
Expected<Rgba8Image> make_contact_sheet(const ValidationReport& report,
                                        const ContactSheetOptions& options = {});
// make_contact_sheet, written as a PNG to `path`.
Status write_contact_sheet(const std::string& path, const ValidationReport& report,
                           const ContactSheetOptions& options = {});

}  // namespace vt::render
