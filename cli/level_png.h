// 8-bit PNG output of an extracted level (`vtbake extract -o x.png`) without an image library:
// the page-file tools start without the bake stack (docs/ARCHITECTURE.md, "Start-up").
#pragma once

#include <string>

#include "common/status.h"
#include "format/page_file.h"
#include "format/page_file_inspect.h"

namespace vt {

// Whether write_level_png can write `image`: 8-bit texels, 1 to 4 channels.
bool level_png_supported(const LevelImage& image);

// Writes the texels unchanged through the atomic writer (format/atomic_output.h): 1 channel as
// grey, 2 as grey + alpha, 3 as RGB, 4 as RGBA (PNG has no other 2- and 4-channel types; a data
// layer's last channel is stored as it is, never divided out). A colour layer in sRGB gets the
// sRGB chunk. kInvalidArgument for what level_png_supported refuses, kIo naming the path for a
// failed write.
Status write_level_png(const std::string& path, const LevelImage& image, const LayerSpec& layer);

}  // namespace vt
