// What `vtbake validate` leaves behind: per view the reference and virtual renders, a
// difference map and a residency heat map as PNGs (OpenImageIO), and report.json.
#pragma once

#include <string>
#include <vector>

#include "common/status.h"
#include "render/renderer.h"
#include "render/validate.h"

namespace vt::render {

// Largest |a - b| over RGB per pixel times `gain` (clamped), grey. Same-size images.
Rgba8Image difference_map(const Rgba8Image& a, const Rgba8Image& b, int gain = 8);
// The level each pixel's fine taps sampled: level 0 white, then yellow, green, cyan, blue,
// purple... by level; pixels that sampled coarser than they wanted are tinted red, pixels with
// nothing resident are magenta, background black.
Rgba8Image residency_heat_map(const VirtualFrame& frame);
// Writes RGB (alpha dropped: renders clear to transparent black) PNG. Errors name the file.
Status write_png(const std::string& path, const Rgba8Image& image);

// Reads an image file (PNG or any format OpenImageIO reads) as RGBA8: grey is spread over RGB,
// a missing alpha is opaque. Errors name the file.
Expected<Rgba8Image> read_png(const std::string& path);

// Why a report has not passed, one line each: a summary naming the failing views and layers,
// then per failing view its reasons, then per failing atlas layer its worst pages as
// (level, x, y). Empty when it passed.
std::vector<std::string> failure_lines(const ValidationReport& report);

// The report as JSON (docs/JSON.md): what report.json holds and `vtbake validate --json` prints.
std::string report_json(const ValidationReport& report);
Status write_report_json(const std::string& path, const ValidationReport& report);

}  // namespace vt::render
