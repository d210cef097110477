// Names of the page-file enums, as docs/FORMAT.md and `vtbake info --json` spell them.
#include "format/page_file.h"

namespace vt {

const char* to_string(LayerSemantic v) {
  switch (v) {
    case LayerSemantic::kAlbedo:
      return "albedo";
    case LayerSemantic::kNormal:
      return "normal";
    case LayerSemantic::kOrm:
      return "orm";
    case LayerSemantic::kEmissive:
      return "emissive";
    case LayerSemantic::kCustom:
      return "custom";
    case LayerSemantic::kLighting:
      return "lighting";
    case LayerSemantic::kLitAlbedo:
      return "lit_albedo";
  }
  return "unknown";
}

bool is_colour(LayerSemantic v) {
  return v == LayerSemantic::kAlbedo || v == LayerSemantic::kEmissive ||
         v == LayerSemantic::kLitAlbedo;
}

bool is_light(LayerSemantic v) {
  return v == LayerSemantic::kLighting || v == LayerSemantic::kLitAlbedo;
}

const char* to_string(TexelType v) {
  switch (v) {
    case TexelType::kU8:
      return "u8";
    case TexelType::kF16:
      return "f16";
    case TexelType::kF32:
      return "f32";
  }
  return "unknown";
}

const char* to_string(PageCodec v) {
  switch (v) {
    case PageCodec::kRaw:
      return "raw";
    case PageCodec::kRawZstd:
      return "raw+zstd";
    case PageCodec::kDct:
      return "dct";
    case PageCodec::kBcZstd:
      return "bc+zstd";
  }
  return "unknown";
}

const char* to_string(ColorSpace v) {
  switch (v) {
    case ColorSpace::kLinear:
      return "linear";
    case ColorSpace::kSrgb:
      return "srgb";
  }
  return "unknown";
}

const char* to_string(AddressMode v) {
  switch (v) {
    case AddressMode::kClamp:
      return "clamp";
    case AddressMode::kWrap:
      return "wrap";
  }
  return "unknown";
}

uint32_t texel_type_bytes(TexelType type) {
  switch (type) {
    case TexelType::kU8:
      return 1;
    case TexelType::kF16:
      return 2;
    case TexelType::kF32:
      return 4;
  }
  return 0;
}

}  // namespace vt
