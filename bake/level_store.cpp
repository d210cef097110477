#include "bake/level_store.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <xxhash.h>
#include <zstd.h>
#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <mutex>

#include "bake/level_dilation.h"
#include "bake/pyramid.h"
#include "common/parallel.h"
#include "format/zstd_frame.h"

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
      return Error(ErrorCode::kIo, path + ": " + verb + " failed: " + std::strerror(errno));
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

// Creates (or empties) `path` and fills it through write(fd); a failed close fails too.
template <class Write>
Status write_new_file(const std::string& path, Write&& write) {
  const int out = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (out < 0) return Error(ErrorCode::kIo, path + ": cannot write: " + std::strerror(errno));
  Status s = write(out);
  if (::close(out) != 0 && s.ok())
    s = Error(ErrorCode::kIo, path + ": write failed: " + std::strerror(errno));
  return s;
}

constexpr uint64_t kBlock = 4096;
uint64_t whole_blocks(uint64_t bytes) {
  return (bytes + kBlock - 1) / kBlock * kBlock;
}

}  // namespace

// A scratch level: raw rows at their offsets, or (`compressed`: scratch_needs_compression) a
// sparse file of rows in chunks of about 1 MiB, one zstd-1 frame per chunk in a fixed slot (the
// frame bound in whole blocks), so a chunk rewritten smaller frees its old tail by punching a
// hole and a chunk never written reads as zeros. VirtualCity's working levels take 1.7x (albedo)
// to 5.4x (orm) fewer bytes so. Parts of chunks (the dilation's row pairs) go through two decoded
// chunks written back when evicted, so a pass compresses each chunk once, not once per row pair.
class ScratchFile {
 public:
  static constexpr size_t kChunkBytes = size_t(1) << 20;

