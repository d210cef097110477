// The streaming page-file writer: pages go to an unlinked spill file as they arrive (any order,
// any thread); finish() lays them out canonically, writes header + index + data + metadata to a
// temporary file, fsyncs it and renames it over the final path.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

#include <atomic>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <mutex>

#include "format/atomic_output.h"
#include "format/page_file.h"
#include "format/page_file_layout.h"

namespace vt {

namespace {

using namespace pagefile;

std::string errno_text() {
  return std::strerror(errno);
}

Status pwrite_all(int fd, const uint8_t* data, size_t size, uint64_t offset,
                  const std::string& path) {
  while (size > 0) {
    ssize_t n = ::pwrite(fd, data, size, off_t(offset));
    if (n < 0) {
      if (errno == EINTR) continue;
      return Error(ErrorCode::kIo, path + ": write to spill file failed: " + errno_text());
    }
    data += n;
    size -= size_t(n);
    offset += uint64_t(n);
  }
  return Status::Ok();
}

Status pread_all(int fd, uint8_t* data, size_t size, uint64_t offset, const std::string& path) {
  while (size > 0) {
    ssize_t n = ::pread(fd, data, size, off_t(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return Error(ErrorCode::kIo, path + ": read of spill file failed");
    data += n;
    size -= size_t(n);
    offset += uint64_t(n);
  }
  return Status::Ok();
}

// Buffers small writes (header, index, pages) into large write() calls.
class OutBuffer {
 public:
  OutBuffer(int fd, const std::string& path) : fd_(fd), path_(path) { buf_.reserve(kCap); }
  Status put(const uint8_t* data, size_t size) {
    if (buf_.size() + size > kCap) VT_RETURN_IF_ERROR(flush());
    if (size >= kCap) {
      written_ += size;
      return write_all(fd_, data, size, path_);
    }
    buf_.insert(buf_.end(), data, data + size);
    written_ += size;
    return Status::Ok();
  }
  Status zeros(uint64_t count) {
    static const uint8_t kZero[4096] = {};
    while (count > 0) {
      size_t n = size_t(std::min<uint64_t>(count, sizeof(kZero)));
      VT_RETURN_IF_ERROR(put(kZero, n));
      count -= n;
    }
    return Status::Ok();
  }
  Status flush() {
    Status s = write_all(fd_, buf_.data(), buf_.size(), path_);
    buf_.clear();
    return s;
  }
  uint64_t written() const { return written_; }

 private:
  static constexpr size_t kCap = 1 << 20;
  int fd_;
  const std::string& path_;
  std::vector<uint8_t> buf_;
  uint64_t written_ = 0;
};

struct SpillEntry {
  PageState state = PageState::kAbsent;
  uint32_t size = 0;
  uint64_t spill_offset = 0;
  uint64_t checksum = 0;
  uint8_t constant[16] = {};
};

std::string dir_of(const std::string& path) {
  size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

class PageFileWriterImpl final : public PageFileWriter {
 public:
  PageFileWriterImpl(std::string path, std::string target, PageFileDesc desc)
      : path_(std::move(path)), target_(std::move(target)), desc_(std::move(desc)) {}

  ~PageFileWriterImpl() override {
    if (spill_fd_ >= 0) ::close(spill_fd_);
    if (out_fd_ >= 0) ::close(out_fd_);
    if (!temp_path_.empty() && !renamed_) ::unlink(temp_path_.c_str());
  }

  Status init() {
    const PageGeometry& g = desc_.geometry;
    layer_count_ = uint32_t(desc_.layers.size());
    uint64_t entries = g.total_pages() * layer_count_;
    // The index lives in memory until finish(); refuse what could never be held.
    if (entries > (uint64_t(1) << 31))
      return Error(ErrorCode::kResourceLimit,
                   path_ + ": " + std::to_string(entries) + " index entries is too many");
    entries_.resize(size_t(entries));
    claimed_.resize(size_t(entries));
    level_first_.resize(g.level_count());
    for (uint32_t l = 0; l < g.level_count(); ++l) level_first_[l] = level_first_page(g, l);

    // Named so that a later writer can sweep it if this process is killed (atomic_output.h).
    auto temp = create_staging_file(target_);
    if (!temp.ok()) return temp.status();
    out_fd_ = temp->fd;
    temp_path_ = temp->path;
    std::string spill = target_ + ".spill-XXXXXX";
    spill_fd_ = ::mkstemp(spill.data());
    if (spill_fd_ < 0)
      return Error(ErrorCode::kIo, path_ + ": cannot create spill file: " + errno_text());
    ::unlink(spill.c_str());  // the data stays reachable through the descriptor only
    return Status::Ok();
  }

  Status add_page(const PageId& id, uint32_t layer, std::span<const uint8_t> data) override {
    VT_ASSIGN_OR_RETURN(size_t slot, check_page(id, layer));
    const LayerSpec& spec = desc_.layers[layer];
    if (data.empty()) return bad(id, layer, "stored page with no bytes");
    if (data.size() > UINT32_MAX) return bad(id, layer, "stored page larger than 4 GiB");
    if (spec.codec == PageCodec::kRaw && data.size() != raw_page_bytes(spec))
      return bad(id, layer,
                 "raw page of " + std::to_string(data.size()) + " bytes, expected " +
                     std::to_string(raw_page_bytes(spec)));
    VT_RETURN_IF_ERROR(claim(id, layer, slot));
    uint64_t offset = spill_end_.fetch_add(data.size());
    Status s = pwrite_all(spill_fd_, data.data(), data.size(), offset, path_);
    SpillEntry e;
    e.state = PageState::kStored;
    e.size = uint32_t(data.size());
    e.spill_offset = offset;
    e.checksum = XXH3_64bits(data.data(), data.size());
    std::lock_guard lock(mutex_);
    release();
    if (!s.ok()) {
      failed_ = s;
      return s;
    }
    entries_[slot] = e;
    return Status::Ok();
  }

  Status add_constant_page(const PageId& id, uint32_t layer,
                           std::span<const uint8_t> texel) override {
    VT_ASSIGN_OR_RETURN(size_t slot, check_page(id, layer));
    const LayerSpec& spec = desc_.layers[layer];
    if (texel.size() != spec.texel_bytes())
      return bad(id, layer,
                 "constant value of " + std::to_string(texel.size()) + " bytes, expected " +
                     std::to_string(spec.texel_bytes()));
    VT_RETURN_IF_ERROR(claim(id, layer, slot));
    SpillEntry e;
    e.state = PageState::kConstant;
    std::memcpy(e.constant, texel.data(), texel.size());
    e.checksum = XXH3_64bits(texel.data(), texel.size());
    std::lock_guard lock(mutex_);
    release();
    entries_[slot] = e;
    return Status::Ok();
  }

  void set_metadata_json(std::string json) override {
    std::lock_guard lock(mutex_);
    desc_.metadata_json = std::move(json);
  }

  Status finish() override {
    {
      std::unique_lock lock(mutex_);
      if (finished_) return Error(ErrorCode::kInvalidArgument, path_ + ": finish() called twice");
      finished_ = true;
      // Pages accepted before finish() but still being written are waited for, not lost.
      idle_.wait(lock, [&] { return in_flight_ == 0; });
      if (!failed_.ok()) return failed_;
    }
    Status s = write_file();
    return s.ok() ? s : s.with_context(path_);
  }

 private:
  uint64_t raw_page_bytes(const LayerSpec& spec) const {
    uint64_t size = desc_.geometry.page_size();
    return size * size * spec.texel_bytes();
  }

  Status bad(const PageId& id, uint32_t layer, const std::string& what) const {
    return Error(ErrorCode::kInvalidArgument, path_ + ": " + page_name(id, layer) + ": " + what);
  }

  Expected<size_t> check_page(const PageId& id, uint32_t layer) const {
    if (!desc_.geometry.contains(id)) return bad(id, layer, "page outside the geometry");
    if (layer >= layer_count_)
      return bad(id, layer, "layer out of range (" + std::to_string(layer_count_) + " layers)");
    uint64_t page =
        level_first_[id.level] + uint64_t(id.y) * desc_.geometry.pages_x(id.level) + id.x;
    return size_t(page * layer_count_ + layer);
  }

  // Reserves the slot so that a second add of the same page fails whatever the thread timing.
  Status claim(const PageId& id, uint32_t layer, size_t slot) {
    std::lock_guard lock(mutex_);
    if (finished_) return bad(id, layer, "page added after finish()");
    if (claimed_[slot]) return bad(id, layer, "page added twice");
    claimed_[slot] = 1;
    ++in_flight_;
    return Status::Ok();
  }

  // Called under mutex_ when a claimed page's entry is recorded.
  void release() {
    if (--in_flight_ == 0) idle_.notify_all();
  }

  Status write_file();

  std::string path_;
  std::string target_;  // resolve_output_path(path_): what the rename replaces
  PageFileDesc desc_;
  uint32_t layer_count_ = 0;
  std::vector<uint64_t> level_first_;
  std::vector<SpillEntry> entries_;
  std::vector<uint8_t> claimed_;
  std::mutex mutex_;
  std::condition_variable idle_;
  uint64_t in_flight_ = 0;
  std::atomic<uint64_t> spill_end_{0};
  Status failed_;
  bool finished_ = false;
  bool renamed_ = false;
  int spill_fd_ = -1;
  int out_fd_ = -1;
  std::string temp_path_;
};

Status PageFileWriterImpl::write_file() {
  const PageGeometry& g = desc_.geometry;
  const uint32_t levels = g.level_count();
  const uint64_t entry_count = entries_.size();

  uint64_t header_size = kFixedHeaderBytes + uint64_t(kLevelRecordBytes) * levels + 8;
  for (const LayerSpec& l : desc_.layers)
    header_size += layer_record_bytes(l.name.size(), l.codec_tables.size());
  const uint64_t index_offset = header_size;
  const uint64_t index_size = entry_count * kEntryBytes;
  const uint64_t data_offset =
      align_up(index_offset + index_size, desc_.align_pages_4k ? kPageAlignment : 8);

  // Canonical data order: coarsest level first, Morton order inside a level, then layers.
  std::vector<uint64_t> final_offset(entry_count, 0);
  std::vector<size_t> order;
  uint64_t pos = data_offset;
  for (uint32_t level = levels; level-- > 0;) {
    const uint32_t px = g.pages_x(level);
    for (uint64_t code : morton_order(g, level)) {
      uint32_t x, y;
      morton_decode(code, &x, &y);
      const uint64_t page = level_first_[level] + uint64_t(y) * px + x;
      for (uint32_t layer = 0; layer < layer_count_; ++layer) {
        const size_t slot = size_t(page * layer_count_ + layer);
        if (entries_[slot].state != PageState::kStored) continue;
        if (desc_.align_pages_4k) pos = align_up(pos, kPageAlignment);
        final_offset[slot] = pos;
        pos += entries_[slot].size;
        order.push_back(slot);
      }
    }
  }
  const uint64_t data_size = pos - data_offset;
  const uint64_t metadata_offset = pos;
  const std::string& metadata = desc_.metadata_json;
  const uint64_t file_size = metadata_offset + metadata.size();

  std::vector<uint8_t> index(size_t(index_size), 0);
  for (size_t slot = 0; slot < entry_count; ++slot) {
    const SpillEntry& e = entries_[slot];
    uint8_t* p = index.data() + slot * kEntryBytes;
    p[0] = uint8_t(e.state);
    if (e.state == PageState::kStored) {
      p[1] = uint8_t(desc_.layers[slot % layer_count_].codec);
      put_u32(p + 4, e.size);
      put_u64(p + 8, final_offset[slot]);
    } else if (e.state == PageState::kConstant) {
      std::memcpy(p + 8, e.constant, 16);
    }
    if (e.state != PageState::kAbsent) put_u64(p + 24, e.checksum);
  }

  std::vector<uint8_t> header(size_t(header_size), 0);
  uint8_t* h = header.data();
  std::memcpy(h + kOffMagic, kMagic, 8);
  put_u32(h + kOffVersion, kVersion);
  put_u32(h + kOffHeaderSize, uint32_t(header_size));
  put_u32(h + kOffWidth, g.width);
  put_u32(h + kOffHeight, g.height);
  put_u32(h + kOffPayload, g.payload);
  put_u32(h + kOffBorder, g.border);
  put_u32(h + kOffLevelCount, levels);
  put_u32(h + kOffLayerCount, layer_count_);
  put_u32(h + kOffFlags, desc_.align_pages_4k ? kFlagAlign4k : 0);
  put_u64(h + kOffIndexOffset, index_offset);
  put_u64(h + kOffIndexSize, index_size);
  put_u64(h + kOffDataOffset, data_offset);
  put_u64(h + kOffDataSize, data_size);
  put_u64(h + kOffMetadataOffset, metadata_offset);
  put_u64(h + kOffMetadataSize, metadata.size());
  put_u64(h + kOffFileSize, file_size);
  put_u64(h + kOffIndexChecksum, XXH3_64bits(index.data(), index.size()));
  put_u64(h + kOffMetadataChecksum, XXH3_64bits(metadata.data(), metadata.size()));
  uint8_t* p = h + kFixedHeaderBytes;
  for (uint32_t level = 0; level < levels; ++level, p += kLevelRecordBytes) {
    put_u32(p, g.pages_x(level));
    put_u32(p + 4, g.pages_y(level));
  }
  for (const LayerSpec& l : desc_.layers) {
    p[0] = uint8_t(l.semantic);
    p[1] = l.channels;
    p[2] = uint8_t(l.texel_type);
    p[3] = uint8_t(l.codec);
    p[4] = uint8_t(l.runtime_format);
    p[5] = uint8_t(l.color_space);
    p[6] = uint8_t(l.address_mode);
    p[7] = uint8_t(l.name.size());
    put_u32(p + 8, uint32_t(l.codec_tables.size()));
    std::memcpy(p + kLayerRecordFixedBytes, l.name.data(), l.name.size());
    if (!l.codec_tables.empty())
      std::memcpy(p + kLayerRecordFixedBytes + l.name.size(), l.codec_tables.data(),
                  l.codec_tables.size());
    p += layer_record_bytes(l.name.size(), l.codec_tables.size());
  }
  put_u64(h + header_size - 8, XXH3_64bits(h, size_t(header_size - 8)));

  OutBuffer out(out_fd_, temp_path_);
  VT_RETURN_IF_ERROR(out.put(header.data(), header.size()));
  VT_RETURN_IF_ERROR(out.put(index.data(), index.size()));
  VT_RETURN_IF_ERROR(out.zeros(data_offset - out.written()));
  std::vector<uint8_t> page;
  for (size_t slot : order) {
    VT_RETURN_IF_ERROR(out.zeros(final_offset[slot] - out.written()));
    page.resize(entries_[slot].size);
    VT_RETURN_IF_ERROR(
        pread_all(spill_fd_, page.data(), page.size(), entries_[slot].spill_offset, path_));
    VT_RETURN_IF_ERROR(out.put(page.data(), page.size()));
  }
  VT_RETURN_IF_ERROR(out.put(reinterpret_cast<const uint8_t*>(metadata.data()), metadata.size()));
  VT_RETURN_IF_ERROR(out.flush());
  if (::fsync(out_fd_) != 0) return Error(ErrorCode::kIo, "fsync failed: " + errno_text());
  if (::close(out_fd_) != 0) {
    out_fd_ = -1;
    return Error(ErrorCode::kIo, "close failed: " + errno_text());
  }
  out_fd_ = -1;
  // mkstemp creates 0600; a page file is an ordinary build output.
  mode_t mask = ::umask(0);
  ::umask(mask);
  ::chmod(temp_path_.c_str(), 0666 & ~mask);
  if (::rename(temp_path_.c_str(), target_.c_str()) != 0)
    return Error(ErrorCode::kIo, "rename into place failed: " + errno_text());
  renamed_ = true;
  // Make the rename itself durable.
  int dir_fd = ::open(dir_of(target_).c_str(), O_RDONLY | O_DIRECTORY);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
  ::close(spill_fd_);
  spill_fd_ = -1;
  return Status::Ok();
}

}  // namespace

Expected<std::unique_ptr<PageFileWriter>> PageFileWriter::create(const std::string& path,
                                                                 const PageFileDesc& desc) {
  Status g = desc.geometry.validate();
  if (!g.ok()) return g.with_context(path);
  if (desc.layers.empty() || desc.layers.size() > kMaxLayers)
    return Error(ErrorCode::kInvalidArgument, path + ": a page file has 1..16 layers, not " +
                                                  std::to_string(desc.layers.size()));
  for (size_t i = 0; i < desc.layers.size(); ++i) {
    std::string problem = layer_problem(desc.layers[i]);
    if (problem.empty() && desc.layers[i].codec == PageCodec::kDct &&
        desc.geometry.page_size() % 8 != 0)
      problem = "dct pages need a page size that is a multiple of 8";
    for (size_t j = 0; j < i && problem.empty(); ++j)
      if (desc.layers[j].name == desc.layers[i].name)
        problem = "name used by layer " + std::to_string(j);
    if (!problem.empty())
      return Error(ErrorCode::kInvalidArgument, path + ": layer " + std::to_string(i) + " \"" +
                                                    desc.layers[i].name + "\": " + problem);
  }
  // The temporary lives beside what is really replaced: a symlink's target, never a device.
  VT_ASSIGN_OR_RETURN(std::string target, resolve_output_path(path));
  auto writer = std::make_unique<PageFileWriterImpl>(path, std::move(target), desc);
  VT_RETURN_IF_ERROR(writer->init());
  return std::unique_ptr<PageFileWriter>(std::move(writer));
}

}  // namespace vt
