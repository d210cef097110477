// Rows of one pyramid level kept for the next pass: in memory when the budget allows, otherwise
// in an unlinked scratch file (removed by the OS even if the process dies), raw or compressed in
// chunks of rows (ScratchFile in level_store.cpp). Layers with a coverage mask keep the level's
// mask (bake/coverage_mask.h) beside it.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bake/coverage_mask.h"
#include "bake/image_source.h"
#include "bake/level_source.h"
#include "common/status.h"

namespace vt {

class ScratchFile;

// What compressed scratch levels take is known only once written. The best ratio real working
// levels showed (VirtualCity: orm 5.4-6.0x, albedo 1.7x) rounded up: scratch estimated from raw
// floats before any is written needs at least bytes / this.
inline constexpr uint64_t kScratchBestCompression = 8;

// Refuses `needed` bytes of scratch files in `dir` ("" = the current folder) when its disk has
// less free, naming the folder and both sizes after `what_needs` ("the atlas's level 0 needs at
// least"); an unknown free space passes (the writes will tell).
Status check_scratch_room(uint64_t needed, const std::string& dir, const std::string& what_needs);
// Bytes as whole GiB, rounded: the unit of the scratch messages.
std::string gib_text(uint64_t bytes);

// Whether scratch levels of `raw_bytes` in all (floats) in `dir` are compressed: where they would
// not fit 90% of the disk's free space raw. Elsewhere compressing costs more time than the disk
// traffic it saves on this project's machines: VirtualCity's build at 16,440² (8.6 GB of raw
// scratch, in the page cache) took 1.4x longer, at 32,760² (34.6 GB, past it) 1.5x.
bool scratch_needs_compression(uint64_t raw_bytes, const std::string& dir);

class LevelStore final : public LevelSource {
 public:
  // width x height texels of `channels` floats; in a scratch file under `scratch_dir` unless
  // `in_memory`, `compressed` in chunks or as raw rows.
  static Expected<std::unique_ptr<LevelStore>> create(uint32_t width, uint32_t height,
                                                      uint32_t channels, bool in_memory,
                                                      const std::string& scratch_dir,
                                                      bool compressed = false);
  // A level file save() wrote: width x height texels of `channels` floats, raw or `compressed`
  // as save() said; read only. A file of another shape is refused (kCorrupt, naming it).
  static Expected<std::unique_ptr<LevelStore>> open_saved(const std::string& path, uint32_t width,
                                                          uint32_t height, uint32_t channels,
                                                          bool compressed);
  // An in-memory level over texels the caller hands over (width * height * channels floats).
  static std::unique_ptr<LevelStore> adopt(uint32_t width, uint32_t height, uint32_t channels,
                                           std::vector<float> texels);
  ~LevelStore() override;
  LevelStore(const LevelStore&) = delete;
  LevelStore& operator=(const LevelStore&) = delete;

  uint32_t width() const override { return width_; }
  uint32_t height() const override { return height_; }
  uint32_t channels() const override { return channels_; }
  bool in_memory() const override { return file_ == nullptr; }
  LevelStore* held_store() override { return this; }
  uint64_t bytes() const { return uint64_t(width_) * height_ * channels_ * sizeof(float); }
  // A scratch file compressed in chunks (scratch_needs_compression).
  bool compressed() const;
  // What a scratch-file store holds on disk now; 0 in memory.
  uint64_t disk_bytes() const;

  // Saves the texels as the new file `path` (the farm's work folder), compressed as the store is
  // (open_saved reads it so). A scratch file is linked there where it is unnamed and on the same
  // file system (`allow_link`), with no copy and its chunks as they are; otherwise copied. An
  // in-memory level is written as raw rows. The store is read only afterwards.
  Status save(const std::string& path, bool allow_link = true);

  Status write_rows(uint32_t y0, uint32_t rows, const float* data);
  Status read(uint32_t y0, uint32_t y1, float* out) override;
  // The texels of an in-memory store (nullptr for a scratch file).
  float* data() { return in_memory() ? memory_.data() : nullptr; }
  // Whether an in-memory store still holds all its texels (not handed over by release()).
  bool holds_texels() const { return in_memory() && memory_.size() * sizeof(float) == bytes(); }
  // Hands over an in-memory store's texels (empty for a scratch file); the store is empty after.
  std::vector<float> release() { return std::move(memory_); }
  // Keeps the first `keep` channels of every texel, in place (in memory, or chunk by chunk in
  // the scratch file, which shrinks): no second copy is made.
  Status keep_channels(uint32_t keep);

  const CoverageMask* coverage() const override { return coverage_.get(); }
  // Sets the level's mask and dilates its uncovered texels (pull-push, same bytes as pull_push
  // on the whole level). A scratch-file level or mask, or one whose pull levels do not fit
  // `memory_budget` bytes, is dilated in bands (level_dilation.h).
  Status set_coverage_and_dilate(std::shared_ptr<const CoverageMask> coverage,
                                 uint64_t memory_budget = ~0ull,
                                 const std::string& scratch_dir = "");
  // The same from one byte per texel (tests).
  Status set_coverage_and_dilate(const std::vector<uint8_t>& coverage,
                                 uint64_t memory_budget = ~0ull,
                                 const std::string& scratch_dir = "") {
    if (coverage.size() != size_t(width_) * height_)
      return Error(ErrorCode::kInternal, "coverage of a level of another size");
    return set_coverage_and_dilate(CoverageMask::from_bytes(width_, height_, coverage.data()),
                                   memory_budget, scratch_dir);
  }

 private:
  LevelStore() = default;
  uint32_t width_ = 0, height_ = 0, channels_ = 0;
  std::unique_ptr<ScratchFile> file_;
  std::vector<float> memory_;
  std::shared_ptr<const CoverageMask> coverage_;  // shared with the layer's input
};

// A store's rows as an image source (the scene bake's transferred layers): `info` gives the
// channels handed out, the first info.channels of the store's.
class StoredImageSource final : public ImageSource {
 public:
  StoredImageSource(ImageInfo info, std::shared_ptr<LevelStore> store)
      : info_(std::move(info)), store_(std::move(store)) {}
  const ImageInfo& info() const override { return info_; }
  Status read_rows(uint32_t y0, uint32_t y1, float* out) override;
  // An in-memory store with as many channels as the source hands its texels over.
  std::vector<float> release_texels() override;
  const float* texels_in_memory() const override {
    return !released_hash_ && store_->holds_texels() && store_->channels() == info_.channels
               ? store_->data()
               : nullptr;
  }
  // A scratch-file store whose texels are the source's as they are, for the build to convert in
  // its own file (no second copy on disk); null otherwise. The source is spent once the caller
  // says so with the hash of the rows it read (content_hash gives it from then on).
  std::shared_ptr<LevelStore> scratch_store() const {
    const bool own =
        !released_hash_ && !store_->in_memory() && store_->channels() == info_.channels;
    return own ? store_ : nullptr;
  }
  void spent(uint64_t content_hash) { released_hash_ = content_hash; }
  // The hash of the rows, computed once (the store is not written after the transfer; the farm's
  // plan asks before the build does) and kept once the texels are handed over.
  Expected<uint64_t> content_hash() override;

 private:
  ImageInfo info_;
  std::shared_ptr<LevelStore> store_;
  std::vector<float> rows_;
  std::optional<uint64_t> released_hash_, hash_;
};

}  // namespace vt
