// Content keys: one XXH3 stream that scene data, materials and settings are fed to, for the
// update mode's keys (bake/update_scene.h: a whole bake; bake/transfer_cache.h: a band of the
// transfer). Paths and times are never fed, only what decides the output.
#pragma once

#define XXH_STATIC_LINKING_ONLY  // XXH3_state_t on the stack
#include <xxhash.h>

#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "scene/scene.h"

namespace vt {

// Strings and arrays go in with their length, so that no two different inputs give the same
// byte stream.
class KeyStream {
 public:
  KeyStream() { XXH3_64bits_reset(&state_); }
  template <typename T>
  void add(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    XXH3_64bits_update(&state_, &v, sizeof v);
  }
  void add(const std::string& s) {
    add(uint64_t(s.size()));
    XXH3_64bits_update(&state_, s.data(), s.size());
  }
  template <typename T>
  void add(const std::vector<T>& v) {
    add(uint64_t(v.size()));
    if constexpr (std::is_trivially_copyable_v<T>) {
      XXH3_64bits_update(&state_, v.data(), v.size() * sizeof(T));
    } else {
      for (const T& e : v) add(e);
    }
  }
  uint64_t digest() const { return XXH3_64bits_digest(&state_); }

 private:
  XXH3_state_t state_;
};

// What this build of the baker is, for the caches that must not outlive it (transfer bands, the
// unwrap): the XXH3 of the file that holds this code (the commands module, or a test program),
// read once. VTBAKE_VERSION stays the same across commits, and a cache written by other code
// of the same version could hold other texels. 0 where the file cannot be read (the version
// string alone then). Not part of the plan hash: output bytes stay comparable across builds.
uint64_t code_identity();

// Every field of a material (its textures by image index, sampler and transform).
void add_material(KeyStream& k, const scene::Material& m);
// Every vertex array, the indices and the material index of a primitive.
void add_primitive(KeyStream& k, const scene::Primitive& p);

}  // namespace vt
