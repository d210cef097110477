// The one thread-count rule and the one parallel loop that every stage uses. Header-only and
// dependency-free, so the runtime side (format/, runtime/) can use it too.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <functional>
#include <thread>
#include <vector>

namespace vt {

// The threads a stage runs on: `requested` when positive, otherwise all cores (at least 1).
inline int thread_count(int requested) {
  if (requested > 0) return requested;
  const unsigned n = std::thread::hardware_concurrency();
  return n == 0 ? 1 : int(n);
}

// Runs fn(i) for every i in [0, n) on up to thread_count(threads) threads, the calling thread
// among them, and returns when all are done. Items are handed out one at a time in index order.
// Each item must write only its own results, so the outcome never depends on the thread count.
// `on_done(k)`, when given, runs on the calling thread after k items have finished (k grows
// to n; a worker's completions are seen when the calling thread finishes its next item).
template <typename Fn>
void parallel_for(size_t n, int threads, Fn&& fn,
                  const std::function<void(size_t)>& on_done = nullptr) {
  const size_t workers = std::min<size_t>(size_t(thread_count(threads)), std::max<size_t>(n, 1));
  if (workers <= 1) {
    for (size_t i = 0; i < n; ++i) {
      fn(i);
      if (on_done) on_done(i + 1);
    }
    return;
  }
  std::atomic<size_t> next{0}, done{0};
  auto work = [&](bool caller) {
    for (size_t i; (i = next.fetch_add(1)) < n;) {
      fn(i);
      const size_t d = done.fetch_add(1) + 1;
      if (caller && on_done) on_done(d);
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(workers - 1);
  for (size_t t = 1; t < workers; ++t) pool.emplace_back(work, false);
  work(true);
  for (auto& t : pool) t.join();
  if (on_done) on_done(n);
}

}  // namespace vt
