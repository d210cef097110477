#include "bake/level_store.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <xxhash.h>
#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>

#include "bake/level_dilation.h"
#include "bake/pyramid.h"

namespace vt {
namespace {

// pread and pwrite may move fewer bytes than asked, or be interrupted: repeat until all moved.
template <class Io, class Byte>
Status move_all(Io io, int fd, Byte* p, size_t left, off_t off, const std::string& path,
                const char* verb) {
  while (left > 0) {
    ssize_t n = io(fd, p, left, off);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      return Error(ErrorCode::kIo, path + ": scratch " + verb + " failed: " + std::strerror(errno));
    }
    p += n, left -= size_t(n), off += n;
  }
  return Status::Ok();
}

// A large level asks for transparent huge pages before it is first written: zeroing it then
// faults 2 MiB at a time rather than 4 KiB (a 1920x1920 RGBA level: 29 faults, not 14,400),
// which was a fifth of an update's time. Where the kernel does not give them, nothing changes.
void advise_huge_pages(void* data, size_t bytes) {
  constexpr uintptr_t kHuge = uintptr_t(2) << 20;
  if (bytes < 4 * kHuge) return;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHuge - 1);
  if (end > begin) (void)madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
}

off_t row_offset(uint32_t y, size_t row_floats) {
  return off_t(uint64_t(y) * row_floats * sizeof(float));
}

}  // namespace

Expected<std::unique_ptr<LevelStore>> LevelStore::create(uint32_t width, uint32_t height,
                                                         uint32_t channels, bool in_memory,
                                                         const std::string& scratch_dir) {
  std::unique_ptr<LevelStore> s(new LevelStore());
  s->width_ = width;
  s->height_ = height;
  s->channels_ = channels;
  if (in_memory) {
    const size_t n = size_t(width) * height * channels;
    s->memory_.reserve(n);
    advise_huge_pages(s->memory_.data(), n * sizeof(float));
    s->memory_.resize(n);
    return s;
  }
  std::string templ =
      (scratch_dir.empty() ? std::string(".") : scratch_dir) + "/.vtbake-level-XXXXXX";
  std::vector<char> name(templ.begin(), templ.end());
  name.push_back('\0');
  int fd = mkstemp(name.data());
  if (fd < 0) {
    return Status(ErrorCode::kIo, templ + ": cannot create scratch file: " + std::strerror(errno));
  }
  unlink(name.data());  // the file lives as long as the descriptor
  s->fd_ = fd;
  s->path_ = name.data();
  return s;
}

std::unique_ptr<LevelStore> LevelStore::adopt(uint32_t width, uint32_t height, uint32_t channels,
                                              std::vector<float> texels) {
  std::unique_ptr<LevelStore> s(new LevelStore());
  s->width_ = width;
  s->height_ = height;
  s->channels_ = channels;
  s->memory_ = std::move(texels);
  s->memory_.resize(size_t(width) * height * channels);
  return s;
}

Status LevelStore::set_coverage_and_dilate(std::shared_ptr<const CoverageMask> coverage,
                                           uint64_t memory_budget, const std::string& scratch_dir) {
  if (!coverage || coverage->width() != width_ || coverage->height() != height_)
    return Error(ErrorCode::kInternal, "coverage of a level of another size");
  coverage_ = std::move(coverage);
  if (in_memory() && coverage_->in_memory() &&
      pull_push_bytes(width_, height_, channels_) <= memory_budget) {
    VT_ASSIGN_OR_RETURN(const std::vector<uint8_t> bytes, coverage_->to_bytes());
    pull_push(memory_.data(), bytes.data(), width_, height_, channels_);
    return Status::Ok();
  }
  BandedDilationOptions o;
  o.memory_budget = memory_budget;
  o.scratch_dir = scratch_dir;
  return pull_push_banded(*this, *coverage_, o).status();
}

LevelStore::~LevelStore() {
  if (fd_ >= 0) close(fd_);
}

