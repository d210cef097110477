// The worst page a bake may store, by layer: the PSNR (dB over a page's 8-bit channels) that
// the validator's atlas check holds every page to through its runtime format
// (render/atlas_check.cpp), and, for DCT layers, the default floor of the page mode decision
// (bake/page_encoder.cpp) a margin above it, so that a default bake stores no page its default
// check rejects. The floor measures the stored codec alone; the check adds the runtime BC
// format's error, which the margin leaves room for (UFO: Alien Invasion's gunboat stored a
// level-3 page at 26.5 dB that read 26.3 after BC1; with the floor, 28.7).
#pragma once

#include <algorithm>

#include "format/page_file.h"

namespace vt {

struct PagePsnrBounds {
  double albedo, normal, orm, emissive;
  // Custom layers get the loosest colour bound.
  double of(LayerSemantic s) const {
    switch (s) {
      case LayerSemantic::kAlbedo:
        return albedo;
      case LayerSemantic::kNormal:
        return normal;
      case LayerSemantic::kOrm:
        return orm;
      case LayerSemantic::kEmissive:
        return emissive;
      default:
        return std::min({albedo, orm, emissive});
    }
  }
};

// Worst page on the sample scene (vtbake sample-scene; bake --codec dct | bc | raw), dB:
//              albedo  normal  orm   emissive   normal mean / max deg
//   dct (q75)  30.1    35.8    32.7  24.8       2.31 / 36.3
//   bc         35.2    40.1    33.1  33.8       1.27 / 28.2
//   raw        35.2    38.3    33.1  33.6       1.42 / 31.5
// The bounds sit about 3 dB below. The BC transcode sets the error of bc and raw bakes alike.
inline constexpr PagePsnrBounds kDctPagePsnr{27, 32, 29, 21}, kBcPagePsnr{32, 35, 30, 30};

// The DCT floor's margin over kDctPagePsnr.
inline constexpr double kDctFloorMarginDb = 1.0;

}  // namespace vt
