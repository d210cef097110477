// Internal to bake/color*.cpp: the OpenColorIO objects behind color.h (OCIO is a private
// dependency of vt_bake, so no public header names it).
#pragma once

#include <OpenColorIO/OpenColorIO.h>

#include <memory>

#include "bake/color.h"

namespace vt {

namespace OCIO = OCIO_NAMESPACE;

struct ColorConfig::Impl {
  OCIO::ConstConfigRcPtr config;
};

// The built-in config (color_builtin.cpp).
OCIO::ConstConfigRcPtr make_builtin_color_config();

// A converter over an OCIO processor (color_converter.cpp); null = identity. `srgb_decode`: the
// processor is the built-in sRGB to linear curve, which apply_rgb computes as common/srgb.h.
std::unique_ptr<ColorConverter> make_color_converter(OCIO::ConstProcessorRcPtr processor,
                                                     bool srgb_decode);

}  // namespace vt
