// Colour management through OpenColorIO. A ColorConfig is either vtbake's built-in config
// (generated in code, since Debian's OCIO 2.1 ships none) or an OCIO config file
// (--colorconfig FILE, else $OCIO). The working space is the config's scene_linear role.
// Built-in spaces: "linear" (linear Rec.709 primaries, the reference and working space),
// "sRGB" (IEC 61966-2-1), "Rec709" (BT.709 OETF), "Gamma1.8", "Gamma2.2", "Gamma2.4" (pure
// powers, as OpenImageIO names a PNG's gAMA), "ACEScg" (AP1), "ACES2065-1" (AP0) and "raw"
// (data, never converted), each with the aliases other tools write.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/status.h"

namespace vt {

class ColorConverter;

class ColorConfig {
 public:
  // The built-in config; shared, built once.
  static std::shared_ptr<const ColorConfig> builtin();
  // An OpenColorIO config file (YAML .ocio). Errors name the file: unreadable, invalid, or
  // without a scene_linear role.
  static Expected<std::shared_ptr<const ColorConfig>> load(const std::string& path);

  ~ColorConfig();
  bool is_builtin() const { return path_.empty(); }
  const std::string& path() const { return path_; }  // "" for the built-in config
  // The config's scene_linear colour space (the built-in config: "linear").
  const std::string& working_space() const { return working_; }
  // The config's colour spaces, in its order.
  std::vector<std::string> color_spaces() const;

  // The config's name for a colour space named by its name, an alias or a role (any case).
  // With a user config, a name the config lacks is also tried under the aliases vtbake knows
  // for it ("sRGB" finds "sRGB - Texture", "ACEScg" finds "ACES - ACEScg" ...), and "linear"
  // means scene_linear (OpenImageIO's convention). kNotFound lists the config's spaces.
  Expected<std::string> resolve(const std::string& name) const;
  // True for a data space (no colour conversion to or from it); false for unknown names.
  bool is_data(const std::string& name) const;

  // What the config's file rules say `path` is; "" when only the default rule matches, or for
  // the built-in config (whose only rule is the default one).
  std::string space_from_file_rules(const std::string& path) const;
  // The colour space of a colour texture (base colour, emissive): the file rules for `path`
  // ("" skips them), else the file's metadata (OpenImageIO's oiio:ColorSpace), else sRGB for
  // 8/16-bit data and the working space for float data. Data slots (normal, ORM) are never
  // converted and do not ask.
  std::string texture_space(const std::string& path, const std::string& metadata,
                            bool is_float) const;

  // A converter between two colour spaces of this config (names as resolve takes them).
  // "GammaX.Y" names the config does not have are a pure power over linear Rec.709.
  Expected<std::unique_ptr<ColorConverter>> converter(const std::string& from,
                                                      const std::string& to) const;

  // The config as OCIO YAML (the built-in one, for provenance and for users who want to
  // reproduce it), and an identity that changes with its content.
  std::string yaml() const;
  std::string cache_id() const;

  struct Impl;

 private:
  ColorConfig(std::string path, std::unique_ptr<Impl> impl);
  std::string path_, working_;
  std::unique_ptr<Impl> impl_;
};

// Converts RGB(A) float texels between two colour spaces; alpha is left alone. Thread-safe
// after creation. Channels 1 and 2 convert the first channel as grey.
class ColorConverter {
 public:
  // Between two spaces of the built-in config.
  static Expected<std::unique_ptr<ColorConverter>> create(const std::string& from,
                                                          const std::string& to);
  virtual ~ColorConverter() = default;
  virtual bool is_identity() const = 0;
  // Converts `count` texels of `channels` (1..4) interleaved floats in place. For per-channel
  // conversions (curves), values that are 8-bit codes (k / 255, however rounded) go through a
  // 256-entry table OpenColorIO filled.
  virtual void apply(float* texels, size_t count, int channels) const = 0;
  // apply() followed by rounding to 8 bits (clamped to [0, 1]), without a per-texel power:
  // for per-channel conversions the colour channels are compared against the 255 code
  // boundaries, found exactly (by bisection over floats) through OpenColorIO when the converter
  // was made. Alpha (channel 3, or 1 for grey+alpha) is rounded as it is.
  virtual void apply_to_u8(const float* texels, size_t count, int channels, uint8_t* out) const = 0;
  // Converts one filtered RGB sample in place (the scene transfer, sample by sample). The
  // built-in sRGB decode is common/srgb.h's srgb_to_linear (negatives as 0) from a table of
  // 4,097 points over [0, 1], linearly interpolated (within 3e-7 of the curve; the curve itself
  // above 1), cheaper than a power per channel; other conversions go through OpenColorIO
  // unclamped.
  virtual void apply_rgb(float rgb[3]) const = 0;
};

}  // namespace vt
