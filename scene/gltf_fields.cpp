// Typed, located reads of glTF JSON fields (see gltf_fields.h).
#include "scene/gltf_fields.h"

#include <cmath>
#include <cstring>

namespace vt::scene::detail {

using json = nlohmann::json;

namespace {

const json& empty_object() {
  static const json kEmpty = json::object();
  return kEmpty;
}

// "meshes" -> "mesh", "bufferViews" -> "bufferView".
std::string singular(const char* array) {
  std::string s = array;
  if (s == "meshes") return "mesh";
  if (!s.empty() && s.back() == 's') s.pop_back();
  return s;
}

// An integer-valued JSON number (1 and 1.0 alike), or false.
bool integer_value(const json& v, double* out) {
  if (!v.is_number()) return false;
  double d = v.get<double>();
  if (!std::isfinite(d) || d != std::floor(d)) return false;
  *out = d;
  return true;
}

std::string quoted_name(const json& object) {
  if (!object.is_object()) return "";
  auto it = object.find("name");
  if (it == object.end() || !it->is_string() || it->get_ref<const std::string&>().empty())
    return "";
  std::string name = it->get<std::string>();
  if (name.size() > 64) name = name.substr(0, 61) + "...";
  return " '" + name + "'";
}

// `v` as an index into the top-level array `array`, or -1 with the problem reported.
int checked_index(FieldErrors* errors, const json& v, const std::string& where, const char* array) {
  size_t n = top_level_size(errors->gltf(), array);
  std::string what = singular(array);
  double d;
  if (!integer_value(v, &d) || d < 0) {
    errors->fail(ErrorCode::kCorrupt, where,
                 std::string("expected ") + (std::strchr("aeiou", what[0]) ? "an " : "a ") + what +
                     " index");
    return -1;
  }
  if (d >= static_cast<double>(n)) {
    errors->fail(ErrorCode::kCorrupt, where,
                 what + " " + v.dump() + " does not exist (the file has " + std::to_string(n) +
                     " " + (n == 1 ? what : std::string(array)) + ")");
    return -1;
  }
  return static_cast<int>(d);
}

}  // namespace

void FieldErrors::fail(ErrorCode code, const std::string& where, const std::string& what) {
  if (first_.ok()) first_ = Error(code, gltf_.path + ": " + where + ": " + what);
}

size_t top_level_size(const Gltf& g, const char* array) {
  auto it = g.doc.find(array);
  return it != g.doc.end() && it->is_array() ? it->size() : 0;
}

std::string entry_name(const Gltf& g, const char* array, size_t index) {
  std::string name = singular(array) + " " + std::to_string(index);
  if (index < top_level_size(g, array)) name += quoted_name(g.doc[array][index]);
  return name;
}

JsonFields::JsonFields(FieldErrors* errors, const json& value, std::string where)
    : errors_(errors), value_(&value), where_(std::move(where)) {
  if (!value_->is_object()) {
    errors_->fail(ErrorCode::kCorrupt, where_.empty() ? "document" : where_, "expected an object");
    value_ = &empty_object();
  }
}

std::string JsonFields::where(const std::string& key) const {
  return where_.empty() ? key : where_ + "." + key;
}

void JsonFields::fail(const std::string& key, const std::string& what) const {
  errors_->fail(ErrorCode::kCorrupt, where(key), what);
}

std::vector<std::string> JsonFields::keys() const {
  std::vector<std::string> keys;
  for (auto it = value_->begin(); it != value_->end(); ++it) keys.push_back(it.key());
  return keys;
}

JsonFields JsonFields::object(const char* key) const {
  auto it = value_->find(key);
  if (it == value_->end()) return JsonFields(errors_, empty_object(), where(key));
  return JsonFields(errors_, *it, where(key));
}

std::vector<JsonFields> JsonFields::objects(const char* key) const {
  std::vector<JsonFields> result;
  auto it = value_->find(key);
  if (it == value_->end()) return result;
  if (!it->is_array()) {
    fail(key, "expected an array");
    return result;
  }
  for (size_t i = 0; i < it->size(); ++i) {
    result.emplace_back(errors_, (*it)[i],
                        where(key) + "[" + std::to_string(i) + "]" + quoted_name((*it)[i]));
    result.back().string("name");  // every glTF object's name is a string
  }
  return result;
}

double JsonFields::number(const char* key, double fallback) const {
  auto it = value_->find(key);
  if (it == value_->end()) return fallback;
  if (!it->is_number() || !std::isfinite(it->get<double>())) {
    fail(key, "expected a number");
    return fallback;
  }
  return it->get<double>();
}

size_t JsonFields::count(const char* key, size_t fallback) const {
  auto it = value_->find(key);
  if (it == value_->end()) return fallback;
  double d;
  // 2^53: beyond it a double no longer holds every integer, and no real count is that large.
  if (!integer_value(*it, &d) || d < 0 || d > 9007199254740992.0) {
    fail(key, "expected a non-negative integer");
    return fallback;
  }
  return static_cast<size_t>(d);
}

int JsonFields::index(const char* key, const char* array) const {
  auto it = value_->find(key);
  if (it == value_->end()) return -1;
  return checked_index(errors_, *it, where(key), array);
}

std::vector<int> JsonFields::indices(const char* key, const char* array) const {
  std::vector<int> result;
  auto it = value_->find(key);
  if (it == value_->end()) return result;
  if (!it->is_array()) {
    fail(key, "expected an array of " + singular(array) + " indices");
    return result;
  }
  for (size_t i = 0; i < it->size(); ++i) {
    int v = checked_index(errors_, (*it)[i], where(key) + "[" + std::to_string(i) + "]", array);
    if (v < 0) return {};
    result.push_back(v);
  }
  return result;
}

std::string JsonFields::string(const char* key, const std::string& fallback) const {
  auto it = value_->find(key);
  if (it == value_->end()) return fallback;
  if (!it->is_string()) {
    fail(key, "expected a string");
    return fallback;
  }
  return it->get<std::string>();
}

std::vector<std::string> JsonFields::strings(const char* key) const {
  std::vector<std::string> result;
  auto it = value_->find(key);
  if (it == value_->end()) return result;
  bool ok = it->is_array();
  for (size_t i = 0; ok && i < it->size(); ++i) {
    ok = (*it)[i].is_string();
    if (ok) result.push_back((*it)[i].get<std::string>());
  }
  if (!ok) {
    fail(key, "expected an array of strings");
    return {};
  }
  return result;
}

bool JsonFields::boolean(const char* key, bool fallback) const {
  auto it = value_->find(key);
  if (it == value_->end()) return fallback;
  if (!it->is_boolean()) {
    fail(key, "expected true or false");
    return fallback;
  }
  return it->get<bool>();
}

std::vector<double> JsonFields::numbers(const char* key, size_t n) const {
  auto it = value_->find(key);
  if (it == value_->end()) return {};
  bool ok = it->is_array() && it->size() == n;
  std::vector<double> result;
  for (size_t i = 0; ok && i < n; ++i) {
    ok = (*it)[i].is_number() && std::isfinite((*it)[i].get<double>());
    if (ok) result.push_back((*it)[i].get<double>());
  }
  if (!ok) {
    fail(key, "expected an array of " + std::to_string(n) + " numbers");
    return {};
  }
  return result;
}

}  // namespace vt::scene::detail