Status LevelStore::keep_channels(uint32_t keep) {
  if (keep >= channels_) return Status::Ok();
  const uint32_t from = channels_;
  if (in_memory()) {
    for (size_t i = 0; i < size_t(width_) * height_; ++i)
      for (uint32_t c = 0; c < keep; ++c) memory_[keep * i + c] = memory_[from * i + c];
    memory_.resize(size_t(width_) * height_ * keep);
    channels_ = keep;
    return Status::Ok();
  }
  // Bands of about 4 MiB; a band is read before any write reaches its bytes.
  const size_t old_row = size_t(width_) * from;
  const uint32_t band = uint32_t(
      std::clamp<size_t>((size_t(4) << 20) / (old_row * sizeof(float)), 1, std::max(height_, 1u)));
  std::vector<float> rows(band * old_row);
  for (uint32_t y = 0; y < height_; y += band) {
    const uint32_t y1 = std::min(height_, y + band);
    VT_RETURN_IF_ERROR(read(y, y1, rows.data()));
    for (size_t i = 0; i < size_t(y1 - y) * width_; ++i)
      for (uint32_t c = 0; c < keep; ++c) rows[keep * i + c] = rows[from * i + c];
    channels_ = keep;
    const Status written = write_rows(y, y1 - y, rows.data());
    channels_ = from;
    VT_RETURN_IF_ERROR(written);
  }
  channels_ = keep;
  if (ftruncate(fd_, off_t(uint64_t(height_) * row_floats() * sizeof(float))) != 0)
    return Error(ErrorCode::kIo, path_ + ": scratch truncate failed: " + std::strerror(errno));
  return Status::Ok();
}

Status LevelStore::write_rows(uint32_t y0, uint32_t rows, const float* data) {
  if (uint64_t(y0) + rows > height_) return Error(ErrorCode::kInternal, "level rows past end");
  const size_t bytes = size_t(rows) * row_floats() * sizeof(float);
  if (in_memory()) {
    std::memcpy(memory_.data() + size_t(y0) * row_floats(), data, bytes);
    return Status::Ok();
  }
  return move_all(::pwrite, fd_, reinterpret_cast<const char*>(data), bytes,
                  row_offset(y0, row_floats()), path_, "write");
}

Status LevelStore::read(uint32_t y0, uint32_t y1, float* out) {
  if (y0 > y1 || y1 > height_) return Error(ErrorCode::kInternal, "level rows past end");
  const size_t bytes = size_t(y1 - y0) * row_floats() * sizeof(float);
  if (in_memory()) {
    if (memory_.size() < size_t(height_) * row_floats())
      return Error(ErrorCode::kInternal, "level rows read after the texels were handed over");
    std::memcpy(out, memory_.data() + size_t(y0) * row_floats(), bytes);
    return Status::Ok();
  }
  return move_all(::pread, fd_, reinterpret_cast<char*>(out), bytes, row_offset(y0, row_floats()),
                  path_, "read");
}

Status StoredImageSource::read_rows(uint32_t y0, uint32_t y1, float* out) {
  if (released_hash_)
    return Error(ErrorCode::kInternal, "layer rows read after the build took them over");
  const uint32_t sc = store_->channels(), c = info_.channels;
  if (sc == c) return store_->read(y0, y1, out);
  rows_.resize(size_t(y1 - y0) * store_->row_floats());
  VT_RETURN_IF_ERROR(store_->read(y0, y1, rows_.data()));
  const size_t texels = size_t(y1 - y0) * info_.width;
  for (size_t i = 0; i < texels; ++i)
    for (uint32_t k = 0; k < c; ++k) out[i * c + k] = rows_[i * sc + k];
  return Status::Ok();
}

std::vector<float> StoredImageSource::release_texels() {
  if (store_->channels() != info_.channels || !store_->in_memory()) return {};
  std::vector<float> texels = store_->release();
  // The texels' identity outlives them (the plan hashes its sources after taking level 0).
  released_hash_ = XXH3_64bits(texels.data(), texels.size() * sizeof(float));
  return texels;
}

Expected<uint64_t> StoredImageSource::content_hash() {
  if (released_hash_) return *released_hash_;
  // An in-memory store handing out all its channels is hashed where it lies: the digest of the
  // rows streamed in bands (ImageSource::content_hash) is XXH3 of the same bytes in one piece,
  // without a band buffer to allocate and copy into.
  if (const float* texels = texels_in_memory()) return XXH3_64bits(texels, store_->bytes());
  return ImageSource::content_hash();
}

}  // namespace vt
