// Engine hooks of the runtime: where page-sized memory comes from (Allocator) and who runs the
// decode/transcode work (JobSystem). Both are plain function pointers plus a user pointer, so
// the C API (runtime/vt_runtime_c.h) hands them through unchanged.
//
// Every page-sized buffer the runtime allocates (the loader's staging pages, the uploads handed
// to the engine, the decode scratch of a page) is a PageBuffer from the Allocator; that is the
// runtime's memory in proportion to its budget. Bookkeeping of a size fixed at open (hash
// tables, the page table, the presence map) uses operator new.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <new>
#include <span>
#include <utility>

namespace vt {

struct Allocator {
  // `bytes` > 0 bytes aligned to `alignment` (a power of two, at most 4096), or null when out
  // of memory (the page then fails to load; the runtime falls back to its parent). Called from
  // any thread the runtime works on: must be thread-safe.
  void* (*allocate)(size_t bytes, size_t alignment, void* user) = nullptr;
  // Frees what allocate returned, with the same size.
  void (*release)(void* memory, size_t bytes, void* user) = nullptr;
  void* user = nullptr;

  // Both set or both null (null: the C++ runtime's aligned operator new).
  bool valid() const { return (allocate == nullptr) == (release == nullptr); }
};

struct JobSystem {
  // Runs `run(job)` exactly once, on any thread, at any later time or from inside submit. Each
  // job is short (one page: a read, a decode, a BC encode: 0.2-2 ms) and never waits on another
  // job. Called from the thread that calls Streamer::update / PageLoader::request.
  void (*submit)(void (*run)(void* job), void* job, void* user) = nullptr;
  void* user = nullptr;

  bool enabled() const { return submit != nullptr; }
};

// A move-only, zero-filled byte buffer from an Allocator. Empty (data() null) when the
// allocator failed or `bytes` was 0.
class PageBuffer {
 public:
  static constexpr size_t kAlignment = 64;  // a cache line; SIMD loads need no more

  PageBuffer() = default;
  PageBuffer(size_t bytes, const Allocator& allocator) : allocator_(allocator) {
    if (bytes == 0) return;
    void* p = allocator_.allocate
                  ? allocator_.allocate(bytes, kAlignment, allocator_.user)
                  : ::operator new(bytes, std::align_val_t(kAlignment), std::nothrow);
    if (!p) return;
    std::memset(p, 0, bytes);
    data_ = static_cast<uint8_t*>(p);
    size_ = bytes;
  }
  ~PageBuffer() { reset(); }
  PageBuffer(PageBuffer&& other) noexcept
      : data_(std::exchange(other.data_, nullptr)),
        size_(std::exchange(other.size_, 0)),
        allocator_(other.allocator_) {}
  PageBuffer& operator=(PageBuffer&& other) noexcept {
    if (this != &other) {
      reset();
      data_ = std::exchange(other.data_, nullptr);
      size_ = std::exchange(other.size_, 0);
      allocator_ = other.allocator_;
    }
    return *this;
  }
  PageBuffer(const PageBuffer&) = delete;
  PageBuffer& operator=(const PageBuffer&) = delete;

  uint8_t* data() { return data_; }
  const uint8_t* data() const { return data_; }
  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  uint8_t& operator[](size_t i) { return data_[i]; }
  const uint8_t& operator[](size_t i) const { return data_[i]; }
  uint8_t* begin() { return data_; }
  uint8_t* end() { return data_ + size_; }
  const uint8_t* begin() const { return data_; }
  const uint8_t* end() const { return data_ + size_; }
  std::span<uint8_t> span() { return {data_, size_}; }
  std::span<const uint8_t> span() const { return {data_, size_}; }
  operator std::span<uint8_t>() { return span(); }
  operator std::span<const uint8_t>() const { return span(); }

  void reset() {
    if (!data_) return;
    if (allocator_.release)
      allocator_.release(data_, size_, allocator_.user);
    else
      ::operator delete(data_, std::align_val_t(kAlignment));
    data_ = nullptr;
    size_ = 0;
  }

 private:
  uint8_t* data_ = nullptr;
  size_t size_ = 0;
  Allocator allocator_;
};

}  // namespace vt
