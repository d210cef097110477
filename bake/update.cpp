#include "bake/update.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>

#include "common/utf8.h"

namespace vt {
namespace {

std::string hex64(uint64_t v) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(v));
  return text;
}

bool parse_hex64(const char* text, uint64_t* out) {
  uint64_t v = 0;
  for (int i = 0; i < 16; ++i) {
    const char c = text[i];
    int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
    if (d < 0) return false;
    v = v << 4 | uint64_t(d);
  }
  *out = v;
  return true;
}

bool parse_hex_field(const nlohmann::json& j, const char* name, uint64_t* out) {
  const auto it = j.find(name);
  return it != j.end() && it->is_string() && it->get_ref<const std::string&>().size() == 16 &&
         parse_hex64(it->get_ref<const std::string&>().c_str(), out);
}

// The record of a file's metadata, if it has a well-formed one for geometry `g`.
bool parse_record(const std::string& metadata, const PageGeometry& g, UpdateRecord* r) {
  const nlohmann::json meta = nlohmann::json::parse(metadata, nullptr, false);
  if (meta.is_discarded() || !meta.is_object()) return false;
  const auto u = meta.find("update");
  if (u == meta.end() || !u->is_object()) return false;
  const auto tool = u->find("tool");
  const auto layers = u->find("layers");
  if (tool == u->end() || !tool->is_string() || layers == u->end() || !layers->is_array())
    return false;
  r->tool = tool->get<std::string>();
  if (!parse_hex_field(*u, "plan", &r->plan_hash) ||
      !parse_hex_field(*u, "settings", &r->settings_key) ||
      !parse_hex_field(*u, "input", &r->input_key))
    return false;
  const uint64_t pages = g.total_pages();
  for (const nlohmann::json& layer : *layers) {
    if (!layer.is_object() || !layer.contains("name") || !layer["name"].is_string() ||
        !layer.contains("keys") || !layer["keys"].is_string())
      return false;
    const std::string& keys = layer["keys"].get_ref<const std::string&>();
    if (keys.size() != pages * 16) return false;
    std::vector<uint64_t> parsed(pages);
    for (uint64_t i = 0; i < pages; ++i)
      if (!parse_hex64(keys.data() + i * 16, &parsed[i])) return false;
    uint64_t input = 0;
    if (layer.contains("input") && !parse_hex_field(layer, "input", &input)) return false;
    r->layer_names.push_back(layer["name"].get<std::string>());
    r->page_keys.push_back(std::move(parsed));
    r->layer_inputs.push_back(input);
  }
  return true;
}

bool same_grid(const PageGeometry& a, const PageGeometry& b) {
  return a.width == b.width && a.height == b.height && a.payload == b.payload &&
         a.border == b.border;
}

}  // namespace

uint64_t page_key_index(const PageGeometry& g, const PageId& id) {
  uint64_t first = 0;
  for (uint32_t l = 0; l < id.level; ++l) first += g.pages_in_level(l);
  return first + uint64_t(id.y) * g.pages_x(id.level) + id.x;
}

std::string update_text(const UpdateSummary& u) {
  std::string text = "update: " + std::to_string(u.reused) + " pages reused, " +
                     std::to_string(u.reencoded) + " re-encoded, " + std::to_string(u.dropped) +
                     " dropped";
  if (u.unchanged) text += "; unchanged, output untouched";
  if (!u.full_rebuild.empty()) text += "; full rebuild: " + u.full_rebuild;
  if (u.tables_fit > 0) {
    char fit[64];
    std::snprintf(fit, sizeof fit, "; pinned tables fit %.3f", u.tables_fit);
    text += fit;
  }
  return text;
}

std::string merge_metadata(const std::string& metadata_json, const std::string& extra) {
  nlohmann::json meta = nlohmann::json::parse(metadata_json, nullptr, false);
  if (meta.is_discarded() || !meta.is_object()) meta = nlohmann::json::object();
  const nlohmann::json more = nlohmann::json::parse(extra, nullptr, false);
  if (more.is_object()) meta.update(more);
  return meta.dump();
}

