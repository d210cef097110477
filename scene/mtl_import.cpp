// MTL libraries as exporters write them, onto the metal-roughness material model.
// The rules where exporters disagree (each also in a comment where it is applied):
// - Opacity: `d` is opacity, `Tr` transparency (1 - d); with both, `d` wins and a difference
//   is warned about. MeshLab (vcglib) writes its alpha as `Tr`, so in MTLs it wrote ("Converted
//   by Meshlab Group") `Tr` is opacity; elsewhere a lone `Tr` that would make the material fully
//   transparent is read the same way, with a warning: nobody bakes an invisible surface.
// - `norm` is a tangent-space normal map; `bump`/`map_Bump` is one too unless it is a height
//   map: `-imfchan l|z`, an image with 1-2 channels, or an RGB image whose first rows are grey.
//   Height maps are not converted to normals: warned and left out.
// - Kd, Ke are linear factors multiplying their maps (the MTL spec's rule); Ke above 1 becomes
//   emissive_strength. map_Ke without Ke means Ke 1. Pr/Pm/map_Pr/map_Pm are the PBR extension.
// - Features that change the look but have no place here (map_Ks, -mm, -t, clearcoat, ...)
//   are listed in one warning per material.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <memory>

#include "scene/image_load.h"
#include "scene/obj_mtl.h"
#include "scene/scene_io_util.h"

namespace vt::scene::detail {
namespace {

// One map statement: the options before the file name, then the file.
struct MapStatement {
  std::string file;  // as written (quotes removed)
  float bump_multiplier = 1.0f;
  TextureTransform transform;
  bool clamp = false;
  char imfchan = 0;                  // 0 when not given
  std::vector<std::string> ignored;  // options that would change the result
};

bool parse_float(const std::string& s, float* out) {
  char* e = nullptr;
  float v = std::strtof(s.c_str(), &e);
  if (s.empty() || !e || *e != 0) return false;
  *out = v;
  return true;
}

// Reads up to `max` numbers from tokens[*i..]; returns how many.
int take_numbers(const std::vector<Token>& t, size_t* i, int max, float* out) {
  int n = 0;
  while (n < max && *i < t.size() && parse_float(t[*i].text, &out[n])) {
    ++*i;
    ++n;
  }
  return n;
}

MapStatement parse_map(const std::string& rest) {
  MapStatement m;
  std::vector<Token> t = split_tokens(rest);
  size_t i = 0;
  auto word_arg = [&]() { return i < t.size() ? t[i++].text : std::string(); };
  while (i + 1 < t.size() && t[i].text.size() > 1 && t[i].text[0] == '-' &&
         rest[t[i].begin] != '"') {
    std::string opt = t[i++].text;
    float v[3] = {0, 0, 0};
    if (opt == "-o" || opt == "-s") {
      float def = opt == "-s" ? 1.0f : 0.0f;
      v[0] = v[1] = def;
      if (take_numbers(t, &i, 3, v) == 1) v[1] = def;
      // MTL's uv is v-up; the scene's is glTF's v-down (v' = 1 - v), so the v offset becomes
      // 1 - s_v - o_v once both are known (below).
      (opt == "-o" ? m.transform.offset : m.transform.scale) = {v[0], v[1]};
    } else if (opt == "-bm") {
      take_numbers(t, &i, 1, &m.bump_multiplier);
    } else if (opt == "-clamp") {
      m.clamp = word_arg() == "on";
    } else if (opt == "-imfchan") {
      std::string c = word_arg();
      m.imfchan = c.empty() ? 0 : static_cast<char>(std::tolower(static_cast<unsigned char>(c[0])));
    } else if (opt == "-mm") {
      v[1] = 1.0f;
      take_numbers(t, &i, 2, v);
      if (v[0] != 0.0f || v[1] != 1.0f) m.ignored.push_back("-mm");
    } else if (opt == "-t") {
      if (take_numbers(t, &i, 3, v) > 0 && (v[0] != 0 || v[1] != 0 || v[2] != 0))
        m.ignored.push_back("-t");
    } else if (opt == "-cc") {
      if (word_arg() == "on") m.ignored.push_back("-cc");
    } else if (opt == "-blendu" || opt == "-blendv" || opt == "-type") {
      word_arg();  // no meaning for a bake
    } else if (opt == "-boost" || opt == "-texres") {
      take_numbers(t, &i, 1, v);  // mip sharpness and resolution hints: no meaning for a bake
    } else {
      m.ignored.push_back("unknown option " + opt);
      while (i + 1 < t.size() && parse_float(t[i].text, v)) ++i;
    }
  }
  // The file is the rest of the statement, so a name with spaces stays whole.
  if (i < t.size()) {
    if (rest[t[i].begin] == '"') {
      m.file = t[i].text;
    } else {
      m.file = rest.substr(t[i].begin);
      while (!m.file.empty() && std::isspace(static_cast<unsigned char>(m.file.back())))
        m.file.pop_back();
    }
  }
  m.transform.offset[1] = 1.0f - m.transform.scale[1] - m.transform.offset[1];
  return m;
}

// A bump map that holds heights rather than normals (see the rules at the top).
bool is_height_map(const std::string& path, char imfchan) {
  if (imfchan == 'l' || imfchan == 'z') return true;
  std::string error;
  auto in = open_image_input(path, error);
  if (!in) return false;  // unreadable here: the transfer reports it, as a normal map
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.nchannels < 3) return true;
  int rows = std::min(spec.height, 16);
  std::vector<uint8_t> px(size_t(spec.width) * rows * 3);
  if (spec.width <= 0 || rows <= 0 ||
      !in->read_scanlines(0, 0, spec.y, spec.y + rows, 0, 0, 3, OIIO::TypeDesc::UINT8, px.data()))
    return false;
  for (size_t i = 0; i < px.size(); i += 3)
    if (std::abs(px[i] - px[i + 1]) > 2 || std::abs(px[i + 1] - px[i + 2]) > 2) return false;
  return true;
}

// A material while its statements are read; finish() applies the rules that need them all.
struct Draft {
  Material m;
  bool has_d = false, has_tr = false, has_ke = false, has_pm = false, has_map_d = false;
  float d = 1.0f, tr = 0.0f;
  TextureRef map_d, map_pr, map_pm;
  char map_d_chan = 0, map_pr_chan = 0, map_pm_chan = 0;  // their -imfchan
  std::vector<std::string> ignored;
  void ignore(const std::string& what) {
    if (std::find(ignored.begin(), ignored.end(), what) == ignored.end()) ignored.push_back(what);
  }
};

class MtlReader {
 public:
  MtlReader(const std::string& path, Scene* scene, std::map<std::string, int>* by_name)
      : path_(path), folder_(parent_folder(path)), scene_(scene), by_name_(by_name) {}