  static Expected<std::unique_ptr<ScratchFile>> create(const std::string& dir, uint32_t rows,
                                                       size_t row_bytes, bool compressed) {
    const std::string folder = dir.empty() ? std::string(".") : dir;
    std::unique_ptr<ScratchFile> f(new ScratchFile());
    // Unnamed where the file system allows (save_as can then link it under a name); else named
    // and unlinked at once. Either way the file lives as long as the descriptor.
    f->fd_ = ::open(folder.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
    f->linkable_ = f->fd_ >= 0;
    f->path_ = folder + "/.vtbake-level (unnamed)";
    if (f->fd_ < 0) {
      std::string templ = folder + "/.vtbake-level-XXXXXX";
      std::vector<char> name(templ.begin(), templ.end());
      name.push_back('\0');
      f->fd_ = mkstemp(name.data());
      if (f->fd_ < 0)
        return Status(ErrorCode::kIo,
                      templ + ": cannot create scratch file: " + std::strerror(errno));
      unlink(name.data());
      f->path_ = name.data();
    }
    f->rows_ = rows;
    f->compressed_ = compressed;
    if (!compressed) return f;
    f->chunk_rows_ = uint32_t(
        std::clamp<size_t>(kChunkBytes / std::max<size_t>(row_bytes, 1), 1, std::max(rows, 1u)));
    f->slot_bytes_ = whole_blocks(ZSTD_COMPRESSBOUND(uint64_t(f->chunk_rows_) * row_bytes));
    f->frame_bytes_.assign((uint64_t(rows) + f->chunk_rows_ - 1) / f->chunk_rows_, 0);
    return f;
  }

  // A level file save_as wrote, `rows` of `row_bytes`, opened to read: raw rows, or compressed
  // chunks whose table the file's footer holds. Every field of the footer is checked against
  // what the caller expects, so a damaged or foreign file is refused, not misread.
  static Expected<std::unique_ptr<ScratchFile>> open_saved(const std::string& path, uint32_t rows,
                                                           size_t row_bytes, bool compressed) {
    std::unique_ptr<ScratchFile> f(new ScratchFile());
    f->fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (f->fd_ < 0) return Error(ErrorCode::kIo, path + ": cannot open: " + std::strerror(errno));
    f->path_ = path;
    f->rows_ = rows;
    f->compressed_ = compressed;
    f->saved_ = true;
    struct stat st;
    if (fstat(f->fd_, &st) != 0) return Error(ErrorCode::kIo, path + ": cannot stat");
    const uint64_t size = uint64_t(st.st_size);
    auto corrupt = [&](const std::string& what) {
      return Error(ErrorCode::kCorrupt, path + ": " + what + " (a damaged work folder?)");
    };
    if (!compressed) {
      if (size != uint64_t(rows) * row_bytes)
        return corrupt("not the " + std::to_string(uint64_t(rows) * row_bytes) + " bytes expected");
      f->disk_bytes_ = size;
      return f;
    }
    Footer foot;
    if (size < sizeof foot) return corrupt("too short for a compressed level");
    VT_RETURN_IF_ERROR(move_all(::pread, f->fd_, reinterpret_cast<uint8_t*>(&foot), sizeof foot,
                                off_t(size - sizeof foot), path, "read"));
    const uint64_t chunks =
        foot.chunk_rows ? (uint64_t(rows) + foot.chunk_rows - 1) / foot.chunk_rows : 0;
    if (std::memcmp(foot.magic, kFooterMagic, sizeof foot.magic) != 0 || foot.rows != rows ||
        foot.row_bytes != row_bytes || foot.chunk_rows == 0 || foot.chunks != chunks ||
        foot.slot_bytes == 0 || foot.slot_bytes > (uint64_t(1) << 32) ||
        size != chunks * foot.slot_bytes + chunks * sizeof(uint32_t) + sizeof foot)
      return corrupt("not a compressed level of " + std::to_string(rows) + " rows of " +
                     std::to_string(row_bytes) + " bytes");
    f->chunk_rows_ = foot.chunk_rows;
    f->slot_bytes_ = foot.slot_bytes;
    f->frame_bytes_.resize(chunks);
    VT_RETURN_IF_ERROR(move_all(::pread, f->fd_, reinterpret_cast<uint8_t*>(f->frame_bytes_.data()),
                                chunks * sizeof(uint32_t), off_t(chunks * foot.slot_bytes), path,
                                "read"));
    for (uint32_t b : f->frame_bytes_) {
      if (b > f->slot_bytes_) return corrupt("a chunk larger than its slot");
      f->disk_bytes_ += b;
    }
    return f;
  }

  // Gives the file the new name `path`: linked there where it is unnamed and on the same file
  // system (`allow_link`), else copied (a compressed file's frames only). A compressed file gets
  // its chunk table as a footer first. Nothing may be written after.
  Status save_as(const std::string& path, size_t row_bytes, bool allow_link) {
    std::lock_guard lock(mutex_);
    for (Decoded& d : decoded_) VT_RETURN_IF_ERROR(write_back(d));
    saved_ = true;
    const uint64_t end =
        compressed_ ? frame_bytes_.size() * slot_bytes_ : uint64_t(rows_) * row_bytes;
    if (compressed_) {
      Footer foot;
      std::memcpy(foot.magic, kFooterMagic, sizeof foot.magic);
      foot.slot_bytes = slot_bytes_;
      foot.row_bytes = row_bytes;
      foot.rows = rows_;
      foot.chunk_rows = chunk_rows_;
      foot.chunks = uint32_t(frame_bytes_.size());
      std::vector<uint8_t> tail(frame_bytes_.size() * sizeof(uint32_t) + sizeof foot);
      std::memcpy(tail.data(), frame_bytes_.data(), frame_bytes_.size() * sizeof(uint32_t));
      std::memcpy(tail.data() + frame_bytes_.size() * sizeof(uint32_t), &foot, sizeof foot);
      VT_RETURN_IF_ERROR(
          move_all(::pwrite, fd_, tail.data(), tail.size(), off_t(end), path_, "write"));
    } else if (ftruncate(fd_, off_t(end)) != 0) {  // rows never written read as zeros
      return Error(ErrorCode::kIo, path_ + ": scratch truncate failed: " + std::strerror(errno));
    }
    if (allow_link && linkable_) {
      ::unlink(path.c_str());  // an empty staging file of that name
      const std::string self = "/proc/self/fd/" + std::to_string(fd_);
      if (::linkat(AT_FDCWD, self.c_str(), AT_FDCWD, path.c_str(), AT_SYMLINK_FOLLOW) == 0)
        return Status::Ok();
    }
    return write_new_file(path, [&](int out) { return copy_to(out, path, end); });
  }

  ~ScratchFile() { close(fd_); }

  bool compressed() const { return compressed_; }
  uint32_t chunk_rows() const { return chunk_rows_; }
  // Raw: the file's size; compressed: the written frames (chunks waiting in the cache count once
  // written back).
  uint64_t disk_bytes() const { return disk_bytes_.load(std::memory_order_relaxed); }

  // Rows [y0, y0 + rows) of `row_bytes` each. The row size may shrink after the first writes
  // (LevelStore::keep_channels) as long as rows are rewritten top to bottom, each chunk whole.
  Status write(uint32_t y0, uint32_t rows, size_t row_bytes, const uint8_t* data) {
    if (saved_) return Error(ErrorCode::kInternal, path_ + ": a saved level is read only");
    if (!compressed_) {
      const uint64_t end = (uint64_t(y0) + rows) * row_bytes;
      VT_RETURN_IF_ERROR(move_all(::pwrite, fd_, data, size_t(rows) * row_bytes,
                                  off_t(uint64_t(y0) * row_bytes), path_, "write"));
      uint64_t was = disk_bytes_.load(std::memory_order_relaxed);
      while (was < end && !disk_bytes_.compare_exchange_weak(was, end)) {
      }
      return Status::Ok();
    }
    std::lock_guard lock(mutex_);
    std::vector<uint32_t> whole;
    for (uint32_t c = y0 / chunk_rows_; rows > 0 && c * chunk_rows_ < y0 + rows; ++c) {
      const auto [cy0, cy1] = chunk_span(c);
      const uint32_t a = std::max(y0, cy0), b = std::min(y0 + rows, cy1);
      if (a == cy0 && b == cy1) {
        for (Decoded& d : decoded_)
          if (d.chunk == c) d = Decoded{};
        whole.push_back(c);
        continue;
      }
      VT_ASSIGN_OR_RETURN(Decoded * d, decode(c, size_t(cy1 - cy0) * row_bytes));
      std::memcpy(d->raw.data() + size_t(a - cy0) * row_bytes, data + size_t(a - y0) * row_bytes,
                  size_t(b - a) * row_bytes);
      d->dirty = true;
    }
    return on_chunks(whole, [&](uint32_t c) {
      const auto [cy0, cy1] = chunk_span(c);
      return write_chunk(c, {data + size_t(cy0 - y0) * row_bytes, size_t(cy1 - cy0) * row_bytes});
    });
  }

  Status read(uint32_t y0, uint32_t y1, size_t row_bytes, uint8_t* out) {
    if (!compressed_)
      return move_all(::pread, fd_, out, size_t(y1 - y0) * row_bytes,
                      off_t(uint64_t(y0) * row_bytes), path_, "read");
    std::lock_guard lock(mutex_);
    std::vector<uint32_t> whole;
    for (uint32_t c = y0 / chunk_rows_; c * chunk_rows_ < y1; ++c) {
      const auto [cy0, cy1] = chunk_span(c);
      const uint32_t a = std::max(y0, cy0), b = std::min(y1, cy1);
      const bool cached = std::any_of(decoded_.begin(), decoded_.end(),
                                      [c](const Decoded& d) { return d.chunk == c; });
      if (a == cy0 && b == cy1 && !cached) {
        whole.push_back(c);
        continue;
      }
      VT_ASSIGN_OR_RETURN(const Decoded* d, decode(c, size_t(cy1 - cy0) * row_bytes));
      std::memcpy(out + size_t(a - y0) * row_bytes, d->raw.data() + size_t(a - cy0) * row_bytes,
                  size_t(b - a) * row_bytes);
    }
    return on_chunks(whole, [&](uint32_t c) {
      const auto [cy0, cy1] = chunk_span(c);
      return read_chunk(c, {out + size_t(cy0 - y0) * row_bytes, size_t(cy1 - cy0) * row_bytes});
    });
  }

  // A raw file rewritten in a smaller row size (keep_channels) ends at `bytes`.
  Status truncate(uint64_t bytes) {
    if (saved_) return Error(ErrorCode::kInternal, path_ + ": a saved level is read only");
    if (compressed_) return Status::Ok();
    if (ftruncate(fd_, off_t(bytes)) != 0)
      return Error(ErrorCode::kIo, path_ + ": scratch truncate failed: " + std::strerror(errno));
    disk_bytes_.store(bytes, std::memory_order_relaxed);
    return Status::Ok();
  }

 private:
  static constexpr uint32_t kNone = ~0u;
  struct Decoded {
    uint32_t chunk = kNone;
    bool dirty = false;
    uint64_t used = 0;
    std::vector<uint8_t> raw;
  };
  ScratchFile() = default;

  // io(c) for whole chunks, on every core: compression is most of a scratch pass's time, and
  // distinct chunks share nothing but disk_bytes_ (atomic). The first error is returned.
  template <class Io>
  Status on_chunks(const std::vector<uint32_t>& chunks, Io&& io) {
    std::vector<Status> done(chunks.size());
    parallel_for(chunks.size(), chunks.size() > 1 ? 0 : 1,
                 [&](size_t i) { done[i] = io(chunks[i]); });
    for (Status& s : done) VT_RETURN_IF_ERROR(std::move(s));
    return Status::Ok();
  }

  std::pair<uint32_t, uint32_t> chunk_span(uint32_t c) const {
    return {c * chunk_rows_, std::min(rows_, (c + 1) * chunk_rows_)};
  }
  off_t slot(uint32_t c) const { return off_t(uint64_t(c) * slot_bytes_); }

  // Chunk `c` decoded (`chunk_bytes` of rows), the least recently used one written back for it.
  Expected<Decoded*> decode(uint32_t c, size_t chunk_bytes) {
    Decoded* d = &decoded_[0];
    for (Decoded& e : decoded_) {
      if (e.chunk == c) {
        d = &e;
        break;
      }
      if (e.used < d->used) d = &e;
    }
    d->used = ++uses_;
    if (d->chunk == c && d->raw.size() == chunk_bytes) return d;
    VT_RETURN_IF_ERROR(write_back(*d));
    d->chunk = kNone;
    d->raw.resize(chunk_bytes);
    VT_RETURN_IF_ERROR(read_chunk(c, d->raw));
    d->chunk = c;
    return d;
  }

  // A decoded chunk's changes to disk (nothing if it has none).
  Status write_back(Decoded& d) {
    if (d.dirty) VT_RETURN_IF_ERROR(write_chunk(d.chunk, d.raw));
    d.dirty = false;
    return Status::Ok();
  }

  Status read_chunk(uint32_t c, std::span<uint8_t> raw) const {
    if (frame_bytes_[c] == 0) {
      std::memset(raw.data(), 0, raw.size());
      return Status::Ok();
    }
    thread_local std::vector<uint8_t> frame;
    frame.resize(frame_bytes_[c]);
    VT_RETURN_IF_ERROR(move_all(::pread, fd_, frame.data(), frame.size(), slot(c), path_, "read"));
    const Status s = zstd_decompress_exact(frame, raw);
    if (!s.ok()) return Error(ErrorCode::kIo, path_ + ": scratch chunk unreadable: " + s.message());
    return Status::Ok();
  }

  Status write_chunk(uint32_t c, std::span<const uint8_t> raw) {
    thread_local std::vector<uint8_t> frame;
    VT_RETURN_IF_ERROR(zstd_compress(raw, 1, frame));
    if (frame.size() > slot_bytes_)
      return Error(ErrorCode::kInternal, "scratch chunk past its slot");
    VT_RETURN_IF_ERROR(
        move_all(::pwrite, fd_, frame.data(), frame.size(), slot(c), path_, "write"));
    const uint64_t was = whole_blocks(frame_bytes_[c]), now = whole_blocks(frame.size());
    // Where holes cannot be punched the old tail stays allocated: only disk is lost.
    if (now < was)
      (void)fallocate(fd_, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, slot(c) + off_t(now),
                      off_t(was - now));
    disk_bytes_.fetch_add(now - was, std::memory_order_relaxed);  // modulo 2^64
    frame_bytes_[c] = uint32_t(frame.size());
    return Status::Ok();
  }

  // Copies the file's bytes up to `end` and, compressed, its footer to `out` (at `path`), frame
  // by frame: slots' unwritten tails stay holes there too.
  Status copy_to(int out, const std::string& path, uint64_t end) {
    std::vector<uint8_t> buffer;
    auto copy = [&](uint64_t at, uint64_t bytes) -> Status {
      for (uint64_t done = 0; done < bytes;) {
        const size_t n = size_t(std::min<uint64_t>(bytes - done, uint64_t(4) << 20));
        buffer.resize(n);
        VT_RETURN_IF_ERROR(
            move_all(::pread, fd_, buffer.data(), n, off_t(at + done), path_, "read"));
        VT_RETURN_IF_ERROR(
            move_all(::pwrite, out, buffer.data(), n, off_t(at + done), path, "write"));
        done += n;
      }
      return Status::Ok();
    };
    if (!compressed_) return copy(0, end);
    for (uint32_t c = 0; c < frame_bytes_.size(); ++c)
      VT_RETURN_IF_ERROR(copy(slot(c), frame_bytes_[c]));
    return copy(end, frame_bytes_.size() * sizeof(uint32_t) + sizeof(Footer));
  }

  // The end of a saved compressed level, after its table of frame sizes (uint32 per chunk).
  static constexpr char kFooterMagic[8] = {'V', 'T', 'L', 'E', 'V', 'Z', '0', '1'};
  struct Footer {
    uint64_t slot_bytes = 0, row_bytes = 0;
    uint32_t rows = 0, chunk_rows = 0, chunks = 0, reserved = 0;
    char magic[8] = {};
  };

  int fd_ = -1;
  std::string path_;
  bool linkable_ = false;  // O_TMPFILE: save_as may link it
  bool saved_ = false;     // save_as'd or open_saved: read only
  bool compressed_ = false;
  uint32_t rows_ = 0, chunk_rows_ = 1;
  uint64_t slot_bytes_ = 0;
  std::vector<uint32_t> frame_bytes_;  // per chunk; 0: never written
  std::atomic<uint64_t> disk_bytes_{0};
  std::mutex mutex_;
  std::array<Decoded, 2> decoded_;
  uint64_t uses_ = 0;
};

std::string gib_text(uint64_t bytes) {
  return std::to_string((bytes + (uint64_t(1) << 29)) >> 30);
}

Status check_scratch_room(uint64_t needed, const std::string& dir, const std::string& what_needs) {
  const std::string folder = dir.empty() ? std::string(".") : dir;
  std::error_code ec;
  const std::filesystem::space_info space = std::filesystem::space(folder, ec);
  if (ec || space.available >= needed) return Status::Ok();
  return Error(ErrorCode::kResourceLimit,
               folder + ": " + what_needs + " " + gib_text(needed) +
                   " GiB of scratch files here, and the disk has " + gib_text(space.available) +
                   " GiB free; give --scratch-dir on a larger disk, or lower --size or "
                   "--texels-per-unit");
}

Expected<std::unique_ptr<LevelStore>> LevelStore::create(uint32_t width, uint32_t height,
                                                         uint32_t channels, bool in_memory,
                                                         const std::string& scratch_dir,
                                                         bool compressed) {
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
  VT_ASSIGN_OR_RETURN(s->file_, ScratchFile::create(scratch_dir, height,
                                                    s->row_floats() * sizeof(float), compressed));
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

LevelStore::~LevelStore() = default;

Expected<std::unique_ptr<LevelStore>> LevelStore::open_saved(const std::string& path,
                                                             uint32_t width, uint32_t height,
                                                             uint32_t channels, bool compressed) {
  std::unique_ptr<LevelStore> s(new LevelStore());
  s->width_ = width;
  s->height_ = height;
  s->channels_ = channels;
  VT_ASSIGN_OR_RETURN(
      s->file_, ScratchFile::open_saved(path, height, s->row_floats() * sizeof(float), compressed));
  return s;
}

Status LevelStore::save(const std::string& path, bool allow_link) {
  if (file_) return file_->save_as(path, row_floats() * sizeof(float), allow_link);
  if (!holds_texels())
    return Error(ErrorCode::kInternal, path + ": level saved after its texels were handed over");
  return write_new_file(path, [&](int out) {
    return move_all(::pwrite, out, reinterpret_cast<const uint8_t*>(memory_.data()), bytes(), 0,
                    path, "write");
  });
}

uint64_t LevelStore::disk_bytes() const {
  return file_ ? file_->disk_bytes() : 0;
}
bool LevelStore::compressed() const {
  return file_ && file_->compressed();
}

bool scratch_needs_compression(uint64_t raw_bytes, const std::string& dir) {
  std::error_code ec;
  const std::filesystem::space_info space =
      std::filesystem::space(dir.empty() ? std::string(".") : dir, ec);
  return !ec && raw_bytes > space.available / 10 * 9;
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
  // Whole chunks at a time, about 4 MiB: each is rewritten whole in the new row size.
  const size_t old_row = size_t(width_) * from;
  const uint32_t chunk = file_->chunk_rows();
  const uint32_t band = chunk * uint32_t(std::clamp<size_t>(
                                    (size_t(4) << 20) / (size_t(chunk) * old_row * sizeof(float)),
                                    1, std::max(height_ / chunk, 1u)));
  std::vector<float> rows(size_t(band) * old_row);
  for (uint32_t y = 0; y < height_; y += band) {
    const uint32_t y1 = std::min(height_, y + band);
    VT_RETURN_IF_ERROR(read(y, y1, rows.data()));
    for (size_t i = 0; i < size_t(y1 - y) * width_; ++i)
      for (uint32_t c = 0; c < keep; ++c) rows[keep * i + c] = rows[from * i + c];
    VT_RETURN_IF_ERROR(file_->write(y, y1 - y, size_t(width_) * keep * sizeof(float),
                                    reinterpret_cast<const uint8_t*>(rows.data())));
  }
  channels_ = keep;
  return file_->truncate(bytes());
}

Status LevelStore::write_rows(uint32_t y0, uint32_t rows, const float* data) {
  if (uint64_t(y0) + rows > height_) return Error(ErrorCode::kInternal, "level rows past end");
  const size_t bytes = size_t(rows) * row_floats() * sizeof(float);
  if (in_memory()) {
    std::memcpy(memory_.data() + size_t(y0) * row_floats(), data, bytes);
    return Status::Ok();
  }
  return file_->write(y0, rows, row_floats() * sizeof(float),
                      reinterpret_cast<const uint8_t*>(data));
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
  return file_->read(y0, y1, row_floats() * sizeof(float), reinterpret_cast<uint8_t*>(out));
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
  if (hash_) return *hash_;
  // An in-memory store handing out all its channels is hashed where it lies: the digest of the
  // rows streamed in bands (ImageSource::content_hash) is XXH3 of the same bytes in one piece,
  // without a band buffer to allocate and copy into.
  if (const float* texels = texels_in_memory()) {
    hash_ = XXH3_64bits(texels, store_->bytes());
  } else {
    VT_ASSIGN_OR_RETURN(hash_, ImageSource::content_hash());
  }
  return *hash_;
}

}  // namespace vt
