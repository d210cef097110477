// Typed, located reads of a glTF document's JSON: each field is read with the type glTF 2.0
// gives it, and an index is checked against the array it points into. The first problem is
// kept as "FILE: materials[2] 'Brick'.emissiveFactor: expected an array of 3 numbers" and later
// reads return their fallbacks, so a reader reads a whole object and checks status() once.
// Internal to vt_scene.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "scene/gltf_document.h"

namespace vt::scene::detail {

// The first problem found while reading one document (shared by every JsonFields of it).
class FieldErrors {
 public:
  explicit FieldErrors(const Gltf& g) : gltf_(g) {}
  void fail(ErrorCode code, const std::string& where, const std::string& what);
  bool failed() const { return !first_.ok(); }
  const Status& status() const { return first_; }
  const Gltf& gltf() const { return gltf_; }

 private:
  const Gltf& gltf_;
  Status first_;
};

// One JSON object of the document and where it is ("nodes[3] 'Arm'"). A value that is not an
// object is reported once and reads as an empty object.
class JsonFields {
 public:
  JsonFields(FieldErrors* errors, const nlohmann::json& value, std::string where);

  const std::string& where() const { return where_; }
  std::string where(const std::string& key) const;  // where of one field
  const nlohmann::json& raw() const { return *value_; }
  bool has(const char* key) const { return value_->contains(key); }
  std::vector<std::string> keys() const;
  FieldErrors* errors() const { return errors_; }
  void fail(const std::string& key, const std::string& what) const;

  // Absent: an empty object.
  JsonFields object(const char* key) const;
  // An array of objects, each named "key[i] 'its name'"; absent: none.
  std::vector<JsonFields> objects(const char* key) const;
  double number(const char* key, double fallback) const;  // finite
  size_t count(const char* key, size_t fallback) const;   // a non-negative integer
  // An index into the document's top-level array `array` ("meshes"), checked in range;
  // absent: -1.
  int index(const char* key, const char* array) const;
  std::vector<int> indices(const char* key, const char* array) const;
  std::string string(const char* key, const std::string& fallback = {}) const;
  std::vector<std::string> strings(const char* key) const;
  bool boolean(const char* key, bool fallback) const;
  std::vector<double> numbers(const char* key, size_t n) const;  // empty when absent
  template <size_t N>
  std::array<float, N> floats(const char* key, std::array<float, N> fallback) const {
    std::vector<double> v = numbers(key, N);
    if (v.empty()) return fallback;
    for (size_t i = 0; i < N; ++i) fallback[i] = static_cast<float>(v[i]);
    return fallback;
  }

 private:
  FieldErrors* errors_;
  const nlohmann::json* value_;
  std::string where_;
};

// How many entries the document's top-level array `array` has (0 when absent).
size_t top_level_size(const Gltf& g, const char* array);
// "node 3 'Arm'": an entry of a top-level array, by its singular name and its "name" field.
std::string entry_name(const Gltf& g, const char* array, size_t index);

}  // namespace vt::scene::detail