std::string with_update_record(const std::string& metadata_json, const UpdateRecord& r) {
  nlohmann::json meta = nlohmann::json::parse(metadata_json, nullptr, false);
  if (meta.is_discarded() || !meta.is_object()) meta = nlohmann::json::object();
  nlohmann::json layers = nlohmann::json::array();
  for (size_t i = 0; i < r.page_keys.size(); ++i) {
    std::string keys;
    keys.reserve(r.page_keys[i].size() * 16);
    for (uint64_t k : r.page_keys[i]) keys += hex64(k);
    layers.push_back({{"name", r.layer_names[i]}, {"keys", std::move(keys)}});
    if (i < r.layer_inputs.size()) layers.back()["input"] = hex64(r.layer_inputs[i]);
  }
  meta["update"] = {{"tool", r.tool},
                    {"plan", hex64(r.plan_hash)},
                    {"settings", hex64(r.settings_key)},
                    {"input", hex64(r.input_key)},
                    {"layers", std::move(layers)}};
  return meta.dump();
}

Expected<std::unique_ptr<PreviousBuild>> PreviousBuild::open(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    return Status(ErrorCode::kNotFound, path + ": no previous file");
  }
  auto made = std::unique_ptr<PreviousBuild>(new PreviousBuild);
  VT_ASSIGN_OR_RETURN(made->reader_, PageFileReader::open(path));
  made->has_record_ =
      parse_record(made->reader_->metadata_json(), made->reader_->geometry(), &made->record_);
  if (!made->has_record_) made->record_ = UpdateRecord{};
  return made;
}

int PreviousBuild::layer_index(const std::string& name) const {
  for (size_t i = 0; i < record_.layer_names.size(); ++i)
    if (record_.layer_names[i] == name) return int(i);
  return -1;
}

uint64_t PreviousBuild::key(int layer, const PageId& id) const {
  const PageGeometry& g = reader_->geometry();
  if (layer < 0 || size_t(layer) >= record_.page_keys.size() || !g.contains(id)) return 0;
  return record_.page_keys[size_t(layer)][page_key_index(g, id)];
}

uint64_t PreviousBuild::layer_input(int layer) const {
  return layer >= 0 && size_t(layer) < record_.layer_inputs.size() ? record_.layer_inputs[layer]
                                                                   : 0;
}

std::vector<uint8_t> PreviousBuild::tables(const std::string& name) const {
  for (const LayerSpec& spec : reader_->layers())
    if (spec.name == name) return spec.codec_tables;
  return {};
}

const std::vector<uint8_t>* PinnedTables::find(const std::string& name) const {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name && !tables[i].empty()) return &tables[i];
  return nullptr;
}

Expected<PinnedTables> read_pinned_tables(const std::string& path) {
  auto reader = PageFileReader::open(path);
  if (!reader.ok()) return reader.status().with_context("--tables-from");
  PinnedTables pinned;
  for (const LayerSpec& spec : (*reader)->layers()) {
    if (spec.codec != PageCodec::kDct) continue;
    pinned.names.push_back(spec.name);
    pinned.tables.push_back(spec.codec_tables);
  }
  return pinned;
}

std::string path_for_metadata(const std::string& path, const std::string& output) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path file = fs::weakly_canonical(fs::absolute(path, ec), ec);
  const fs::path dir = fs::weakly_canonical(fs::absolute(output, ec), ec).parent_path();
  // JSON holds UTF-8: a file name in another encoding is recorded as its Latin-1 reading (the
  // record is for people; nothing opens it).
  if (ec) return as_utf8(fs::path(path).lexically_normal().generic_string());
  const fs::path rel = file.lexically_relative(dir);
  return as_utf8(rel.empty() ? file.generic_string() : rel.generic_string());
}

uint64_t count_dropped(const PreviousBuild& previous, int layer, const PageGeometry& g,
                       const std::vector<uint64_t>& new_keys) {
  if (layer < 0 || !same_grid(previous.reader().geometry(), g)) return 0;
  uint64_t dropped = 0;
  const auto& old_keys = previous.record().page_keys[size_t(layer)];
  for (size_t i = 0; i < old_keys.size() && i < new_keys.size(); ++i)
    dropped += old_keys[i] != 0 && new_keys[i] == 0;
  return dropped;
}

}  // namespace vt
