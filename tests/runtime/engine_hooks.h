// Engine hooks for runtime tests: a job system whose jobs the test runs when and how it likes,
// and an allocator that counts (and can refuse) what the runtime asks for.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <mutex>
#include <new>
#include <utility>

#include "runtime/page_buffer.h"

namespace vt::testing {

// Jobs are queued by submit and run by run_all() (newest first, so that run order differs from
// submit order), or inside submit when `inline_run` is set.
class TestJobQueue {
 public:
  bool inline_run = false;

  JobSystem hook() { return {&TestJobQueue::submit, this}; }
  // Runs queued jobs (and the ones they submit) until none is left; returns how many ran.
  size_t run_all() {
    size_t n = 0;
    for (;;) {
      std::pair<void (*)(void*), void*> job;
      {
        std::lock_guard lock(mutex_);
        if (jobs_.empty()) return n;
        job = jobs_.back();
        jobs_.pop_back();
      }
      job.first(job.second);
      ++n;
    }
  }
  size_t queued() {
    std::lock_guard lock(mutex_);
    return jobs_.size();
  }
  size_t submitted() const { return submitted_; }

 private:
  static void submit(void (*run)(void*), void* job, void* user) {
    auto* q = static_cast<TestJobQueue*>(user);
    ++q->submitted_;
    if (q->inline_run) {
      run(job);
      return;
    }
    std::lock_guard lock(q->mutex_);
    q->jobs_.push_back({run, job});
  }
  std::mutex mutex_;
  std::deque<std::pair<void (*)(void*), void*>> jobs_;
  std::atomic<size_t> submitted_{0};
};

// Counts live allocations and bytes; refuses every allocation once `fail_after` have been made.
class CountingAllocator {
 public:
  std::atomic<int64_t> live_blocks{0}, live_bytes{0}, allocations{0};
  std::atomic<int64_t> misaligned{0}, size_mismatches{0};
  int64_t fail_after = INT64_MAX;

  Allocator hook() { return {&CountingAllocator::allocate, &CountingAllocator::release, this}; }

 private:
  static void* allocate(size_t bytes, size_t alignment, void* user) {
    auto* a = static_cast<CountingAllocator*>(user);
    if (a->allocations.fetch_add(1) >= a->fail_after) return nullptr;
    // The size travels in a header so that release can check it is given back unchanged.
    auto* base = static_cast<uint8_t*>(::operator new(bytes + 64, std::align_val_t(64)));
    *reinterpret_cast<size_t*>(base) = bytes;
    uint8_t* p = base + 64;
    if (reinterpret_cast<uintptr_t>(p) % alignment != 0) a->misaligned++;
    a->live_blocks++;
    a->live_bytes += int64_t(bytes);
    return p;
  }
  static void release(void* memory, size_t bytes, void* user) {
    auto* a = static_cast<CountingAllocator*>(user);
    uint8_t* base = static_cast<uint8_t*>(memory) - 64;
    if (*reinterpret_cast<size_t*>(base) != bytes) a->size_mismatches++;
    a->live_blocks--;
    a->live_bytes -= int64_t(bytes);
    ::operator delete(base, std::align_val_t(64));
  }
};

}  // namespace vt::testing
