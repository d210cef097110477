// Replaces the global operator new of the scene test binary to record the largest allocation
// made while a probe is active (alloc_probe.h), and checks the probe itself.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

#include "tests/scene/alloc_probe.h"

namespace {

std::atomic<bool> g_probing{false};
std::atomic<size_t> g_largest{0};

void* allocate(size_t n) {
  if (g_probing.load(std::memory_order_relaxed)) {
    size_t seen = g_largest.load(std::memory_order_relaxed);
    while (n > seen && !g_largest.compare_exchange_weak(seen, n)) {
    }
  }
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}

}  // namespace

void* operator new(size_t n) {
  return allocate(n);
}
void* operator new[](size_t n) {
  return allocate(n);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, size_t) noexcept {
  std::free(p);
}

namespace vt::test {

size_t largest_allocation_during(const std::function<void()>& fn) {
  g_largest = 0;
  g_probing = true;
  fn();
  g_probing = false;
  return g_largest;
}

TEST(AllocProbe, SeesTheLargestAllocation) {
  size_t largest = largest_allocation_during([] {
    std::vector<char> small(100), big(10 << 20);
    big[5] = small[5];
  });
  EXPECT_EQ(largest, size_t{10} << 20);
}

}  // namespace vt::test
