// Asynchronous page loading: worker threads (or the engine's job system) read, decode and
// transcode pages (through a PageSource) off the calling thread. The caller queues requests with a
// priority, cancels the ones no longer needed and collects finished pages; none of these calls
// waits for I/O or decoding (they only take a short internal lock). Thread-safe.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "common/status.h"
#include "format/page_geometry.h"
#include "runtime/page_buffer.h"
#include "runtime/page_source.h"

namespace vt {

struct LoaderOptions {
  uint32_t threads = 2;         // worker threads (1..256); ignored with a job system
  uint32_t max_in_flight = 64;  // queued + loading + finished-but-not-collected pages
  // When enabled, the loader starts no thread: each request() submits one job, which loads the
  // best-priority queued page when it runs (so priorities hold whatever order jobs run in).
  // A job that runs after the loader is destroyed returns at once.
  JobSystem jobs;
  Allocator allocator;  // the pages' upload buffers
};

// Lower sorts first: coarser level, then more pixels, then request order.
struct LoadPriority {
  uint32_t level = 0;
  uint32_t pixels = 0;
};

struct LoadedPage {
  PageId id;
  Status status;                   // not ok: the source failed (layers is empty)
  std::vector<PageBuffer> layers;  // upload bytes per layer
};

class PageLoader {
 public:
  static Expected<std::unique_ptr<PageLoader>> create(std::shared_ptr<const PageSource> source,
                                                      const LoaderOptions& options);
  // Cancels everything, joins the workers and waits for jobs already running (jobs submitted
  // but not started are not waited for).
  ~PageLoader();
  PageLoader(const PageLoader&) = delete;
  PageLoader& operator=(const PageLoader&) = delete;

  // Queues a page. False when it is already queued/loading/finished or max_in_flight is reached.
  bool request(const PageId& id, LoadPriority priority);
  // Updates the priority of a queued page (no-op otherwise).
  void reprioritise(const PageId& id, LoadPriority priority);
  // Drops a page: removed from the queue, or its result discarded when it finishes. Finished
  // pages not yet collected are dropped too. True when something was dropped.
  bool cancel(const PageId& id);
  // Whether a page is queued, loading or finished but not collected.
  bool pending(const PageId& id) const;
  // Moves finished pages into `out` (appended) in a deterministic order: priority order, then
  // request order. Never waits.
  void collect(std::vector<LoadedPage>& out);
  // Number of pages queued, loading or finished but not collected.
  uint32_t in_flight() const;
  // Blocks until nothing is queued or loading (finished pages stay until collected). For tools,
  // tests and the validation renderer, which want every frame to converge deterministically.
  // With a job system this needs the engine to run the submitted jobs meanwhile.
  void wait_idle();

 private:
  struct Impl;
  explicit PageLoader(std::shared_ptr<Impl> impl);
  std::shared_ptr<Impl> impl_;  // shared with submitted jobs, which may outlive the loader
};

}  // namespace vt
