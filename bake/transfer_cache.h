// The transfer's band cache (update mode, issue 16): the finished texels, coverage and counts of
// every band of atlas rows, each under the key of what the band reads (bake/transfer.h
// TransferOptions::cache_in). A band is taken from the cache only when its key matches and its
// bytes check out (size and checksum); anything else is transferred again, so a stale, foreign
// or damaged cache costs time, never wrong texels. Layout: a header (magic, version, the file
// key of the settings and atlas size, band count), the bands' zstd frames, an index of (key,
// offset, sizes, checksum) per band and a trailer pointing at it; written under a temporary name
// and renamed when complete, without OutputSet's sync: it is hundreds of MB at a few thousand
// texels a side, and a cache torn by a crash fails its checksums and is ignored.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "common/status.h"

namespace vt {

// One band's index entry (key 0: not stored).
struct CachedBand {
  uint64_t key = 0, offset = 0, checksum = 0;
  uint32_t stored = 0, size = 0;  // bytes of its zstd frame, and unpacked
};

class TransferCacheReader {
 public:
  // The cache at `path` written for `file_key` with `bands` bands; null when there is none, or
  // it is damaged or was written for other settings (every band is then transferred).
  static std::unique_ptr<TransferCacheReader> open(const std::string& path, uint64_t file_key,
                                                   uint32_t bands);
  ~TransferCacheReader();
  // Whether band `band` is listed under `key` (read() may still find it damaged).
  bool has(uint32_t band, uint64_t key) const {
    return band < index_.size() && key != 0 && index_[band].key == key;
  }
  // Band `band`'s bytes into `out` (exactly out.size() of them) when it was stored under `key`
  // and they check out; false otherwise. Thread-safe.
  // `frame`, when given, receives the stored zstd frame (for TransferCacheWriter::add_frame).
  bool read(uint32_t band, uint64_t key, std::span<uint8_t> out,
            std::vector<uint8_t>* frame = nullptr) const;

 private:
  int fd_ = -1;
  std::vector<CachedBand> index_;
};

class TransferCacheWriter {
 public:
  static Expected<std::unique_ptr<TransferCacheWriter>> create(const std::string& path,
                                                               uint64_t file_key, uint32_t bands);
  ~TransferCacheWriter();  // removes the temporary file unless finished
  // Stores band `band` under `key`. Thread-safe; the first failure is kept for finish().
  void add(uint32_t band, uint64_t key, std::span<const uint8_t> bytes);
  // The same with `bytes` already compressed as `frame` (a band read from the previous cache).
  void add_frame(uint32_t band, uint64_t key, std::span<const uint8_t> bytes,
                 std::span<const uint8_t> frame);
  // Writes the index and renames the file into place (it replaces the previous cache).
  Status finish();

 private:
  std::string path_, temp_;
  int fd_ = -1;
  uint64_t end_ = 0;
  std::vector<CachedBand> index_;
  std::mutex mutex_;
  Status error_;
  bool finished_ = false;
};

}  // namespace vt
