// ColorConfig (see color.h): the built-in config or an OpenColorIO config file, names resolved
// through the config, file rules, and converters between its spaces.
#include "bake/color.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <sstream>

#include "bake/color_ocio.h"

namespace vt {
namespace {

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Names other tools write for the same space, tried in a user config that lacks the name it
// was asked for. The first name of each family is the built-in config's.
const std::vector<std::vector<const char*>>& space_families() {
  static const std::vector<std::vector<const char*>> kFamilies = {
      {"linear", "lin_rec709", "lin_srgb", "linear_srgb", "Linear Rec.709 (sRGB)",
       "Utility - Linear - sRGB", "lin_rec709_srgb", "srgb linear", "linear srgb", "rec709 linear"},
      {"sRGB", "sRGB - Texture", "srgb_tx", "srgb_texture", "Utility - sRGB - Texture",
       "srgb texture", "srgb gamma"},
      {"Rec709", "Rec.709", "rec709_camera", "Camera Rec.709"},
      {"Gamma1.8", "Gamma 1.8", "g18_rec709", "Gamma 1.8 Rec.709 - Texture"},
      {"Gamma2.2", "Gamma 2.2", "g22_rec709", "Gamma 2.2 Rec.709 - Texture",
       "Utility - Gamma 2.2 - Rec.709 - Texture"},
      {"Gamma2.4", "Gamma 2.4", "g24_rec709", "Gamma 2.4 Rec.709 - Texture"},
      {"ACEScg", "ACES - ACEScg", "lin_ap1"},
      {"ACES2065-1", "ACES - ACES2065-1", "lin_ap0", "aces", "aces_interchange"},
      {"raw", "Raw", "Utility - Raw", "Non-Color", "data", "none"},
  };
  return kFamilies;
}

// The exponent of "GammaX.Y" / "Gamma X.Y" (OpenImageIO's name for a PNG gAMA), or 0.
double gamma_of(const std::string& name) {
  std::string n = lower(name);
  if (n.rfind("gamma", 0) != 0) return 0;
  const char* p = n.c_str() + 5;
  while (*p == ' ' || *p == '_') ++p;
  char* end = nullptr;
  const double g = std::strtod(p, &end);
  return end != p && *end == '\0' && g > 0 && g < 10 ? g : 0;
}

struct Space {
  std::string name;  // the config's name (for a bare gamma: its linear Rec.709 space)
  double gamma = 0;  // > 0: a power `gamma` over `name`, a space the config does not have
};

}  // namespace

ColorConfig::ColorConfig(std::string path, std::unique_ptr<Impl> impl)
    : path_(std::move(path)), impl_(std::move(impl)) {
  auto cs = impl_->config->getColorSpace(OCIO::ROLE_SCENE_LINEAR);
  if (cs) working_ = cs->getName();
}

ColorConfig::~ColorConfig() = default;

std::shared_ptr<const ColorConfig> ColorConfig::builtin() {
  // Config objects are immutable after setup and safe to share between threads.
  static const std::shared_ptr<const ColorConfig> c(
      new ColorConfig("", std::make_unique<Impl>(Impl{make_builtin_color_config()})));
  return c;
}

Expected<std::shared_ptr<const ColorConfig>> ColorConfig::load(const std::string& path) {
  auto impl = std::make_unique<Impl>();
  try {
    impl->config = OCIO::Config::CreateFromFile(path.c_str());
    impl->config->validate();
  } catch (const OCIO::Exception& e) {
    return Status(ErrorCode::kInvalidArgument,
                  path + ": not a usable OpenColorIO config: " + std::string(e.what()));
  }
  std::shared_ptr<const ColorConfig> c(new ColorConfig(path, std::move(impl)));
  if (c->working_.empty()) {
    return Status(ErrorCode::kInvalidArgument,
                  path +
                      ": the OpenColorIO config has no scene_linear role (vtbake's working "
                      "space)");
  }
  return c;
}

std::vector<std::string> ColorConfig::color_spaces() const {
  std::vector<std::string> names;
  const auto& config = *impl_->config;
  for (int i = 0; i < config.getNumColorSpaces(); ++i)
    names.emplace_back(config.getColorSpaceNameByIndex(i));
  return names;
}

Expected<std::string> ColorConfig::resolve(const std::string& name) const {
  const auto& config = *impl_->config;
  if (auto cs = config.getColorSpace(name.c_str())) return std::string(cs->getName());
  if (!is_builtin()) {
    const std::string n = lower(name);
    if (n == "linear") return working_;
    for (const auto& family : space_families()) {
      if (std::none_of(family.begin(), family.end(), [&](const char* f) { return lower(f) == n; }))
        continue;
      for (const char* f : family)
        if (auto cs = config.getColorSpace(f)) return std::string(cs->getName());
    }
  }
  std::string known;
  for (const std::string& s : color_spaces()) known += (known.empty() ? "" : ", ") + s;
  return Status(ErrorCode::kNotFound,
                "unknown colour space '" + name + "' in " +
                    (is_builtin() ? std::string("the built-in colour config") : path_) +
                    " (its colour spaces: " + known + "; aliases and roles are accepted too)");
}

bool ColorConfig::is_data(const std::string& name) const {
  auto resolved = resolve(name);
  if (!resolved.ok()) return false;
  auto cs = impl_->config->getColorSpace(resolved->c_str());
  return cs && cs->isData();
}

std::string ColorConfig::space_from_file_rules(const std::string& path) const {
  if (is_builtin() || path.empty()) return "";
  const auto& config = *impl_->config;
  try {
    if (config.filepathOnlyMatchesDefaultRule(path.c_str())) return "";
    return config.getColorSpaceFromFilepath(path.c_str());
  } catch (const OCIO::Exception&) {
    return "";  // a rule the config validated cannot fail on a path; be safe regardless
  }
}

std::string ColorConfig::texture_space(const std::string& path, const std::string& metadata,
                                       bool is_float) const {
  std::string ruled = space_from_file_rules(path);
  if (!ruled.empty()) return ruled;
  if (!metadata.empty()) return metadata;
  return is_float ? working_ : "sRGB";
}

Expected<std::unique_ptr<ColorConverter>> ColorConfig::converter(const std::string& from,
                                                                 const std::string& to) const {
  auto find = [&](const std::string& name) -> Expected<Space> {
    auto resolved = resolve(name);
    if (resolved.ok()) return Space{*resolved, 0};
    const double g = gamma_of(name);
    if (g == 0) return resolved.status();
    // A power the config has no space for: over its linear Rec.709 space.
    auto lin = is_builtin() ? Expected<std::string>(working_) : resolve("lin_rec709");
    if (!lin.ok()) return resolved.status();
    return Space{*lin, g};
  };
  VT_ASSIGN_OR_RETURN(Space src, find(from));
  VT_ASSIGN_OR_RETURN(Space dst, find(to));
  const auto& config = impl_->config;
  const bool data = config->getColorSpace(src.name.c_str())->isData() ||
                    config->getColorSpace(dst.name.c_str())->isData();
  if (data || (src.name == dst.name && src.gamma == dst.gamma)) {
    return make_color_converter(nullptr, false);
  }
  try {
    auto group = OCIO::GroupTransform::Create();
    auto power = [](double g, OCIO::TransformDirection dir) {
      auto t = OCIO::ExponentTransform::Create();
      t->setValue({g, g, g, 1.0});
      t->setDirection(dir);
      return t;
    };
    if (src.gamma > 0) group->appendTransform(power(src.gamma, OCIO::TRANSFORM_DIR_FORWARD));
    auto cst = OCIO::ColorSpaceTransform::Create();
    cst->setSrc(src.name.c_str());
    cst->setDst(dst.name.c_str());
    group->appendTransform(cst);
    if (dst.gamma > 0) group->appendTransform(power(dst.gamma, OCIO::TRANSFORM_DIR_INVERSE));
    auto processor = src.gamma > 0 || dst.gamma > 0
                         ? config->getProcessor(group)
                         : config->getProcessor(src.name.c_str(), dst.name.c_str());
    const bool srgb_decode = is_builtin() && src.name == "sRGB" && dst.name == "linear";
    return make_color_converter(processor, srgb_decode);
  } catch (const OCIO::Exception& e) {
    return Status(ErrorCode::kInvalidArgument,
                  (is_builtin() ? std::string("built-in colour config") : path_) + ": " + from +
                      " to " + to + ": " + e.what());
  }
}

std::string ColorConfig::yaml() const {
  std::ostringstream s;
  impl_->config->serialize(s);
  return s.str();
}

std::string ColorConfig::cache_id() const {
  return impl_->config->getCacheID();
}

Expected<std::unique_ptr<ColorConverter>> ColorConverter::create(const std::string& from,
                                                                 const std::string& to) {
  return ColorConfig::builtin()->converter(from, to);
}

}  // namespace vt
