#include "bake/transfer_cache.h"

#include <fcntl.h>
#include <unistd.h>
#include <xxhash.h>

#include <atomic>
#include <cstring>
#include <filesystem>

#include "format/zstd_frame.h"

namespace vt {
namespace {

constexpr char kMagic[8] = {'V', 'T', 'T', 'C', 'A', 'C', 'H', 'E'};
constexpr char kEnd[8] = {'V', 'T', 'T', 'C', '-', 'E', 'N', 'D'};
constexpr uint32_t kVersion = 1;
constexpr int kZstdLevel = 1;  // fast: the cache is written by every bake

struct Header {
  char magic[8];
  uint32_t version, bands;
  uint64_t file_key;
};
struct Trailer {
  uint64_t index_offset, index_checksum;
  char end[8];
};

bool read_at(int fd, void* data, size_t n, uint64_t offset) {
  auto* p = static_cast<uint8_t*>(data);
  while (n > 0) {
    const ssize_t got = ::pread(fd, p, n, off_t(offset));
    if (got <= 0) return false;
    p += got, n -= size_t(got), offset += uint64_t(got);
  }
  return true;
}

bool write_at(int fd, const void* data, size_t n, uint64_t offset) {
  auto* p = static_cast<const uint8_t*>(data);
  while (n > 0) {
    const ssize_t put = ::pwrite(fd, p, n, off_t(offset));
    if (put <= 0) return false;
    p += put, n -= size_t(put), offset += uint64_t(put);
  }
  return true;
}

}  // namespace

std::unique_ptr<TransferCacheReader> TransferCacheReader::open(const std::string& path,
                                                               uint64_t file_key, uint32_t bands) {
  auto reader = std::unique_ptr<TransferCacheReader>(new TransferCacheReader);
  reader->fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (reader->fd_ < 0) return nullptr;
  const off_t size = ::lseek(reader->fd_, 0, SEEK_END);
  Header h{};
  Trailer t{};
  const uint64_t index_bytes = uint64_t(bands) * sizeof(CachedBand);
  if (size < off_t(sizeof h + sizeof t) || !read_at(reader->fd_, &h, sizeof h, 0) ||
      !read_at(reader->fd_, &t, sizeof t, uint64_t(size) - sizeof t) ||
      std::memcmp(h.magic, kMagic, 8) != 0 || std::memcmp(t.end, kEnd, 8) != 0 ||
      h.version != kVersion || h.file_key != file_key || h.bands != bands ||
      t.index_offset + index_bytes + sizeof t != uint64_t(size))
    return nullptr;
  reader->index_.resize(bands);
  if (!read_at(reader->fd_, reader->index_.data(), index_bytes, t.index_offset) ||
      XXH3_64bits(reader->index_.data(), index_bytes) != t.index_checksum)
    return nullptr;
  for (const CachedBand& b : reader->index_)
    if (b.key != 0 && b.offset + b.stored > t.index_offset) return nullptr;
  return reader;
}

TransferCacheReader::~TransferCacheReader() {
  if (fd_ >= 0) ::close(fd_);
}

bool TransferCacheReader::read(uint32_t band, uint64_t key, std::span<uint8_t> out,
                               std::vector<uint8_t>* stored) const {
  if (band >= index_.size() || key == 0) return false;
  const CachedBand& b = index_[band];
  if (b.key != key || b.size != out.size()) return false;
  thread_local std::vector<uint8_t> own;
  std::vector<uint8_t>& frame = stored ? *stored : own;
  frame.resize(b.stored);
  return read_at(fd_, frame.data(), frame.size(), b.offset) &&
         zstd_decompress_exact(frame, out).ok() &&
         XXH3_64bits(out.data(), out.size()) == b.checksum;
}

Expected<std::unique_ptr<TransferCacheWriter>> TransferCacheWriter::create(const std::string& path,
                                                                           uint64_t file_key,
                                                                           uint32_t bands) {
  static std::atomic<uint64_t> made{0};
  auto w = std::unique_ptr<TransferCacheWriter>(new TransferCacheWriter);
  w->path_ = path;
  w->temp_ = path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(made++);
  w->fd_ = ::open(w->temp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (w->fd_ < 0) return Error(ErrorCode::kIo, w->temp_ + ": cannot create the transfer cache");
  Header h{};
  std::memcpy(h.magic, kMagic, 8);
  h.version = kVersion, h.bands = bands, h.file_key = file_key;
  w->index_.resize(bands);
  w->end_ = sizeof h;
  if (!write_at(w->fd_, &h, sizeof h, 0))
    w->error_ = Error(ErrorCode::kIo, w->temp_ + ": cannot write the transfer cache");
  return w;
}

TransferCacheWriter::~TransferCacheWriter() {
  if (fd_ >= 0) ::close(fd_);
  if (!finished_) {
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
  }
}

void TransferCacheWriter::add(uint32_t band, uint64_t key, std::span<const uint8_t> bytes) {
  thread_local std::vector<uint8_t> frame;
  if (!zstd_compress(bytes, kZstdLevel, frame).ok()) frame.clear();
  add_frame(band, key, bytes, frame);
}

void TransferCacheWriter::add_frame(uint32_t band, uint64_t key, std::span<const uint8_t> bytes,
                                    std::span<const uint8_t> frame) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!error_.ok() || band >= index_.size()) return;
  if (frame.empty() || !write_at(fd_, frame.data(), frame.size(), end_)) {
    error_ = Error(ErrorCode::kIo, temp_ + ": cannot write the transfer cache");
    return;
  }
  index_[band] = {key, end_, XXH3_64bits(bytes.data(), bytes.size()), uint32_t(frame.size()),
                  uint32_t(bytes.size())};
  end_ += frame.size();
}

Status TransferCacheWriter::finish() {
  if (!error_.ok()) return error_;
  const uint64_t index_bytes = index_.size() * sizeof(CachedBand);
  Trailer t{end_, XXH3_64bits(index_.data(), index_bytes), {}};
  std::memcpy(t.end, kEnd, 8);
  if (!write_at(fd_, index_.data(), index_bytes, end_) ||
      !write_at(fd_, &t, sizeof t, end_ + index_bytes) || ::close(fd_) != 0) {
    fd_ = -1;
    return Error(ErrorCode::kIo, temp_ + ": cannot write the transfer cache");
  }
  fd_ = -1;
  std::error_code ec;
  std::filesystem::rename(temp_, path_, ec);
  if (ec)
    return Error(ErrorCode::kIo, path_ + ": cannot replace the transfer cache: " + ec.message());
  finished_ = true;
  return Status::Ok();
}

}  // namespace vt
