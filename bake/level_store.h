// Rows of one pyramid level kept for the next pass: in memory when the budget allows, otherwise
// in an unlinked scratch file (removed by the OS even if the process dies).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/status.h"

namespace vt {

class LevelStore {
 public:
  // width x height texels of `channels` floats; in a scratch file under `scratch_dir` unless
  // `in_memory`.
  static Expected<std::unique_ptr<LevelStore>> create(uint32_t width, uint32_t height,
                                                      uint32_t channels, bool in_memory,
                                                      const std::string& scratch_dir);
  ~LevelStore();
  LevelStore(const LevelStore&) = delete;
  LevelStore& operator=(const LevelStore&) = delete;

  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  uint32_t channels() const { return channels_; }
  bool in_memory() const { return fd_ < 0; }
  uint64_t bytes() const { return uint64_t(width_) * height_ * channels_ * sizeof(float); }
  size_t row_floats() const { return size_t(width_) * channels_; }

  Status write_rows(uint32_t y0, uint32_t rows, const float* data);
  Status read_rows(uint32_t y0, uint32_t rows, float* out) const;
  // The texels of an in-memory store (nullptr for a scratch file).
  float* data() { return in_memory() ? memory_.data() : nullptr; }

 private:
  LevelStore() = default;
  uint32_t width_ = 0, height_ = 0, channels_ = 0;
  int fd_ = -1;
  std::string path_;
  std::vector<float> memory_;
};

}  // namespace vt