  void statement(const std::string& key, LineCursor* c);
  void finish();

 private:
  void warn(const std::string& what) {
    scene_->warnings.push_back(path_ + ": material '" + draft_->m.name + "': " + what);
  }
  void number_key(const std::string& key, LineCursor* c);
  // `key` is lower case (for matching), `written` as the file spells it (for messages).
  void map_key(const std::string& key, const std::string& written, const std::string& rest);
  std::string resolve(const std::string& key, const std::string& file);
  TextureRef texture(const std::string& key, const MapStatement& map, const std::string& path);
  void finish_opacity();
  void finish_metal_roughness();
  // `base` with its image replaced by a packed one; an invalid ref (and a warning) on failure.
  TextureRef packed(const TextureRef& base, const std::vector<ChannelSource>& channels,
                    const std::string& what);
  ChannelSource channel_of(const TextureRef& ref, char imfchan, int fallback) const;

  std::string path_, folder_;
  Scene* scene_;
  std::map<std::string, int>* by_name_;
  std::unique_ptr<Draft> draft_;
  bool written_by_meshlab_ = false;  // its header comment says so
};

std::string MtlReader::resolve(const std::string& key, const std::string& file) {
  std::string note;
  std::string path = resolve_written_path(folder_, file, &note);
  if (!note.empty()) warn(key + " " + note);
  return path;
}

// The image at `path` (one Image per file) sampled with the statement's options.
TextureRef MtlReader::texture(const std::string& key, const MapStatement& map,
                              const std::string& path) {
  TextureRef ref;
  auto& images = scene_->images;
  auto it = std::find_if(images.begin(), images.end(),
                         [&](const Image& im) { return !im.embedded() && im.path == path; });
  if (it == images.end()) {
    Image img;
    img.uri = map.file;
    img.name = map.file;
    img.path = path;
    images.push_back(std::move(img));
    it = images.end() - 1;
  }
  ref.image = static_cast<int>(it - images.begin());
  ref.transform = map.transform;
  if (map.clamp) ref.wrap_s = ref.wrap_t = WrapMode::kClampToEdge;
  for (const auto& what : map.ignored) draft_->ignore(what + " on " + key);
  return ref;
}

void MtlReader::number_key(const std::string& key, LineCursor* c) {
  Material& m = draft_->m;
  if (key == "kd") {
    for (int k = 0; k < 3; ++k) c->number(&m.base_color_factor[k]);
  } else if (key == "d") {
    LineCursor before = *c;
    if (c->word() == "-halo")
      draft_->ignore("d -halo");  // view-dependent opacity: the factor alone is kept
    else
      *c = before;
    draft_->has_d = c->number(&draft_->d) || draft_->has_d;
  } else if (key == "tr") {
    draft_->has_tr = c->number(&draft_->tr) || draft_->has_tr;
  } else if (key == "ke") {
    draft_->has_ke = true;
    for (int k = 0; k < 3; ++k) c->number(&m.emissive_factor[k]);
  } else if (key == "pr") {
    c->number(&m.roughness_factor);
  } else if (key == "pm") {
    draft_->has_pm = true;
    c->number(&m.metallic_factor);
  } else if (key == "pc" || key == "pcr" || key == "ps" || key == "aniso" || key == "anisor") {
    float v = 0;
    if (c->number(&v) && v != 0.0f)
      draft_->ignore(key == "pc" || key == "pcr" ? "clearcoat"
                     : key == "ps"               ? "sheen"
                                                 : "anisotropy");
  }
}

void MtlReader::map_key(const std::string& key, const std::string& written,
                        const std::string& rest) {
  MapStatement map = parse_map(rest);
  if (map.file.empty()) return;
  Material& m = draft_->m;
  bool baked = key == "map_kd" || key == "map_ke" || key == "norm" || key == "map_bump" ||
               key == "bump" || key == "map_d" || key == "map_pr" || key == "map_pm";
  if (!baked) {
    draft_->ignore(written);  // map_Ks, map_Ka, map_Ns, disp, decal, refl, ...
    return;
  }
  std::string path = resolve(written, map.file);
  if (key == "map_kd") {
    m.base_color_texture = texture(written, map, path);
  } else if (key == "map_ke") {
    m.emissive_texture = texture(written, map, path);
  } else if (key == "norm" || key == "map_bump" || key == "bump") {
    if (key != "norm" && is_height_map(path, map.imfchan)) {
      warn(written + " '" + map.file + "' is a height map: not baked (only normal maps are)");
      return;
    }
    m.normal_texture = texture(written, map, path);
    m.normal_scale = map.bump_multiplier;
  } else if (key == "map_d") {
    draft_->has_map_d = true;
    draft_->map_d = texture(written, map, path);
    draft_->map_d_chan = map.imfchan;
  } else if (key == "map_pr") {
    draft_->map_pr = texture(written, map, path);
    draft_->map_pr_chan = map.imfchan;
  } else {
    draft_->map_pm = texture(written, map, path);
    draft_->map_pm_chan = map.imfchan;
  }
}

void MtlReader::statement(const std::string& key_as_written, LineCursor* c) {
  std::string key = key_as_written;
  for (char& ch : key) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (key.rfind("#", 0) == 0) {
    std::string comment = c->rest_of_line();
    for (char& ch : comment) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (!draft_ && comment.find("meshlab") != std::string::npos) written_by_meshlab_ = true;
  } else if (key == "newmtl") {
    finish();
    draft_ = std::make_unique<Draft>();
    draft_->m.name = c->rest_of_line();
    draft_->m.metallic_factor = 0.0f;  // OBJ materials are dielectric unless Pm says otherwise
  } else if (!draft_) {
    return;
  } else if (key.rfind("map_", 0) == 0 || key == "bump" || key == "norm" || key == "disp" ||
             key == "decal" || key == "refl") {
    map_key(key, key_as_written, c->rest_of_line());
  } else {
    number_key(key, c);
  }
}

// The opacity rule (see the top of the file): `d` is opacity and wins; `Tr` is transparency,
// except where MeshLab wrote it (its alpha) or where it would hide the material altogether.
void MtlReader::finish_opacity() {
  Draft& f = *draft_;
  float opacity = 1.0f;
  if (f.has_d) {
    opacity = f.d;
    float tr_opacity = written_by_meshlab_ ? f.tr : 1.0f - f.tr;
    if (f.has_tr && std::fabs(tr_opacity - f.d) > 1e-3f)
      warn("d " + std::to_string(f.d) + " and Tr " + std::to_string(f.tr) +
           " disagree; d (opacity) wins");
  } else if (f.has_tr) {
    opacity = written_by_meshlab_ ? f.tr : 1.0f - f.tr;
    if (opacity <= 0.0f && !written_by_meshlab_) {
      opacity = f.tr;
      warn("Tr " + std::to_string(f.tr) +
           " read as opacity (as MeshLab writes it), not transparency: the material would be "
           "invisible");
    }
  }
  if (opacity <= 0.0f) warn("d 0 makes the material fully transparent");
  f.m.base_color_factor[3] = opacity;
  if (opacity < 1.0f || f.has_map_d) f.m.alpha_mode = AlphaMode::kBlend;
  // glTF's opacity is the base colour texture's alpha: a map_d in another image is packed
  // into a copy of map_Kd (or into white) as its alpha.
  auto& kd = f.m.base_color_texture;
  if (!f.map_d.valid() || (kd.valid() && kd.image == f.map_d.image)) return;
  std::vector<ChannelSource> rgba(4);
  for (int c = 0; c < 3; ++c) rgba[c] = kd.valid() ? channel_of(kd, 0, c) : ChannelSource{};
  rgba[3] = channel_of(f.map_d, f.map_d_chan, -1);
  TextureRef base = packed(kd.valid() ? kd : f.map_d, rgba, "map_Kd + map_d");
  if (base.valid()) kd = base;
}

ChannelSource MtlReader::channel_of(const TextureRef& ref, char imfchan, int fallback) const {
  ChannelSource s;
  s.path = scene_->images[ref.image].path;
  s.channel = imfchan == 'r' ? 0 : imfchan == 'g' ? 1 : imfchan == 'b' ? 2 : imfchan ? 0 : fallback;
  return s;
}

TextureRef MtlReader::packed(const TextureRef& base, const std::vector<ChannelSource>& channels,
                             const std::string& what) {
  auto image = composite_image(channels, draft_->m.name + ": " + what);
  if (!image.ok()) {
    warn(what + " not packed into one texture, so the second map is not baked: " +
         image.status().message());
    return {};
  }
  scene_->images.push_back(std::move(image).value());
  TextureRef ref = base;
  ref.image = static_cast<int>(scene_->images.size()) - 1;
  return ref;
}

// glTF packs roughness in G and metallic in B of one texture: map_Pr and map_Pm are used as
// they are when they are one image, or when map_Pr is alone and the material is not metallic
// (its B is unused); otherwise they are packed into G and B of a new texture (1 where a map is
// absent, so that its factor alone applies).
void MtlReader::finish_metal_roughness() {
  Draft& f = *draft_;
  Material& m = f.m;
  if (f.map_pm.valid() && !f.has_pm) m.metallic_factor = 1.0f;
  const bool one_image = f.map_pr.valid() && f.map_pm.valid() && f.map_pr.image == f.map_pm.image;
  if (one_image || (f.map_pr.valid() && !f.map_pm.valid() && m.metallic_factor == 0.0f)) {
    m.metallic_roughness_texture = f.map_pr;
    return;
  }
  if (!f.map_pr.valid() && !f.map_pm.valid()) return;
  std::vector<ChannelSource> orm(3);
  if (f.map_pr.valid()) orm[1] = channel_of(f.map_pr, f.map_pr_chan, 0);
  if (f.map_pm.valid()) orm[2] = channel_of(f.map_pm, f.map_pm_chan, 0);
  m.metallic_roughness_texture =
      packed(f.map_pr.valid() ? f.map_pr : f.map_pm, orm, "map_Pr + map_Pm");
  if (!m.metallic_roughness_texture.valid() && f.map_pm.valid() && !f.has_pm)
    m.metallic_factor = 0.0f;
}

void MtlReader::finish() {
  if (!draft_) return;
  Material& m = draft_->m;
  finish_opacity();
  finish_metal_roughness();
  if (m.emissive_texture.valid() && !draft_->has_ke) m.emissive_factor = {1, 1, 1};
  // glTF's emissive factor stays within [0, 1]; brighter Ke is carried by the strength.
  float peak = std::max({m.emissive_factor[0], m.emissive_factor[1], m.emissive_factor[2]});
  if (peak > 1.0f) {
    for (float& e : m.emissive_factor) e /= peak;
    m.emissive_strength = peak;
  }
  if (!draft_->ignored.empty()) {
    std::string list;
    for (const auto& what : draft_->ignored) list += (list.empty() ? "" : ", ") + what;
    warn("ignored (not baked): " + list);
  }
  scene_->materials.push_back(std::move(m));
  (*by_name_)[scene_->materials.back().name] = static_cast<int>(scene_->materials.size() - 1);
  draft_.reset();
}

}  // namespace

Status load_mtl(const std::string& path, Scene* scene, std::map<std::string, int>* by_name) {
  VT_ASSIGN_OR_RETURN(auto bytes, read_file(path));
  std::string note;
  VT_ASSIGN_OR_RETURN(std::string text, decode_text(bytes, path, &note));
  if (!note.empty()) scene->warnings.push_back(path + ": " + note);
  MtlReader reader(path, scene, by_name);
  LineCursor c{text.data(), text.data() + text.size()};
  while (c.p < c.end) {
    std::string key = c.word();
    if (!key.empty()) reader.statement(key, &c);
    c.next_line();
  }
  reader.finish();
  return Status::Ok();
}

}  // namespace vt::scene::detail
